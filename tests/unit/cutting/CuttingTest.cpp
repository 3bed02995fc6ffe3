// The cutting model against closed forms: the stepped cantilever, the
// engagement and chip factor of a slot and of a straight wall measured on a
// height field, the force model's limits, and the cutting-data reader.
#include "cutting/CuttingData.h"
#include "cutting/Deflection.h"
#include "cutting/Mechanics.h"
#include "tests/unit/TestSupport.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace stepnc;
using namespace stepnc::cutting;

TEST_CASE("cantilever: the test vector of the references and the stepped tool", "[cutting]") {
  // D = 10 with De = 8 over the whole length L = 40, E = 600 GPa, F = 200 N at the
  // tip: delta = F L^3 / (3 E I), I = pi 8^4 / 64 -> 35.4 um.
  ToolBeam uniform{40, 40, 10, 8, 600000};
  CHECK(deflection(uniform, 200, 0, 0) * 1000 == Approx(35.37).margin(0.01));
  // Load at distance a from the clamp, deflection at x: F a^2 (3x - a) / (6 E I).
  const double i = std::numbers::pi * std::pow(8, 4) / 64;
  CHECK(deflection(uniform, 200, 10, 0) == Approx(200 * 30 * 30 * (3 * 40 - 30) / (6 * 600000 * i)));
  // A shank of full diameter is stiffer than the fluted part: the stepped tool
  // bends less than one fluted all along and more than one solid all along.
  ToolBeam stepped{40, 20, 10, 8, 600000};
  ToolBeam solid{40, 0, 10, 8, 600000};
  CHECK(deflection(stepped, 200, 0, 0) < deflection(uniform, 200, 0, 0));
  CHECK(deflection(stepped, 200, 0, 0) > deflection(solid, 200, 0, 0));
  // Above the load: the tip loaded, the point x from the clamp moves
  // F x^2 (3L - x) / (6 E I); and by reciprocity a load at one height moves a
  // second height as much as a load there moves the first, stepped or not.
  CHECK(deflection(uniform, 200, 0, 15) == Approx(200 * 25 * 25 * (3 * 40 - 25) / (6 * 600000 * i)));
  CHECK(deflection(stepped, 200, 5, 25) == Approx(deflection(stepped, 200, 25, 5)));
  // A load spread evenly over the whole length: w L^4 / (8 E I) at the tip,
  // w = F / L; the midpoint rule over 16 slices is within 0.2 %.
  CHECK(deflectionUnderSpreadLoad(uniform, 200, 40, 0) ==
        Approx(200 * std::pow(40, 3) / (8 * 600000 * i)).epsilon(0.002));
  // Bending stress at the clamp: sigma = F L (D/2) / I.
  CHECK(forceForClampStress(solid, 800, 0) * 40 * 5 / (std::numbers::pi * std::pow(10, 4) / 64) == Approx(800));
}

namespace {

/// A block of material [0, 100] x [0, 50] up to z = 0.
HeightMap block(double cell) {
  HeightMap map(geom::Box{Vec2(-20, -20), Vec2(120, 80)}, cell);
  map.addBlock(Vec2(0, 0), Vec2(100, 50), 0);
  return map;
}

} // namespace

TEST_CASE("engagement: a slot and a straight wall on the height field", "[cutting]") {
  const Cutter cutter{5, 4, 20, true};
  HeightMap map = block(5.0 / 60);
  // Slot: the tool in the middle of the block, 5 deep.
  const Engagement slot = measureEngagement(map, Vec2(50, 25), -5, Vec2::UnitX(), cutter);
  CHECK(slot.chipFactor() == Approx(1).margin(1e-3));
  CHECK(slot.radialDepth(5) == Approx(10));
  CHECK(slot.axialDepth() == Approx(5));
  CHECK(slot.side() == 0);
  // A wall taken to ae = 1: the tool's edge reaches 1 mm into the block's side.
  for (const double ae : {0.5, 1.0, 2.5}) {
    const Engagement wall = measureEngagement(map, Vec2(50, 50 + 5 - ae), -5, Vec2::UnitX(), cutter);
    const double phi = std::acos(1 - ae / 5);
    INFO("ae " << ae);
    // A cell of position error (R / 60), half a degree of angle: at ae = 0.5
    // that is 5 % of the chip factor.
    CHECK(wall.radialDepth(5) == Approx(ae).margin(0.09));
    CHECK(wall.chipFactor() == Approx(std::sin(phi)).epsilon(0.06));
    CHECK(wall.side() == -1);  // material on the right of +x: the block is at y < 50
  }
  // Cutting the slot removes it: the same place has nothing left to cut.
  map.cutAlong(geom::Seg::line(Vec2(-10, 25), Vec2(110, 25)), 5, -5, -5, 0.05);
  CHECK_FALSE(measureEngagement(map, Vec2(50, 25), -5, Vec2::UnitX(), cutter).cutting());
  CHECK(measureEngagement(map, Vec2(50, 25), -10, Vec2::UnitX(), cutter).cutting());
}

