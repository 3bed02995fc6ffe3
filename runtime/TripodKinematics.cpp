// The linear tripod with a tilting table (TripodKinematics.h): the parallel
// module's closed-form inverse and forward kinematics, with the table's part
// left to the table-table chain of Kinematics.cpp.
#include "runtime/TripodKinematics.h"

#include "support/Format.h"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

namespace stepnc::runtime {

namespace {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

constexpr double kDeg = std::numbers::pi / 180;

/// The parallel module's numbers, as the machine file gives them.
struct Geometry {
  double baseRadius = 0;      ///< mm: the guideways' circle
  double platformRadius = 0;  ///< mm: the platform's joints' circle
  double strutLength = 0;     ///< mm: between a slider's joint and the platform's
  double toolLength = 0;      ///< mm: from the platform's joints' plane down to the tool tip
  double firstGuidewayDeg = 0;  ///< deg: guideway 1's direction from the z axis (the others at +120, +240)
  double minStrutAngleDeg = 0;  ///< deg from the guideway
  double maxStrutAngleDeg = 0;
};

std::string mm(double v) { return formatTrimmed(v, 3); }

class LinearTripodKinematics final : public Kinematics {
public:
  LinearTripodKinematics(const Machine &machine, const Geometry &g, std::unique_ptr<Kinematics> table)
      : g_(g), table_(std::move(table)), sliders_(machine.axes.begin(), machine.axes.begin() + 3) {
    // With the platform's centre on the z axis, strut i joins the platform's
    // joint at platformRadius to the slider's at baseRadius in the same
    // direction: moving the slider's joint in by the platform's radius, each
    // strut joins the platform's centre to a point on guideway i's line at
    // (baseRadius - platformRadius) from the axis.
    for (int i = 0; i < 3; ++i) {
      const double angle = (g.firstGuidewayDeg + 120.0 * i) * kDeg;
      guide_[size_t(i)] = (g.baseRadius - g.platformRadius) * Vec2(std::cos(angle), std::sin(angle));
    }
    lowestLean_ = g.strutLength * std::sin(g.minStrutAngleDeg * kDeg);
    highestLean_ = g.strutLength * std::sin(g.maxStrutAngleDeg * kDeg);
  }

  std::string_view name() const override { return kLinearTripodSolver; }
  size_t jointCount() const override { return 5; }
  bool linearJointsAreCartesian() const override { return false; }

  ToolPose forward(const Joints &q) const override {
    const Vec3 tip = tipAt(q.head<3>());
    Joints t(5);
    t << tip, q[3], q[4];
    return table_->forward(t);
  }

  InverseResult inverse(const ToolPose &pose, const Joints *near) const override {
    InverseResult out;
    // The table chain's joints nearest `near`: its tip where near's sliders
    // put it (the linear joints only break ties), its rotary axes.
    Joints nearTable = Joints::Zero(5);
    if (near && near->size() == 5) {
      const Vec3 tip = tipAt(near->head<3>());
      if (tip.allFinite())
        nearTable.head<3>() = tip;
      nearTable.tail<2>() = near->tail<2>();
    }
    const InverseResult table = table_->inverse(pose, &nearTable);
    if (!table.joints) {
      out.why = "the tilting table cannot turn the workpiece so that the tool stands along it (" + table.why + ")";
      return out;
    }
    const Vec3 tip = table.joints->head<3>();
    Joints q(5);
    q.tail<2>() = table.joints->tail<2>();
    bool inside = !table.outsideTravel;
    for (int i = 0; i < 3; ++i) {
      const std::optional<double> s = slider(i, tip, out.why);
      if (!s)
        return out;
      q[i] = *s;
      const Axis &a = sliders_[size_t(i)];
      const double slack = 1e-9 * std::max(1.0, std::max(std::abs(a.travelMin), std::abs(a.travelMax)));
      inside &= *s >= a.travelMin - slack && *s <= a.travelMax + slack;
    }
    out.joints = q;
    out.singular = table.singular;
    out.outsideTravel = !inside;
    return out;
  }

private:
  /// Slider i's position that puts the tip at `tip` (machine coordinates);
  /// nullopt with `why` when its strut cannot reach or leans beyond its limits.
  std::optional<double> slider(int i, const Vec3 &tip, std::string &why) const {
    const double across = (guide_[size_t(i)] - tip.head<2>()).norm();
    if (across >= lowestLean_ && across <= highestLean_ && across < g_.strutLength)
      return tip.z() + g_.toolLength + std::sqrt((g_.strutLength - across) * (g_.strutLength + across));
    // Why not (the message built only here: the planner asks at every sample).
    const double lean = std::asin(std::min(1.0, across / g_.strutLength)) / kDeg;
    const std::string where = "the tool tip at machine (" + mm(tip.x()) + ", " + mm(tip.y()) + ", " + mm(tip.z()) +
                              ") mm: strut " + std::to_string(i + 1) + " ";
    if (across >= g_.strutLength) {
      why = where + "cannot reach (its slider's guideway is " + mm(across) + " mm across from the platform's joint, "
                    "the strut " + mm(g_.strutLength) + " mm long)";
      return std::nullopt;
    }
    if (across > highestLean_) {
      why = where + "would lean " + formatTrimmed(lean, 2) + " deg from its guideway, beyond max_strut_angle " +
            formatTrimmed(g_.maxStrutAngleDeg, 6) + " deg (near lying across it, where the slider cannot push the "
            "platform)";
      return std::nullopt;
    }
    if (across < lowestLean_) {
      why = where + "would lean " + formatTrimmed(lean, 2) + " deg from its guideway, within min_strut_angle " +
            formatTrimmed(g_.minStrutAngleDeg, 6) + " deg (near the struts standing parallel, where the platform "
            "could move sideways with the sliders still)";
      return std::nullopt;
    }
    why = where + "cannot be placed: the tip's position is not a number";
    return std::nullopt;
  }

