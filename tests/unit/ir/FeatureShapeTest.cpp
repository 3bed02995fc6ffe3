// Feature shapes: the area each kind of feature asks to clear, with exact
// areas worked out by hand.
#include "ir/geom/FeatureShape.h"

#include "SampleModule.h"

#include <catch2/catch.hpp>

#include <numbers>

using namespace stepnc;

namespace {

constexpr double kPi = std::numbers::pi;

const std::string kHead = "project \"P\"\n"
                          "  workpiece %wp \"WP\"\n"
                          "    rawpiece shape=block size=(100.0000,80.0000,30.0000)mm at=(0.0000,0.0000,0.0000)mm "
                          "axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)\n";

const std::string kZ = "axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)";

ir::ShapeResult shapeOf(const std::string &features, std::string_view symbol,
                            std::unique_ptr<ir::Module> *keep = nullptr) {
  auto parsed = ir::test::parse(kHead + features);
  REQUIRE(parsed.errors.empty());
  const ir::Node *f = ir::findFeature(*parsed.module, symbol);
  REQUIRE(f);
  ir::ShapeResult r = ir::featureShape(*parsed.module, *f);
  if (keep)
    *keep = std::move(parsed.module);
  return r;
}

} // namespace

TEST_CASE("a rectangular pocket with corner radii", "[shape]") {
  auto r = shapeOf("    closed_pocket %p \"P\" at=(50.0000,40.0000,30.0000)mm " + kZ +
                       " depth=10.0000mm bottom=planar orthogonal_radius=8.0000mm\n"
                       "      rectangular_profile width=40.0000mm length=60.0000mm\n",
                   "%p");
  REQUIRE(r.shape);
  CHECK(r.shape->target.area() == Approx(2400 - (4 - kPi) * 64).epsilon(1e-12));
  CHECK(r.shape->top == 30);
  CHECK(r.shape->bottom == 20);
  CHECK_FALSE(r.shape->unbounded);
  // Length along the profile's x axis: the pocket spans x 20..80, y 20..60.
  const geom::Box box = r.shape->target.box();
  CHECK(box.lo.x() == Approx(20));
  CHECK(box.hi.x() == Approx(80));
  CHECK(box.lo.y() == Approx(20));
  CHECK(box.hi.y() == Approx(60));
}

TEST_CASE("a pocket turned by its placement keeps its area and turns its box", "[shape]") {
  auto r = shapeOf("    closed_pocket %p \"P\" at=(50.0000,40.0000,30.0000)mm axis=(0.000000,0.000000,1.000000) "
                   "ref=(0.000000,1.000000,0.000000) depth=10.0000mm bottom=planar\n"
                   "      rectangular_profile width=40.0000mm length=60.0000mm\n",
                   "%p");
  REQUIRE(r.shape);
  CHECK(r.shape->target.area() == Approx(2400));
  CHECK(r.shape->target.box().hi.y() == Approx(70));
  CHECK(r.shape->target.box().hi.x() == Approx(70));
}

TEST_CASE("a circular pocket with a boss island", "[shape]") {
  auto r = shapeOf("    closed_pocket %p \"P\" at=(50.0000,40.0000,30.0000)mm " + kZ +
                       " depth=10.0000mm bottom=planar\n"
                       "      circular_profile diameter=60.0000mm\n"
                       "      island feature=%b\n"
                       "    boss %b \"B\" at=(55.0000,40.0000,25.0000)mm " + kZ + " depth=5.0000mm\n"
                       "      circular_profile diameter=10.0000mm\n",
                   "%p");
  REQUIRE(r.shape);
  CHECK(r.shape->target.area() == Approx(900 * kPi).epsilon(1e-12));
  REQUIRE(r.shape->islands.size() == 1);
  CHECK(r.shape->islands[0].region.area() == Approx(25 * kPi).epsilon(1e-12));
  CHECK(r.shape->islands[0].top == 25);
  CHECK(r.shape->islands[0].region.contains({55, 40}));
}

TEST_CASE("an L-shaped pocket from a general profile", "[shape]") {
  auto r = shapeOf("    closed_pocket %p \"P\" at=(10.0000,10.0000,30.0000)mm " + kZ +
                       " depth=5.0000mm bottom=planar\n"
                       "      general_profile closed=true\n"
                       "        polyline\n"
                       "          point at=(0.0000,0.0000,0.0000)mm\n"
                       "          point at=(40.0000,0.0000,0.0000)mm\n"
                       "          point at=(40.0000,20.0000,0.0000)mm\n"
                       "          point at=(20.0000,20.0000,0.0000)mm\n"
                       "          point at=(20.0000,40.0000,0.0000)mm\n"
                       "          point at=(0.0000,40.0000,0.0000)mm\n"
                       "          point at=(0.0000,0.0000,0.0000)mm\n",
                   "%p");
  REQUIRE(r.shape);
  CHECK(r.shape->target.area() == Approx(1200));
  CHECK(r.shape->target.contains({15, 15}));
  CHECK_FALSE(r.shape->target.contains({45, 45}));
}

