// Turned shapes in the half plane (z, r): the material each turned feature
// removes from a 40 mm bar and the surface it leaves, with areas worked out
// by hand (the reach is the stock's radius and free end plus 10 mm).
#include "ir/geom/TurnedShape.h"

#include "SampleModule.h"
#include "geom/Boolean.h"

#include <catch2/catch.hpp>

#include <numbers>

using namespace stepnc;

namespace {

constexpr double kPi = std::numbers::pi;

const std::string kHead = "project \"P\"\n"
                          "  workpiece %wp \"WP\"\n"
                          "    rawpiece shape=cylinder diameter=40.0000mm height=100.0000mm at=(0.0000,0.0000,0.0000)mm "
                          "axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)\n";

const std::string kZ = "axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)";

struct Parsed {
  std::unique_ptr<ir::Module> module;
  const ir::Node *feature = nullptr;
  ir::TurnStock stock;
};

Parsed parsed(const std::string &features, std::string_view symbol) {
  auto p = ir::test::parse(kHead + features);
  REQUIRE(p.errors.empty());
  Parsed out;
  out.feature = ir::findFeature(*p.module, symbol);
  REQUIRE(out.feature);
  const ir::StockResult s = ir::turnStock(ir::workpieceOf(*p.module, *out.feature));
  REQUIRE(s.stock);
  out.stock = *s.stock;
  out.module = std::move(p.module);
  return out;
}

/// The removal within the stock's rectangle (the reach cut away).
double areaInStock(const ir::TurnedShape &s, const ir::TurnStock &stock) {
  return geom::intersect(s.removal, stock.region()).area();
}

} // namespace

TEST_CASE("the raw piece as a lathe holds it", "[turned]") {
  auto p = parsed("    outer_diameter %od \"OD\" at=(0.0000,0.0000,10.0000)mm " + kZ +
                      " diameter=30.0000mm length=50.0000mm\n",
                  "%od");
  CHECK(p.stock.z0 == 0);
  CHECK(p.stock.z1 == 100);
  CHECK(p.stock.radius == 20);
  CHECK(p.stock.region().area() == Approx(2000));
}

TEST_CASE("an outer diameter removes the ring over its length, open towards the free end", "[turned]") {
  auto p = parsed("    outer_diameter %od \"OD\" at=(0.0000,0.0000,10.0000)mm " + kZ +
                      " diameter=30.0000mm length=50.0000mm\n",
                  "%od");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  // From z=10 to the free end (100) between r=15 and 20: the surface runs on
  // past its length at its radius.
  CHECK(areaInStock(*r.shape, p.stock) == Approx(90 * 5).epsilon(1e-12));
  // The surface: along z at r=15 from the reach to z=10, then out the wall.
  REQUIRE(r.shape->contour.size() == 3);
  CHECK(r.shape->contour[1].a.x() == Approx(60));
  CHECK(r.shape->contour[1].b.x() == Approx(10));
  CHECK(r.shape->contour[1].a.y() == Approx(15));
  CHECK(r.shape->contour[2].b.y() == Approx(30));  // the reach: the stock's radius + 10
}

TEST_CASE("a tapered outer diameter", "[turned]") {
  auto p = parsed("    outer_diameter %od \"OD\" at=(0.0000,0.0000,10.0000)mm " + kZ +
                      " diameter=30.0000mm length=50.0000mm reduced_diameter=20.0000mm\n",
                  "%od");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  // r 15 at z=10 to r 10 at z=60, then r 10 to the free end.
  CHECK(areaInStock(*r.shape, p.stock) == Approx(50 * (5 + 10) / 2.0 + 40 * 10).epsilon(1e-12));
}

TEST_CASE("a diameter to a shoulder with a fillet", "[turned]") {
  auto p = parsed("    outer_diameter_to_shoulder %od \"OD\" at=(0.0000,0.0000,60.0000)mm " + kZ +
                      " diameter=30.0000mm\n"
                      "      vee_profile profile_radius=2.0000mm profile_angle=90.0000deg tilt_angle=0.0000deg\n",
                  "%od");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  // z 60..100, r 15..20, less the fillet's corner (r^2 - pi r^2 / 4).
  CHECK(areaInStock(*r.shape, p.stock) == Approx(40 * 5 - (4 - kPi)).epsilon(1e-12));
  REQUIRE(r.shape->contour.size() == 3);
  CHECK(r.shape->contour[1].isArc());
}

