// Kinematic transforms (runtime/Kinematics.h): inverse(forward(q)) gives q
// back over many random joint values of each chain, poses worked out by
// hand, the singular poses (the tool along a rotary axis, a lathe's tip on
// the spindle axis) keep the free axis where it was, unreachable poses are
// refused, and a generic chain finds its solver in the registry.
#include "runtime/Kinematics.h"

#include "../TestSupport.h"
#include "ShippedMachine.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <numbers>
#include <random>

using namespace stepnc;
using runtime::Joints;
using runtime::ToolPose;
using Vec3 = Eigen::Vector3d;

namespace {

/// Tolerances of the round trips: mm on linear axes and positions, deg on
/// rotary axes, and on unit tool directions.
constexpr double kTolMm = 1e-8;
constexpr double kTolDeg = 1e-8;
constexpr double kTolAxis = 1e-12;
constexpr int kRandomPoses = 20000;

runtime::Machine machineFrom(const std::string &text) {
  auto file = SourceFile::fromString("m.toml", text);
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  std::optional<runtime::Machine> m = runtime::readMachine(*file, diags);
  INFO(test::locatedMessages(collector, *file).size());
  for (const std::string &e : test::locatedMessages(collector, *file))
    UNSCOPED_INFO(e);
  REQUIRE(m);
  return *m;
}

std::unique_ptr<runtime::Kinematics> kinematicsOf(const runtime::Machine &m) {
  std::string error;
  std::unique_ptr<runtime::Kinematics> k = runtime::makeKinematics(m, error);
  INFO(error);
  REQUIRE(k);
  REQUIRE(k->jointCount() == m.axes.size());
  return k;
}

const std::string kHeader = "format = 1\nname = \"K\"\n"
                            "[controller]\ncycle_time = 0.001\nlookahead = 100\npath_tolerance = 0.01\n"
                            "[spindle]\nmin_speed = 100\nmax_speed = 10000\npower = 7.5\n";

std::string linear(const std::string &name, double lo, double hi) {
  return "[axes." + name + "]\ntravel = [" + std::to_string(lo) + ", " + std::to_string(hi) +
         "]\nmax_velocity = 20000\nmax_acceleration = 2000\nmax_jerk = 20000\n";
}

std::string rotary(const std::string &name, double lo, double hi, const std::string &pivot) {
  return "[axes." + name + "]\ntravel = [" + std::to_string(lo) + ", " + std::to_string(hi) +
         "]\nmax_velocity = 9000\nmax_acceleration = 1000\nmax_jerk = 10000\npivot = " + pivot + "\n";
}

std::string fiveAxis(const std::string &type, const std::string &head, const std::string &table,
                     const std::string &rotaries) {
  return kHeader + "[kinematics]\ntype = \"" + type + "\"\nhead = " + head + "\ntable = " + table + "\n" +
         linear("x", -500, 500) + linear("y", -500, 500) + linear("z", -500, 500) + rotaries;
}

/// Random joints inside every axis's travel (rotary axes: within a turn of
/// 0 where the travel is wider).
Joints randomJoints(const runtime::Machine &m, std::mt19937 &rng) {
  Joints q(static_cast<Eigen::Index>(m.axes.size()));
  for (size_t k = 0; k < m.axes.size(); ++k) {
    const runtime::Axis &a = m.axes[k];
    double lo = a.travelMin, hi = a.travelMax;
    if (a.rotary) {
      lo = std::max(lo, -180.0);
      hi = std::min(hi, 180.0);
    }
    q[static_cast<Eigen::Index>(k)] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

double worstDifference(const runtime::Machine &m, const Joints &a, const Joints &b, bool rotary) {
  double worst = 0;
  for (size_t k = 0; k < m.axes.size(); ++k)
    if (m.axes[k].rotary == rotary)
      worst = std::max(worst, std::abs(a[static_cast<Eigen::Index>(k)] - b[static_cast<Eigen::Index>(k)]));
  return worst;
}

/// inverse(forward(q), near = q) == q, and forward(inverse(pose)) == pose
/// with no hint, over kRandomPoses random q. Returns the count of checks.
int roundTrips(const runtime::Machine &m, uint32_t seed) {
  const auto k = kinematicsOf(m);
  std::mt19937 rng(seed);
  double worstMm = 0, worstDeg = 0, worstPose = 0, worstAxis = 0;
  int checks = 0;
  for (int i = 0; i < kRandomPoses; ++i) {
    const Joints q = randomJoints(m, rng);
    const ToolPose pose = k->forward(q);
    REQUIRE(std::abs(pose.axis.norm() - 1) < 1e-12);
    const runtime::InverseResult back = k->inverse(pose, &q);
    INFO("joints " << q.transpose());
    REQUIRE(back.joints);
    CHECK_FALSE(back.outsideTravel);
    worstMm = std::max(worstMm, worstDifference(m, *back.joints, q, false));
    worstDeg = std::max(worstDeg, worstDifference(m, *back.joints, q, true));
    const runtime::InverseResult fresh = k->inverse(pose);
    REQUIRE(fresh.joints);
    const ToolPose again = k->forward(*fresh.joints);
    worstPose = std::max(worstPose, (again.tipMm - pose.tipMm).norm());
    worstAxis = std::max(worstAxis, (again.axis - pose.axis).norm());
    checks += 2;
  }
  INFO(m.name << ": worst " << worstMm << " mm, " << worstDeg << " deg; forward(inverse): " << worstPose << " mm, "
              << worstAxis);
  CHECK(worstMm < kTolMm);
  CHECK(worstDeg < kTolDeg);
  CHECK(worstPose < kTolMm);
  CHECK(worstAxis < kTolAxis * 1000);
  return checks;
}

void checkPose(const ToolPose &got, const Vec3 &tip, const Vec3 &axis) {
  INFO("tip " << got.tipMm.transpose() << " axis " << got.axis.transpose());
  CHECK((got.tipMm - tip).norm() < 1e-9);
  CHECK((got.axis - axis).norm() < 1e-12);
}

Joints joints(std::initializer_list<double> values) {
  Joints q(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double v : values)
    q[i++] = v;
  return q;
}

} // namespace

TEST_CASE("xyz: the tip is the axes, the tool along +z", "[kinematics]") {
  const runtime::Machine m = test::shippedMachine("hsc-3axis");
  const auto k = kinematicsOf(m);
  checkPose(k->forward(joints({10, 20, -30})), {10, 20, -30}, Vec3::UnitZ());
  const runtime::InverseResult r = k->inverse({{10, 20, -30}, Vec3::UnitZ()});
  REQUIRE(r.joints);
  CHECK(*r.joints == joints({10, 20, -30}));
  const runtime::InverseResult tilted = k->inverse({{10, 20, -30}, Vec3(1, 0, 1).normalized()});
  CHECK_FALSE(tilted.joints);
  CHECK(tilted.why == "an xyz machine holds its tool along +z");
  CHECK(k->inverse({{-10, 20, -30}, Vec3::UnitZ()}).outsideTravel);
}

TEST_CASE("5-axis chains: inverse(forward(q)) == q over random joints", "[kinematics]") {
  int checks = 0;
  // The shipped trunnion machine: table-table A/C with pivots.
  checks += roundTrips(test::shippedMachine("table-table-5axis"), 1);
  // Table-table B/C.
  checks += roundTrips(machineFrom(fiveAxis("table-table", "[]", "[\"b\", \"c\"]",
                                            rotary("b", -110, 110, "[10, -20, -150]") +
                                                rotary("c", -36000, 36000, "[30, 40, -120]"))),
                       2);
  // Head-table: a B head 180 mm above the tip, C table.
  checks += roundTrips(machineFrom(fiveAxis("head-table", "[\"b\"]", "[\"c\"]",
                                            rotary("b", -100, 100, "[0, 0, 180]") +
                                                rotary("c", -360, 360, "[120, 80, 0]"))),
                       3);
  // Head-table A/C.
  checks += roundTrips(machineFrom(fiveAxis("head-table", "[\"a\"]", "[\"c\"]",
                                            rotary("a", -95, 95, "[0, 5, 200]") +
                                                rotary("c", -360, 360, "[-50, 60, 0]"))),
                       4);
  // Head-head: a C fork carrying an A head.
  checks += roundTrips(machineFrom(fiveAxis("head-head", "[\"c\", \"a\"]", "[]",
                                            rotary("c", -360, 360, "[0, 0, 400]") +
                                                rotary("a", -100, 100, "[0, 0, 150]"))),
                       5);
  CHECK(checks == 5 * 2 * kRandomPoses);
}

/// tipTurn(q) against the inverse kinematics' own differences: the tip
/// moved 1e-4 mm along each coordinate, the direction held, moves x, y, z by
/// the matrix's columns (to 1e-6: the differences' rounding), over random
/// joints of `m`. Returns the number of joints checked.
int tipTurns(const runtime::Machine &m, uint32_t seed) {
  const auto k = kinematicsOf(m);
  std::mt19937 rng(seed);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const Joints q = randomJoints(m, rng);
    const ToolPose pose = k->forward(q);
    const std::optional<Eigen::Matrix3d> turn = k->tipTurn(q);
    REQUIRE(turn);
    constexpr double kStep = 1e-4;
    for (int c = 0; c < 3; ++c) {
      const runtime::InverseResult moved = k->inverse({pose.tipMm + kStep * Vec3::Unit(c), pose.axis}, &q);
      REQUIRE(moved.joints);
      if (moved.singular)
        continue;
      const Vec3 seen = ((*moved.joints).head<3>() - q.head<3>()) / kStep;
      INFO("joints " << q.transpose() << ", column " << c);
      CHECK((seen - turn->col(c)).norm() < 1e-6);
    }
    ++checked;
  }
  return checked;
}

TEST_CASE("5-axis chains: tipTurn is how the tip's moves move x, y, z", "[kinematics]") {
  int checks = 0;
  checks += tipTurns(test::shippedMachine("table-table-5axis"), 11);
  checks += tipTurns(test::shippedMachine("head-table-5axis"), 12);
  checks += tipTurns(test::shippedMachine("head-head-5axis"), 13);
  checks += tipTurns(machineFrom(fiveAxis("table-table", "[]", "[\"b\", \"c\"]",
                                          rotary("b", -110, 110, "[10, -20, -150]") +
                                              rotary("c", -36000, 36000, "[30, 40, -120]"))),
                     14);
  CHECK(checks == 4 * 2000);
  // An xyz machine's axes are the tip's coordinates.
  const auto xyz = kinematicsOf(test::shippedMachine("hsc-3axis"));
  REQUIRE(xyz->tipTurn(Joints::Zero(3)));
  CHECK(*xyz->tipTurn(Joints::Zero(3)) == Eigen::Matrix3d::Identity());
}

/// rates(q) against the inverse kinematics' own central differences: the
/// tip moved along a random direction and the tool turned across itself
/// by a small step moves every joint by rates * (dp, dk) (to 1e-5 per unit:
/// the differences' error), over random joints of `m` away from the
/// singular direction; inverseWithRates gives the same joints as inverse
/// and the same rates as rates(). Returns the number of poses checked.
int ratesAgree(const runtime::Machine &m, uint32_t seed) {
  const auto k = kinematicsOf(m);
  const std::optional<Vec3> singular = k->singularDirection();
  REQUIRE(singular);
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  int checked = 0;
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const Joints q = randomJoints(m, rng);
    const ToolPose pose = k->forward(q);
    if (singular->cross(pose.axis).norm() < 0.05)
      continue;  // within 3 deg of the singular direction: rates() may refuse
    const std::optional<runtime::JointRates> rates = k->rates(q, 0);
    REQUIRE(rates);
    CHECK((rates->tipTurn - *k->tipTurn(q)).norm() < 1e-12);
    const Vec3 dp = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    Vec3 dk = Vec3(normal(rng), normal(rng), normal(rng));
    dk = (dk - pose.axis * pose.axis.dot(dk)).normalized();  // across the tool
    constexpr double kStep = 1e-5;
    auto at = [&](double h) {
      const Vec3 axis = (pose.axis + h * dk).normalized();
      const runtime::InverseResult r = k->inverse({pose.tipMm + h * dp, axis}, &q);
      REQUIRE(r.joints);
      return *r.joints;
    };
    const Joints seen = (at(kStep) - at(-kStep)) / (2 * kStep);
    const Joints predicted = rates->of(dp, dk);
    const double scale = 1 + predicted.cwiseAbs().maxCoeff();
    INFO("joints " << q.transpose() << "; seen " << seen.transpose() << "; predicted " << predicted.transpose());
    CHECK((seen - predicted).cwiseAbs().maxCoeff() < 1e-5 * scale);
    worst = std::max(worst, (seen - predicted).cwiseAbs().maxCoeff() / scale);
    // One call, the same answers.
    std::optional<runtime::JointRates> both;
    const runtime::InverseResult solved = k->inverseWithRates(pose, &q, 0, both);
    const runtime::InverseResult alone = k->inverse(pose, &q);
    REQUIRE(solved.joints);
    REQUIRE(alone.joints);
    CHECK(*solved.joints == *alone.joints);
    REQUIRE(both);
    const std::optional<runtime::JointRates> again = k->rates(*solved.joints, 0);
    REQUIRE(again);
    CHECK((both->map - again->map).cwiseAbs().maxCoeff() < 1e-9);
    ++checked;
  }
  INFO(m.name << ": worst relative difference " << worst);
  CHECK(checked > 1500);
  return checked;
}