TEST_CASE("a slot with radiused ends and one with open ends", "[shape]") {
  const std::string path = "      path\n        line at=(0.0000,0.0000,0.0000)mm dir=(1.000000,0.000000,0.000000) "
                           "length=50.0000mm\n      square_u_profile width=10.0000mm\n";
  auto closed = shapeOf("    slot %s \"S\" at=(20.0000,40.0000,30.0000)mm " + kZ +
                            " depth=5.0000mm end_1=radiused end_2=radiused\n" + path,
                        "%s");
  REQUIRE(closed.shape);
  CHECK(closed.shape->target.area() == Approx(500 + 25 * kPi).epsilon(1e-12));
  CHECK(closed.shape->limit.area() == Approx(closed.shape->target.area()));
  auto open = shapeOf("    slot %s \"S\" at=(20.0000,40.0000,30.0000)mm " + kZ +
                          " depth=5.0000mm end_1=open end_2=open\n" + path,
                      "%s");
  REQUIRE(open.shape);
  CHECK(open.shape->target.area() == Approx(500));
  CHECK(open.shape->limit.area() > 500);
  CHECK(open.shape->limit.contains({10, 40}));  // past the open end
}

TEST_CASE("a slot open at one end and radiused at the other keeps both in its limit", "[shape]") {
  auto r = shapeOf("    slot %s \"S\" at=(20.0000,40.0000,30.0000)mm " + kZ +
                       " depth=5.0000mm end_1=open end_2=radiused\n      path\n        line "
                       "at=(0.0000,0.0000,0.0000)mm dir=(1.000000,0.000000,0.000000) length=50.0000mm\n"
                       "      rounded_u_profile width=10.0000mm\n",
                   "%s");
  REQUIRE(r.shape);
  CHECK(r.shape->target.area() == Approx(500 + 12.5 * kPi).epsilon(1e-12));
  CHECK(r.shape->limit.contains({73, 40}));       // in the radiused end
  CHECK_FALSE(r.shape->limit.contains({76, 40}));  // past it: material
  CHECK(r.shape->limit.contains({0, 40}));        // past the open end: air
  REQUIRE(r.shape->slot);
  CHECK((r.shape->slot->from - geom::Vec2(20, 40)).norm() < 1e-12);
  CHECK((r.shape->slot->to - geom::Vec2(70, 40)).norm() < 1e-12);
  CHECK(r.shape->slot->width == 10);
  CHECK(r.shape->slot->end1 == "open");
  CHECK(r.shape->slot->end2 == "radiused");
}

TEST_CASE("an open pocket is its walls closed by the open side, with air beyond", "[shape]") {
  // Walls from (10,60) down to (10,20), across to (40,20), up to (40,60):
  // 30 x 40 = 1200 mm2, open towards +y.
  auto r = shapeOf("    open_pocket %p \"P\" at=(0.0000,0.0000,30.0000)mm " + kZ +
                       " depth=8.0000mm bottom=planar\n      general_profile closed=false\n        polyline\n"
                       "          point at=(10.0000,60.0000,0.0000)mm\n          point at=(10.0000,20.0000,0.0000)mm\n"
                       "          point at=(40.0000,20.0000,0.0000)mm\n          point at=(40.0000,60.0000,0.0000)mm\n",
                   "%p");
  REQUIRE(r.shape);
  CHECK(r.shape->target.area() == Approx(1200).epsilon(1e-12));
  CHECK_FALSE(r.shape->unbounded);
  CHECK(r.shape->limit.contains({25, 70}));        // past the open side
  CHECK(r.shape->limit.contains({0, 70}));         // beside it, still beyond the open side's line
  CHECK_FALSE(r.shape->limit.contains({5, 40}));   // behind a wall
  CHECK_FALSE(r.shape->limit.contains({25, 15}));  // behind the bottom wall
  // An open boundary that is one straight line encloses nothing.
  auto flat = shapeOf("    open_pocket %p \"P\" at=(0.0000,0.0000,30.0000)mm " + kZ +
                          " depth=8.0000mm bottom=planar\n      general_profile closed=false\n        polyline\n"
                          "          point at=(10.0000,60.0000,0.0000)mm\n          point at=(10.0000,20.0000,0.0000)mm\n",
                      "%p");
  CHECK_FALSE(flat.shape);
  CHECK(flat.error.find("encloses no area") != std::string::npos);
}

