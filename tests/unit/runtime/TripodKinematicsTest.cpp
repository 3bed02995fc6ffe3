// The linear tripod with a tilting table (runtime/TripodKinematics.h) on the
// shipped machine: registered and found by makeKinematics, forward(inverse)
// and inverse(forward) round trips over a grid of the workspace and of tool
// axes, sliders worked out by hand, unreachable poses refused with their
// reason, and the machine file's mistakes located.
#include "runtime/TripodKinematics.h"

#include "../TestSupport.h"
#include "ShippedMachine.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

using namespace stepnc;
using runtime::Joints;
using runtime::ToolPose;
using Vec3 = Eigen::Vector3d;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

std::unique_ptr<runtime::Kinematics> tripod(const runtime::Machine &m) {
  std::string error;
  std::unique_ptr<runtime::Kinematics> k = runtime::makeKinematics(m, error);
  INFO(error);
  REQUIRE(k);
  return k;
}

std::string shippedText() {
  std::ifstream in(std::string(STEPNC_SOURCE_DIR) + "/machines/linear-tripod-5axis.toml");
  std::stringstream s;
  s << in.rdbuf();
  REQUIRE_FALSE(s.str().empty());
  return s.str();
}

using Read = test::ReadMachine;

Read read(const std::string &text) { return test::readMachineText(text); }

using test::edited;

/// The line (from 1) where `what` first stands in `text`.
int lineOf(const std::string &text, const std::string &what) {
  const size_t at = text.find(what);
  REQUIRE(at != std::string::npos);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

/// The one error of `text`, which must be at `line`.
void oneErrorAt(const std::string &text, int line, const std::string &says) {
  const Read r = read(text);
  CHECK_FALSE(r.machine);
  REQUIRE(r.errors.size() == 1);
  INFO(r.errors[0]);
  CHECK(r.errors[0].rfind(std::to_string(line) + ":", 0) == 0);
  CHECK(r.errors[0].find(says) != std::string::npos);
}

/// A unit tool axis leaning `tilt` deg from +z towards the azimuth `turn` deg.
Vec3 leaning(double tilt, double turn) {
  return {std::sin(tilt * kDeg) * std::cos(turn * kDeg), std::sin(tilt * kDeg) * std::sin(turn * kDeg),
          std::cos(tilt * kDeg)};
}

} // namespace

TEST_CASE("the linear tripod is registered and found for its machine", "[kinematics][tripod]") {
  const std::vector<std::string> names = runtime::kinematicsSolverNames();
  CHECK(std::find(names.begin(), names.end(), "linear-tripod") != names.end());
  REQUIRE(runtime::kinematicsSolverParameters("linear-tripod"));
  const runtime::Machine m = test::shippedMachine("linear-tripod-5axis");
  CHECK(m.kinematics.chain == runtime::Chain::Generic);
  REQUIRE(m.axes.size() == 5);
  CHECK(m.axes[3].rotary);
  CHECK(m.axes[4].rotary);
  const auto k = tripod(m);
  CHECK(k->name() == "linear-tripod");
  CHECK(k->jointCount() == 5);
  CHECK_FALSE(k->linearJointsAreCartesian());
}

TEST_CASE("linear tripod: sliders worked out by hand", "[kinematics][tripod]") {
  const auto k = tripod(test::shippedMachine("linear-tripod-5axis"));
  // Tool upright at machine (0, 0, 0), the table at 0: every strut spans
  // 600 - 150 = 450 mm across, so its slider stands sqrt(800^2 - 450^2)
  // above the platform, which is 250 mm above the tip.
  runtime::InverseResult r = k->inverse({Vec3::Zero(), Vec3::UnitZ()});
  REQUIRE(r.joints);
  CHECK(r.singular);  // the tool along C: C keeps its value (0)
  const double centred = 250 + std::sqrt(800.0 * 800 - 450.0 * 450);
  for (int i = 0; i < 3; ++i)
    CHECK(std::abs((*r.joints)[i] - centred) < 1e-9);
  CHECK((*r.joints)[3] == 0);
  CHECK((*r.joints)[4] == 0);
  // 100 mm along +x and 20 up: guideway 1 (towards +y) is sqrt(100^2 +
  // 450^2) across; guideways 2 and 3 (210 and 330 deg) at (-389.7, -225)
  // and (389.7, -225) less (100, 0).
  r = k->inverse({{100, 0, 20}, Vec3::UnitZ()});
  REQUIRE(r.joints);
  const double g = 450 * std::cos(30 * kDeg);
  const double across[3] = {std::hypot(100.0, 450.0), std::hypot(-g - 100, -225.0), std::hypot(g - 100, -225.0)};
  for (int i = 0; i < 3; ++i)
    CHECK(std::abs((*r.joints)[i] - (270 + std::sqrt(800.0 * 800 - across[i] * across[i]))) < 1e-9);
  const ToolPose back = k->forward(*r.joints);
  CHECK((back.tipMm - Vec3(100, 0, 20)).norm() < 1e-9);
}