TEST_CASE("forces: linear in the feed per tooth, limits solved exactly", "[cutting]") {
  const Cutter cutter{5, 2, 20, true};
  const CuttingCoefficients k{2000, 800, 20, 20};
  // A slot 4 deep: a tooth at the front (theta = 0) takes h = fz.
  const Engagement slot = wallEngagement(Vec2::UnitX(), 1, 10, 4, cutter);
  const ForceModel f(slot, cutter, k);
  // Mean torque: N a R / (2 pi) (Ktc c * integral of cos over the front half + Kte pi)
  // = N a R / (2 pi) (2 Ktc fz + pi Kte), in N m.
  const double fz = 0.1;
  CHECK(f.meanTorque(fz) == Approx(2 * 4 * 5 / (2 * std::numbers::pi) * (2 * 2000 * fz + std::numbers::pi * 20) / 1000)
                                .epsilon(0.01));
  // The peak force with one tooth at the front: |(Ktc h + Kte, Krc h + Kre)| a.
  CHECK(f.peakForce(fz) == Approx(4 * std::hypot(2000 * fz + 20, 800 * fz + 20)).epsilon(0.01));
  // The limits give back the forces they were asked for.
  const double fzF = f.fzForForce(1000);
  CHECK(f.peakForce(fzF) == Approx(1000).epsilon(1e-9));
  const double fzT = f.fzForTorque(2);
  CHECK(f.meanTorque(fzT) == Approx(2).epsilon(1e-9));
  // Edge forces alone above the limit: no feed is safe.
  CHECK(f.fzForForce(10) == 0);
}

TEST_CASE("cutting data: the shipped file reads, names match, user files are checked", "[cutting]") {
  const CuttingData &data = shippedCuttingData();
  REQUIRE(data.materials.count(data.defaultMaterial));
  std::string alias;
  CHECK(data.match("C45E 1.1191", "EN 10083-2", alias)->key == "steel_1045");
  CHECK(data.match("id", "SAE 1015", alias)->key == "steel_1020");
  // A specific grade before a generic word.
  CHECK(data.match("STEEL", "ST-50", alias)->key == "steel_e295");
  CHECK(data.match("STEEL", "", alias)->key == "generic_steel");
  CHECK(data.match("unobtainium", "", alias) == nullptr);

  auto file = SourceFile::fromString("user.toml", "format = 1\n"
                                                  "[materials.steel_1020]\n"
                                                  "chip_thickness = 0.05\n"
                                                  "[tools.\"%t1\"]\n"
                                                  "overhang = 45\n"
                                                  "material = \"hss\"\n");
  DiagnosticCollector c;
  DiagnosticEngine e(c);
  auto user = readCuttingData(*file, data, e);
  REQUIRE(user);
  CHECK(user->materials.at("steel_1020").chipThickness == 0.05);
  CHECK(user->materials.at("steel_1020").ktc == data.materials.at("steel_1020").ktc);
  CHECK(*user->tools.at("t1").overhang == 45);

  auto bad = SourceFile::fromString("bad.toml", "format = 1\n"
                                                "[materials.steel_1020]\n"
                                                "chip_thicknes = 0.05\n"
                                                "[tools.t2]\n"
                                                "material = \"wood\"\n"
                                                "overhang = -3\n");
  DiagnosticCollector c2;
  DiagnosticEngine e2(c2);
  CHECK_FALSE(readCuttingData(*bad, data, e2));
  const std::vector<std::string> got = test::locatedMessages(c2, *bad);
  REQUIRE(got.size() == 3);
  CHECK(got[0].starts_with("3:1: unknown key 'chip_thicknes' in [materials.steel_1020]"));
  CHECK(got[1].starts_with("5:12: [tools.\"t2\"].material 'wood' is not a tool material"));
  CHECK(got[2].starts_with("6:12: [tools.\"t2\"].overhang must be a number of mm"));
}
