// The adapt-feed pass against closed forms (a straight slot, a wall taken to
// a constant radial depth), on a pocket whose corners must get lower feeds
// than its walls, and its invariants on every corpus file that reaches the
// toolpath IR.
#include "passes/CuttingModel.h"
#include "ir/motion/MotionIR.h"

#include "tests/unit/TestSupport.h"
#include "tests/unit/ir/SampleModule.h"
#include "tests/unit/passes/PassTestSupport.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <numbers>

using namespace stepnc;
using namespace stepnc::passes;
using ir::Node;
using ir::Value;
using ir::Vec3;

namespace {

// The block of SAE 1020 with its pocket (corner radius 5), rough milled;
// moves written by hand under its workingstep.
ir::test::Parsed parsed() {
  return test::parseModule(
      test::blockPocketModule(5, test::oneStep(R"(bottom_and_side_rough_milling "OP" tool=%mill10)")));
}

/// Feeds of the feed moves of a moves node, in order.
std::vector<double> feeds(const Node &moves) {
  std::vector<double> out;
  for (const Node &n : moves.children)
    if (n.kind != ir::Kind::Rapid)
      out.push_back(*n.number("feed"));
  return out;
}

} // namespace

TEST_CASE("adapt-feed: a straight slot gets fz = h*", "[adapt-feed]") {
  ir::test::Parsed p = parsed();
  // Programmed 0.2 mm per tooth: 0.2 x 4 x 3000 = 2400 mm/min. Slotting 5 deep.
  test::addStraightCut(*p.module, Vec3(-10, 25, -5), Vec3(110, 25, -5), 2400);
  REQUIRE(test::runPipeline(*p.module, "adapt-feed"));
  const std::vector<double> f = feeds(*ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves));
  // The plunge outside the block is kept; the slot in full engagement gets
  // h* x flutes x rev/min = 0.10 x 4 x 3000 = 1200 mm/min; where the tool
  // enters and leaves the block it is engaged less, so the pieces there are
  // no slower.
  REQUIRE(f.size() >= 2);
  CHECK(f.front() == 2400);
  double lowest = 1e9;
  for (size_t i = 1; i < f.size(); ++i)
    lowest = std::min(lowest, f[i]);
  CHECK(lowest == Approx(1200).margin(1));
  for (double v : f)
    CHECK(v <= 2400);
}

TEST_CASE("adapt-feed: a wall at constant radial depth gets the chip-thinning feed", "[adapt-feed]") {
  for (const double ae : {0.5, 1.0, 2.0}) {
    ir::test::Parsed p = parsed();
    // Along the block's side y = 50, the tool's edge 1 mm into it, 5 deep, well
    // over the chip target (1 mm per tooth programmed).
    const double y = 50 + 5 - ae;
    test::addStraightCut(*p.module, Vec3(-10, y, -5), Vec3(110, y, -5), 12000);
    REQUIRE(test::runPipeline(*p.module, "adapt-feed"));
    const std::vector<double> f = feeds(*ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves));
    // fz = h* / sin(phi_e), phi_e = acos(1 - ae / R) (REFERENCES: chip thinning).
    const double expected = 0.10 / std::sin(std::acos(1 - ae / 5)) * 4 * 3000;
    // The piece along the middle of the wall (the ends, where the tool enters
    // and leaves the block, take less).
    double middle = 0;
    for (const ir::Move &m : ir::walkMoves(*ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves)))
      if (m.isFeed() && m.from && !m.changesHeight() && m.from->x() < 50 && m.to.x() > 50)
        middle = m.feed;
    INFO("ae " << ae << " feeds " << f.size());
    // The height field places the wall to a cell (R / 60): at ae = 0.5 that is
    // 5 % of the chip factor, less for wider cuts.
    CHECK(middle == Approx(expected).epsilon(ae < 1 ? 0.06 : 0.04));
  }
}

TEST_CASE("adapt-feed: pocket corners get lower feeds than the walls", "[adapt-feed]") {
  ir::test::Parsed p = parsed();
  // Contour-parallel roughing of the 40 x 30 pocket, 3 mm stepover at one level.
  Node &op = ir::test::find(p.module->root, "bottom_and_side_rough_milling");
  op.set("axial_depth", Value::length(10)).set("radial_depth", Value::length(3));
  Node &tech = op.add(Node(ir::Kind::Technology));
  tech.set("feed", Value::feed(12000)).set("spindle", Value::spindle(-3000)).set("feed_reference", Value::word("tcp"));
  op.add(Node(ir::Kind::Strategy)).set("type", Value::word("contour_parallel"));
  std::vector<std::string> errors;
  const bool ran = test::runPipeline(*p.module, "expand-strategies,adapt-feed,verify-toolpaths", &errors);
  INFO((errors.empty() ? std::string() : errors.front()));
  REQUIRE(ran);
  const Node &moves = *ir::test::find(p.module->root, "@ws").child(ir::Kind::Moves);
  // The outermost ring at the floor: the tool centre runs round [35, 65] x
  // [15, 35]. Along the middles of its sides the tool takes the 3 mm left by
  // the ring inside it; coming into a corner it meets the side ahead too, so
  // the engagement and the chip factor rise and the feed must drop.
  double wallLow = 1e9, cornerLow = 1e9;
  for (const ir::Move &m : ir::walkMoves(moves)) {
    if (!m.isFeed() || !m.from || m.changesHeight() || std::abs(m.to.z() + 10) > 1e-6)
      continue;
    auto onRing = [](const Vec3 &q) {
      return std::abs(q.x() - 35) < 1e-3 || std::abs(q.x() - 65) < 1e-3 || std::abs(q.y() - 15) < 1e-3 ||
             std::abs(q.y() - 35) < 1e-3;
    };
    if (!onRing(*m.from) || !onRing(m.to))
      continue;
    double nearest = 1e9;
    for (const Vec3 &c : {Vec3(35, 15, 0), Vec3(65, 15, 0), Vec3(65, 35, 0), Vec3(35, 35, 0)})
      nearest = std::min(nearest, (m.to.head<2>() - c.head<2>()).norm());
    const Vec3 mid = (*m.from + m.to) / 2;
    double midNearest = 1e9;
    for (const Vec3 &c : {Vec3(35, 15, 0), Vec3(65, 15, 0), Vec3(65, 35, 0), Vec3(35, 35, 0)})
      midNearest = std::min(midNearest, (mid.head<2>() - c.head<2>()).norm());
    if (nearest < 1e-3)
      cornerLow = std::min(cornerLow, m.feed); // the piece that ends in a corner
    else if (midNearest > 8)
      wallLow = std::min(wallLow, m.feed);
  }
  REQUIRE(wallLow < 1e9);
  REQUIRE(cornerLow < 1e9);
  // At ae 3 of R 5 the chip factor on the walls is sin(acos(1 - 3/5)) =
  // 0.917; in the corners the tool engages over half a turn, a factor of 1.
  CHECK(cornerLow < 0.95 * wallLow);
}