TEST_CASE("linear tripod: the table's choices are the table-table chain's", "[kinematics][tripod]") {
  const auto k = tripod(test::shippedMachine("linear-tripod-5axis"));
  // Upright, the tool lies along C: C keeps the value it has in `near`.
  Joints near(5);
  near << 900, 900, 900, 0, 123;
  runtime::InverseResult r = k->inverse({{10, 20, 30}, Vec3::UnitZ()}, &near);
  REQUIRE(r.joints);
  CHECK(r.singular);
  CHECK((*r.joints)[3] == 0);
  CHECK((*r.joints)[4] == 123);
  // Tilted, C takes the whole turn nearest `near`: two turns on, 725 deg.
  Joints q(5);
  q << 950, 900, 1000, 20, 5;
  const ToolPose pose = k->forward(q);
  near << 950, 900, 1000, 20, 700;
  r = k->inverse(pose, &near);
  REQUIRE(r.joints);
  CHECK_FALSE(r.singular);
  CHECK(std::abs((*r.joints)[4] - 725) < 1e-9);
  CHECK(std::abs((*r.joints)[3] - 20) < 1e-9);
  CHECK((r.joints->head<3>() - q.head<3>()).norm() < 1e-9);
  // Without `near`, the other branch (A the other way, C half a turn on) is
  // not taken while this one is in the travel and turns less from 0.
  r = k->inverse(pose);
  REQUIRE(r.joints);
  CHECK(std::abs((*r.joints)[3] - 20) < 1e-9);
  CHECK(std::abs((*r.joints)[4] - 5) < 1e-9);
}

TEST_CASE("linear tripod: forward(inverse(pose)) == pose over the workspace and tool axes", "[kinematics][tripod]") {
  const runtime::Machine m = test::shippedMachine("linear-tripod-5axis");
  const auto k = tripod(m);
  double worstMm = 0, worstAxis = 0;
  int reached = 0, tried = 0;
  for (double x = -150; x <= 150; x += 50)
    for (double y = -150; y <= 150; y += 50)
      for (double z = 0; z <= 200; z += 50)
        for (double tilt : {0.0, 10.0, 25.0, 45.0, 70.0})
          for (double turn : {0.0, 60.0, 135.0, 250.0}) {
            if (tilt == 0 && turn > 0)
              continue;
            const ToolPose pose{{x, y, z}, leaning(tilt, turn)};
            ++tried;
            const runtime::InverseResult r = k->inverse(pose);
            if (!r.joints) {
              INFO(r.why);
              CHECK_FALSE(r.why.empty());
              continue;
            }
            ++reached;
            const ToolPose got = k->forward(*r.joints);
            worstMm = std::max(worstMm, (got.tipMm - pose.tipMm).norm());
            worstAxis = std::max(worstAxis, (got.axis - pose.axis).norm());
          }
  INFO(reached << " of " << tried << " poses reached; worst " << worstMm << " mm, " << worstAxis);
  CHECK(reached > tried * 4 / 5);  // the rest lean a strut too far (the table swings the tip out)
  CHECK(worstMm < 1e-9);
  CHECK(worstAxis < 1e-12);
}

TEST_CASE("linear tripod: inverse(forward(q)) == q over the joints", "[kinematics][tripod]") {
  const runtime::Machine m = test::shippedMachine("linear-tripod-5axis");
  const auto k = tripod(m);
  double worstMm = 0, worstDeg = 0;
  int reached = 0, tried = 0;
  // Sliders about the centred height (911.44 mm with the tip at z = 0), and
  // the table's axes through their travel.
  for (double s1 = 700; s1 <= 1100; s1 += 100)
    for (double s2 = 700; s2 <= 1100; s2 += 100)
      for (double s3 = 700; s3 <= 1100; s3 += 100)
        for (double a : {-100.0, -35.0, 0.0, 20.0, 90.0})
          for (double c : {-170.0, 0.0, 45.0, 300.0}) {
            Joints q(5);
            q << s1, s2, s3, a, c;
            const ToolPose pose = k->forward(q);
            ++tried;
            if (!pose.tipMm.allFinite())
              continue;  // the struts cannot meet: no pose
            const runtime::InverseResult r = k->inverse(pose, &q);
            if (!r.joints)
              continue;  // a strut beyond its angle limits
            ++reached;
            CHECK_FALSE(r.outsideTravel);
            worstMm = std::max(worstMm, (r.joints->head<3>() - q.head<3>()).cwiseAbs().maxCoeff());
            worstDeg = std::max(worstDeg, (r.joints->tail<2>() - q.tail<2>()).cwiseAbs().maxCoeff());
          }
  INFO(reached << " of " << tried << " joint sets reached; worst " << worstMm << " mm, " << worstDeg << " deg");
  CHECK(reached > tried / 2);
  CHECK(worstMm < 1e-9);
  CHECK(worstDeg < 1e-9);
  // Sliders whose struts cannot meet give no pose: 1500 mm apart in height
  // and 779 mm across, further than two struts reach.
  Joints apart(5);
  apart << 0, 1500, 0, 0, 0;
  CHECK_FALSE(k->forward(apart).tipMm.allFinite());
}

