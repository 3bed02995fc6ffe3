// The forward and inverse transforms of the chains a machine file can
// describe (runtime/Kinematics.h), and the registry of external solvers for
// generic chains.
//
// 5-axis inverse: the tool's direction in the workpiece's frame is the tool
// direction at zero turned by the two rotary axes, so their angles solve
// R(w1, s1 t1) R(w2, s2 t2) k0 = k, two rotations about known axes taking
// one known vector to another (Paden-Kahan subproblem 2: the intermediate
// vector is where two cones meet, 0, 1 or 2 places). Positions then follow
// by undoing the table's rotations about their pivots and the head's offset.
#include "runtime/Kinematics.h"

#include "runtime/TripodKinematics.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <span>

namespace stepnc::runtime {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

constexpr double kDeg = std::numbers::pi / 180;
/// Below this, a vector has no direction left (relative to unit vectors):
/// the rotary axis it is perpendicular to is free.
constexpr double kSingular = 1e-12;
/// How far forward(inverse(pose)) may be from pose for the pose to count as
/// reached: mm per mm of the tip's distance from the origin, and on unit
/// vectors.
constexpr double kReachTol = 1e-9;

Mat3 rotation(const Vec3 &axis, double deg) { return Eigen::AngleAxisd(deg * kDeg, axis).toRotationMatrix(); }

/// An angle by its cosine and sine: the inverse kinematics finds them
/// without trigonometry, and the rotation is built from them so.
struct Turning {
  double cos = 1, sin = 0;
  double degrees() const { return std::atan2(sin, cos) / kDeg; }
  Turning reversed() const { return {cos, -sin}; }
};

/// The rotation by `t` about the unit axis w (Rodrigues).
Mat3 rotation(const Vec3 &w, const Turning &t) {
  Mat3 cross;
  cross << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return t.cos * Mat3::Identity() + t.sin * cross + (1 - t.cos) * w * w.transpose();
}

/// The turn about the unit axis w that takes p onto q, when both have a part
/// across w; nullopt when either lies along w (any angle does).
std::optional<Turning> angleTaking(const Vec3 &w, const Vec3 &p, const Vec3 &q) {
  const Vec3 pp = p - w * w.dot(p), qp = q - w * w.dot(q);
  const double pn = pp.squaredNorm(), qn = qp.squaredNorm();
  if (pn < kSingular * kSingular || qn < kSingular * kSingular)
    return std::nullopt;
  const double scale = 1 / std::sqrt(pn * qn);
  return Turning{pp.dot(qp) * scale, w.dot(pp.cross(qp)) * scale};
}

bool inTravel(const Axis &a, double v) {
  const double slack = 1e-9 * std::max(1.0, std::max(std::abs(a.travelMin), std::abs(a.travelMax)));
  return v >= a.travelMin - slack && v <= a.travelMax + slack;
}

/// `deg` plus a whole number of turns: inside the axis's travel if some is,
/// and nearest `nearDeg` among those.
double wrapNear(const Axis &a, double deg, double nearDeg) {
  const double k0 = std::round((nearDeg - deg) / 360);
  // The nearest turn, when it is inside the travel, is the answer (most
  // calls, along a path).
  if (inTravel(a, deg + 360 * k0))
    return deg + 360 * k0;
  const std::array<double, 5> tries = {deg + 360 * (k0 - 1), deg + 360 * k0, deg + 360 * (k0 + 1),
                               deg + 360 * std::ceil((a.travelMin - deg) / 360),
                               deg + 360 * std::floor((a.travelMax - deg) / 360)};
  double best = deg + 360 * k0;
  bool bestIn = inTravel(a, best);
  for (double t : tries) {
    const bool in = inTravel(a, t);
    if ((in && !bestIn) || (in == bestIn && std::abs(t - nearDeg) < std::abs(best - nearDeg))) {
      best = t;
      bestIn = in;
    }
  }
  return best;
}

/// Of several solutions, the one inside every axis's travel (if any) whose
/// rotary axes turn least from `near`, then whose linear axes move least.
InverseResult choose(std::span<const Joints> solutions, const std::vector<Axis> &axes, const Joints &near,
                     bool singular) {
  InverseResult r;
  r.singular = singular;
  double bestRotary = 0, bestLinear = 0;
  bool bestIn = false;
  for (const Joints &q : solutions) {
    bool in = true;
    double rotary = 0, linear = 0;
    for (size_t k = 0; k < axes.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      in &= inTravel(axes[k], q[i]);
      (axes[k].rotary ? rotary : linear) += std::abs(q[i] - near[i]);
    }
    const bool better = !r.joints || (in && !bestIn) ||
                        (in == bestIn && (rotary < bestRotary - 1e-9 ||
                                          (rotary <= bestRotary + 1e-9 && linear < bestLinear)));
    if (better) {
      r.joints = q;
      bestIn = in;
      bestRotary = rotary;
      bestLinear = linear;
    }
  }
  r.outsideTravel = r.joints && !bestIn;
  return r;
}

Joints nearOrZero(const Joints *near, size_t n) {
  if (near && static_cast<size_t>(near->size()) == n)
    return *near;
  return Joints::Zero(static_cast<Eigen::Index>(n));
}

/// Checks that forward(q) is the pose asked for: a solver's last word on
/// whether the pose is reachable (a lathe's tool cannot tilt, an xyz
/// machine's cannot either).
InverseResult verified(const Kinematics &k, const ToolPose &pose, InverseResult r) {
  if (!r.joints)
    return r;
  const ToolPose got = k.forward(*r.joints);
  const double scale = 1 + pose.tipMm.norm();
  if ((got.tipMm - pose.tipMm).norm() > kReachTol * scale * 1000 || (got.axis - pose.axis.normalized()).norm() > 1e-7) {
    r.joints.reset();
    r.why = "the " + std::string(k.name()) + " chain cannot put the tool there with that direction";
  }
  return r;
}

class XyzKinematics final : public Kinematics {
public:
  explicit XyzKinematics(const Machine &m) : axes_(m.axes) {}
  std::string_view name() const override { return "xyz"; }
  size_t jointCount() const override { return 3; }
  ToolPose forward(const Joints &q) const override { return {q.head<3>(), Vec3::UnitZ()}; }
  InverseResult inverse(const ToolPose &pose, const Joints *near) const override {
    InverseResult r;
    if ((pose.axis.normalized() - Vec3::UnitZ()).norm() > 1e-7) {
      r.why = "an xyz machine holds its tool along +z";
      return r;
    }
    const Joints q = pose.tipMm;
    return choose({&q, 1}, axes_, nearOrZero(near, 3), false);
  }
  std::optional<Mat3> tipTurn(const Joints &) const override { return Mat3::Identity(); }

private:
  std::vector<Axis> axes_;
};

/// x, y, z carry the head; the head's rotary axes carry the tool, the
/// table's the workpiece.
class FiveAxisKinematics final : public Kinematics {
public:
  struct Rotary {
    Eigen::Index joint = 0;
    Vec3 direction = Vec3::UnitZ();
    Vec3 pivotMm = Vec3::Zero();
  };

