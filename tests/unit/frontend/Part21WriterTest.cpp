#include "frontend/part21/Part21File.h"
#include "frontend/part21/Writer.h"
#include "../TestSupport.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <random>

using namespace stepnc;
using namespace stepnc::p21;

namespace {

struct Read {
  std::unique_ptr<SourceFile> source;
  std::unique_ptr<Part21File> file;
  DiagnosticCollector collector;
  unsigned errors = 0;
};

std::unique_ptr<Read> readText(std::string name, std::string_view text) {
  auto r = std::make_unique<Read>();
  r->source = SourceFile::fromString(std::move(name), text);
  DiagnosticEngine engine(r->collector);
  r->file = readPart21(*r->source, engine);
  checkInstances(*r->file, engine);
  r->errors = engine.errorCount();
  return r;
}

std::string canonical(const Part21File &f) {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  bool ok = false;
  std::string text = writePart21ToString(f, engine, &ok);
  REQUIRE(ok);
  return text;
}

} // namespace

TEST_CASE("the canonical form sorts ids and normalises layout", "[part21][writer]") {
  auto r = readText("in.stp", "ISO-10303-21;\r\nHEADER;\r\nFILE_DESCRIPTION(('d'),'2;1');\r\n"
                              "FILE_NAME('n','t',('a'),('o'),'p','s','x');\r\n"
                              "FILE_SCHEMA(('S'));\r\nENDSEC;\r\nDATA;\r\n"
                              "#10 = B ( 1.50 , 'it''s' , .t. ) ;\r\n/* c */ #2=a(#10,(1.E2,-0.0),$,*);\r\n"
                              "ENDSEC;\r\nEND-ISO-10303-21;\r\n");
  REQUIRE(r->errors == 0);
  CHECK(canonical(*r->file) == "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('d'),'2;1');\n"
                               "FILE_NAME('n','t',('a'),('o'),'p','s','x');\n"
                               "FILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n"
                               "#2=A(#10,(100.,-0.),$,*);\n"
                               "#10=B(1.5,'it''s',.T.);\n"
                               "ENDSEC;\nEND-ISO-10303-21;\n");
}

TEST_CASE("strings re-encode to Part 21 escapes and read back equal", "[part21][writer]") {
  const std::string samples[] = {"plain", "it's", "back\\slash", "\xC3\xA9t\xC3\xA9",
                                 "\xE2\x98\xBA smile", "\xF0\x9F\x98\x80", "tab\there", ""};
  for (const std::string &s : samples) {
    std::string lit;
    appendString(lit, s);
    auto r = readText("s.stp", "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n#1=A(" +
                                   lit + ");\nENDSEC;\nEND-ISO-10303-21;\n");
    INFO("literal " << lit);
    size_t errs = 0;
    for (const auto &d : r->collector.diags)
      errs += d.severity == Severity::Error;
    REQUIRE(errs == 0);
    ValueArena arena;
    REQUIRE(r->file->decodeInstance(0, arena, nullptr));
    CHECK(arena.params(arena.records()[0])[0].str() == s);
  }
  std::string lit;
  appendString(lit, "\xC3\xA9\xE2\x98\xBA");
  CHECK(lit == "'\\X\\E9\\X2\\263A\\X0\\'");
}

TEST_CASE("reals are written with the fewest digits that read back exactly", "[part21][writer]") {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> exp(-30, 30);
  for (int i = 0; i < 2000; ++i) {
    double v = std::ldexp(mant(rng), exp(rng) * 3);
    std::string lit;
    appendReal(lit, v);
    CHECK(lit.find('.') != std::string::npos);
    auto r = readText("r.stp", "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n#1=A(" + lit +
                                   ");\nENDSEC;\nEND-ISO-10303-21;\n");
    REQUIRE(r->errors == 0);
    ValueArena arena;
    REQUIRE(r->file->decodeInstance(0, arena, nullptr));
    double back = arena.params(arena.records()[0])[0].real;
    CHECK(std::memcmp(&back, &v, sizeof v) == 0);
  }
  std::string lit;
  appendReal(lit, 1e-5);
  CHECK(lit == "1.E-05");
}

TEST_CASE("compareGraphs finds a changed value", "[part21][writer]") {
  auto a = readText("a.stp", "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n#1=A(1.,#2);\n#2=B();\nENDSEC;\nEND-ISO-10303-21;\n");
  auto b = readText("b.stp", "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n#2=B();\n#1=A(1.0,#2);\nENDSEC;\nEND-ISO-10303-21;\n");
  auto c = readText("c.stp", "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n#1=A(1.5,#2);\n#2=B();\nENDSEC;\nEND-ISO-10303-21;\n");
  CHECK(compareGraphs(*a->file, *b->file).empty());
  CHECK(compareGraphs(*a->file, *c->file) == "#1 differs: A(1.,#2) vs A(1.5,#2)");
}

TEST_CASE("every corpus Part 21 file round-trips", "[part21][writer][corpus]") {
  const std::string corpus = test::corpusDir();
  if (corpus.empty()) {
    WARN("sample corpus not found (set STEPNC_CORPUS): corpus round trip skipped");
    return;
  }
  size_t files = 0;
  for (const auto &[path, source, error] : test::part21FilesBelow(corpus)) {
    INFO(path.string() << ": " << error);
    REQUIRE(source);
    DiagnosticCollector c;
    DiagnosticEngine engine(c);
    auto first = readPart21(*source, engine);
    checkInstances(*first, engine);
    if (path.filename() == "exp2.stpnc") {
      CHECK(engine.errorCount() > 0);  // truncated on purpose: dangling references
      continue;
    }
    REQUIRE(engine.errorCount() == 0);
    ++files;
    const std::string once = canonical(*first);
    auto second = readText("once.stp", once);
    REQUIRE(second->errors == 0);
    CHECK(compareGraphs(*first, *second->file) == "");
    const std::string twice = canonical(*second->file);
    CHECK(twice == once);
  }
  CHECK(files >= 30);
}