TEST_CASE("a face clears from its radius out", "[turned]") {
  auto p = parsed("    revolved_flat %f \"F\" at=(0.0000,0.0000,95.0000)mm " + kZ +
                      " radius=0.0000mm material_side=(0.000000,0.000000,-1.000000)\n"
                      "      linear_profile length=20.0000mm\n",
                  "%f");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(5 * 20).epsilon(1e-12));
  REQUIRE(r.shape->contour.size() == 1);
}

TEST_CASE("an outer groove with corner radii", "[turned]") {
  auto p = parsed("    groove %g \"G\" at=(0.0000,0.0000,50.0000)mm " + kZ +
                      " radius=16.0000mm material_side=(-1.000000,0.000000,0.000000)\n"
                      "      square_u_profile width=4.0000mm first_radius=0.5000mm first_angle=90.0000deg "
                      "second_radius=0.5000mm second_angle=90.0000deg\n",
                  "%g");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(4 * 4 - 2 * (0.25 - kPi * 0.25 / 4)).epsilon(1e-12));
  REQUIRE(r.shape->grooveSpan);
  CHECK(r.shape->grooveSpan->first == 48);
  CHECK(r.shape->grooveSpan->second == 52);
  CHECK(r.shape->grooveFloor == 16);
}

TEST_CASE("what is not turned is said", "[turned]") {
  SECTION("off the axis") {
    auto p = parsed("    outer_diameter %od \"OD\" at=(1.0000,0.0000,10.0000)mm " + kZ +
                        " diameter=30.0000mm length=50.0000mm\n",
                    "%od");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    CHECK_FALSE(r.shape);
    CHECK(r.error.find("off the turning axis") != std::string::npos);
  }
  SECTION("a face groove in a face looking towards the chuck") {
    auto p = parsed("    groove %g \"G\" at=(0.0000,0.0000,50.0000)mm " + kZ +
                        " radius=16.0000mm material_side=(0.000000,0.000000,1.000000)\n"
                        "      square_u_profile width=4.0000mm\n",
                    "%g");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    CHECK_FALSE(r.shape);
    CHECK(r.error.find("looking towards the chuck") != std::string::npos);
  }
  SECTION("a taper to nothing") {
    auto p = parsed("    outer_diameter %od \"OD\" at=(0.0000,0.0000,10.0000)mm " + kZ +
                        " diameter=30.0000mm length=50.0000mm taper_angle=45.0000deg\n",
                    "%od");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    CHECK_FALSE(r.shape);
    CHECK(r.error.find("no turned surface") != std::string::npos);
  }
}

TEST_CASE("a general revolved profile: steps from the free end", "[turned]") {
  auto p = parsed("    general_revolution %g \"G\" at=(0.0000,0.0000,0.0000)mm " + kZ +
                      " radius=0.0000mm material_side=(-1.000000,0.000000,0.000000)\n"
                      "      general_profile closed=false\n"
                      "        polyline\n"
                      "          point at=(15.0000,0.0000,100.0000)mm\n"
                      "          point at=(15.0000,0.0000,50.0000)mm\n"
                      "          point at=(18.0000,0.0000,50.0000)mm\n"
                      "          point at=(18.0000,0.0000,20.0000)mm\n",
                  "%g");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  // z 50..100 between r 15 and 20, z 20..50 between 18 and 20.
  CHECK(areaInStock(*r.shape, p.stock) == Approx(50 * 5 + 30 * 2).epsilon(1e-12));
  // The same profile written from the chuck end reads the same.
  auto q = parsed("    general_revolution %g \"G\" at=(0.0000,0.0000,0.0000)mm " + kZ +
                      " radius=0.0000mm\n"
                      "      general_profile closed=false\n"
                      "        polyline\n"
                      "          point at=(18.0000,0.0000,20.0000)mm\n"
                      "          point at=(18.0000,0.0000,50.0000)mm\n"
                      "          point at=(15.0000,0.0000,50.0000)mm\n"
                      "          point at=(15.0000,0.0000,100.0000)mm\n",
                  "%g");
  ir::TurnedShapeResult back = ir::turnedShape(*q.feature, q.stock);
  REQUIRE(back.shape);
  CHECK(areaInStock(*back.shape, q.stock) == Approx(310).epsilon(1e-12));
  CHECK(back.shape->contour[1].a.x() == Approx(100));
}