  explicit FiveAxisKinematics(const Machine &m) : chain_(m.kinematics.chain), axes_(m.axes), k0_(m.kinematics.toolAxis) {
    auto rotary = [&](const std::string &name) {
      const int k = m.axisIndex(name);
      const Axis &a = m.axes[static_cast<size_t>(k)];
      return Rotary{k, a.direction, a.pivotMm};
    };
    for (const std::string &n : m.kinematics.head)
      head_.push_back(rotary(n));
    for (const std::string &n : m.kinematics.table)
      table_.push_back(rotary(n));
    // The tool direction in the workpiece's frame is k0 turned by the head's
    // axes, innermost first, then by the table's backwards, outermost first.
    for (auto it = head_.rbegin(); it != head_.rend(); ++it)
      turns_.push_back({*it, 1.0});
    for (const Rotary &t : table_)
      turns_.push_back({t, -1.0});
  }

  std::string_view name() const override { return chainName(chain_); }
  size_t jointCount() const override { return axes_.size(); }

  ToolPose forward(const Joints &q) const override {
    auto [offset, k] = headAt(q);
    Vec3 tip = q.head<3>() + offset;
    for (const Rotary &t : table_) {  // outermost first: undo the table's turns
      const Mat3 back = rotation(t.direction, -q[t.joint]);
      tip = t.pivotMm + back * (tip - t.pivotMm);
      k = back * k;
    }
    return {tip, k};
  }

