// Part 28 XML: Part 21 -> XML -> Part 21 gives the same instance graph (hand
// made files covering every kind of value, and the whole corpus), the terse
// form reads, and diagnostics of every stage point into the XML.
#include "../TestSupport.h"
#include "frontend/binding/Aliases.h"
#include "frontend/binding/Binder.h"
#include "frontend/express/Builtin.h"
#include "frontend/part21/Part21File.h"
#include "frontend/part21/Writer.h"
#include "frontend/part28/Reader.h"
#include "frontend/part28/Writer.h"

#include <catch2/catch.hpp>
#include <random>

using namespace stepnc;

namespace {

const express::Schema *chooseBuiltin(const std::vector<std::string> &names, const express::Model *&model) {
  model = &express::builtinModel();
  return express::builtinSchemaFor(names.empty() ? std::vector<std::string>{"ISO14649_ARM"} : names);
}

/// A Part 21 file read, checked and bound to the built-in schema.
struct Loaded {
  std::unique_ptr<SourceFile> source;
  std::unique_ptr<p21::Part21File> file;
  std::unique_ptr<binding::BoundFile> bound;
  DiagnosticCollector collector;
  unsigned part21Errors = 0; ///< syntax errors, before binding
};

std::unique_ptr<Loaded> loadPart21(std::unique_ptr<SourceFile> source) {
  auto l = std::make_unique<Loaded>();
  l->source = std::move(source);
  DiagnosticEngine diags(l->collector);
  l->file = p21::readPart21(*l->source, diags);
  l->part21Errors = diags.errorCount(); // binding adds the reference check
  const express::Model *model = nullptr;
  const express::Schema *schema = chooseBuiltin(l->file->schemaNames(), model);
  if (schema) {
    binding::BindOptions lenient;
    lenient.lenient = true;
    l->bound = binding::bind(*l->file, *model, *schema, diags, lenient);
  }
  return l;
}

std::string toXml(const Loaded &l) {
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  bool ok = false;
  std::string xml = p28::writePart28ToString(*l.bound, diags, &ok);
  for (const Diagnostic &d : c.diags)
    if (d.severity == Severity::Error)
      FAIL(d.message);
  REQUIRE(ok);
  return xml;
}

/// Reads XML text through the translation; the Loaded keeps the collector.
std::unique_ptr<Loaded> fromXml(std::string_view xml, const std::string &name = "test.stpx") {
  auto l = std::make_unique<Loaded>();
  DiagnosticEngine diags(l->collector);
  std::unique_ptr<SourceFile> source = SourceFile::fromString(name, xml);
  auto translated = p28::translatePart28(source, chooseBuiltin, diags);
  if (!translated) {
    l->source = std::move(source);
    return l;
  }
  auto read = loadPart21(std::move(translated));
  read->collector.diags.insert(read->collector.diags.begin(), l->collector.diags.begin(), l->collector.diags.end());
  return read;
}

/// The errors as "line:col: #id message" (or without the position).
std::vector<std::string> errors(const Loaded &l, bool located = true) {
  std::vector<std::string> out;
  for (const Diagnostic &d : l.collector.diags) {
    if (d.severity != Severity::Error)
      continue;
    std::string s;
    if (located) {
      const LineCol lc = d.loc.file ? d.loc.file->lineCol(d.loc.offset) : LineCol{};
      s += std::to_string(lc.line);
      s += ':';
      s += std::to_string(lc.col);
      s += ": ";
    }
    if (d.entityId) {
      s += '#';
      s += std::to_string(d.entityId);
      s += ' ';
    }
    s += d.message;
    out.push_back(std::move(s));
  }
  return out;
}

/// The entity names of `a` as the schema spells them, for graphs written
/// through an alias.
p21::NameMap schemaNames() {
  return [](std::string_view name) {
    const std::string_view entity = binding::AliasTable::builtin().entity(name);
    if (entity.empty())
      return std::string(name);
    std::string upper(entity);
    for (char &c : upper)
      c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return upper;
  };
}

// Every kind of value the mapping has a rule for.
constexpr std::string_view kEveryKind = R"(ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('a & b <c>','second line'),'4;1');
FILE_NAME('every kind','2026-11-22T00:00:00',('one','two'),(),'pre','sys','');
FILE_SCHEMA(('MACHINING_SCHEMA','MILLING_SCHEMA'));
ENDSEC;
ANCHOR;
<origin>=#1;
ENDSEC;
DATA;
#1=CARTESIAN_POINT('o''k \X2\00E9\X0\ \X\09tab ]]> "q"',(0.,-0.,1.E-05));
#2=CARTESIAN_POINT($,(1.5,2.5,3.));
#3=DIRECTION('d',(0.,0.,1.));
#4=LINE('l',#1,#5);
#5=VECTOR('v',#3,10.);
#6=TRIMMED_CURVE('t',#4,(#1,PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.5)),.T.,.PARAMETER.);
#8=CUTTER_LOCATION_TRAJECTORY(.T.,.APPROACH.,SPEED_NAME(.RAPID.),$,$,$,#6,$,$);
#7=(B_SPLINE_SURFACE(1,1,((#1,#2),(#1,#2)),.PLANE_SURF.,.F.,.T.,.U.)BOUNDED_SURFACE()GEOMETRIC_REPRESENTATION_ITEM()RATIONAL_B_SPLINE_SURFACE(((1.,2.5),(3.,4.)))REPRESENTATION_ITEM()SURFACE('s'));
ENDSEC;
DATA('second',('MILLING_SCHEMA'));
#20=CARTESIAN_POINT('in the second section',(5.,5.,5.));
ENDSEC;
END-ISO-10303-21;
)";

} // namespace

