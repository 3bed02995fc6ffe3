// The Part 28 XSD generator's choices: which elements a reference or a SELECT
// allows (each once, as XSD's Unique Particle Attribution requires), what the
// scope of a schema's XSD holds, and the refusal of clashing names.
#include "frontend/part28/Xsd.h"
#include "frontend/express/SchemaReader.h"
#include "ExpressTestSupport.h"

#include <catch2/catch.hpp>

using namespace stepnc;
using namespace stepnc::express;
using namespace stepnc::p28;

namespace {

std::unique_ptr<test::LoadedExpress> load(std::string_view text) { return test::loadExpress(text); }

using Names = std::vector<std::string>;

const char *kDiamond = R"(
SCHEMA base;
TYPE length_measure = REAL; END_TYPE;
TYPE distance = length_measure; END_TYPE;
TYPE inner = SELECT (c, length_measure); END_TYPE;
TYPE outer = SELECT (a, d, inner, distance, length_measure); END_TYPE;
TYPE outer_alias = outer; END_TYPE;
ENTITY a; END_ENTITY;
ENTITY b SUBTYPE OF (a); END_ENTITY;
ENTITY c SUBTYPE OF (a); END_ENTITY;
ENTITY d SUBTYPE OF (b, c); END_ENTITY;
ENTITY e SUBTYPE OF (d); END_ENTITY;
ENTITY holder;
  item : outer;
END_ENTITY;
END_SCHEMA;
)";

} // namespace

TEST_CASE("xsd: element names are the EXPRESS name with the first letter upper case") {
  CHECK(xmlName("machining_workingstep") == "Machining_workingstep");
  CHECK(xmlName("TWO5D_MILLING_STRATEGY") == "Two5d_milling_strategy");
  CHECK(schemaNamespace("ISO14649_ARM") == "urn:iso10303-28:xs/iso14649_arm");
}

TEST_CASE("xsd: a reference allows the entity and each subtype once under multiple inheritance") {
  auto l = load(kDiamond);
  REQUIRE(l->ok);
  const Schema &s = l->model.schemas().front();
  XsdScope scope(l->model, s);
  // d is reached through b and through c; e below it too.
  CHECK(scope.entityChoice(l->model.findEntity(s, "a")) == Names{"A", "B", "D", "E", "C"});
  CHECK(scope.entityChoice(l->model.findEntity(s, "c")) == Names{"C", "D", "E"});
}

TEST_CASE("xsd: a SELECT allows each element once, nested SELECTs flattened") {
  auto l = load(kDiamond);
  REQUIRE(l->ok);
  const Schema &s = l->model.schemas().front();
  XsdScope scope(l->model, s);
  // d is a subtype of a (already listed), inner's c too, and length_measure
  // is both an item and an item of inner; distance is its own element.
  const Names expected{"A", "B", "D", "E", "C", "Length_measure", "Distance"};
  CHECK(scope.selectChoice(l->model.findType(s, "outer")) == expected);
  CHECK(scope.isSelect(l->model.findType(s, "outer_alias")));
  CHECK(scope.selectChoice(l->model.findType(s, "outer_alias")) == expected);
  CHECK_FALSE(scope.isSelect(l->model.findType(s, "distance")));
}

TEST_CASE("xsd: the scope is what the schema sees and what that refers to, not other schemas' subtypes") {
  auto l = load(R"(
SCHEMA lib;
TYPE label = STRING; END_TYPE;
ENTITY part; name : label; END_ENTITY;
ENTITY unused; END_ENTITY;
ENTITY special_part SUBTYPE OF (part); END_ENTITY;
END_SCHEMA;
SCHEMA app;
USE FROM lib (part);
ENTITY assembly; parts : LIST [1:?] OF part; END_ENTITY;
END_SCHEMA;
SCHEMA ext;
USE FROM app;
ENTITY ext_part SUBTYPE OF (part); END_ENTITY;
END_SCHEMA;
)");
  REQUIRE(l->ok);
  const Model &m = l->model;
  XsdScope scope(m, *m.findSchema("app"));
  Names entities, types;
  for (EntityId e : scope.entities())
    entities.push_back(m.entity(e).name);
  for (DeclTypeId t : scope.types())
    types.push_back(m.typeDecl(t).name);
  CHECK(entities == Names{"assembly", "part"});
  CHECK(types == Names{"label"}); // through part's attribute
  CHECK(scope.entityChoice(m.findEntity(*m.findSchema("app"), "part")) == Names{"Part"});
}

TEST_CASE("xsd: declarations that would share an element name are refused, naming both") {
  auto l = load(R"(
SCHEMA lib;
ENTITY widget; END_ENTITY;
ENTITY part; shape : widget; END_ENTITY;
END_SCHEMA;
SCHEMA app;
USE FROM lib (part);
TYPE widget = STRING; END_TYPE;
ENTITY holder; p : part; w : widget; END_ENTITY;
END_SCHEMA;
)");
  REQUIRE(l->ok);
  std::string out, error;
  CHECK_FALSE(schemaXsd(l->model, *l->model.findSchema("app"), out, error));
  CHECK(error.find("Widget (entity widget in schema lib, type widget in schema app)") != std::string::npos);
  CHECK(out.empty());
}

TEST_CASE("xsd: the same model gives the same bytes") {
  auto a = load(kDiamond);
  auto b = load(kDiamond);
  REQUIRE(a->ok);
  REQUIRE(b->ok);
  std::string first, second, error;
  REQUIRE(schemaXsd(a->model, a->model.schemas().front(), first, error));
  REQUIRE(schemaXsd(b->model, b->model.schemas().front(), second, error));
  CHECK(first == second);
  CHECK(first.find(R"(<xs:group name="Outer-group">)") != std::string::npos);
  CHECK(first.find(R"(<xs:element name="Item" type="Outer" minOccurs="0"/>)") != std::string::npos);
}

TEST_CASE("xsd: attributes of the same name from two supertypes are qualified by their entity") {
  auto l = load(R"(
SCHEMA t;
TYPE label = STRING; END_TYPE;
ENTITY item; name : label; END_ENTITY;
ENTITY transformation; name : label; description : label; END_ENTITY;
ENTITY operator SUBTYPE OF (item, transformation); scale : REAL; END_ENTITY;
ENTITY operator_3d SUBTYPE OF (operator); DERIVE SELF\transformation.description : label := 'x'; END_ENTITY;
END_SCHEMA;
)");
  REQUIRE(l->ok);
  const Schema &s = l->model.schemas().front();
  CHECK(attributeElementNames(l->model, l->model.findEntity(s, "item")) == Names{"Name"});
  CHECK(attributeElementNames(l->model, l->model.findEntity(s, "operator")) ==
        Names{"Item.Name", "Transformation.Name", "Description", "Scale"});
  CHECK(attributeElementNames(l->model, l->model.findEntity(s, "operator_3d")) ==
        Names{"Item.Name", "Transformation.Name", "Description", "Scale"});
}
