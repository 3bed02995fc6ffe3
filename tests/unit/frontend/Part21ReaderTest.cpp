#include "frontend/part21/Part21File.h"

#include <catch2/catch.hpp>

using namespace stepnc;
using namespace stepnc::p21;

namespace {

struct Loaded {
  std::unique_ptr<SourceFile> source;
  std::unique_ptr<Part21File> file;
  DiagnosticCollector diags;

  /// "line:col: message" for each diagnostic, notes excluded.
  std::vector<std::string> messages() const {
    std::vector<std::string> out;
    for (const Diagnostic &d : diags.diags) {
      std::string where;
      if (d.loc.valid()) {
        LineCol lc = d.loc.file->lineCol(d.loc.offset);
        where = std::to_string(lc.line) + ":" + std::to_string(lc.col) + ": ";
      }
      out.push_back(where + std::string(severityName(d.severity)) + ": " + d.message);
    }
    return out;
  }
  size_t errors() const {
    size_t n = 0;
    for (const Diagnostic &d : diags.diags)
      n += d.severity == Severity::Error;
    return n;
  }
};

std::unique_ptr<Loaded> load(std::string_view text, bool check = true) {
  auto l = std::make_unique<Loaded>();
  l->source = SourceFile::fromString("t.stp", text);
  DiagnosticEngine engine(l->diags);
  l->file = readPart21(*l->source, engine);
  if (check)
    checkInstances(*l->file, engine);
  return l;
}

const std::string kHeader = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
                            "FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('S'));\nENDSEC;\n";

std::string withData(std::string_view data) {
  return kHeader + "DATA;\n" + std::string(data) + "ENDSEC;\nEND-ISO-10303-21;\n";
}

bool contains(const std::vector<std::string> &msgs, std::string_view needle) {
  for (const auto &m : msgs)
    if (m.find(needle) != std::string::npos)
      return true;
  return false;
}

} // namespace

TEST_CASE("a minimal file reads clean and builds the instance table", "[part21]") {
  auto l = load(withData("#1=CARTESIAN_POINT('',(1.,2.,3.));\n#2 = DIRECTION ( 'd' , ( 0., 0., 1. ) ) ;\n"));
  CHECK(l->messages().empty());
  REQUIRE(l->file->entries().size() == 2);
  CHECK(l->file->entityName(l->file->entries()[0]) == "CARTESIAN_POINT");
  CHECK(l->file->find(2) != nullptr);
  CHECK(l->file->find(3) == nullptr);
  CHECK(l->file->schemaNames() == std::vector<std::string>{"S"});
}

TEST_CASE("every parameter kind decodes", "[part21]") {
  auto l = load(withData("#7=E(1,-2,+3,1.5,-2.E-3,1.0e+2,'s',\"0F\",.T.,#7,$,*,(),((1),(2,3)),"
                         "LENGTH_MEASURE(2.5));\n"));
  REQUIRE(l->messages().empty());
  ValueArena arena;
  REQUIRE(l->file->decodeInstance(0, arena, nullptr));
  auto p = arena.params(arena.records()[0]);
  REQUIRE(p.size() == 15);
  CHECK(p[0].kind == ValueKind::Integer);
  CHECK(p[0].integer == 1);
  CHECK(p[1].integer == -2);
  CHECK(p[2].integer == 3);
  CHECK(p[3].kind == ValueKind::Real);
  CHECK(p[3].real == 1.5);
  CHECK(p[4].real == -0.002);
  CHECK(p[5].real == 100.0);
  CHECK(p[6].kind == ValueKind::String);
  CHECK(p[6].str() == "s");
  CHECK(p[7].kind == ValueKind::Binary);
  CHECK(p[7].str() == "0F");
  CHECK(p[8].kind == ValueKind::Enumeration);
  CHECK(p[8].str() == "T");
  CHECK(p[9].kind == ValueKind::Reference);
  CHECK(p[9].ref == 7);
  CHECK(p[10].kind == ValueKind::Unset);
  CHECK(p[11].kind == ValueKind::Derived);
  CHECK(p[12].kind == ValueKind::List);
  CHECK(p[12].count == 0);
  REQUIRE(p[13].count == 2);
  auto inner = arena.children(p[13]);
  CHECK(arena.children(inner[1]).size() == 2);
  CHECK(arena.children(inner[1])[1].integer == 3);
  CHECK(p[14].kind == ValueKind::Typed);
  CHECK(l->file->names().name(p[14].node.name) == "LENGTH_MEASURE");
  CHECK(arena.children(p[14])[0].real == 2.5);
  // Offsets point at each value in the source.
  const auto &e = l->file->entries()[0];
  CHECK(l->source->text().substr(e.begin() + p[6].offset, 3) == "'s'");
}