TEST_CASE("a general outside profile stands as an island in the raw piece", "[shape]") {
  auto r = shapeOf("    general_outside_profile %o \"O\" at=(50.0000,40.0000,30.0000)mm " + kZ +
                       " depth=10.0000mm\n      circular_profile diameter=20.0000mm\n",
                   "%o");
  REQUIRE(r.shape);
  CHECK(r.shape->unbounded);
  CHECK(r.shape->target.area() == Approx(100 * 80));
  REQUIRE(r.shape->islands.size() == 1);
  CHECK(r.shape->islands[0].region.area() == Approx(100 * kPi).epsilon(1e-12));
  CHECK(r.shape->islands[0].top == 30);
  CHECK(r.shape->bottom == 20);
}

TEST_CASE("slots with slanted or curved walls have a cross-section", "[shape]") {
  auto slot = [&](const std::string &profile, const std::string &depth) {
    return shapeOf("    slot %s \"S\" at=(20.0000,40.0000,30.0000)mm " + kZ + " depth=" + depth +
                       "mm end_1=open end_2=open\n      path\n        line "
                       "at=(0.0000,0.0000,0.0000)mm dir=(1.000000,0.000000,0.000000) length=50.0000mm\n      " +
                       profile + "\n",
                   "%s");
  };
  // A sharp vee, its first flank (right of the course) vertical, the other 60 deg from it.
  auto vee = slot("vee_profile profile_angle=60.0000deg tilt_angle=0.0000deg", "5.0000");
  REQUIRE(vee.shape);
  REQUIRE(vee.shape->section);
  const ir::SlotSection &v = *vee.shape->section;
  CHECK(v.span(0)->first == Approx(0).margin(1e-12));
  CHECK(v.span(0)->second == Approx(0).margin(1e-12));
  CHECK(v.span(2.5)->first == Approx(0).margin(1e-12));
  CHECK(v.span(2.5)->second == Approx(2.5 * std::sqrt(3.0)));
  CHECK_FALSE(v.span(-0.1));
  CHECK(v.breaks() == std::vector<double>{0, 5});
  // The outline at the top is the vee's width there, left of the course.
  CHECK(vee.shape->target.area() == Approx(50 * 5 * std::sqrt(3.0)));
  CHECK(vee.shape->target.contains({40, 41}));
  CHECK_FALSE(vee.shape->target.contains({40, 39.9}));
  // A vee rounded at the bottom: its lowest point is the floor.
  auto round = slot("vee_profile profile_radius=2.0000mm profile_angle=90.0000deg tilt_angle=45.0000deg", "8.0000");
  REQUIRE(round.shape);
  const double apex = 2 * std::sqrt(2.0) - 2;  // below the floor, where the flanks would meet
  CHECK(round.shape->section->span(8)->second == Approx(8 + apex));
  CHECK(round.shape->section->span(0)->second == Approx(0).margin(1e-9));
  CHECK(round.shape->section->span(0.5)->second == Approx(std::sqrt(4 - 1.5 * 1.5)));  // on the rounding
  CHECK(round.shape->section->span(1)->second == Approx(1 + apex));                     // on the flank
  // A partial circle as deep as its arc, and a rounded U deeper than its half circle.
  auto arc = slot("partial_circular_profile radius=10.0000mm sweep_angle=120.0000deg", "5.0000");
  REQUIRE(arc.shape);
  CHECK(arc.shape->section->span(5)->second == Approx(10 * std::sqrt(3.0) / 2));
  CHECK(arc.shape->section->span(1)->first == Approx(-std::sqrt(100 - 81.0)));
  auto u = slot("rounded_u_profile width=10.0000mm", "8.0000");
  REQUIRE(u.shape);
  CHECK(u.shape->section->span(1)->second == Approx(3));
  CHECK(u.shape->section->span(6)->second == Approx(5));
  CHECK(u.shape->slot->width == Approx(10));
  // A flank that does not rise cannot be cut from above.
  auto bad = slot("vee_profile profile_angle=150.0000deg tilt_angle=100.0000deg", "5.0000");
  CHECK_FALSE(bad.shape);
  CHECK(bad.error.find("does not rise") != std::string::npos);
}

