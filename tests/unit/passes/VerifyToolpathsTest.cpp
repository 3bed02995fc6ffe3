// Tests of the verify-toolpaths pass on small modules: feature IR parsed from
// text, moves written by hand. Every expected area is worked out by hand in
// the comments (tool D10, r = 5, unless said otherwise); the pass prints
// areas with 3 decimals in messages and 2 in the figures comment, so they are
// compared to that precision.
#include "passes/PassRegistry.h"

#include "support/Format.h"
#include "tests/unit/ir/SampleModule.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <numbers>

using namespace stepnc;
using namespace stepnc::passes;
using ir::Node;
using ir::Value;
using ir::Vec3;

namespace {

constexpr double kPi = std::numbers::pi;

// A 40 x 30 closed pocket (corner radius 5) centred on the origin, top z=0,
// floor z=-10, a boss of diameter 6 in its centre (used as an island only when
// ISLAND is replaced), an L-shaped pocket and a circular pocket of diameter 40
// beside it; a D10 end mill and a 4 mm drill.
constexpr const char *kModule = R"(project "VERIFY"
  workpiece %wp "WP" global_tolerance=0.0100mm
    closed_pocket %pocket "POCKET" at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=10.0000mm bottom=planar orthogonal_radius=5.0000mm
      rectangular_profile width=30.0000mm length=40.0000mm
      ISLAND
    boss %boss "BOSS" at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=10.0000mm
      circular_profile diameter=6.0000mm
    closed_pocket %lpocket "L POCKET" at=(100.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=10.0000mm bottom=planar
      general_profile closed=true
        polyline
          point at=(0.0000,0.0000,0.0000)mm
          point at=(40.0000,0.0000,0.0000)mm
          point at=(40.0000,20.0000,0.0000)mm
          point at=(20.0000,20.0000,0.0000)mm
          point at=(20.0000,40.0000,0.0000)mm
          point at=(0.0000,40.0000,0.0000)mm
          point at=(0.0000,0.0000,0.0000)mm
    closed_pocket %round "ROUND POCKET" at=(0.0000,100.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=10.0000mm bottom=planar
      circular_profile diameter=40.0000mm
    closed_pocket %domed "DOMED" at=(100.0000,100.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=10.0000mm bottom=radiused bottom_radius=5.0000mm
      circular_profile diameter=40.0000mm
  tool %mill10 "MILL 10" type=endmill diameter=10.0000mm
  setup %s1 "S1" at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) secplane=20.0000mm
  workplan @plan "PLAN" setup=%s1
)";

/// A workingstep line and its operation, for the workplan.
std::string workingstep(const std::string &symbol, const std::string &feature, const std::string &op) {
  return "    workingstep " + symbol + " \"" + symbol.substr(1) + "\" feature=" + feature +
         " secplane=20.0000mm\n      " + op + " \"OP\" tool=%mill10\n";
}

constexpr const char *kFinish = "bottom_and_side_finish_milling";

/// The module with the given workingsteps, the pocket's boss an island or not.
ir::test::Parsed parseModule(const std::string &workingsteps, bool island = false) {
  std::string text = kModule;
  text.replace(text.find("ISLAND"), 6, island ? "island feature=%boss" : "");
  if (!island)  // drop the line left empty
    text.erase(text.find("\n      \n"), 7);
  ir::test::Parsed p = ir::test::parse(text + workingsteps);
  INFO(text + workingsteps);
  for (const std::string &e : p.errors)
    FAIL(e);
  REQUIRE(p.module);
  return p;
}

/// Moves written by hand, each starting where the last ended; the tool
/// enters and leaves along its axis above (x, y) through z=2 (2 mm above the top).
class Path {
public:
  explicit Path(double spindle = -3000) {
    moves.set("tool", Value::ref("%mill10"))
        .set("spindle", Value::spindle(spindle))
        .set("coolant", Value::word("flood"))
        .set("secplane", Value::length(20));
  }

  Path &rapid(double x, double y, double z) { return add(ir::Kind::Rapid, Vec3(x, y, z)); }
  Path &line(double x, double y, double z) { return add(ir::Kind::Linear, Vec3(x, y, z)).feed(); }
  Path &line(double x, double y) { return line(x, y, at_.z()); }
  Path &arc(double x, double y, double cx, double cy, bool ccw = true, int64_t turns = 0, double z = NAN) {
    add(ir::Kind::Arc, Vec3(x, y, std::isnan(z) ? at_.z() : z));
    Node &m = moves.children.back();
    m.set("center", Value::point(Vec3(cx, cy, 0))).set("dir", Value::word(ccw ? "ccw" : "cw"));
    if (turns > 0)
      m.set("turns", Value::integer(turns));
    return feed();
  }
  /// Down to z at (x, y): rapid to the security plane, rapid to z=2, feed down.
  Path &enter(double x, double y, double z = -10) { return rapid(x, y, 20).rapid(x, y, 2).line(x, y, z); }
  Path &leave() { return line(at_.x(), at_.y(), 2).rapid(at_.x(), at_.y(), 20); }
  /// The closed rectangle [x0, x1] x [y0, y1] from (x0, y0), counter-clockwise.
  Path &rectangle(double x0, double y0, double x1, double y1) {
    return line(x1, y0).line(x1, y1).line(x0, y1).line(x0, y0);
  }

  Node moves{ir::Kind::Moves};

private:
  Path &add(ir::Kind kind, const Vec3 &to) {
    moves.add(Node(kind)).set("to", Value::point(to));
    at_ = to;
    return *this;
  }
  Path &feed() {
    moves.children.back().set("feed", Value::feed(600));
    return *this;
  }
  Vec3 at_ = Vec3::Zero();
};

struct Outcome {
  bool ok = false;
  std::vector<std::string> errors, warnings;
  PassStats stats;
};

/// Runs verify-toolpaths with `options` ("key=value,...", or none).
Outcome verify(ir::Module &m, const std::string &options = "") {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  std::string error;
  auto pipeline = parsePipeline("verify-toolpaths" + (options.empty() ? "" : "<" + options + ">"), error);
  INFO(error);
  REQUIRE(pipeline);
  auto pass = createPass(pipeline->front());
  REQUIRE(pass);
  Outcome out;
  out.ok = pass->run(m, engine, out.stats).ok;
  for (const Diagnostic &d : c.diags)
    (d.severity == Severity::Error ? out.errors : out.warnings).push_back(d.message);
  return out;
}

/// Attaches the path to the workingstep `symbol` and returns the moves node.
Node &attach(ir::Module &m, std::string_view symbol, const Path &p) {
  return ir::test::find(m.root, symbol).add(p.moves);
}

/// The number written right after `prefix` in `text` (fails the test when absent).
double numberAfter(const std::string &text, const std::string &prefix) {
  const size_t at = text.find(prefix);
  INFO(text);
  REQUIRE(at != std::string::npos);
  return std::strtod(text.c_str() + at + prefix.size(), nullptr);
}

bool contains(const std::string &text, const std::string &part) {
  return text.find(part) != std::string::npos;
}

/// The errors whose text contains `part`; all of them are shown when a check fails.
std::vector<std::string> errorsWith(const Outcome &o, const std::string &part) {
  std::string all;
  for (const std::string &e : o.errors)
    all += e + "\n";
  UNSCOPED_INFO("errors:\n" << all);
  std::vector<std::string> found;
  for (const std::string &e : o.errors)
    if (contains(e, part))
      found.push_back(e);
  return found;
}

/// The only error whose text contains `part`.
std::string errorWith(const Outcome &o, const std::string &part) {
  std::vector<std::string> found = errorsWith(o, part);
  INFO("errors containing '" << part << "'");
  REQUIRE(found.size() == 1);
  return found[0];
}

// Areas of the 40 x 30 pocket with corner radius 5.
const double kPocketArea = 1200 - (4 - kPi) * 25;  // 1100 + 25 pi: a D10 tool reaches all of it

/// The pocket cleared by two rings: the rectangle at offset 5 (lines) and the
/// stadium at offset 10 (lines and half circles). Every point of the pocket
/// is within 5 of one of them. `push` moves the first line of the outer ring
/// down (outward) by that much.
Path clearingPath(double push = 0) {
  Path p;
  p.enter(-15, -10 - push).line(15, -10 - push).line(15, 10).line(-15, 10).line(-15, -10 - push);
  p.line(-10, -5).line(10, -5).arc(10, 5, 10, 0).line(-10, 5).arc(-10, -5, -10, 0);
  return p.leave();
}

/// The left half of the pocket: the rectangle [-15, -5] x [-10, 10] and its
/// middle line. It sweeps the rectangle grown by 5 (rounded): 200 + 60*5 + 25 pi.
Path leftHalfPath() {
  Path p;
  p.enter(-15, -10).rectangle(-15, -10, -5, 10).line(-10, -10).line(-10, 10);
  return p.leave();
}

/// The right part of the pocket, overlapping the left half: the rectangle
/// [-5, 15] x [-10, 10] and its middle line x=5 sweep [-10, 20] x [-15, 15]
/// with rounded corners. Left uncut: the pocket's 10 mm at x < -10, less its
/// two corners, and the two rounded corners of the sweep at x=-10, together
/// 300 - (4 - pi) 12.5 + (4 - pi) 12.5 = 300.
Path rightPartPath() {
  Path p;
  p.enter(-5, -10).rectangle(-5, -10, 15, 10).line(5, -10).line(5, 10);
  return p.leave();
}

} // namespace

TEST_CASE("verify-toolpaths: a path clearing the whole pocket passes, with its figures", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
  Node &moves = attach(*p.module, "@ws", clearingPath());
  Outcome o = verify(*p.module);
  for (const std::string &e : o.errors)
    FAIL(e);
  CHECK(o.ok);
  CHECK(o.warnings.empty());
  // Path: down 18 + 12, ring 100, link 5 sqrt 2, stadium 40 + 10 pi, up 12 + 18.
  const double path = 18 + 12 + 100 + 5 * std::sqrt(2.0) + 40 + 10 * kPi + 12 + 18;
  CHECK(moves.comment == "swept " + formatFixed(kPocketArea, 2) +
                             " mm2, uncut 0.00 mm2 (0.000 %), gouge 0.0000 mm, " + "path " +
                             formatFixed(path, 1) + " mm, 14 moves");
  CHECK(o.stats["workingsteps verified"] == 1);
  CHECK(o.stats["moves checked"] == 14);
  CHECK(o.stats["gouge errors"] == 0);
  CHECK(o.stats["uncut errors"] == 0);
  CHECK(o.stats["safety errors"] == 0);

  // A second run replaces the figures rather than adding to them.
  const std::string first = moves.comment;
  verify(*p.module);
  CHECK(moves.comment == first);
}

TEST_CASE("verify-toolpaths: a move pushed 0.5 mm out of the pocket gouges", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
  Node &moves = attach(*p.module, "@ws", clearingPath(0.5));
  Outcome o = verify(*p.module);
  CHECK_FALSE(o.ok);
  // The plunge at (-15, -10.5), the first side at y = -10.5 and the two
  // moves that end or start on it: the tool's disc of radius 5 stands 4.5
  // from the wall at y = -15. Three are reported, all five counted.
  const std::vector<std::string> found = errorsWith(o, " gouges a wall of %pocket by ");
  REQUIRE(found.size() == 3);
  CHECK(contains(found[0], "workingstep @ws: linear to (-15.0000, -10.5000, -10.0000) gouges a wall of %pocket by "
                           "0.5000 mm at (-15.0000, -10.5000, -10.0000) (tool %mill10, radius 5.0000 mm, "
                           "allowance_side 0.0000 mm, tolerance 0.0100 mm)"));
  for (const std::string &e : found)
    CHECK(numberAfter(e, " by ") == Approx(0.5).margin(1e-9));
  CHECK(numberAfter(moves.comment, "gouge ") == Approx(0.5).margin(1e-9));
  CHECK(o.stats["gouge errors"] == 5);

  // Within the tolerance, a gouge is not an error.
  ir::test::Parsed q = parseModule(workingstep("@ws", "%pocket", kFinish));
  attach(*q.module, "@ws", clearingPath(0.5));
  CHECK(verify(*q.module, "tolerance=0.6").errors.empty());
  ir::test::Parsed r = parseModule(workingstep("@ws", "%pocket", kFinish));
  attach(*r.module, "@ws", clearingPath(0.5));
  CHECK(verify(*r.module, "tolerance=0.4").stats["gouge errors"] == 5);
}

TEST_CASE("verify-toolpaths: half a pocket cleared leaves the other half uncut", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
  Node &moves = attach(*p.module, "@ws", leftHalfPath());
  Outcome o = verify(*p.module);
  CHECK_FALSE(o.ok);
  // Reachable: the whole pocket, 1100 + 25 pi. Swept: 500 + 25 pi. Uncut: exactly 600.
  const std::string e = errorWith(o, "uncut at its floor level");
  CHECK(contains(e, "workingstep @ws: leaves 600.000 mm2 (" + formatFixed(100 * 600 / kPocketArea, 3) +
                        " %) of %pocket uncut at its floor level z=-10.0000 mm"));
  CHECK(numberAfter(e, "leaves ") == Approx(600).epsilon(1e-6));
  CHECK(numberAfter(moves.comment, "swept ") == Approx(500 + 25 * kPi).margin(0.005));
  CHECK(o.stats["uncut errors"] == 1);
  CHECK(o.stats["gouge errors"] == 0);
}

TEST_CASE("verify-toolpaths: an L-shaped pocket", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%lpocket", kFinish));
  // The lower arm's ring at offset 5: [105, 135] x [5, 15].
  Path path;
  path.enter(105, 5).rectangle(105, 5, 135, 15);
  Node &moves = attach(*p.module, "@ws", path.leave());
  Outcome o = verify(*p.module);
  // Reachable: the L (1200) less its five convex corners, (1 - pi/4) 25 each.
  // Swept: the ring's rectangle grown by 5: 300 + 80*5 + 25 pi. Uncut: the
  // upper arm less two corners, and the lower arm's upper left corner, which
  // the L does not have: 375 + 6.25 pi.
  const double uncut = 375 + 6.25 * kPi;
  const std::string e = errorWith(o, "uncut at its floor level");
  CHECK(numberAfter(e, "leaves ") == Approx(uncut).margin(0.0005));
  CHECK(numberAfter(e, "mm2 (") == Approx(100 * uncut / 1200).margin(0.0005));
  CHECK(numberAfter(moves.comment, "swept ") == Approx(700 + 25 * kPi).margin(0.005));
  CHECK(numberAfter(moves.comment, "gouge ") == Approx(0).margin(0.0005));
  CHECK(o.errors.size() == 1);
}

TEST_CASE("verify-toolpaths: a pocket with a boss", "[verify]") {
  SECTION("the outer ring leaves the middle around the boss") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish), true);
    Path path;
    path.enter(-15, -10).rectangle(-15, -10, 15, 10);
    Node &moves = attach(*p.module, "@ws", path.leave());
    Outcome o = verify(*p.module);
    // Reachable: the pocket less the boss (radius 3): 1100 + 16 pi. The ring
    // leaves the rectangle [-10, 10] x [-5, 5] less the boss: 200 - 9 pi.
    const std::string e = errorWith(o, "uncut at its floor level");
    CHECK(numberAfter(e, "leaves ") == Approx(200 - 9 * kPi).margin(0.0005));
    CHECK(numberAfter(moves.comment, "swept ") == Approx(900 + 25 * kPi).margin(0.005));
    CHECK(o.errors.size() == 1);
  }
  SECTION("a cut across the boss gouges all of it") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish), true);
    Path path;
    path.enter(-15, 0).line(15, 0);
    attach(*p.module, "@ws", path.leave());
    Outcome o = verify(*p.module);
    // Over the boss's centre the disc of radius 5 reaches 5 + 3 into it.
    const std::string e = errorWith(o, " gouges island %boss by ");
    CHECK(numberAfter(e, " by ") == Approx(8).margin(0.005));
    CHECK(contains(e, " at (0.00"));
  }
  SECTION("without the island the same cut is fine") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish), false);
    Path path;
    path.enter(-15, 0).line(15, 0);
    attach(*p.module, "@ws", path.leave());
    Outcome o = verify(*p.module);
    CHECK(o.stats["gouge errors"] == 0);
  }
}

