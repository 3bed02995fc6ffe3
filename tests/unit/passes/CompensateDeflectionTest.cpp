// The compensate-deflection pass: a wall taken at constant radial depth,
// against the fixed point of the model worked out here; the independent
// residual check (DeflectionCheck.h); zero force leaves the program as it
// is; a tight offset limit lowers the feed; a finished pocket passes
// verification on its predicted path and fails it on its programmed one.
#include "passes/CuttingModel.h"

#include "tests/unit/TestSupport.h"
#include "tests/unit/ir/SampleModule.h"
#include "tests/unit/passes/DeflectionCheck.h"
#include "tests/unit/passes/PassTestSupport.h"
#include "tests/unit/passes/SlowPlaces.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace stepnc;
using namespace stepnc::passes;
using ir::Node;
using ir::Value;
using ir::Vec3;

namespace {

// The block of SAE 1020 with its pocket (corner radius 6), side finished.
ir::test::Parsed parsed() {
  return test::parseModule(test::blockPocketModule(6, test::oneStep(R"(side_finish_milling "OP" tool=%mill10)")));
}

const cutting::CuttingData &shipped() {
  static const cutting::CuttingData data = cutting::shippedCuttingData();
  return data;
}

/// The fixed point c = bend(ae + c) of a straight wall on the right of a
/// line along +x, worked out on the model with the exact ae.
double wallOffset(double ae, double ap, double fz) {
  ir::test::Parsed p = parsed();
  const CutterSetup tool = cutterSetup(ir::test::find(p.module->root, "%mill10"), shipped());
  CutStep step;
  step.tool = &tool;
  step.cutter = tool.cutter; // clockwise, as the moves' spindle -3000 turns
  step.material = &shipped().materials.at("steel_1020");
  CutSample s;
  s.dir = geom::Vec2(1, 0);
  s.side = -1;
  s.ae = ae;
  s.ap = ap;
  double c = 0;
  for (int i = 0; i < 100; ++i)
    c = wallBend(step, s, c, fz).mid;
  return c;
}

} // namespace

TEST_CASE("compensate-deflection: a wall at constant radial depth is offset by the model's fixed point",
          "[compensate-deflection]") {
  ir::test::Parsed p = parsed();
  // Along the block's side y = 50, 0.5 mm into it, 8 deep, fz = 0.1 mm: the
  // material is on the right of the feed.
  const double y = 50 + 5 - 0.5;
  test::addStraightCut(*p.module, Vec3(-10, y, -8), Vec3(110, y, -8), 1200);
  const ir::Module before = *p.module;
  REQUIRE(test::runPipeline(*p.module, "compensate-deflection"));

  const double expected = wallOffset(0.5, 8, 0.1);
  INFO("expected offset " << expected << " mm");
  REQUIRE(expected > 0.005); // a wall worth compensating
  // The piece along the middle of the wall: moved towards the material (-y)
  // by the fixed point, within what a cell of the stock does to ae; its
  // predicted end on the nominal line.
  const Node &moves = *ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves);
  const Node *middle = nullptr;
  for (const ir::Move &m : ir::walkMoves(moves))
    if (m.isFeed() && m.from && !m.changesHeight() && m.from->x() < 50 && m.to.x() > 50)
      middle = m.node;
  REQUIRE(middle);
  const Vec3 to = *middle->vec("to");
  REQUIRE(middle->vec("nominal"));
  CHECK(middle->vec("nominal")->y() == Approx(y).margin(1e-9));
  CHECK(y - to.y() == Approx(expected).epsilon(0.1));
  CHECK(*middle->number("feed") == 1200);

  const test::DeflectionCheck check = test::checkDeflection(before, *p.module, shipped());
  for (const std::string &f : check.failures)
    FAIL_CHECK(f);
  CHECK(check.walls >= 90); // a sample a millimetre along the 100 mm wall
  CHECK(check.offsetWalls > 0.9 * check.walls);
  CHECK(check.worstBefore > 0.005);
  CHECK(check.worstResidual <= 0.002);
}

TEST_CASE("compensate-deflection: the residual check sees an uncompensated wall", "[compensate-deflection]") {
  // The check must be able to fail: on the nominal program the residual is
  // the whole bend.
  ir::test::Parsed p = parsed();
  test::addStraightCut(*p.module, Vec3(-10, 54.5, -8), Vec3(110, 54.5, -8), 1200);
  const test::DeflectionCheck check = test::checkDeflection(*p.module, *p.module, shipped());
  CHECK(check.failures.empty());
  CHECK(check.worstResidual == Approx(check.worstBefore));
  CHECK(check.worstResidual > 0.005);
}