TEST_CASE("Part 21 -> Part 28 -> Part 21 keeps every kind of value", "[part28]") {
  auto original = loadPart21(SourceFile::fromString("every.stp", kEveryKind));
  REQUIRE(errors(*original).empty());
  const std::string xml = toXml(*original);
  // Spot checks of the mapping (docs/part28.md).
  CHECK(xml.find("<exp:documentation>a &amp; b &lt;c&gt;</exp:documentation>") != std::string::npos);
  CHECK(xml.find("<?stepnc-p21 implementation_level=\"4;1\"?>") != std::string::npos);
  CHECK(xml.find("<?stepnc-p21-anchor <origin>=#1;?>") != std::string::npos);
  CHECK(xml.find("<?stepnc-p21-data ('second',('MILLING_SCHEMA'))?>") != std::string::npos);
  CHECK(xml.find("<Coordinates exp:cType=\"list\"><Length_measure>0.</Length_measure><Length_measure>-0."
                 "</Length_measure><Length_measure>1.E-05</Length_measure></Coordinates>") != std::string::npos);
  CHECK(xml.find("<Trim_1 exp:cType=\"set\"><Cartesian_point ref=\"i1\" xsi:nil=\"true\"/>"
                 "<Parameter_value>0.</Parameter_value></Trim_1>") != std::string::npos);
  CHECK(xml.find("<Control_points_list exp:cType=\"list\"><exp:list><Cartesian_point ref=\"i1\"") != std::string::npos);
  CHECK(xml.find("<Weights_data exp:cType=\"list\"><exp:list><exp:double>1.</exp:double>") != std::string::npos);
  CHECK(xml.find("<Self_intersect>unknown</Self_intersect>") != std::string::npos);
  CHECK(xml.find("<Its_speed><Speed_name>rapid</Speed_name></Its_speed>") != std::string::npos);
  CHECK(xml.find("<Sense_agreement>true</Sense_agreement>") != std::string::npos);
  CHECK(xml.find("<Master_representation>parameter</Master_representation>") != std::string::npos);
  CHECK(xml.find("&#9;tab ]]&gt; &quot;q&quot;") != std::string::npos);
  CHECK(xml.find("<B_spline_surface-bounded_surface-geometric_representation_item-rational_b_spline_surface-"
                 "representation_item-surface id=\"i7\">") != std::string::npos);
  CHECK(xml.find("<Name>") == xml.find("<Name>o'k é")); // the first name, UTF-8 as is

  auto back = fromXml(xml);
  REQUIRE(errors(*back).empty());
  CHECK(p21::compareGraphs(*original->file, *back->file) == "");
}

