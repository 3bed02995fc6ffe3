#include "frontend/express/Builtin.h"
#include "frontend/express/SchemaIO.h"
#include "frontend/express/SchemaReader.h"
#include "ExpressTestSupport.h"
#include "../TestSupport.h"

#include <catch2/catch.hpp>
#include <filesystem>

using namespace stepnc;
using namespace stepnc::express;

namespace {

std::unique_ptr<test::LoadedExpress> load(std::string_view text) { return test::loadExpress(text); }

std::vector<std::string> slotNames(const Model &m, std::string_view entity) {
  std::vector<std::string> out;
  EntityId id = m.findEntity(m.schemas().front(), entity);
  REQUIRE(id != kNone);
  for (const Slot &s : m.entity(id).slots)
    out.push_back(s.name + (s.optional ? "?" : "") + (s.derived ? "*" : ""));
  return out;
}

const char *kInheritance = R"(
SCHEMA test;
TYPE length_measure = REAL; END_TYPE;
TYPE label = STRING; END_TYPE;
TYPE side = ENUMERATION OF (left, right); END_TYPE;
TYPE thing = SELECT (a, length_measure); END_TYPE;
ENTITY a ABSTRACT SUPERTYPE OF (ONEOF (b, c));
  name : label;
  size : OPTIONAL length_measure;
END_ENTITY;
ENTITY b SUBTYPE OF (a);
  width : length_measure;
END_ENTITY;
ENTITY c SUBTYPE OF (a);
  SELF\a.size : length_measure;            -- redeclared: no longer optional
  hand : side;
END_ENTITY;
ENTITY d SUBTYPE OF (b, c);         -- diamond: a's attributes once
  parts : LIST [1:3] OF UNIQUE thing;
DERIVE
  SELF\b.width : length_measure := 2.0;     -- derived redeclaration: written *
END_ENTITY;
ENTITY e SUBTYPE OF (d);
  SELF\c.hand RENAMED side_of : side;
END_ENTITY;
END_SCHEMA;
)";

} // namespace

TEST_CASE("attributes come in Part 21 order, inherited first, each once", "[express]") {
  auto l = load(kInheritance);
  REQUIRE(l->ok);
  CHECK(slotNames(l->model, "b") == std::vector<std::string>{"name", "size?", "width"});
  CHECK(slotNames(l->model, "c") == std::vector<std::string>{"name", "size", "hand"});
  CHECK(slotNames(l->model, "d") == std::vector<std::string>{"name", "size?", "width*", "hand", "parts"});
  CHECK(slotNames(l->model, "e") == std::vector<std::string>{"name", "size?", "width*", "side_of", "parts"});
  const Model &m = l->model;
  const Entity &d = m.entity(m.findEntity(m.schemas().front(), "d"));
  CHECK(m.typeText(d.slots[4].type) == "LIST [1:3] OF UNIQUE thing");
  CHECK(d.ownSlots == std::vector<uint32_t>{4});
  const Entity &a = m.entity(m.findEntity(m.schemas().front(), "a"));
  CHECK(a.abstract);
  REQUIRE(a.supertypeConstraints.size() == 1);
  CHECK(a.supertypeConstraints[0].op == SupertypeExpr::OneOf);
  CHECK(a.subtypes.size() == 2);
  CHECK(m.isSubtypeOf(m.findEntity(m.schemas().front(), "e"), m.findEntity(m.schemas().front(), "a")));
}

TEST_CASE("the built-in ARM gives deep subtypes their full attribute lists", "[express]") {
  const Model &m = builtinModel();
  CHECK(slotNames(m, "closed_pocket") ==
        std::vector<std::string>{"its_id", "its_workpiece", "its_operations", "feature_placement", "depth",
                                 "its_boss", "slope?", "bottom_condition", "planar_radius?",
                                 "orthogonal_radius?", "feature_boundary"});
  CHECK(slotNames(m, "bottom_and_side_rough_milling") ==
        std::vector<std::string>{"its_toolpath?", "its_tool_direction?", "its_id", "retract_plane?",
                                 "start_point?", "its_tool", "its_technology", "its_machine_functions",
                                 "overcut_length?", "approach?", "retract?", "its_machining_strategy?",
                                 "axial_cutting_depth?", "radial_cutting_depth?", "allowance_side?",
                                 "allowance_bottom?"});
  const Schema *s = builtinSchemaFor("machining_schema");
  REQUIRE(s);
  CHECK(builtinSchemaFor("MILLING_SCHEMA") == s);
  CHECK(builtinSchemaFor("AUTOMOTIVE_DESIGN") == nullptr);
  CHECK(m.entities().size() >= 495);
}