TEST_CASE("complex instances decode into their records", "[part21]") {
  auto l = load(withData("#20=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));\n"));
  REQUIRE(l->messages().empty());
  const auto &e = l->file->entries()[0];
  CHECK(e.name() == kComplexInstance);
  CHECK(l->file->describe(e) == "NAMED_UNIT+PLANE_ANGLE_UNIT+SI_UNIT");
  ValueArena arena;
  REQUIRE(l->file->decodeInstance(0, arena, nullptr));
  REQUIRE(arena.records().size() == 3);
  CHECK(arena.params(arena.records()[2])[1].str() == "RADIAN");
}

TEST_CASE("string escapes decode to UTF-8", "[part21]") {
  auto l = load(withData("#1=S('it''s','a\\\\b','\\S\\D','\\X\\E9','\\X2\\00E9263A\\X0\\',"
                         "'\\X4\\0001F600\\X0\\','\\PB\\\\S\\1','split\nline','\\X2\\D83DDE00\\X0\\');\n"));
  REQUIRE(l->messages().empty());
  ValueArena arena;
  REQUIRE(l->file->decodeInstance(0, arena, nullptr));
  auto p = arena.params(arena.records()[0]);
  CHECK(p[0].str() == "it's");
  CHECK(p[1].str() == "a\\b");
  CHECK(p[2].str() == "\xC3\x84");          // \S\D = 0xC4 = Ä
  CHECK(p[3].str() == "\xC3\xA9");          // é
  CHECK(p[4].str() == "\xC3\xA9\xE2\x98\xBA");  // é☺
  CHECK(p[5].str() == "\xF0\x9F\x98\x80");  // U+1F600
  CHECK(p[6].str() == "\xC4\x85");          // ISO 8859-2 0xB1 = ą
  CHECK(p[7].str() == "splitline");
  CHECK(p[8].str() == "\xF0\x9F\x98\x80");  // surrogate pair
}

TEST_CASE("edition 3 sections are read", "[part21]") {
  std::string text = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'3;1');\n"
                     "FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('S'));\nENDSEC;\n"
                     "ANCHOR;\n<origin>=#1;\n<pair>=(#1,#2);\nENDSEC;\n"
                     "REFERENCE;\n#9=<other.stp#x>;\nENDSEC;\n"
                     "DATA('first',('S'));\n#1=A(#9);\nENDSEC;\n"
                     "DATA('second',('S'));\n#2=B(#1);\nENDSEC;\n"
                     "SIGNATURE;\nabc\nENDSEC;\nEND-ISO-10303-21;\n";
  auto l = load(text);
  auto msgs = l->messages();
  REQUIRE(msgs.size() == 1);
  CHECK(msgs[0].find("warning: SIGNATURE section") != std::string::npos);
  CHECK(l->file->anchors().size() == 2);
  CHECK(l->file->references().size() == 1);
  REQUIRE(l->file->sections().size() == 2);
  CHECK(l->file->sections()[1].params[0].str() == "second");
  CHECK(l->file->isDefined(9));
}

TEST_CASE("a UTF-8 byte order mark is skipped with a warning", "[part21]") {
  auto l = load("\xEF\xBB\xBF" + withData("#1=A();\n"));
  CHECK(l->messages() == std::vector<std::string>{"1:1: warning: UTF-8 byte order mark at the start of the file ignored"});
  CHECK(l->file->entries().size() == 1);
}

TEST_CASE("sparse large ids use the sorted index", "[part21]") {
  auto l = load(withData("#3595070=A(#5);\n#5=B(#3595070);\n#900000000000=C(#5);\n"));
  CHECK(l->messages().empty());
  CHECK(l->file->find(900000000000ull) != nullptr);
  CHECK(l->file->indexOf(5) == 1);
}