TEST_CASE("Part 28 writing canonicalises what only Part 21 drift can say", "[part28]") {
  // An integer where a REAL is declared reads as a real; Part 28 says so.
  auto original = loadPart21(SourceFile::fromString("int.stp", R"(ISO-10303-21;
HEADER;
FILE_DESCRIPTION((''),'2;1');
FILE_NAME('','',(''),(''),'','','');
FILE_SCHEMA(('MACHINING_SCHEMA'));
ENDSEC;
DATA;
#1=CARTESIAN_POINT('p',(1,2,3.5));
#2=TOOL_DIMENSION(20.,0.,0.,8.,0.,0.,0.);
ENDSEC;
END-ISO-10303-21;
)"));
  const std::string xml = toXml(*original);
  CHECK(xml.find("<Length_measure>1.</Length_measure><Length_measure>2.</Length_measure>") != std::string::npos);
  CHECK(xml.find("<Milling_tool_dimension id=\"i2\">") != std::string::npos);
  auto back = fromXml(xml);
  REQUIRE(errors(*back).empty());
  CHECK(p21::compareGraphs(*original->file, *back->file, schemaNames()) ==
        "#1 differs: CARTESIAN_POINT('p',(1,2,3.5)) vs CARTESIAN_POINT('p',(1.,2.,3.5))");
}

TEST_CASE("the terse form reads as the default form does", "[part28]") {
  auto terse = fromXml(R"(<?xml version="1.0"?>
<iso_10303_28_terse express="MACHINING_SCHEMA">
  <Cartesian_point id="origin" Name="o" Coordinates="0 0 10"/>
  <Direction id="i7" Name="z" Direction_ratios="0 0 1"/>
  <Axis2_placement_3d id="i8" Name="" Location="origin" Axis="#7">
    <Ref_direction><Direction Name="x" Direction_ratios="1 0 0"/></Ref_direction>
  </Axis2_placement_3d>
</iso_10303_28_terse>
)");
  REQUIRE(errors(*terse).empty());
  auto expected = loadPart21(SourceFile::fromString("expected.stp", R"(ISO-10303-21;
HEADER;
FILE_DESCRIPTION((),'2;1');
FILE_NAME('','',(),(),'','','');
FILE_SCHEMA(('MACHINING_SCHEMA'));
ENDSEC;
DATA;
#7=DIRECTION('z',(0.,0.,1.));
#8=AXIS2_PLACEMENT_3D('',#9,#7,#10);
#9=CARTESIAN_POINT('o',(0.,0.,10.));
#10=DIRECTION('x',(1.,0.,0.));
ENDSEC;
END-ISO-10303-21;
)"));
  // Ids that are not numbers get numbers above the largest one, in order of
  // first appearance: "origin" is #9, the inline direction #10.
  CHECK(p21::compareGraphs(*expected->file, *terse->file) == "");
}

TEST_CASE("Part 28 reading errors point at the XML", "[part28]") {
  const std::string head = R"(<?xml version="1.0"?>
<exp:iso_10303_28 xmlns:exp="urn:oid:1.0.10303.28.2.1.1" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
  <uos xmlns="urn:iso10303-28:xs/iso14649_arm" id="uos_1" express="MACHINING_SCHEMA">
)";
  const std::string tail = "  </uos>\n</exp:iso_10303_28>\n";
  auto read = [&](std::string_view body) { return fromXml(head + std::string(body) + tail); };

  SECTION("an unknown element") {
    auto r = read("    <Cartesian_pont id=\"i1\"/>\n");
    CHECK(errors(*r) == std::vector<std::string>{"4:5: #1 <Cartesian_pont> is not an entity of schema 'iso14649_arm'"});
  }
  SECTION("an unknown attribute names the instance") {
    auto r = read("    <Cartesian_point id=\"i1\">\n      <Nmae>x</Nmae>\n    </Cartesian_point>\n");
    CHECK(errors(*r) == std::vector<std::string>{"5:7: #1 <Nmae> is not an attribute of cartesian_point"});
  }
  SECTION("wrong nesting") {
    auto r = read("    <Line id=\"i1\">\n      <Pnt><Name>x</Name></Pnt>\n    </Line>\n");
    CHECK(errors(*r) == std::vector<std::string>{"5:12: #1 <Name> is not expected here: expected <Cartesian_point> "
                                                 "or the element of one of its subtypes"});
  }
  SECTION("a bad value") {
    auto r = read("    <Vector id=\"i1\"><Magnitude>ten</Magnitude></Vector>\n");
    CHECK(errors(*r) == std::vector<std::string>{"4:21: #1 'ten' is not a finite real number"});
  }
  SECTION("a dangling reference is found by the Part 21 check, at the XML element") {
    auto r = read("    <Vector id=\"i1\">\n      <Orientation><Direction ref=\"i9\" xsi:nil=\"true\"/></Orientation>\n"
                  "      <Magnitude>1</Magnitude>\n    </Vector>\n");
    CHECK(errors(*r) == std::vector<std::string>{"5:20: #1 reference to #9, which is not defined"});
  }
  SECTION("a schema error is found by binding, at the XML element") {
    auto r = read("    <Trimmed_curve id=\"i1\"><Master_representation>sideways</Master_representation>"
                  "</Trimmed_curve>\n");
    const auto e = errors(*r);
    REQUIRE(!e.empty());
    INFO(e.front());
    CHECK(e.front().starts_with("4:28: #1 "));
    CHECK(e.front().find("SIDEWAYS") != std::string::npos);
  }
  SECTION("a truncated file") {
    auto r = fromXml(head + "    <Cartesian_point id=\"i1\">\n      <Name>x</Na");
    const auto e = errors(*r);
    REQUIRE(!e.empty());
    CHECK(e.front().starts_with("5:"));
  }
  SECTION("a document type declaration is refused") {
    auto r = fromXml("<?xml version=\"1.0\"?>\n<!DOCTYPE x [<!ENTITY a \"b\">]>\n<iso_10303_28/>\n");
    CHECK(errors(*r).at(0).find("document type declaration") != std::string::npos);
  }
  SECTION("not Part 28") {
    auto r = fromXml("<html/>");
    CHECK(errors(*r) ==
          std::vector<std::string>{"1:1: not a Part 28 document: the root element is <html>, not <iso_10303_28> or "
                                   "<iso_10303_28_terse>"});
  }
}

TEST_CASE("every corpus file with a built-in schema goes through Part 28 unchanged", "[part28][corpus]") {
  const std::string corpus = test::corpusDir();
  if (corpus.empty()) {
    WARN("corpus not found; set STEPNC_CORPUS (skipped)");
    return;
  }
  size_t converted = 0;
  for (auto &[path, source, error] : test::part21FilesBelow(corpus)) {
    INFO(path.string() << ": " << error);
    REQUIRE(source);
    auto original = loadPart21(std::move(source));
    if (!original->bound || original->part21Errors > 0)
      continue; // a schema that is not built in, or syntax errors: convert refuses both
    const std::string xml = toXml(*original);
    auto back = fromXml(xml, path.filename().string() + ".stpx");
    // Schema errors stay what they were (JSDAI-written files have some),
    // now located in the XML.
    CHECK(errors(*back, false) == errors(*original, false));
    CHECK(p21::compareGraphs(*original->file, *back->file, schemaNames()) == "");
    ++converted;
  }
  CHECK(converted >= 27);
}

TEST_CASE("the Part 28 reader survives damaged documents", "[part28]") {
  // Deterministic damage to a written document (cut short, bytes replaced by
  // markup characters, spans deleted or repeated): every variant either
  // reads or is refused with located errors; none crashes or hangs (the
  // sanitizer build runs this too).
  auto original = loadPart21(SourceFile::fromString("every.stp", kEveryKind));
  const std::string xml = toXml(*original);
  std::mt19937 random(2811);
  auto pick = [&](size_t n) { return static_cast<size_t>(random() % std::max<size_t>(n, 1)); };
  const std::string alphabet = "<>/\"=&;#x0 \n?!-ia";
  size_t refused = 0;
  for (int i = 0; i < 300; ++i) {
    std::string damaged = xml;
    switch (i % 4) {
    case 0: damaged.resize(pick(damaged.size())); break;
    case 1:
      for (size_t k = 0, n = 1 + pick(5); k < n; ++k)
        damaged[pick(damaged.size())] = alphabet[pick(alphabet.size())];
      break;
    case 2: {
      const size_t at = pick(damaged.size());
      damaged.erase(at, pick(200));
      break;
    }
    default: {
      const size_t from = pick(damaged.size());
      damaged.insert(pick(damaged.size()), damaged.substr(from, 1 + pick(300)));
    }
    }
    auto read = fromXml(damaged);
    const auto e = errors(*read);
    if (!e.empty()) {
      ++refused;
      for (const std::string &message : e)
        CHECK(!message.starts_with("0:0:"));  // every error is located
    }
  }
  CHECK(refused > 150);
}