TEST_CASE("the compact schema form round-trips", "[express]") {
  const Model &m = builtinModel();
  const std::string once = serializeModel(m);
  Model again;
  std::string error;
  REQUIRE(deserializeModel(once, again, error));
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  REQUIRE(again.resolve(engine));
  CHECK(serializeModel(again) == once);
  Model bad;
  CHECK_FALSE(deserializeModel("stepnc-schema 1\nschema s\nentity e\n attr x mandatory NOPE\n", bad, error));
  CHECK(error == "line 4: unknown type token 'NOPE'");
}

TEST_CASE("EXPRESS syntax errors are located", "[express]") {
  auto l = load("SCHEMA s;\nENTITY e;\n  x : INTEGER\nEND_ENTITY;\nEND_SCHEMA;\n");
  CHECK_FALSE(l->ok);
  REQUIRE_FALSE(l->diags.diags.empty());
  LineCol lc = l->diags.diags[0].loc.file->lineCol(l->diags.diags[0].loc.offset);
  CHECK(lc.line == 4);
  CHECK(lc.col == 1);
  CHECK(l->diags.diags[0].message.find("EXPRESS syntax") == 0);
}

TEST_CASE("unknown names and missing interfaced schemas are reported", "[express]") {
  auto l = load("SCHEMA s;\nUSE FROM missing_schema;\nENTITY e;\n  x : nowhere;\nEND_ENTITY;\nEND_SCHEMA;\n"
                "SCHEMA t;\nENTITY f SUBTYPE OF (ghost);\n  y : unknown_type;\nEND_ENTITY;\nEND_SCHEMA;\n");
  CHECK_FALSE(l->ok);
  std::vector<std::string> msgs;
  for (const auto &d : l->diags.diags)
    msgs.push_back(std::string(severityName(d.severity)) + ": " + d.message);
  CHECK(msgs == std::vector<std::string>{
                    "error: schema 's' uses schema 'missing_schema', which is not loaded",
                    "note: 1 name(s) in schema 's' stay unresolved because interfaced schemas are missing",
                    "error: unknown type 'unknown_type' in attribute 'y' of entity 'f'",
                    "error: entity 'f' is a subtype of unknown entity 'ghost'"});
}

TEST_CASE("USE FROM with renames brings names into scope", "[express]") {
  auto l = load("SCHEMA base;\nTYPE len = REAL; END_TYPE;\nENTITY point; x : len; END_ENTITY;\nEND_SCHEMA;\n"
                "SCHEMA user;\nUSE FROM base (point AS pt);\nREFERENCE FROM base (len);\n"
                "ENTITY segment; a, b : pt; l : len; END_ENTITY;\nEND_SCHEMA;\n");
  REQUIRE(l->ok);
  const Schema *user = l->model.findSchema("USER");
  REQUIRE(user);
  CHECK(l->model.findEntity(*user, "pt") != kNone);
  CHECK(l->model.findEntity(*user, "point") == kNone);
  CHECK(l->model.findType(*user, "len") != kNone);
}

TEST_CASE("the built-in ARM matches the corpus ARM schema slot by slot", "[express][corpus]") {
  const std::string corpus = test::corpusDir();
  if (corpus.empty()) {
    WARN("sample corpus not found (set STEPNC_CORPUS): ARM cross-check skipped");
    return;
  }
  const auto loaded = test::loadExpressFile(corpus + "/johnmichaloski__STEPNCpp/machinetool_resource_schema9_exp.txt");
  REQUIRE(loaded->ok);
  const Model &ref = loaded->model;
  const Model &ours = builtinModel();
  const Schema &rs = ref.schemas().front();
  const Schema &os = ours.schemas().front();
  size_t compared = 0;
  for (EntityId id : rs.entities) {
    const Entity &re = ref.entity(id);
    if (re.name == "bolt_holes")
      continue;  // declared twice in the corpus schema; see schemas/README.md
    EntityId oid = ours.findEntity(os, re.name);
    INFO("entity " << re.name);
    REQUIRE(oid != kNone);
    test::checkSameSlots(ours, ours.entity(oid), ref, re);
    ++compared;
  }
  CHECK(compared >= 490);
}