TEST_CASE("5-axis chains: rates are how the tip's and the tool's moves move the joints", "[kinematics]") {
  ratesAgree(test::shippedMachine("table-table-5axis"), 21);
  ratesAgree(test::shippedMachine("head-table-5axis"), 22);
  ratesAgree(test::shippedMachine("head-head-5axis"), 23);
  ratesAgree(machineFrom(fiveAxis("table-table", "[]", "[\"b\", \"c\"]",
                                  rotary("b", -110, 110, "[10, -20, -150]") +
                                      rotary("c", -36000, 36000, "[30, 40, -120]"))),
             24);
  ratesAgree(machineFrom(fiveAxis("head-head", "[\"c\", \"a\"]", "[]",
                                  rotary("c", -360, 360, "[0, 0, 400]") + rotary("a", -100, 100, "[0, 0, 150]"))),
             25);
}

TEST_CASE("5-axis chains: no rates at the singular direction; other chains have none", "[kinematics]") {
  const auto k = kinematicsOf(test::shippedMachine("table-table-5axis"));
  // The tool along the C axis: C is free.
  const runtime::InverseResult upright = k->inverse({Vec3(10, 20, 30), Vec3::UnitZ()});
  REQUIRE(upright.joints);
  CHECK(upright.singular);
  CHECK_FALSE(k->rates(*upright.joints, 0));
  std::optional<runtime::JointRates> rates;
  CHECK(k->inverseWithRates({Vec3(10, 20, 30), Vec3::UnitZ()}, nullptr, 0, rates).joints);
  CHECK_FALSE(rates);
  // minSine: refused within that sine of it.
  const Vec3 near = Vec3(std::sin(0.01), 0, std::cos(0.01));
  const runtime::InverseResult tilted = k->inverse({Vec3(10, 20, 30), near});
  REQUIRE(tilted.joints);
  CHECK(k->rates(*tilted.joints, 0));
  CHECK_FALSE(k->rates(*tilted.joints, 0.02));
  const auto xyz = kinematicsOf(test::shippedMachine("hsc-3axis"));
  CHECK_FALSE(xyz->rates(Joints::Zero(3), 0));
  CHECK_FALSE(xyz->singularDirection());
}