  InverseResult inverse(const ToolPose &pose, const Joints *nearIn) const override {
    return solve(pose, nearIn, 0, nullptr);
  }

  InverseResult inverseWithRates(const ToolPose &pose, const Joints *near, double minSine,
                                 std::optional<JointRates> &rates) const override {
    return solve(pose, near, minSine, &rates);
  }

  std::optional<Mat3> tipTurn(const Joints &q) const override {
    // The table's turns act on the tip innermost first (inverse above).
    Mat3 m = Mat3::Identity();
    for (const Rotary &t : table_)
      m = m * rotation(t.direction, q[t.joint]);
    return m;
  }

  std::optional<JointRates> rates(const Joints &q, double minSine) const override {
    return ratesFrom(q, rotationsAt(q), minSine);
  }

  std::optional<Vec3> singularDirection() const override { return turns_[1].rotary.direction; }

private:
  struct Turn {
    Rotary rotary;
    double sign = 1;  ///< +1 for a head's axis, -1 for a table's (it turns the workpiece)
  };

  /// The rotations of the two rotary joints (each about its direction by
  /// its angle): j1's, the joint of the last turn acting on k0 (turns_[1]),
  /// and j2's.
  struct Rotations {
    Mat3 r1, r2;
  };
  Eigen::Index j1() const { return turns_[1].rotary.joint; }
  Eigen::Index j2() const { return turns_[0].rotary.joint; }
  const Mat3 &of(const Rotations &r, Eigen::Index joint) const { return joint == j1() ? r.r1 : r.r2; }
  /// A turn's rotation as it acts on k0: the joint's, or its reverse for a
  /// table's.
  Mat3 acting(const Turn &t, const Rotations &r) const {
    const Mat3 &m = of(r, t.rotary.joint);
    return t.sign > 0 ? m : Mat3(m.transpose());
  }
  Rotations rotationsAt(const Joints &q) const {
    return {rotation(turns_[1].rotary.direction, q[j1()]), rotation(turns_[0].rotary.direction, q[j2()])};
  }