TEST_CASE("errors are located precisely", "[part21]") {
  SECTION("dangling reference at the use site, with a note") {
    auto l = load(withData("#1=A(#2,\n  #3);\n#2=B();\n"));
    auto m = l->messages();
    REQUIRE(m.size() == 1);
    CHECK(m[0] == "9:3: error: reference to #3, which is not defined");
    CHECK(l->diags.diags[0].entityId == 1);
    CHECK(l->diags.diags[0].notes.size() == 1);
  }
  SECTION("duplicate id, note at the first definition") {
    auto l = load(withData("#1=A();\n#1=B();\n"));
    auto m = l->messages();
    REQUIRE(m.size() == 1);
    CHECK(m[0] == "9:1: error: duplicate instance id #1");
    LineCol first = l->source->lineCol(l->diags.diags[0].notes[0].loc.offset);
    CHECK(first.line == 8);
  }
  SECTION("unterminated string") {
    auto l = load(withData("#1=A('abc);\n"));
    CHECK(contains(l->messages(), "8:6: error: unterminated string"));
    CHECK(l->errors() == 1);
  }
  SECTION("unterminated comment") {
    auto l = load(withData("#1=A(); /* never closed\n"));
    CHECK(contains(l->messages(), "8:9: error: unterminated comment"));
  }
  SECTION("bad token inside parameters") {
    auto l = load(withData("#1=A(1,?);\n"));
    CHECK(l->messages() == std::vector<std::string>{
                               "8:8: error: unexpected '?' where a parameter was expected"});
  }
  SECTION("missing semicolon is caught at the closing parenthesis") {
    auto l = load(withData("#1=A(1)\n#2=B(#1);\n"));
    CHECK(contains(l->messages(), "8:8: error: expected ';' at end of instance"));
    CHECK(l->file->find(2) != nullptr);  // reading went on
  }
  SECTION("non-ASCII byte outside strings") {
    auto l = load(withData("#1=A(1,\xC3\xA9);\n"));
    CHECK(contains(l->messages(), "8:8: error: non-ASCII byte outside a string"));
  }
  SECTION("missing ENDSEC before END-ISO-10303-21") {
    auto l = load(kHeader + "DATA;\n#1=A();\nEND-ISO-10303-21;\n");
    CHECK(contains(l->messages(), "9:1: error: missing 'ENDSEC;' before 'END-ISO-10303-21'"));
  }
  SECTION("missing END-ISO-10303-21") {
    auto l = load(kHeader + "DATA;\n#1=A();\nENDSEC;\n");
    CHECK(contains(l->messages(), "10:1: error: missing 'END-ISO-10303-21;' at end of file"));
  }
  SECTION("truncated in the middle of an instance") {
    auto l = load(kHeader + "DATA;\n#1=A(1,2");
    CHECK(l->errors() >= 1);
    CHECK(contains(l->messages(), "8:1: error: instance is not terminated"));
  }
  SECTION("not a Part 21 file") {
    auto l = load("\x7F" "ELF\x01\x02garbage");
    CHECK(l->messages() == std::vector<std::string>{
                               "1:1: error: not a Part 21 file: expected 'ISO-10303-21;' at the start"});
  }
  SECTION("empty file") {
    auto l = load("");
    CHECK(l->messages() == std::vector<std::string>{"1:1: error: empty file: expected 'ISO-10303-21;'"});
  }
  SECTION("nesting deeper than the limit is rejected without recursion overflow") {
    std::string deep(100000, '(');
    auto l = load(withData("#1=A(" + deep + ");\n"));
    CHECK(contains(l->messages(), "nested deeper than 128 levels"));
  }
  SECTION("a real needs its decimal point") {
    auto l = load(withData("#1=A(1E5);\n"));
    CHECK(contains(l->messages(), "8:6: error: a real needs a decimal point"));
  }
  SECTION("several errors are collected") {
    auto l = load(withData("#1=A(?);\n#2=B(#99);\n#3=C('x'y);\n"));
    CHECK(l->errors() == 3);
  }
}