TEST_CASE("table-table A/C: poses worked out by hand", "[kinematics]") {
  // The shipped machine: A about +x through y = 225, z = -300; C about +z
  // through x = 250, y = 225.
  const runtime::Machine m = test::shippedMachine("table-table-5axis");
  const auto k = kinematicsOf(m);
  // All at 0: the workpiece's frame is the machine's.
  checkPose(k->forward(joints({100, 200, -50, 0, 0})), {100, 200, -50}, Vec3::UnitZ());
  // A = -90: the tip 100 mm above the A axis is, in the table's frame,
  // turned +90 about x: (0, 0, 100) -> (0, -100, 0) from the pivot; the tool
  // points along -y of the workpiece.
  checkPose(k->forward(joints({250, 225, -200, -90, 0})), {250, 125, -300}, -Vec3::UnitY());
  // C = 90: the tip 100 mm along +x from the table's centre is, in the
  // workpiece's frame, 100 mm along -y from it.
  checkPose(k->forward(joints({350, 225, -250, 0, 90})), {250, 125, -250}, Vec3::UnitZ());
  // Back: the same joints from the poses.
  auto r = k->inverse({{250, 125, -300}, -Vec3::UnitY()});
  REQUIRE(r.joints);
  CHECK((*r.joints - joints({250, 225, -200, -90, 0})).norm() < 1e-9);
  // A tool direction 60 deg from +z: A = +60 is beyond the tilt's travel
  // (-120 to 30), so the other branch, A = -60 with C turned half a turn.
  const Vec3 k60(0, std::sin(60 * std::numbers::pi / 180), std::cos(60 * std::numbers::pi / 180));
  r = k->inverse({{250, 225, -250}, k60});
  REQUIRE(r.joints);
  CHECK_FALSE(r.outsideTravel);
  CHECK(std::abs((*r.joints)[3] - -60) < 1e-9);
  CHECK(std::abs(std::abs((*r.joints)[4]) - 180) < 1e-9);
  checkPose(k->forward(*r.joints), {250, 225, -250}, k60);
}