  /// inverse(), and with `rates` the joints' rates at the solution.
  InverseResult solve(const ToolPose &pose, const Joints *nearIn, double minSine,
                      std::optional<JointRates> *rates) const {
    InverseResult none;
    if (rates)
      rates->reset();
    const Joints near = nearOrZero(nearIn, axes_.size());
    const Vec3 k = pose.axis.normalized();
    // k = R(w1, s1 t1) R(w2, s2 t2) k0: c = R(w2, s2 t2) k0 = R(w1, -s1 t1) k
    // lies on the cone about w2 through k0 and on the one about w1 through k.
    const Turn &first = turns_[0], &last = turns_[1];
    const Vec3 &w1 = last.rotary.direction, &w2 = first.rotary.direction;
    const double c12 = w1.dot(w2), d = c12 * c12 - 1;
    const double a = (c12 * w2.dot(k0_) - w1.dot(k)) / d;
    const double b = (c12 * w1.dot(k) - w2.dot(k0_)) / d;
    const Vec3 across = w1.cross(w2);
    // |c|^2 = 1 gives the part along w1 x w2; written as 1 - a^2 - ... it
    // loses half the digits near the singularity (a or b near 1, the part
    // near 0). The parts of k across w1 and of k0 across w2 are kept by the
    // rotations and are exact: |c across w1|^2 = (b^2 + g^2) |w1 x w2|^2,
    // and likewise with a for w2. The one subtracting the smaller term.
    const double cross2 = across.squaredNorm();
    const double g2 = std::abs(b) <= std::abs(a) ? (k - w1 * w1.dot(k)).squaredNorm() / cross2 - b * b
                                                 : (k0_ - w2 * w2.dot(k0_)).squaredNorm() / cross2 - a * a;
    if (g2 < -1e-9) {
      none.why = "the " + std::string(name()) + " chain cannot turn the tool to that direction";
      return none;
    }
    const double g = std::sqrt(std::max(0.0, g2));
    const Eigen::Index j1 = this->j1(), j2 = this->j2();
    // Each solution's two turns in the joints' own sense (a table's turns
    // the workpiece: its joint is the turn reversed); a free one (k0 along
    // w2, or k along w1) keeps its value in `near`.
    struct Solution {
      std::optional<Turning> turn1, turn2;  ///< joints j1 and j2; nullopt where free
    };
    auto jointSense = [](std::optional<Turning> t, const Turn &turn) {
      if (t && turn.sign < 0)
        t = t->reversed();
      return t;
    };
    std::array<Solution, 2> found;
    size_t count = 0;
    for (double sign : {1.0, -1.0}) {
      const Vec3 c = a * w1 + b * w2 + sign * g * across;
      found[count++] = {jointSense(angleTaking(w1, c, k), last), jointSense(angleTaking(w2, k0_, c), first)};
      if (g == 0)
        break;  // the cones touch: one solution
    }
    const bool singular = !found[0].turn1 || !found[0].turn2;
    // A solution's joints (nearest `near` by whole turns) and rotations.
    struct Candidate {
      Joints q;
      Rotations rotations;
    };
    auto angleOf = [&](const std::optional<Turning> &t, Eigen::Index j) {
      return t ? wrapNear(axes_[static_cast<size_t>(j)], t->degrees(), near[j]) : near[j];
    };
    auto candidate = [&](const Solution &f, double q1, double q2) {
      Candidate out{near, {}};
      out.q[j1] = q1;
      out.q[j2] = q2;
      out.rotations = {f.turn1 ? rotation(w1, *f.turn1) : rotation(w1, q1),
                       f.turn2 ? rotation(w2, *f.turn2) : rotation(w2, q2)};
      place(pose.tipMm, out.q, out.rotations);
      return out;
    };
    // The tool's direction the turns give, against the one asked for: the
    // solver's last word on whether the pose is reachable (the tip follows
    // by construction).
    auto finish = [&](const Candidate &chosen, std::span<const Joints> solutions) {
      if ((acting(last, chosen.rotations) * (acting(first, chosen.rotations) * k0_) - k).norm() > 1e-7) {
        none.why = "the " + std::string(name()) + " chain cannot put the tool there with that direction";
        return none;
      }
      InverseResult r = choose(solutions, axes_, near, singular);
      if (rates && !singular)
        *rates = ratesFrom(chosen.q, chosen.rotations, minSine);
      return r;
    };
    // Along a path (most calls), one solution turns each rotary joint less
    // than 1 deg from `near` and the other differs from it by more than 3
    // deg in one of them (so turns it more than 2 from `near`): when the
    // first is inside the travel it is what choose() takes, and the other's
    // angles and positions are not needed. The second solution is tried
    // first: on the shipped chains along a path it is the one taken.
    if (count == 2 && !singular) {
      static const double kApart = std::cos(3 * kDeg);
      for (const size_t i : {size_t(1), size_t(0)}) {
        const Solution &f = found[i], &other = found[1 - i];
        const double q1 = angleOf(f.turn1, j1), q2 = angleOf(f.turn2, j2);
        if (!(std::abs(q1 - near[j1]) < 1 && std::abs(q2 - near[j2]) < 1))
          continue;
        auto cosApart = [](const Turning &x, const Turning &y) { return x.cos * y.cos + x.sin * y.sin; };
        if (std::min(cosApart(*f.turn1, *other.turn1), cosApart(*f.turn2, *other.turn2)) >= kApart)
          break;
        const Candidate c = candidate(f, q1, q2);
        bool in = true;
        for (size_t j = 0; j < axes_.size(); ++j)
          in &= inTravel(axes_[j], c.q[static_cast<Eigen::Index>(j)]);
        if (in)
          return finish(c, {&c.q, 1});
        break;
      }
    }
    std::array<Candidate, 2> all;
    std::array<Joints, 2> solutions;
    for (size_t i = 0; i < count; ++i) {
      all[i] = candidate(found[i], angleOf(found[i].turn1, j1), angleOf(found[i].turn2, j2));
      solutions[i] = all[i].q;
    }
    // choose() takes the first of equals: the candidate whose joints it
    // returns is found by them.
    const InverseResult picked = choose({solutions.data(), count}, axes_, near, singular);
    const size_t at = count == 2 && picked.joints && *picked.joints == solutions[1] ? 1 : 0;
    return finish(all[at], {solutions.data(), count});
  }