TEST_CASE("verify-toolpaths: a plunge clears a disc at the floor", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
  // A plunge in the middle, then the outer ring: the ring leaves the
  // rectangle [-10, 10] x [-5, 5] (200), the plunge a disc of it (25 pi).
  Path path;
  path.enter(0, 0).leave().enter(-15, -10).rectangle(-15, -10, 15, 10);
  Node &moves = attach(*p.module, "@ws", path.leave());
  Outcome o = verify(*p.module);
  const std::string e = errorWith(o, "uncut at its floor level");
  CHECK(numberAfter(e, "leaves ") == Approx(200 - 25 * kPi).margin(0.0005));
  CHECK(numberAfter(moves.comment, "swept ") == Approx(900 + 50 * kPi).margin(0.005));
}

TEST_CASE("verify-toolpaths: a circular pocket entered by a helix", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%round", kFinish));
  // Down two whole turns of radius 15 from z=2 to the floor, then one circle.
  Path path;
  path.rapid(15, 100, 20).rapid(15, 100, 2).arc(15, 100, 0, 100, true, 1, -10).arc(15, 100, 0, 100);
  Node &moves = attach(*p.module, "@ws", path.leave());
  Outcome o = verify(*p.module);
  // Reachable: the disc of radius 20, 400 pi; swept: the ring 10..20, 300 pi.
  const std::string e = errorWith(o, "uncut at its floor level");
  CHECK(numberAfter(e, "leaves ") == Approx(100 * kPi).margin(0.0005));
  CHECK(numberAfter(e, "mm2 (") == Approx(25).margin(0.0005));
  CHECK(numberAfter(moves.comment, "swept ") == Approx(300 * kPi).margin(0.005));
  // Path: 18, the helix sqrt((2 * 2 pi 15)^2 + 12^2), the circle 30 pi, up 12 and 18.
  const double helix = std::hypot(60 * kPi, 12.0);
  CHECK(numberAfter(moves.comment, "path ") == Approx(18 + helix + 30 * kPi + 30).margin(0.05));
  CHECK(o.errors.size() == 1);
}

