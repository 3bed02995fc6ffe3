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
  SECTION("an inner groove") {
    auto p = parsed("    groove %g \"G\" at=(0.0000,0.0000,50.0000)mm " + kZ +
                        " radius=16.0000mm material_side=(1.000000,0.000000,0.000000)\n"
                        "      square_u_profile width=4.0000mm\n",
                    "%g");
    ir::TurnedShapeResult r = ir::turnedShape(*p.feature, p.stock);
    CHECK_FALSE(r.shape);
    CHECK(r.error.find("only outer grooves") != std::string::npos);
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