  /// JointRates at q, whose rotary joints turn by `r`: the forward map's
  /// derivatives per degree of each rotary joint (tip and tool direction,
  /// in the workpiece's frame), then solved for the joints' rates: the
  /// direction's rate takes the rotary joints' (two unknowns, three
  /// equations that agree), the tip's then the linear joints' through the
  /// table's turn.
  std::optional<JointRates> ratesFrom(const Joints &q, const Rotations &r, double minSine) const {
    std::array<Eigen::Index, 2> joint{};
    std::array<Vec3, 2> dTip, dAxis;
    size_t n = 0;
    Vec3 offset = Vec3::Zero(), k = k0_;
    for (auto it = head_.rbegin(); it != head_.rend(); ++it) {  // innermost first, as headAt
      const Mat3 &turn = of(r, it->joint);
      offset = it->pivotMm + turn * (offset - it->pivotMm);
      k = turn * k;
      for (size_t c = 0; c < n; ++c) {
        dTip[c] = turn * dTip[c];
        dAxis[c] = turn * dAxis[c];
      }
      joint[n] = it->joint;
      dTip[n] = kDeg * it->direction.cross(offset - it->pivotMm);
      dAxis[n++] = kDeg * it->direction.cross(k);
    }
    Vec3 tip = q.head<3>() + offset;
    Mat3 back = Mat3::Identity();  // the linear joints' part: the table's turns undone
    for (const Rotary &t : table_) {  // outermost first, as forward
      const Mat3 turn = of(r, t.joint).transpose();
      tip = t.pivotMm + turn * (tip - t.pivotMm);
      k = turn * k;
      back = turn * back;
      for (size_t c = 0; c < n; ++c) {
        dTip[c] = turn * dTip[c];
        dAxis[c] = turn * dAxis[c];
      }
      joint[n] = t.joint;
      dTip[n] = -kDeg * t.direction.cross(tip - t.pivotMm);
      dAxis[n++] = -kDeg * t.direction.cross(k);
    }
    if (turns_[1].rotary.direction.cross(k).norm() < minSine)
      return std::nullopt;
    Eigen::Matrix<double, 3, 2> axisRates;
    axisRates << dAxis[0], dAxis[1];
    const Eigen::Matrix2d normal = axisRates.transpose() * axisRates;
    const double det = normal.determinant();
    if (!(std::abs(det) > 1e-12 * kDeg * kDeg * kDeg * kDeg))
      return std::nullopt;
    // Rotary rates per unit of direction rate (least squares: exact on a
    // rate the chain can follow).
    const Eigen::Matrix<double, 2, 3> rotary = normal.inverse() * axisRates.transpose();
    Eigen::Matrix<double, 3, 2> tipRates;
    tipRates << dTip[0], dTip[1];
    JointRates out;
    out.tipTurn = back.transpose();
    out.map = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxJoints, 6>::Zero(q.size(), 6);
    // x, y, z: the tip's rate less what the rotary joints move it by,
    // turned back into the machine's frame.
    out.map.topLeftCorner<3, 3>() = out.tipTurn;
    out.map.topRightCorner<3, 3>() = -out.tipTurn * tipRates * rotary;
    for (size_t j = 0; j < 2; ++j)
      out.map.row(joint[j]).tail<3>() = rotary.row(Eigen::Index(j));
    return out;
  }