TEST_CASE("WHERE rules are kept in parsed form", "[express]") {
  auto l = load(R"(SCHEMA s;
ENTITY circle;
  radius : REAL;
  centre : LIST [2:3] OF REAL;
WHERE
  wr1 : radius > 0.0;
  wr2 : SIZEOF(QUERY(c <* centre | c < -1.E3)) = 0;
  wr3 : {0 < radius <= 10};
  'S.CIRCLE' IN TYPEOF(SELF\circle) AND NOT (centre[1] = 2 ** 3);
  wr5 : EXISTS(radius) OR (HIINDEX(centre) - 1 >= centre[2]) OR (centre = [1, 2:3]);
END_ENTITY;
END_SCHEMA;
)");
  REQUIRE(l->ok);
  const Entity &e = l->model.entity(0);
  REQUIRE(e.where.size() == 5);
  CHECK(e.where[0].label == "wr1");
  CHECK(e.where[3].label.empty());
  std::vector<std::string> printed;
  for (const WhereRule &w : e.where) {
    REQUIRE(w.expr);
    printed.push_back(printExpr(*w.expr));
  }
  CHECK(printed == std::vector<std::string>{
                       "(> radius 0.0)",
                       "(= (call SIZEOF (query c centre (< c (- 1.E3)))) 0)",
                       "(interval < <= 0 radius 10)",
                       // EXPRESS binds AND tighter than IN (AND is a multiplication
                       // operator, IN a relational one): the standard's precedence.
                       "(IN 'S.CIRCLE' (AND (call TYPEOF (\\ circle SELF)) (NOT (= ([] centre 1) (** 2 3)))))",
                       "(OR (OR (call EXISTS radius) (>= (- (call HIINDEX centre) 1) ([] centre 2))) (= centre (aggregate 1 (: 2 3))))"});
}

TEST_CASE("built-in WHERE rules are parsed on first use", "[express]") {
  const Model &m = builtinModel();
  const Schema &s = m.schemas().front();
  DeclTypeId month = m.findType(s, "month_in_year_number");
  REQUIRE(month != kNone);
  const TypeDecl &t = m.typeDecl(month);
  REQUIRE(t.where.size() == 1);
  const Expr *e = m.whereExpression(t.where[0]);
  REQUIRE(e);
  CHECK(printExpr(*e) == "(interval <= <= 1 SELF 12)");
  CHECK(parseExpression("1 + ") == nullptr);
  CHECK(parseExpression("a b") == nullptr);
}

TEST_CASE("operator chains keep their left-deep shape and long ones are built and freed", "[express]") {
  auto small = parseExpression("a AND b AND c.e[1]");
  REQUIRE(small);
  CHECK(printExpr(*small) == "(AND (AND a b) ([] (. e c) 1))");
  // 100,000 operands: copying the left operand at each step took minutes;
  // the tree is 100,000 levels deep, more than a recursive destructor
  // survives under ASan.
  std::string text = "x";
  for (int i = 0; i < 100000; ++i)
    text += " AND x";
  auto chain = parseExpression(text);
  REQUIRE(chain);
  const Expr *e = chain.get();
  size_t depth = 0;
  while (e->kind == Expr::Binary) {
    e = &e->args[0];
    ++depth;
  }
  CHECK(depth == 100000);
}

TEST_CASE("EXPRESS text that is not UTF-8 or nests too deeply is a located error", "[express]") {
  auto bad = load("SCHEMA s;\n-- caf\xe9\nEND_SCHEMA;\n");
  CHECK_FALSE(bad->ok);
  REQUIRE(bad->diags.diags.size() == 1);
  CHECK(bad->diags.diags[0].loc.offset == 16);
  CHECK(parseExpression("'\xff'") == nullptr);
  auto deep = load("SCHEMA s; CONSTANT c : INTEGER := " + std::string(300, '(') + "1" + std::string(300, ')') +
                   "; END_CONSTANT; END_SCHEMA;");
  CHECK_FALSE(deep->ok);
  REQUIRE(deep->diags.diags.size() == 1);
  CHECK(deep->diags.diags[0].message == "EXPRESS brackets nest deeper than 256 levels");
}
