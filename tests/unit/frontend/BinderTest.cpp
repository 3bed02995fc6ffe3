#include "frontend/binding/Binder.h"
#include "frontend/binding/Instance.h"
#include "frontend/express/SchemaReader.h"
#include "ExpressTestSupport.h"

#include <catch2/catch.hpp>

using namespace stepnc;

namespace {

const char *kSchema = R"(
SCHEMA shop;
TYPE length_measure = REAL; END_TYPE;
TYPE label = STRING; END_TYPE;
TYPE hand = ENUMERATION OF (cw, ccw); END_TYPE;
TYPE measure_select = SELECT (length_measure, count_measure, tool); END_TYPE;
TYPE count_measure = INTEGER; END_TYPE;
ENTITY tool ABSTRACT SUPERTYPE OF (ONEOF (drill, mill));
  name : label;
  diameter : length_measure;
END_ENTITY;
ENTITY drill SUBTYPE OF (tool);
  tip_angle : REAL;
END_ENTITY;
ENTITY mill SUBTYPE OF (tool);
  flutes : INTEGER;
  rotation : hand;
END_ENTITY;
ENTITY coated SUBTYPE OF (tool);
  coating : label;
END_ENTITY;
ENTITY step;
  its_tool : tool;
  passes : LIST [1:3] OF length_measure;
  empty_ok : SET [0:?] OF tool;
  amount : measure_select;
  flag : OPTIONAL BOOLEAN;
END_ENTITY;
ENTITY special_step SUBTYPE OF (step);
DERIVE
  SELF\step.flag : BOOLEAN := TRUE;
END_ENTITY;
END_SCHEMA;
)";

struct Fixture {
  express::Model model;
  binding::AliasTable aliases;
  Fixture() {
    DiagnosticCollector c;
    DiagnosticEngine engine(c);
    REQUIRE(express::readExpress(SourceFile::fromString("shop.exp", kSchema), model, engine));
    REQUIRE(model.resolve(engine));
    std::string error;
    REQUIRE(aliases.parse("# test aliases\nentity BORER drill\n", error));
  }
};

Fixture &fixture() {
  static Fixture f;
  return f;
}

struct Result {
  std::unique_ptr<SourceFile> source;
  std::unique_ptr<p21::Part21File> file;
  std::unique_ptr<binding::BoundFile> bound;
  DiagnosticCollector diags;
  std::vector<std::string> messages;  // "line:col: severity: message" (notes excluded)
};

/// How bindText reads: the binder's default, --strict's or the commands'
/// lenient reading without it (driver::bindOptions).
enum class Reading { Default, Strict, Lenient };

std::unique_ptr<Result> bindText(std::string_view data, Reading reading = Reading::Default) {
  auto r = std::make_unique<Result>();
  r->source = SourceFile::fromString("t.stp", "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
                                              "FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('SHOP'));\n"
                                              "ENDSEC;\nDATA;\n" +
                                                  std::string(data) + "ENDSEC;\nEND-ISO-10303-21;\n");
  DiagnosticEngine engine(r->diags);
  r->file = p21::readPart21(*r->source, engine);
  binding::BindOptions opts;
  opts.aliases = &fixture().aliases;
  opts.strict = reading == Reading::Strict;
  opts.lenient = reading == Reading::Lenient;
  r->bound = binding::bind(*r->file, fixture().model, fixture().model.schemas().front(), engine, opts);
  for (const Diagnostic &d : r->diags.diags) {
    LineCol lc = d.loc.valid() ? d.loc.file->lineCol(d.loc.offset) : LineCol{};
    r->messages.push_back(std::to_string(lc.line) + ":" + std::to_string(lc.col) + ": " +
                          severityName(d.severity) + ": " + d.message);
  }
  return r;
}

const char *kGoodStep = "#1=DRILL('d',10.,118.);\n#2=STEP(#1,(1.,2.),(),LENGTH_MEASURE(3.),.T.);\n";

} // namespace

TEST_CASE("a valid file binds clean and every instance gets its entity", "[binding]") {
  auto r = bindText(kGoodStep);
  CHECK(r->messages.empty());
  const auto &m = fixture().model;
  express::EntityId tool = m.findEntity(m.schemas().front(), "tool");
  CHECK(r->bound->isA(0, tool));
  CHECK(m.entity(r->bound->entity(1)).name == "step");
}