  /// q's x, y, z for the tip at `tipMm` in the workpiece's frame, its rotary
  /// joints turned by `r`: the tip turned by the table (innermost first),
  /// less the head's offset.
  void place(const Vec3 &tipMm, Joints &q, const Rotations &r) const {
    Vec3 tip = tipMm;
    for (auto it = table_.rbegin(); it != table_.rend(); ++it)
      tip = it->pivotMm + of(r, it->joint) * (tip - it->pivotMm);
    Vec3 offset = Vec3::Zero();
    for (auto it = head_.rbegin(); it != head_.rend(); ++it)  // innermost first
      offset = it->pivotMm + of(r, it->joint) * (offset - it->pivotMm);
    q.head<3>() = tip - offset;
  }

  /// The tip's offset from (x, y, z) and the tool's direction, in machine
  /// coordinates, with the head's axes at q.
  std::pair<Vec3, Vec3> headAt(const Joints &q) const {
    Vec3 offset = Vec3::Zero(), k = k0_;
    for (auto it = head_.rbegin(); it != head_.rend(); ++it) {  // innermost first
      const Mat3 turn = rotation(it->direction, q[it->joint]);
      offset = it->pivotMm + turn * (offset - it->pivotMm);
      k = turn * k;
    }
    return {offset, k};
  }

  Chain chain_;
  std::vector<Axis> axes_;
  Vec3 k0_;
  std::vector<Rotary> head_, table_;  ///< each from the machine's base outwards
  std::vector<Turn> turns_;           ///< in the order they act on k0
};

/// x is the tip's distance from the spindle axis (machine z through x = y =
/// 0), z its place along it; c, when there is one, turns the workpiece.
class LatheKinematics final : public Kinematics {
public:
  explicit LatheKinematics(const Machine &m) : axes_(m.axes), k0_(m.kinematics.toolAxis), c_(m.axisIndex("c")) {}
  std::string_view name() const override { return "lathe"; }
  size_t jointCount() const override { return axes_.size(); }

  ToolPose forward(const Joints &q) const override {
    const Vec3 tip(q[0], 0, q[1]);
    if (c_ < 0)
      return {tip, k0_};
    const Mat3 back = rotation(Vec3::UnitZ(), -q[c_]);
    return {back * tip, back * k0_};
  }

  InverseResult inverse(const ToolPose &pose, const Joints *nearIn) const override {
    const Joints near = nearOrZero(nearIn, axes_.size());
    const Vec3 &p = pose.tipMm;
    Joints q = near;
    q[1] = p.z();
    if (c_ < 0) {
      q[0] = p.x();
      return verified(*this, pose, choose({&q, 1}, axes_, near, false));
    }
    const double r = std::hypot(p.x(), p.y());
    if (r < kSingular * (1 + std::abs(p.z()))) {
      // On the spindle axis the position says nothing of c: the tool's
      // direction does, k = Rz(-c) k0, unless the tool lies along the
      // spindle axis too (a drill on centre), when c is free.
      q[0] = 0;
      const Vec3 k = pose.axis.normalized();
      const bool free = std::hypot(k0_.x(), k0_.y()) < 1e-9 || std::hypot(k.x(), k.y()) < 1e-9;
      if (!free)
        q[c_] = wrapNear(axes_[static_cast<size_t>(c_)],
                         (std::atan2(k0_.y(), k0_.x()) - std::atan2(k.y(), k.x())) / kDeg, near[c_]);
      return verified(*this, pose, choose({&q, 1}, axes_, near, free));
    }
    // The workpiece turned by c shows the tip at angle -c in its frame.
    const double c = -std::atan2(p.y(), p.x()) / kDeg;
    const Axis &axisC = axes_[static_cast<size_t>(c_)];
    Joints across = q;  // the tool on the far side of the spindle axis
    q[0] = r;
    q[c_] = wrapNear(axisC, c, near[c_]);
    across[0] = -r;
    across[c_] = wrapNear(axisC, c + 180, near[c_]);
    const std::array<Joints, 2> both = {q, across};
    return verified(*this, pose, choose(both, axes_, near, false));
  }

private:
  std::vector<Axis> axes_;
  Vec3 k0_;
  Eigen::Index c_;  ///< the c joint, or -1
};

struct Registry {
  std::mutex mutex;
  std::map<std::string, KinematicsFactory> factories;
  std::map<std::string, std::vector<SolverParameter>> parameters;
  /// The runtime's own solvers, there for every program that reads a
  /// machine file.
  Registry() {
    factories[std::string(kLinearTripodSolver)] = makeLinearTripod;
    parameters[std::string(kLinearTripodSolver)] = linearTripodParameters();
  }
};

Registry &registry() {
  static Registry r;
  return r;
}

} // namespace