  /// The tip (machine coordinates) with the sliders at s: the lower of the
  /// two points at the strut's length from the three (moved-in) slider
  /// joints; NaN where the spheres do not meet (no pose).
  Vec3 tipAt(const Eigen::Vector3d &s) const {
    const Vec3 c1(guide_[0].x(), guide_[0].y(), s[0]), c2(guide_[1].x(), guide_[1].y(), s[1]),
        c3(guide_[2].x(), guide_[2].y(), s[2]);
    // A frame on the centres: ex towards c2, ey towards c3 in their plane.
    const double d = (c2 - c1).norm();
    const Vec3 ex = (c2 - c1) / d;
    const double i = ex.dot(c3 - c1);
    const Vec3 towards3 = c3 - c1 - i * ex;
    const double j = towards3.norm();
    const Vec3 ey = towards3 / j;
    Vec3 ez = ex.cross(ey);
    // Equal radii: the point is halfway to c2 along ex, and equally far
    // from c1 and c3 along ey.
    const double x = d / 2, y = (i * i + j * j - 2 * i * x) / (2 * j);
    const double L = g_.strutLength;
    const double h2 = L * L - x * x - y * y;
    if (!(h2 >= 0))
      return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    if (ez.z() > 0)
      ez = -ez;  // the lower point
    const Vec3 platform = c1 + x * ex + y * ey + std::sqrt(h2) * ez;
    return platform - Vec3(0, 0, g_.toolLength);
  }