TEST_CASE("binding errors name the instance, attribute, expectation and finding", "[binding]") {
  SECTION("unknown entity, with a suggestion") {
    auto r = bindText("#1=DRIL('d',10.,118.);\n");
    REQUIRE(r->messages.size() == 1);
    CHECK(r->messages[0] == "8:1: error: unknown entity 'DRIL' in schema 'shop'");
    CHECK(r->diags.diags[0].notes[0].message == "did you mean 'drill'?");
  }
  SECTION("alias: accepted with one warning naming it, one error with --strict") {
    const char *text = "#1=BORER('d',10.,118.);\n#3=BORER('e',12.,118.);\n#2=STEP(#1,(1.),(),LENGTH_MEASURE(3.),$);\n";
    auto r = bindText(text);
    REQUIRE(r->messages.size() == 1);
    CHECK(r->messages[0] == "8:1: warning: 'BORER' is not an entity of schema 'shop'; read as its alias 'drill' "
                            "(2 instances; --strict makes each an error)");
    auto strict = bindText(text, Reading::Strict);
    CHECK(strict->messages == std::vector<std::string>{
                                  "8:1: error: 'BORER' is not an entity of schema 'shop'; it is an alias of 'drill', "
                                  "read as such without --strict (2 instances)"});
  }
  SECTION("abstract entity") {
    auto r = bindText("#1=TOOL('t',10.);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:4: error: entity 'tool' is abstract and cannot be instantiated; use one of its "
                             "subtypes: drill, mill, coated"});
  }
  SECTION("attribute count") {
    auto r = bindText("#1=DRILL('d',10.);\n");
    CHECK(r->messages == std::vector<std::string>{"8:4: error: 'drill' has 3 attributes, found 2"});
    CHECK(r->diags.diags[0].notes[0].message == "attributes of drill in order: name, diameter, tip_angle");
  }
  SECTION("wrong simple type") {
    auto r = bindText("#1=DRILL('d','ten',118.);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:14: error: attribute 2 'diameter': expected REAL, found a string"});
  }
  SECTION("wrong enumeration value") {
    auto r = bindText("#1=MILL('m',10.,4,.LEFT.);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:19: error: attribute 4 'rotation': .LEFT. is not a value of 'hand' (.cw., .ccw.)"});
  }
  SECTION("reference to an incompatible entity") {
    auto r = bindText("#1=DRILL('d',10.,118.);\n#2=STEP(#1,(1.),(),LENGTH_MEASURE(3.),$);\n#3=STEP(#2,(1.),(),LENGTH_MEASURE(3.),$);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "10:9: error: attribute 1 'its_tool': expected a reference to tool, found #2 STEP, "
                             "which is not a tool"});
    CHECK(r->diags.diags[0].entityId == 3);
  }
  SECTION("$ in a mandatory attribute") {
    auto r = bindText("#1=DRILL('d',$,118.);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:14: error: attribute 2 'diameter': '$' (no value) where a value is required (a length_measure)"});
  }
  SECTION("* where the attribute is not derived, and a value where it is") {
    auto r = bindText("#1=DRILL('d',*,118.);\n#2=SPECIAL_STEP(#1,(1.),(),LENGTH_MEASURE(3.),.T.);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:14: error: attribute 2 'diameter': '*' but the attribute is not derived; expected a length_measure",
                             "9:47: error: attribute 5 'flag': the attribute is derived in 'special_step' and must be "
                             "written '*', found .T."});
  }
  SECTION("aggregate bounds and element types") {
    auto r = bindText("#1=DRILL('d',10.,118.);\n#2=STEP(#1,(),(),LENGTH_MEASURE(3.),$);\n#3=STEP(#1,(1.,'x'),(),LENGTH_MEASURE(3.),$);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "9:12: error: attribute 2 'passes': expected a LIST [1:3] OF length_measure, found 0 elements",
                             "10:16: error: attribute 2 'passes'[2]: expected REAL, found a string"});
  }
  SECTION("select: typed member, wrong type name, entity member") {
    auto r = bindText("#1=DRILL('d',10.,118.);\n#2=STEP(#1,(1.),(),COUNT_MEASURE(3),$);\n"
                      "#3=STEP(#1,(1.),(),LABEL('x'),$);\n#4=STEP(#1,(1.),(),#1,$);\n#5=STEP(#1,(1.),(),#2,$);\n");
    CHECK(r->messages == std::vector<std::string>{
                             "10:20: error: attribute 4 'amount': type 'label' is not a member of SELECT type "
                             "'measure_select' (types: length_measure, count_measure)",
                             "12:20: error: attribute 4 'amount': expected a reference to an entity of SELECT type "
                             "'measure_select' (tool), found #2 STEP"});
  }
  SECTION("select: an untyped value is read with a warning") {
    auto r = bindText("#1=DRILL('d',10.,118.);\n#2=STEP(#1,(1.),(),3.,$);\n");
    REQUIRE(r->messages.size() == 1);
    CHECK(r->messages[0].find("9:20: warning: attribute 4 'amount': a value of SELECT type 'measure_select' should "
                              "be typed") == 0);
  }
  SECTION("complex instances: ONEOF and missing supertype") {
    auto r = bindText("#1=(DRILL(118.)MILL(4,.CW.)TOOL('x',10.));\n#2=(COATED('tin')DRILL(118.));\n"
                      "#3=(COATED('tin')DRILL(118.)TOOL('y',8.));\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:1: error: 'drill' and 'mill' cannot be combined: they are ONEOF subtypes of 'tool'",
                             "9:1: error: complex instance has 'coated' but not its supertype 'tool'; every "
                             "supertype must have its record",
                             "9:1: error: complex instance has 'drill' but not its supertype 'tool'; every "
                             "supertype must have its record"});
  }
  SECTION("complex instance records carry their own attributes") {
    auto r = bindText("#1=(COATED('tin')DRILL(118.,1.)TOOL('y',8.));\n");
    CHECK(r->messages == std::vector<std::string>{
                             "8:18: error: record 'drill' of a complex instance has 1 attribute, found 2"});
  }
}