TEST_CASE("a planar face is unbounded; a step takes the nearer side of the raw piece", "[shape]") {
  auto face = shapeOf("    planar_face %f \"F\" at=(0.0000,0.0000,30.0000)mm " + kZ +
                          " depth=2.0000mm travel=80.0000mm travel_dir=(0.000000,1.000000,0.000000) "
                          "width=100.0000mm width_dir=(1.000000,0.000000,0.000000)\n",
                      "%f");
  REQUIRE(face.shape);
  CHECK(face.shape->unbounded);
  CHECK(face.shape->target.area() == Approx(8000));
  CHECK(face.shape->target.contains({50, 40}));
  auto step = shapeOf("    step %t \"T\" at=(85.0000,0.0000,30.0000)mm " + kZ +
                          " depth=10.0000mm\n      path\n        line at=(0.0000,0.0000,0.0000)mm "
                          "dir=(0.000000,1.000000,0.000000) length=80.0000mm\n",
                      "%t");
  REQUIRE(step.shape);
  CHECK(step.shape->target.area() == Approx(15 * 80));
  CHECK(step.shape->target.contains({90, 40}));
  CHECK(step.shape->limit.contains({120, 40}));
  CHECK_FALSE(step.shape->limit.contains({80, 40}));
}

TEST_CASE("a round hole and a tilted feature", "[shape]") {
  auto hole = shapeOf("    round_hole %h \"H\" at=(20.0000,30.0000,30.0000)mm " + kZ +
                          " depth=12.0000mm diameter=8.0000mm bottom=flat\n",
                      "%h");
  REQUIRE(hole.shape);
  REQUIRE(hole.shape->holeCentre);
  CHECK(hole.shape->holeCentre->x() == 20);
  CHECK(hole.shape->target.area() == Approx(16 * kPi).epsilon(1e-12));
  auto tilted = shapeOf("    round_hole %h \"H\" at=(20.0000,30.0000,30.0000)mm axis=(1.000000,0.000000,0.000000) "
                        "ref=(0.000000,1.000000,0.000000) depth=12.0000mm diameter=8.0000mm bottom=flat\n",
                        "%h");
  CHECK_FALSE(tilted.shape);
  CHECK(tilted.error.find("+z") != std::string::npos);
}

TEST_CASE("a boss whose walls lean in: its outline at its foot, shrunk going up", "[shape]") {
  const std::string boss = "    planar_face %f \"F\" at=(0.0000,0.0000,30.0000)mm " + kZ +
                           " depth=10.0000mm travel=80.0000mm travel_dir=(0.000000,1.000000,0.000000) "
                           "width=100.0000mm width_dir=(1.000000,0.000000,0.000000)\n"
                           "      island feature=%b\n"
                           "    boss %b \"B\" at=(50.0000,40.0000,30.0000)mm " + kZ + " depth=10.0000mm ";
  auto r = shapeOf(boss + "slope=45.0000deg\n      rectangular_profile width=30.0000mm length=30.0000mm\n", "%f");
  REQUIRE(r.shape);
  REQUIRE(r.shape->islands.size() == 1);
  const ir::IslandShape &isl = r.shape->islands[0];
  CHECK(isl.sloped());
  CHECK(isl.foot == 20);
  CHECK(isl.top == 30);
  CHECK(isl.slope == Approx(1));
  // 30 x 30 at the foot, 10 mm in at the top: 10 x 10, its corners sharp.
  CHECK(isl.sectionAt(20).area() == Approx(900));
  CHECK(isl.sectionAt(25).area() == Approx(400).epsilon(1e-9));
  CHECK(isl.sectionAt(30).area() == Approx(100).epsilon(1e-9));
  CHECK(isl.sectionAt(30).contains({54.99, 44.99}));
  CHECK_FALSE(isl.sectionAt(30).contains({55.01, 40}));

  // Walls that close the outline below the top, lean out (an undercut), or
  // a pocket's slope: said, not cut as vertical walls.
  auto closed = shapeOf(boss + "slope=60.0000deg\n      rectangular_profile width=30.0000mm length=30.0000mm\n", "%f");
  CHECK_FALSE(closed.shape);
  CHECK(closed.error.find("close its outline below its top") != std::string::npos);
  auto out = shapeOf(boss + "slope=-5.0000deg\n      rectangular_profile width=30.0000mm length=30.0000mm\n", "%f");
  CHECK_FALSE(out.shape);
  CHECK(out.error.find("a slope of -5 deg is not expanded") != std::string::npos);
  auto pocket = shapeOf("    closed_pocket %p \"P\" at=(50.0000,40.0000,30.0000)mm " + kZ +
                            " depth=10.0000mm slope=5.0000deg bottom=planar\n"
                            "      circular_profile diameter=60.0000mm\n",
                        "%p");
  CHECK_FALSE(pocket.shape);
  CHECK(pocket.error.find("pockets are expanded with vertical walls only") != std::string::npos);
}