  Geometry g_;
  std::unique_ptr<Kinematics> table_;  ///< the table-table chain: joints (tip x, y, z, then the rotary axes)
  std::vector<Axis> sliders_;
  std::array<Vec2, 3> guide_;  ///< each strut's far end with the platform's centre at the origin, in the plane
  double lowestLean_ = 0, highestLean_ = 0;  ///< mm across, the strut angle limits' sines times its length
};

} // namespace

std::vector<SolverParameter> linearTripodParameters() {
  return {
      {"base_radius", "mm", 1, 1e5, "the radius of the circle the three guideways stand on, about the z axis"},
      {"platform_radius", "mm", 0, 1e5, "the radius of the circle of the platform's strut joints"},
      {"strut_length", "mm", 1, 1e5, "each strut's length between its slider's joint and the platform's"},
      {"tool_length", "mm", 0, 1e4, "from the plane of the platform's strut joints down to the tool tip"},
      {"first_guideway", "deg", -360, 360, "guideway 1's direction from the z axis (2 and 3 at +120 and +240)"},
      {"min_strut_angle", "deg", 0, 89, "the least a strut may lean from its guideway"},
      {"max_strut_angle", "deg", 1, 89.9, "the most a strut may lean from its guideway"},
      {"tilt_pivot_x", "mm", -1e5, 1e5, "a point on the table's outer rotary axis (the tilt), x"},
      {"tilt_pivot_y", "mm", -1e5, 1e5, "the same point, y"},
      {"tilt_pivot_z", "mm", -1e5, 1e5, "the same point, z"},
      {"turn_pivot_x", "mm", -1e5, 1e5, "a point on the table's inner rotary axis (the one carrying the workpiece), x"},
      {"turn_pivot_y", "mm", -1e5, 1e5, "the same point, y"},
      {"turn_pivot_z", "mm", -1e5, 1e5, "the same point, z"},
  };
}

std::unique_ptr<Kinematics> makeLinearTripod(const Machine &machine, std::string &error) {
  const std::string solver = "the " + std::string(kLinearTripodSolver) + " solver";
  // Its joints: three sliders, then the table's two rotary axes.
  const std::vector<Axis> &axes = machine.axes;
  if (axes.size() != 5 || axes[0].rotary || axes[1].rotary || axes[2].rotary || !axes[3].rotary || !axes[4].rotary) {
    error = solver + " moves 5 joints: three linear sliders, then the tilting table's two rotary axes (the machine "
                     "\"" + machine.name + "\" has " + std::to_string(axes.size()) + " joints of another kind)";
    return nullptr;
  }
  auto direction = [](const std::string &name) -> std::optional<Vec3> {
    if (name == "a")
      return Vec3::UnitX();
    if (name == "b")
      return Vec3::UnitY();
    if (name == "c")
      return Vec3::UnitZ();
    return std::nullopt;
  };
  const std::optional<Vec3> outer = direction(axes[3].name), inner = direction(axes[4].name);
  if (!outer || !inner || axes[3].name == axes[4].name) {
    error = solver + "'s table axes must be two different rotary axes named a, b or c (about x, y, z), not " +
            axes[3].name + " and " + axes[4].name;
    return nullptr;
  }
  std::map<std::string, double> given(machine.kinematics.parameters.begin(), machine.kinematics.parameters.end());
  std::map<std::string, double> value;
  for (const SolverParameter &p : linearTripodParameters()) {
    auto it = given.find(p.name);
    if (it == given.end()) {
      error = solver + " needs kinematics.parameters." + p.name + " (" + p.unit + ": " + p.meaning + ")";
      return nullptr;
    }
    if (!(it->second >= p.min && it->second <= p.max)) {
      error = "kinematics.parameters." + p.name + " must be from " + formatTrimmed(p.min, 6) + " to " +
              formatTrimmed(p.max, 6) + " " + p.unit + ", not " + formatTrimmed(it->second, 6);
      return nullptr;
    }
    value[p.name] = it->second;
    given.erase(it);
  }
  if (!given.empty()) {
    error = "kinematics.parameters." + given.begin()->first + " is not a parameter of " + solver;
    return nullptr;
  }
  Geometry g;
  g.baseRadius = value["base_radius"];
  g.platformRadius = value["platform_radius"];
  g.strutLength = value["strut_length"];
  g.toolLength = value["tool_length"];
  g.firstGuidewayDeg = value["first_guideway"];
  g.minStrutAngleDeg = value["min_strut_angle"];
  g.maxStrutAngleDeg = value["max_strut_angle"];
  if (!(g.platformRadius < g.baseRadius)) {
    error = "kinematics.parameters.platform_radius " + mm(g.platformRadius) +
            " mm must be below base_radius " + mm(g.baseRadius) + " mm: the struts lean out from the platform to the "
            "guideways";
    return nullptr;
  }
  if (!(g.minStrutAngleDeg < g.maxStrutAngleDeg)) {
    error = "kinematics.parameters.min_strut_angle " + formatTrimmed(g.minStrutAngleDeg, 6) +
            " deg must be below max_strut_angle " + formatTrimmed(g.maxStrutAngleDeg, 6) + " deg";
    return nullptr;
  }
  // The table: the table-table chain on the tip's machine coordinates.
  Machine table;
  table.name = machine.name;
  table.kinematics.chain = Chain::TableTable;
  table.kinematics.table = {axes[3].name, axes[4].name};
  constexpr double kAnywhere = 1e6;  // the tip's coordinates have no travel of their own here
  for (const char *n : {"x", "y", "z"})
    table.axes.push_back({n, -kAnywhere, kAnywhere, 1, 1, 1});
  for (int k = 3; k < 5; ++k) {
    Axis a = axes[size_t(k)];
    const std::string which = k == 3 ? "tilt" : "turn";
    a.direction = k == 3 ? *outer : *inner;
    a.pivotMm = Vec3(value[which + "_pivot_x"], value[which + "_pivot_y"], value[which + "_pivot_z"]);
    table.axes.push_back(a);
  }
  std::unique_ptr<Kinematics> chain = makeKinematics(table, error);
  if (!chain)
    return nullptr;
  return std::make_unique<LinearTripodKinematics>(machine, g, std::move(chain));
}

} // namespace stepnc::runtime