TEST_CASE("verify-toolpaths: safety and depth", "[verify]") {
  SECTION("a rapid across the pocket below the security plane") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
    Path path = clearingPath();
    path.rapid(0, 0, 2);  // sideways at z=2: above the top, below the plane
    attach(*p.module, "@ws", path);
    Outcome o = verify(*p.module);
    CHECK(contains(errorWith(o, "rapid from"),
                   "rapid from (-10.0000, -5.0000, 20.0000) to (0.0000, 0.0000, 2.0000) "
                   "below the security plane z=20.0000 mm and not along the tool axis "
                   "above %pocket"));
    CHECK(o.stats["safety errors"] == 1);
  }
  SECTION("a rapid along the axis into the pocket") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
    Path path;
    path.rapid(-15, -10, 20).rapid(-15, -10, -5);
    attach(*p.module, "@ws", path);
    CHECK(verify(*p.module).stats["safety errors"] == 1);
  }
  SECTION("the first move must be a rapid up to the security plane") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
    Path path;
    path.rapid(-15, -10, 2).rapid(-15, -10, 20);
    attach(*p.module, "@ws", path);
    Outcome o = verify(*p.module);
    CHECK(contains(errorWith(o, "first move"), "must be a rapid ending at or above the security plane"));
  }
  SECTION("feeding with the spindle stopped") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
    Path path(0);
    path.enter(-15, -10).rectangle(-15, -10, 15, 10).leave();
    attach(*p.module, "@ws", path);
    Outcome o = verify(*p.module);
    CHECK(contains(errorWith(o, "spindle"), "feed move with the spindle stopped"));
    CHECK(o.stats["safety errors"] == 1);
  }
  SECTION("a move below the floor") {
    ir::test::Parsed p = parseModule(workingstep("@ws", "%pocket", kFinish));
    Path path;
    path.enter(-15, -10, -10.5).rectangle(-15, -10, 15, 10).leave();
    attach(*p.module, "@ws", path);
    Outcome o = verify(*p.module);
    // The plunge, the four sides and the way up; the first three are reported.
    const std::vector<std::string> found = errorsWith(o, "below the floor");
    REQUIRE(found.size() == 3);
    CHECK(contains(found[0], "linear to (-15.0000, -10.0000, -10.5000) goes below the floor of %pocket: "
                             "z=-10.5000 mm, lowest allowed z=-10.0000 mm"));
    CHECK(o.stats["depth errors"] == 6);
  }
}