TEST_CASE("a bore: an inner revolved profile", "[turned]") {
  // 30 mm across for 20 mm from the free end, then 24 mm to 50 mm deep, a
  // flat bottom: the removal reaches in to the axis.
  auto p = parsed("    general_revolution %b \"B\" at=(0.0000,0.0000,0.0000)mm " + kZ +
                      " radius=0.0000mm material_side=(1.000000,0.000000,0.000000)\n"
                      "      general_profile closed=false\n"
                      "        polyline\n"
                      "          point at=(15.0000,0.0000,100.0000)mm\n"
                      "          point at=(15.0000,0.0000,80.0000)mm\n"
                      "          point at=(12.0000,0.0000,80.0000)mm\n"
                      "          point at=(12.0000,0.0000,50.0000)mm\n",
                  "%b");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  CHECK(r.shape->inner);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(20 * 15 + 30 * 12).epsilon(1e-12));
  // The surface from past the free end, into the bore, across its bottom to the axis.
  REQUIRE(r.shape->contour.size() == 5);
  CHECK(r.shape->contour.front().a.x() == Approx(110));
  CHECK(r.shape->contour.back().b.x() == Approx(50));
  CHECK(r.shape->contour.back().b.y() == Approx(0));
  // The part keeps what lies outside it.
  CHECK_FALSE(r.shape->removal.contains(geom::Vec2(90, 16)));
  CHECK(r.shape->removal.contains(geom::Vec2(90, 14)));
}

TEST_CASE("a hole on the axis turned as an inner diameter", "[turned]") {
  auto hole = [](const std::string &bottom) {
    return "    round_hole %h \"H\" at=(0.0000,0.0000,100.0000)mm " + kZ +
           " depth=30.0000mm diameter=20.0000mm " + bottom + "\n";
  };
  SECTION("flat") {
    auto p = parsed(hole("bottom=flat"), "%h");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    REQUIRE(r.shape);
    CHECK(r.shape->inner);
    CHECK(areaInStock(*r.shape, p.stock) == Approx(30 * 10).epsilon(1e-12));
  }
  SECTION("through: on past the chuck side") {
    auto p = parsed(hole("bottom=through"), "%h");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    REQUIRE(r.shape);
    CHECK(areaInStock(*r.shape, p.stock) == Approx(100 * 10).epsilon(1e-12));
  }
  SECTION("conical: the point at its depth") {
    // A 90 degree point: a cone 10 mm long ending at z 70.
    auto p = parsed(hole("bottom=conical tip_angle=90.0000deg"), "%h");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    REQUIRE(r.shape);
    CHECK(areaInStock(*r.shape, p.stock) == Approx(20 * 10 + 10 * 10 / 2.0).epsilon(1e-12));
  }
  SECTION("a tapered hole to its final diameter") {
    auto p = parsed(hole("bottom=flat final_diameter=16.0000mm"), "%h");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    REQUIRE(r.shape);
    CHECK(areaInStock(*r.shape, p.stock) == Approx(30 * (10 + 8) / 2.0).epsilon(1e-12));
  }
  SECTION("a spherical bottom is said") {
    auto p = parsed(hole("bottom=spherical"), "%h");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    CHECK_FALSE(r.shape);
    CHECK(r.error.find("spherical bottom is not turned yet") != std::string::npos);
  }
}