TEST_CASE("drift: $ for an empty aggregate or a name is a warning unless strict", "[binding]") {
  const char *text = "#1=DRILL($,10.,118.);\n#2=STEP(#1,(1.),$,LENGTH_MEASURE(3.),$);\n";
  auto lenient = bindText(text);
  CHECK(lenient->messages == std::vector<std::string>{
                                 "9:17: warning: '$' written for a mandatory aggregate; read as empty (1 place; "
                                 "--strict makes each an error)",
                                 "8:10: warning: '$' written for a mandatory string (a name, label or identifier); "
                                 "read as '' (1 place; --strict makes each an error)"});
  auto strict = bindText(text, Reading::Strict);
  CHECK(strict->messages == std::vector<std::string>{
                                "8:10: error: attribute 1 'name': '$' (no value) where a value is required (a label)",
                                "9:17: error: attribute 3 'empty_ok': '$' (no value) where a value is required (a SET "
                                "[0:?] OF tool)"});
}

TEST_CASE("the lenient reading: $ in another mandatory attribute and an abstract entity are warnings",
          "[binding]") {
  const char *text = "#1=DRILL('d',$,118.);\n#2=TOOL('t',10.);\n";
  auto lenient = bindText(text, Reading::Lenient);
  CHECK(lenient->messages ==
        std::vector<std::string>{
            "8:14: warning: attribute 2 'diameter': '$' (no value) where a value is required (a length_measure); "
            "read as absent; --strict makes it an error",
            "9:4: warning: entity 'tool' is abstract and cannot be instantiated; use one of its subtypes: drill, "
            "mill, coated (read as written); --strict makes it an error"});
  CHECK_FALSE(lenient->diags.diags[0].entityId == 0);
  // Without it (what --strict asks for), each is an error.
  auto strict = bindText(text, Reading::Strict);
  CHECK(strict->messages ==
        std::vector<std::string>{
            "8:14: error: attribute 2 'diameter': '$' (no value) where a value is required (a length_measure)",
            "9:4: error: entity 'tool' is abstract and cannot be instantiated; use one of its subtypes: drill, mill, "
            "coated"});
}

TEST_CASE("integers where a REAL is expected are read with one warning", "[binding]") {
  auto r = bindText("#1=DRILL('d',10,118);\n");
  CHECK(r->messages == std::vector<std::string>{
                           "8:14: warning: integer written where a REAL is expected; read as a real (2 places)"});
}

