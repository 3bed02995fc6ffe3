// The built-in AP238 AIM schemas: found by the FILE_SCHEMA names real files
// write, and equal, slot by slot and type by type, to the published long
// forms in the sample corpus they were written from (docs/ap238.md).
#include "frontend/express/Builtin.h"
#include "../TestSupport.h"
#include "ExpressTestSupport.h"

#include <catch2/catch.hpp>

using namespace stepnc;
using namespace stepnc::express;

TEST_CASE("FILE_SCHEMA names find the built-in AIM schemas", "[express][ap238]") {
  const BuiltinSchema e1 = findBuiltinSchema("INTEGRATED_CNC_SCHEMA");
  REQUIRE(e1);
  CHECK(e1.schema->name == "integrated_cnc_schema");
  CHECK(isAimSchema(*e1.schema));
  CHECK(findBuiltinSchema("integrated_cnc_schema").schema == e1.schema);
  const BuiltinSchema e3 = findBuiltinSchema("MODEL_BASED_INTEGRATED_MANUFACTURING_SCHEMA { 1 0 10303 238 3 1 1 }");
  REQUIRE(e3);
  CHECK(e3.schema->name == "model_based_integrated_manufacturing_schema");
  CHECK(e3.model != e1.model);
  // The ARM's names answer to the ARM, which is no AIM.
  const BuiltinSchema arm = findBuiltinSchema(std::vector<std::string>{"MACHINING_SCHEMA", "MILLING_SCHEMA"});
  REQUIRE(arm);
  CHECK(arm.model == &builtinModel());
  CHECK_FALSE(isAimSchema(*arm.schema));
  CHECK_FALSE(findBuiltinSchema("AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }"));
  // si_unit derives named_unit.dimensions: the slot a complex instance writes '*'.
  const EntityId si = e1.model->findEntity(*e1.schema, "si_unit");
  REQUIRE(si != kNone);
  const Entity &unit = e1.model->entity(si);
  REQUIRE(unit.slots.size() == 3);
  CHECK(unit.slots[0].name == "dimensions");
  CHECK(unit.slots[0].derived);
}

namespace {

/// Compares a built-in schema with the long form it was written from: every
/// entity's abstractness, supertypes and Part 21 slots (name, type,
/// optional, derived), every type's underlying type, SELECT list and
/// ENUMERATION values.
void compareWithCorpus(const std::string &path, const BuiltinSchema &ours, size_t minEntities) {
  const auto loaded = test::loadExpressFile(path);
  REQUIRE(loaded->ok);
  const Model &ref = loaded->model;
  const Schema &rs = ref.schemas().front();
  CHECK(rs.entities.size() == ours.schema->entities.size());
  CHECK(rs.types.size() == ours.schema->types.size());
  size_t compared = 0;
  for (EntityId id : rs.entities) {
    const Entity &re = ref.entity(id);
    INFO("entity " << re.name);
    const EntityId oid = ours.model->findEntity(*ours.schema, re.name);
    REQUIRE(oid != kNone);
    const Entity &oe = ours.model->entity(oid);
    CHECK(oe.supertypeNames == re.supertypeNames);
    test::checkSameSlots(*ours.model, oe, ref, re);
    ++compared;
  }
  for (DeclTypeId id : rs.types) {
    const TypeDecl &rt = ref.typeDecl(id);
    INFO("type " << rt.name);
    const DeclTypeId oid = ours.model->findType(*ours.schema, rt.name);
    REQUIRE(oid != kNone);
    const TypeDecl &ot = ours.model->typeDecl(oid);
    CHECK(ours.model->typeText(ot.underlying) == ref.typeText(rt.underlying));
    CHECK(ot.selectItems == rt.selectItems);
    CHECK(ot.enumValues == rt.enumValues);
    CHECK(ot.extensible == rt.extensible);
    CHECK(ot.basedOn == rt.basedOn);
  }
  CHECK(compared >= minEntities);
}

} // namespace

TEST_CASE("the built-in AIM schemas match the published long forms slot by slot", "[express][ap238][corpus]") {
  const std::string corpus = test::corpusDir();
  if (corpus.empty()) {
    WARN("sample corpus not found (set STEPNC_CORPUS): AIM cross-check skipped");
    return;
  }
  SECTION("edition 1") {
    compareWithCorpus(corpus + "/stepcode__stepcode/ap238-aim-long.exp", findBuiltinSchema("INTEGRATED_CNC_SCHEMA"),
                      481);
  }
  SECTION("edition 3") {
    compareWithCorpus(corpus + "/stepmfg__ap238/ap238e3_aim_lf.exp",
                      findBuiltinSchema("MODEL_BASED_INTEGRATED_MANUFACTURING_SCHEMA"), 1464);
  }
}