TEST_CASE("head-table B/C: a pose worked out by hand", "[kinematics]") {
  const runtime::Machine m = machineFrom(fiveAxis(
      "head-table", "[\"b\"]", "[\"c\"]", rotary("b", -100, 100, "[0, 0, 150]") + rotary("c", -360, 360, "[0, 0, 0]")));
  const auto k = kinematicsOf(m);
  // B = 90 turns the tool, 150 mm below the pivot, about +y: the tip swings
  // to 150 mm along -x and up to the pivot's height; the tool points along +x.
  checkPose(k->forward(joints({0, 0, 0, 90, 0})), {-150, 0, 150}, Vec3::UnitX());
  // C = 90 as well turns the workpiece: in its frame the tip is at
  // Rz(-90) (-150, 0, 150) = (0, 150, 150) and the tool along -y.
  checkPose(k->forward(joints({0, 0, 0, 90, 90})), {0, 150, 150}, -Vec3::UnitY());
}

TEST_CASE("5-axis singularity: the tool along the inner rotary axis keeps it where it was", "[kinematics]") {
  const runtime::Machine m = test::shippedMachine("table-table-5axis");
  const auto k = kinematicsOf(m);
  const ToolPose down{{300, 200, -100}, Vec3::UnitZ()};
  // With the previous joints at C = 37 deg: A = 0, C stays 37.
  const Joints near = joints({0, 0, 0, 5, 37});
  runtime::InverseResult r = k->inverse(down, &near);
  REQUIRE(r.joints);
  CHECK(r.singular);
  CHECK(std::abs((*r.joints)[3]) < 1e-12);
  CHECK((*r.joints)[4] == 37);
  checkPose(k->forward(*r.joints), down.tipMm, down.axis);
  // Without previous joints, C is 0 and the axes are the tip's coordinates.
  r = k->inverse(down);
  REQUIRE(r.joints);
  CHECK(r.singular);
  CHECK((*r.joints - joints({300, 200, -100, 0, 0})).norm() < 1e-9);
  // Near, not at, the singularity both angles are determined.
  const Vec3 almost = Vec3(0, 1e-6, 1).normalized();
  r = k->inverse({{300, 200, -100}, almost}, &near);
  REQUIRE(r.joints);
  CHECK_FALSE(r.singular);
  checkPose(k->forward(*r.joints), {300, 200, -100}, almost);
}