TEST_CASE("the alias table format is checked", "[binding]") {
  binding::AliasTable t;
  std::string error;
  CHECK_FALSE(t.parse("entity ONLY_TWO\n", error));
  CHECK(error == "line 1: expected 'entity ALIAS schema_name'");
  CHECK(binding::AliasTable::builtin().entity("BIDIRECTIONAL_MILLING") == "bidirectional");
  CHECK(binding::AliasTable::builtin().entity("CENTER_DRILL") == "centerdrill");
}

TEST_CASE("instances give typed access to attributes by name", "[binding]") {
  auto r = bindText("#1=DRILL('d 10',10,118.);\n#2=STEP(#1,(1.,2.5),(),LENGTH_MEASURE(3.),.T.);\n"
                    "#3=(COATED('tin')DRILL(130.)TOOL('c',8.));\n");
  binding::Instance step(*r->bound, 1);
  REQUIRE(step);
  CHECK(step.entityName() == "step");
  CHECK(step.id() == 2);
  CHECK(step.isA("step"));
  CHECK_FALSE(step.isA("tool"));
  CHECK(step.real("amount") == 3.0);  // typed value unwrapped
  CHECK(step.boolean("flag") == true);
  CHECK(step.reals("passes") == std::vector<double>{1.0, 2.5});
  CHECK(step.refs("empty_ok").empty());
  CHECK(step.real("no_such_attribute") == std::nullopt);
  binding::Instance tool = step.ref("its_tool");
  REQUIRE(tool);
  CHECK(tool.isA("tool"));
  CHECK(tool.string("name") == "d 10");
  CHECK(tool.real("diameter") == 10.0);  // integer read as a real
  CHECK(tool.integer("diameter") == 10);
  binding::Instance coated(*r->bound, 2);
  CHECK(coated.isA("drill"));
  CHECK(coated.isA("coated"));
  CHECK(coated.string("coating") == "tin");
  CHECK(coated.real("tip_angle") == 130.0);
  CHECK(coated.real("diameter") == 8.0);
  LineCol lc = r->source->lineCol(step.attrLoc("passes").offset);
  CHECK(lc.line == 9);
  CHECK(lc.col == 12);
}

TEST_CASE("the binder stops on defined types that refer to themselves, even in a model that failed to resolve",
          "[binding]") {
  // resolve() rejects these cycles; bind() is still given the model here, as
  // a caller that ignores the result would, and must end with an error.
  auto loaded = test::loadExpress("SCHEMA s; TYPE t = t; END_TYPE; TYPE u = v; END_TYPE; TYPE v = u; END_TYPE; "
                                  "ENTITY project; a : t; b : u; END_ENTITY; END_SCHEMA;");
  CHECK_FALSE(loaded->ok);
  CHECK(loaded->diags.diags.size() == 2);
  const express::Model &model = loaded->model;
  auto source = SourceFile::fromString("cyc.stp", "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
                                                  "FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('S'));\n"
                                                  "ENDSEC;\nDATA;\n#1=PROJECT(1,2);\nENDSEC;\nEND-ISO-10303-21;\n");
  DiagnosticCollector collected;
  DiagnosticEngine diags(collected);
  auto file = p21::readPart21(*source, diags);
  REQUIRE(file);
  binding::bind(*file, model, model.schemas().front(), diags, {});
  CHECK(diags.errorCount() == 2);  // one per attribute
  for (const Diagnostic &d : collected.diags)
    CHECK(d.loc.valid());
}

TEST_CASE("a supertype cycle is reported once, and subtype queries on it end", "[binding]") {
  auto loaded = test::loadExpress("SCHEMA s; ENTITY a SUBTYPE OF (b); END_ENTITY; ENTITY b SUBTYPE OF (a); "
                                  "END_ENTITY; ENTITY c; END_ENTITY; END_SCHEMA;");
  CHECK_FALSE(loaded->ok);
  REQUIRE(loaded->diags.diags.size() == 1);
  CHECK(loaded->diags.diags[0].message == "entity 'a' is its own supertype (inheritance cycle: a -> b -> a)");
  CHECK(loaded->model.isSubtypeOf(0, 1));
  CHECK(loaded->model.isSubtypeOf(1, 0));
  CHECK_FALSE(loaded->model.isSubtypeOf(0, 2));
}