TEST_CASE("linear tripod: unreachable poses are refused with the reason", "[kinematics][tripod]") {
  const auto k = tripod(test::shippedMachine("linear-tripod-5axis"));
  // Strut 1's guideway is 750 mm across: it would lean 69.6 deg.
  runtime::InverseResult r = k->inverse({{0, -300, 0}, Vec3::UnitZ()});
  CHECK_FALSE(r.joints);
  CHECK(r.why.find("strut 1 would lean 69.64 deg from its guideway, beyond max_strut_angle 60 deg") !=
        std::string::npos);
  // 850 mm across, longer than the strut.
  r = k->inverse({{0, -400, 0}, Vec3::UnitZ()});
  CHECK_FALSE(r.joints);
  CHECK(r.why.find("strut 1 cannot reach") != std::string::npos);
  // Right under guideway 1: the strut would stand almost upright.
  r = k->inverse({{0, 400, 0}, Vec3::UnitZ()});
  CHECK_FALSE(r.joints);
  CHECK(r.why.find("strut 1 would lean 3.58 deg from its guideway, within min_strut_angle 10 deg") !=
        std::string::npos);
  // Reached, but only with an axis out of its travel: the tool straight
  // up from below needs A at 180 deg; a tip 700 mm up, sliders above 1500.
  r = k->inverse({{0, 0, 0}, -Vec3::UnitZ()});
  REQUIRE(r.joints);
  CHECK(r.outsideTravel);
  r = k->inverse({{0, 0, 700}, Vec3::UnitZ()});
  REQUIRE(r.joints);
  CHECK(r.outsideTravel);
  r = k->inverse({{0, 0, 100}, Vec3::UnitZ()});
  REQUIRE(r.joints);
  CHECK_FALSE(r.outsideTravel);
}

TEST_CASE("linear tripod: the machine file's mistakes are located", "[machine][tripod]") {
  const std::string good = shippedText();
  REQUIRE(read(good).errors.empty());
  // A missing parameter: at the parameters' table.
  std::string text = edited(good, "strut_length = 800.0", "");
  oneErrorAt(text, lineOf(text, "[kinematics.parameters]"),
             "the solver 'linear-tripod' needs kinematics.parameters.strut_length (mm:");
  // One out of its range, one that is not a number, one misspelt: at each.
  text = edited(good, "strut_length = 800.0", "strut_length = -800.0");
  oneErrorAt(text, lineOf(text, "strut_length = -800.0"), "kinematics.parameters.strut_length must be from 1 to");
  text = edited(good, "tool_length = 250.0", "tool_length = \"250\"");
  oneErrorAt(text, lineOf(text, "tool_length = \"250\""), "kinematics.parameters.tool_length must be a number");
  text = edited(good, "tilt_pivot_z = -120.0", "tilt_pivot_z = -120.0\ntilt_pivot_w = 0.0");
  oneErrorAt(text, lineOf(text, "tilt_pivot_w"), "unknown key 'tilt_pivot_w' in [kinematics.parameters]");
  // What only the solver knows: at the [kinematics] table.
  text = edited(good, "platform_radius = 150.0", "platform_radius = 700.0");
  oneErrorAt(text, lineOf(text, "[kinematics]"), "platform_radius 700 mm must be below base_radius 600 mm");
  text = edited(good, "min_strut_angle = 10.0", "min_strut_angle = 70.0");
  oneErrorAt(text, lineOf(text, "[kinematics]"), "min_strut_angle 70 deg must be below max_strut_angle 60 deg");
  text = edited(edited(good, "\"s3\", \"a\", \"c\"]", "\"s3\", \"a\", \"w\"]"), "[axes.c]", "[axes.w]");
  oneErrorAt(text, lineOf(text, "[kinematics]"), "moves 5 joints: three linear sliders, then the tilting table's");
}