TEST_CASE("lathe: radius and c, diameters, the tip on the spindle axis", "[kinematics]") {
  runtime::Machine m = test::shippedMachine("lathe-2axis");
  REQUIRE(m.axes.size() == 2);
  CHECK(m.kinematics.diameterProgramming);
  CHECK(runtime::programmedX(m, 25) == 50);
  CHECK(runtime::radiusFromProgrammedX(m, 50) == 25);
  auto k = kinematicsOf(m);
  checkPose(k->forward(joints({40, -120})), {40, 0, -120}, Vec3::UnitX());
  runtime::InverseResult r = k->inverse({{40, 0, -120}, Vec3::UnitX()});
  REQUIRE(r.joints);
  CHECK(*r.joints == joints({40, -120}));
  // Without a c axis the tool cannot leave the x-z plane.
  r = k->inverse({{40, 3, -120}, Vec3::UnitX()});
  CHECK_FALSE(r.joints);

  // With c (a mill-turn's spindle as an axis).
  const runtime::Machine mc = machineFrom(kHeader + "[kinematics]\ntype = \"lathe\"\n" + linear("x", -5, 180) +
                                          linear("z", -550, 0) +
                                          "[axes.c]\ntravel = [-36000, 36000]\nmax_velocity = 9000\n"
                                          "max_acceleration = 1000\nmax_jerk = 10000\n");
  CHECK_FALSE(mc.kinematics.diameterProgramming);
  CHECK(runtime::programmedX(mc, 25) == 25);
  k = kinematicsOf(mc);
  // c = 90 turns the workpiece: the tip at radius 50 is at -y in its frame.
  checkPose(k->forward(joints({50, -20, 90})), {0, -50, -20}, -Vec3::UnitY());
  std::mt19937 rng(6);
  for (int i = 0; i < kRandomPoses; ++i) {
    const Joints q = randomJoints(mc, rng);
    r = k->inverse(k->forward(q), &q);
    INFO("joints " << q.transpose() << ": " << r.why);
    REQUIRE(r.joints);
    CHECK((*r.joints - q).norm() < kTolMm);
  }
  // The tip on the spindle axis: the radial tool's direction sets c.
  const Joints near = joints({10, -5, 123});
  r = k->inverse({{0, 0, -30}, -Vec3::UnitY()}, &near);
  REQUIRE(r.joints);
  CHECK_FALSE(r.singular);
  CHECK((*r.joints - joints({0, -30, 90})).norm() < 1e-9);
  // An axial tool (a drill on centre) on the spindle axis: c is free and
  // keeps its value.
  const runtime::Machine axial = machineFrom((
      kHeader + "[kinematics]\ntype = \"lathe\"\ntool_axis = [0, 0, 1]\n" + linear("x", -5, 180) +
          linear("z", -550, 0) + "[axes.c]\ntravel = [-36000, 36000]\nmax_velocity = 9000\n"
                                 "max_acceleration = 1000\nmax_jerk = 10000\n"));
  k = kinematicsOf(axial);
  r = k->inverse({{0, 0, -30}, Vec3::UnitZ()}, &near);
  REQUIRE(r.joints);
  CHECK(r.singular);
  CHECK(*r.joints == joints({0, -30, 123}));
}