TEST_CASE("an inner groove: open towards the axis", "[turned]") {
  // Its floor 16 mm from the axis, 4 mm wide, a 0.5 mm round at the chuck
  // side: the removal from the axis out to the floor.
  auto p = parsed("    groove %g \"G\" at=(0.0000,0.0000,50.0000)mm " + kZ +
                      " radius=16.0000mm material_side=(1.000000,0.000000,0.000000)\n"
                      "      square_u_profile width=4.0000mm first_radius=0.5000mm\n",
                  "%g");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  CHECK(r.shape->inner);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(4 * 16 - (0.25 - kPi * 0.25 / 4)).epsilon(1e-12));
  CHECK(r.shape->grooveFloor == 16);
  CHECK_FALSE(r.shape->removal.contains(geom::Vec2(48.1, 15.9)));  // the round's corner stays
  CHECK(r.shape->removal.contains(geom::Vec2(51, 15.9)));
}

TEST_CASE("an inner thread: from its minor diameter out to its major", "[turned]") {
  // M20x1.5 inside, 20 mm from the end: ISO 965-1's D1 = 20 - 1.082532 x 1.5.
  auto p = parsed("    thread %t \"T\" at=(0.0000,0.0000,100.0000)mm axis=(0.000000,0.000000,-1.000000) "
                  "ref=(1.000000,0.000000,0.000000) major_diameter=20.0000mm pitch_diameter=19.0260mm "
                  "length=20.0000mm starts=2 hand=left inner=true\n",
                  "%t");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  REQUIRE(r.shape->thread);
  CHECK(r.shape->inner);
  const ir::TurnedShape::ThreadSpan &t = *r.shape->thread;
  CHECK(t.pitch == Approx(1.5).epsilon(1e-3));  // as exact as the pitch diameter's decimals
  CHECK(t.rootRadius == 10);
  CHECK(t.crestRadius == Approx((20 - 1.082532 * t.pitch) / 2).epsilon(1e-12));
  CHECK(t.lo == 80);
  CHECK(t.hi == 100);
  CHECK(t.starts == 2);
  CHECK(t.leftHand);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(20 * 10).epsilon(1e-12));
}

TEST_CASE("a revolved round: the corner outside a quarter circle", "[turned]") {
  // The bar's edge at the free end (z 100, r 20) rounded by 2 mm: the corner
  // material outside the round, 4 - pi, within the bar.
  auto p = parsed("    revolved_round %r \"R\" at=(0.0000,0.0000,100.0000)mm " + kZ +
                      " radius=20.0000mm\n"
                      "      partial_circular_profile radius=2.0000mm sweep_angle=90.0000deg\n",
                  "%r");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(4 - kPi).epsilon(1e-9));
  REQUIRE(r.shape->contour.size() == 3);
  CHECK(r.shape->contour[1].isArc());
  CHECK_FALSE(r.shape->removal.contains(geom::Vec2(99, 19)));  // inside the round: the part
  CHECK(r.shape->removal.contains(geom::Vec2(99.9, 19.9)));    // the corner
  // A round over other than a quarter turn is said.
  auto q = parsed("    revolved_round %r \"R\" at=(0.0000,0.0000,100.0000)mm " + kZ +
                      " radius=20.0000mm\n"
                      "      partial_circular_profile radius=2.0000mm sweep_angle=60.0000deg\n",
                  "%r");
  ir::TurnedShapeResult bad = ir::turnedShape(*q.feature, q.stock);
  CHECK_FALSE(bad.shape);
  CHECK(bad.error.find("a round over 60 deg is not turned yet") != std::string::npos);
}

TEST_CASE("a face groove: in the end face, open towards the free end", "[turned]") {
  // Its floor at z 95, 4 mm wide about a radius of 10 mm: 5 x 4 of the bar.
  auto p = parsed("    groove %g \"G\" at=(0.0000,0.0000,95.0000)mm " + kZ +
                      " radius=10.0000mm material_side=(0.000000,0.000000,-1.000000)\n"
                      "      square_u_profile width=4.0000mm\n",
                  "%g");
  ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
  REQUIRE(r.shape);
  CHECK(r.shape->faceGroove);
  CHECK(areaInStock(*r.shape, p.stock) == Approx(5 * 4).epsilon(1e-12));
  REQUIRE(r.shape->grooveSpan);
  CHECK(r.shape->grooveSpan->first == 8);
  CHECK(r.shape->grooveSpan->second == 12);
  CHECK(r.shape->grooveFloor == 95);
}