TEST_CASE("compensate-deflection: zero force leaves the path unchanged", "[compensate-deflection]") {
  // Three passes along the wall: the first takes 0.5 mm; the second, a
  // spring pass on the same line, meets no material; the third runs 1 mm
  // clear of it. Neither of the last two has a force to compensate.
  ir::test::Parsed p = parsed();
  for (const double y : {54.5, 54.5, 56.0})
    test::addStraightCut(*p.module, Vec3(-10, y, -8), Vec3(110, y, -8), 1200);
  Node &ws = ir::test::find(p.module->root, "@ws");
  // One moves node: the passes one after the other.
  for (size_t i = 1; i < ws.childrenOf(ir::Kind::Moves).size(); ++i)
    for (const Node &n : ws.childrenOf(ir::Kind::Moves)[i]->children)
      const_cast<Node *>(ws.childrenOf(ir::Kind::Moves)[0])->add(n);
  while (ws.childrenOf(ir::Kind::Moves).size() > 1)
    ws.children.pop_back();
  const ir::Module before = *p.module;
  REQUIRE(test::runPipeline(*p.module, "compensate-deflection"));
  const Node &a = *ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves);
  const Node &b = *ir::test::find(const_cast<Node &>(before.root), "@ws").child(ir::Kind::Moves);
  // The first pass is compensated (and so split or joined by connectors);
  // the other two end exactly as programmed, their moves unchanged.
  REQUIRE(a.children.size() > b.children.size());
  const size_t tail = 8; // rapid, plunge, line, rapid; twice
  for (size_t i = 1; i <= tail; ++i)
    CHECK(ir::equal(a.children[a.children.size() - i], b.children[b.children.size() - i]));
  const test::DeflectionCheck check = test::checkDeflection(before, *p.module, shipped());
  CHECK(check.failures.empty());
  CHECK(check.worstResidual <= 0.002);
}

TEST_CASE("compensate-deflection: an offset above the limit lowers the feed", "[compensate-deflection]") {
  ir::test::Parsed p = parsed();
  test::addStraightCut(*p.module, Vec3(-10, 54.5, -8), Vec3(110, 54.5, -8), 1200);
  const double full = wallOffset(0.5, 8, 0.1);
  const double limit = std::round(full / 2 * 1e4) / 1e4;
  const ir::Module before = *p.module;
  REQUIRE(test::runPipeline(*p.module, "compensate-deflection<max-offset=" + std::to_string(limit) + ">"));
  double lowest = 1e9;
  for (const ir::Move &m : ir::walkMoves(*ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves)))
    if (m.isFeed())
      lowest = std::min(lowest, m.feed);
  INFO("limit " << limit << " mm, full offset " << full << " mm");
  // Half the offset: roughly half the force beyond the edge forces, so a
  // feed well below the programmed one.
  CHECK(lowest < 0.7 * 1200);
  const test::DeflectionCheck check = test::checkDeflection(before, *p.module, shipped());
  for (const std::string &f : check.failures)
    FAIL_CHECK(f);
  CHECK(check.largestOffset <= limit + 0.001);
  CHECK(check.worstResidual <= 0.002);
}

TEST_CASE("compensate-deflection: a finished pocket verifies on its predicted path", "[compensate-deflection]") {
  // The pocket roughed to 0.5 mm from its walls, then its walls finished in
  // one pass 10 deep.
  ir::test::Parsed p = test::parseModule(test::blockPocketModule(
      6, "    workingstep @rough \"ROUGH\" feature=%pocket secplane=20.0000mm\n"
         "      bottom_and_side_rough_milling \"ROUGH\" tool=%mill10 axial_depth=5.0000mm radial_depth=4.0000mm "
         "allowance_side=0.5000mm\n"
         "        technology feed=1200.0mm/min spindle=-3000.0rev/min feed_reference=tcp\n"
         "        strategy type=contour_parallel\n"
         "    workingstep @ws \"WS\" feature=%pocket secplane=20.0000mm\n"
         "      side_finish_milling \"OP\" tool=%mill10 axial_depth=10.0000mm radial_depth=0.5000mm\n"
         "        technology feed=1200.0mm/min spindle=-3000.0rev/min feed_reference=tcp\n"));
  std::vector<std::string> errors;
  REQUIRE(test::runPipeline(*p.module, "expand-strategies", &errors));
  const ir::Module before = *p.module;
  const bool ok = test::runPipeline(*p.module, "compensate-deflection,verify-toolpaths", &errors);
  for (const std::string &e : errors)
    FAIL_CHECK(e);
  REQUIRE(ok);
  const test::DeflectionCheck check = test::checkDeflection(before, *p.module, shipped());
  for (const std::string &f : check.failures)
    FAIL_CHECK(f);
  INFO("walls " << check.walls << ", offset " << check.offsetWalls << ", largest offset " << check.largestOffset);
  CHECK(check.offsetWalls > 0.5 * check.walls);
  CHECK(check.largestOffset > 0.01);
  CHECK(check.worstResidual <= 0.002);
  // The offset changes along the walls and in the corners without a step:
  // the machine slows below half the feed nowhere the nominal program does
  // not (square connectors between the pieces did, to 1 % of the feed).
  const runtime::Machine machine = test::shippedMachine("hsc-3axis");
  const std::vector<Vec3> nominalSlow = test::slowPlaces(before, machine, 0.5);
  const std::vector<Vec3> added = test::placesAdded(nominalSlow, test::slowPlaces(*p.module, machine, 0.5), 0.5);
  INFO(nominalSlow.size() << " slow samples on the nominal program; " << added.size() << " added, the first at "
                          << (added.empty() ? Vec3::Zero() : added.front()).transpose());
  CHECK(added.empty());
  // Without `nominal` the verifier checks the programmed path, which is
  // offset into the walls by more than the tolerance.
  Node &ws = ir::test::find(p.module->root, "@ws");
  for (Node &n : ws.children.back().children)
    std::erase_if(n.attrs, [](const ir::Attr &a) { return a.name == "nominal"; });
  errors.clear();
  CHECK_FALSE(test::runPipeline(*p.module, "verify-toolpaths", &errors));
  REQUIRE_FALSE(errors.empty());
  CHECK(errors[0].find("gouge") != std::string::npos);
}