bool registerKinematicsSolver(const std::string &name, KinematicsFactory factory,
                              std::optional<std::vector<SolverParameter>> parameters) {
  if (name.empty() || !factory)
    return false;
  Registry &r = registry();
  std::lock_guard lock(r.mutex);
  r.factories[name] = std::move(factory);
  if (parameters)
    r.parameters[name] = std::move(*parameters);
  else
    r.parameters.erase(name);
  return true;
}

std::optional<std::vector<SolverParameter>> kinematicsSolverParameters(const std::string &name) {
  Registry &r = registry();
  std::lock_guard lock(r.mutex);
  if (auto it = r.parameters.find(name); it != r.parameters.end())
    return it->second;
  return std::nullopt;
}

bool kinematicsSolverRegistered(const std::string &name) {
  Registry &r = registry();
  std::lock_guard lock(r.mutex);
  return r.factories.count(name) > 0;
}

std::vector<std::string> kinematicsSolverNames() {
  Registry &r = registry();
  std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto &[name, factory] : r.factories)
    names.push_back(name);
  return names;
}

std::unique_ptr<Kinematics> makeKinematics(const Machine &machine, std::string &error) {
  switch (machine.kinematics.chain) {
  case Chain::Xyz:
    return std::make_unique<XyzKinematics>(machine);
  case Chain::TableTable:
  case Chain::HeadTable:
  case Chain::HeadHead:
    return std::make_unique<FiveAxisKinematics>(machine);
  case Chain::Lathe:
    return std::make_unique<LatheKinematics>(machine);
  case Chain::Generic:
    break;
  }
  KinematicsFactory factory;
  {
    Registry &r = registry();
    std::lock_guard lock(r.mutex);
    if (auto it = r.factories.find(machine.kinematics.solver); it != r.factories.end())
      factory = it->second;
  }
  if (!factory) {
    std::string names;
    for (const std::string &n : kinematicsSolverNames())
      names += (names.empty() ? "" : ", ") + n;
    error = "the machine \"" + machine.name + "\" names the kinematics solver '" + machine.kinematics.solver +
            "', which this program has not registered (registered: " + (names.empty() ? "none" : names) + ")";
    return nullptr;
  }
  std::unique_ptr<Kinematics> k = factory(machine, error);
  if (k && k->jointCount() != machine.axes.size()) {
    error = "the kinematics solver '" + machine.kinematics.solver + "' moves " + std::to_string(k->jointCount()) +
            " joints, and the machine \"" + machine.name + "\" has " + std::to_string(machine.axes.size()) + " axes";
    return nullptr;
  }
  return k;
}

double programmedX(const Machine &machine, double radiusMm) {
  return machine.kinematics.diameterProgramming ? 2 * radiusMm : radiusMm;
}

double radiusFromProgrammedX(const Machine &machine, double programmedXMm) {
  return machine.kinematics.diameterProgramming ? programmedXMm / 2 : programmedXMm;
}

} // namespace stepnc::runtime