TEST_CASE("a generic chain finds its solver in the registry", "[kinematics]") {
  const std::string text = kHeader +
                           "[kinematics]\ntype = \"generic\"\nsolver = \"test-doubled\"\n"
                           "joints = [\"u\", \"v\", \"w\"]\n[kinematics.parameters]\nscale = 2.0\n" +
                           linear("u", -100, 100) + linear("v", -100, 100) + linear("w", -100, 100);
  const runtime::Machine m = machineFrom(text);
  REQUIRE(m.axes.size() == 3);
  CHECK(m.axes[0].name == "u");
  REQUIRE(m.kinematics.parameters.size() == 1);
  CHECK(m.whyNotThreeAxis().find("generic chain moved by the solver 'test-doubled'") != std::string::npos);

  std::string error;
  CHECK_FALSE(runtime::makeKinematics(m, error));
  CHECK(error.find("names the kinematics solver 'test-doubled', which this program has not registered") !=
        std::string::npos);

  // A toy solver: the tip is the joints times the machine's `scale`.
  struct Doubled final : runtime::Kinematics {
    double scale = 1;
    std::string_view name() const override { return "test-doubled"; }
    size_t jointCount() const override { return 3; }
    ToolPose forward(const Joints &q) const override { return {scale * q.head<3>(), Vec3::UnitZ()}; }
    runtime::InverseResult inverse(const ToolPose &pose, const Joints *) const override {
      runtime::InverseResult r;
      r.joints = Joints(pose.tipMm / scale);
      return r;
    }
  };
  CHECK(runtime::registerKinematicsSolver("test-doubled", [](const runtime::Machine &machine, std::string &) {
    auto k = std::make_unique<Doubled>();
    for (const auto &[key, value] : machine.kinematics.parameters)
      if (key == "scale")
        k->scale = value;
    return std::unique_ptr<runtime::Kinematics>(std::move(k));
  }));
  const auto k = kinematicsOf(m);
  checkPose(k->forward(joints({1, 2, 3})), {2, 4, 6}, Vec3::UnitZ());
  CHECK(*k->inverse({{2, 4, 6}, Vec3::UnitZ()}).joints == joints({1, 2, 3}));
}