TEST_CASE("verify-toolpaths: roughing and finishing together", "[verify]") {
  const std::string steps = workingstep("@rough", "%pocket", "freeform_operation") +
                            workingstep("@finish", "%pocket", kFinish);
  SECTION("two parts cut by two workingsteps cover the pocket") {
    ir::test::Parsed p = parseModule(steps);
    attach(*p.module, "@rough", leftHalfPath());
    attach(*p.module, "@finish", rightPartPath());
    Outcome o = verify(*p.module);
    // The freeform half is only measured; the finishing part is an error on its own.
    REQUIRE(errorsWith(o, "").size() == 1);
    CHECK(contains(o.errors[0], "workingstep @finish: leaves 300.000 mm2"));
  }
  SECTION("two halves leave the corners of their sweeps where they meet") {
    ir::test::Parsed p = parseModule(steps);
    attach(*p.module, "@rough", leftHalfPath());
    Path right;
    right.enter(5, -10).rectangle(5, -10, 15, 10).line(10, -10).line(10, 10);
    attach(*p.module, "@finish", right.leave());
    Outcome o = verify(*p.module);
    // Four corners (1 - pi/4) 25 around (0, 15) and (0, -15): 100 - 25 pi.
    const std::string e = errorWith(o, "rough + finish");
    CHECK(numberAfter(e, "leave ") == Approx(100 - 25 * kPi).margin(0.0005));
  }
  SECTION("the same half twice leaves the other half") {
    ir::test::Parsed p = parseModule(steps);
    attach(*p.module, "@rough", leftHalfPath());
    attach(*p.module, "@finish", leftHalfPath());
    Outcome o = verify(*p.module);
    CHECK(contains(errorWith(o, "rough + finish"), "feature %pocket: rough + finish leave 600.000 mm2 (" +
                                                       formatFixed(100 * 600 / kPocketArea, 3) +
                                                       " %) uncut"));
  }
}

TEST_CASE("verify-toolpaths: what it cannot verify it says", "[verify]") {
  ir::test::Parsed p = parseModule(workingstep("@ws", "%domed", kFinish));
  Path path;
  path.enter(100, 100).leave();
  Node &moves = attach(*p.module, "@ws", path);
  Outcome o = verify(*p.module);
  CHECK(o.errors.empty());
  REQUIRE(o.warnings.size() == 1);
  CHECK(contains(o.warnings[0], "workingstep @ws: not verified: pocket %domed has a radiused bottom"));
  CHECK(moves.comment == "path 60.0 mm, 5 moves");
  CHECK(o.stats["workingsteps not verified"] == 1);
  // Option values are checked by the registry (PipelineTest.cpp).
  CHECK(verify(*p.module, "tolerance=0.05mm").ok);
}
