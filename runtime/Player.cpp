// The reference player (Player.h): samples a trajectory at the controller
// cycle, evaluates every axis analytically, and checks it against the
// machine, the programmed feed and, when given, the programmed path.
//
// Choices the figures depend on:
//  - Samples fall at t = kT while kT < D - 1e-9 T, then one more exactly at
//    the end D: floor(D/T) + 2 samples, or floor(D/T) + 1 when D is a whole
//    number of periods (the last regular sample would be the end itself).
//    Sample times are k T, not a running sum, so they do not drift; segment
//    start times are a running sum of profile durations in segment order,
//    the same sum as D, so the last segment ends exactly at D.
//  - The lowest feed ratio and the slowest places are taken "between stops":
//    a sample does not count while its segment speeds up from rest (the
//    rising phases of a segment that starts with a stop: the first segment
//    or one whose SegmentInfo::stop is set) or slows down to rest (the
//    falling phases of the last segment or of one followed by a stop). A
//    speed-up or slow-down that a short stop-adjacent segment hands on to
//    its neighbour still counts on the neighbour. Slow time counts every
//    sample, stops included.
//  - Slow time weighs each sample by the interval to the next sample.
//  - Slowest places are feed segments whose lowest counted speed is below
//    slowFraction of their feed; segments at full feed are not listed.
//  - Deviation is measured from the programmed moves themselves (arcs about
//    the centre as programmed), not from the planner's segments, so that a
//    planner that misreads a move is caught.
#include "runtime/Player.h"

#include "runtime/Kinematics.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace stepnc::runtime {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
/// Relative slack on every limit: the planner may use a limit exactly, and
/// the derivatives carry rounding.
constexpr double kSlack = 1e-6;
/// The joints' dynamics of a segment that tilts the tool come from differences
/// between samples (one sample period behind the analytic values) and from
/// the planner's sampled demand: 2 % beyond a limit is a violation.
constexpr double kJointSlack = 0.02;
constexpr double kEndPositionTol = 1e-9;       // mm, against the last segment's end
constexpr double kProgrammedEndTol = 1e-6;     // mm, against the last programmed point
constexpr double kEndSpeedTol = 1e-9;          // mm/s
constexpr double kEndAccelerationTol = 1e-6;   // mm/s^2
/// In the plane, an arc's end this close to its start closes a full turn.
constexpr double kSamePointInPlane = 1e-9;     // mm

/// A programmed move, prepared for distance queries.
struct Programmed {
  bool arc = false;
  Vec3 from = Vec3::Zero();
  Vec3 to = Vec3::Zero();
  // Arcs and helices: the axis through (cx, cy), the start angle, the swept
  // angle (> 0) and its sense (+1 counter-clockwise), the radius at the
  // start and its change over the sweep.
  double cx = 0, cy = 0;
  double radius = 0, radiusChange = 0;
  double startAngle = 0;
  double sweep = 0;
  double dir = 1;
};

/// The angle brought into [0, 2 pi).
double wrap(double angle) {
  angle = std::fmod(angle, kTwoPi);
  if (angle < 0)
    angle += kTwoPi;
  if (angle >= kTwoPi)  // -tiny + 2 pi rounds to 2 pi
    angle = 0;
  return angle;
}

Programmed prepare(const Vec3 &from, const PathMove &move) {
  Programmed m;
  m.from = from;
  m.to = move.to;
  if (move.kind == PathMove::Kind::Dwell)
    m.from = move.to;  // a point: where the tool waits
  if (move.kind != PathMove::Kind::Arc)
    return m;
  m.arc = true;
  m.dir = move.ccw ? 1 : -1;
  // About the programmed centre as given, not the planner's centre moved
  // onto the bisector: the check is meant to be independent of the planner.
  // Where rounding makes the start and end radius differ, the radius changes
  // in proportion to the angle (a spiral, as controllers run such arcs); the
  // difference is the rounding, far below any path tolerance.
  m.cx = move.center.x();
  m.cy = move.center.y();
  const double fx = from.x() - m.cx, fy = from.y() - m.cy;
  const double tx = move.to.x() - m.cx, ty = move.to.y() - m.cy;
  m.radius = std::hypot(fx, fy);
  m.radiusChange = std::hypot(tx, ty) - m.radius;
  m.startAngle = std::atan2(fy, fx);
  double last = kTwoPi;  // over the start in the plane: the last arc is a whole turn
  if (std::hypot(tx - fx, ty - fy) > kSamePointInPlane) {
    last = wrap(m.dir * (std::atan2(ty, tx) - m.startAngle));
    if (last == 0)
      last = kTwoPi;
  }
  m.sweep = last + kTwoPi * static_cast<double>(std::max<int64_t>(move.turns, 0));
  return m;
}

double distanceToLine(const Vec3 &from, const Vec3 &to, const Vec3 &q) {
  const Vec3 d = to - from;
  const double ll = d.squaredNorm();
  if (ll == 0)
    return (q - from).norm();
  const double u = std::clamp((q - from).dot(d) / ll, 0.0, 1.0);
  return (q - (from + u * d)).norm();
}

/// Distance from q to the move: exact for lines and plane arcs; for helices
/// (and spirals) the distance to the curve's point at q's own angle on the
/// nearest turns, an upper bound that is close while q is near the curve.
double distanceTo(const Programmed &m, const Vec3 &q) {
  if (!m.arc)
    return distanceToLine(m.from, m.to, q);
  double best = std::min((q - m.from).norm(), (q - m.to).norm());
  const double qx = q.x() - m.cx, qy = q.y() - m.cy;
  const double rho = std::hypot(qx, qy);
  // At q's angle the curve lies straight out from q's foot on the axis, so
  // the distance is hypot(rho - r, dz): no sin or cos.
  const double delta = wrap(m.dir * (std::atan2(qy, qx) - m.startAngle));
  if (delta > m.sweep)
    return best;
  const double z0 = m.from.z(), dz = m.to.z() - m.from.z();
  auto consider = [&](double theta) {
    const double f = theta / m.sweep;
    best = std::min(best, std::hypot(rho - (m.radius + m.radiusChange * f), q.z() - (z0 + dz * f)));
  };
  // Candidate angles delta + 2 pi k, k = 0 .. maxTurn: the turn nearest q in
  // z (helices) or in radius (plane spirals), and its neighbours; on a plane
  // arc every turn passes the same point.
  const double maxTurn = std::floor((m.sweep - delta) / kTwoPi);
  double k = 0;
  if (dz != 0)
    k = std::round(((q.z() - z0) / dz * m.sweep - delta) / kTwoPi);
  else if (m.radiusChange != 0)
    k = std::round(((rho - m.radius) / m.radiusChange * m.sweep - delta) / kTwoPi);
  k = std::clamp(k, 0.0, maxTurn);
  for (double kk : {k - 1, k, k + 1})
    if (kk >= 0 && kk <= maxTurn)
      consider(delta + kk * kTwoPi);
  return best;
}

struct SlowCandidate {
  SlowSpot spot;
  double ratio = 0;
};

} // namespace

std::string_view violationKindName(ViolationKind kind) {
  switch (kind) {
  case ViolationKind::Velocity:
    return "velocity";
  case ViolationKind::Acceleration:
    return "acceleration";
  case ViolationKind::Jerk:
    return "jerk";
  case ViolationKind::Feed:
    return "feed";
  case ViolationKind::Deviation:
    return "deviation";
  case ViolationKind::EndState:
    return "end state";
  case ViolationKind::Travel:
    return "travel";
  case ViolationKind::Extent:
    return "extent";
  case ViolationKind::Spindle:
    return "spindle";
  case ViolationKind::Reach:
    return "reach";
  }
  return "?";
}

SimReport simulate(const Trajectory &trajectory, const Machine &machine, const SimOptions &options,
                   const std::function<void(const Sample &)> &onSample) {
  SimReport r;
  const size_t n =
      std::min({trajectory.segments.size(), trajectory.profiles.size(), trajectory.info.size()});
  double period = options.period > 0 ? options.period : machine.cycleTime;
  if (!(period > 0))
    period = trajectory.cycleTime;
  r.period = period;
  r.slowFraction = options.slowFraction;

  constexpr double kInf = std::numeric_limits<double>::infinity();
  Vec3 vMax(kInf, kInf, kInf), aMax(kInf, kInf, kInf), jMax(kInf, kInf, kInf);
  for (size_t k = 0; k < 3 && k < machine.axes.size(); ++k) {
    vMax[k] = machine.axes[k].velocity / 60;
    aMax[k] = machine.axes[k].acceleration;
    jMax[k] = machine.axes[k].jerk;
  }
  const Vec3 vAllowed = vMax * (1 + kSlack), aAllowed = aMax * (1 + kSlack), jAllowed = jMax * (1 + kSlack);

  // Times and distances come from the profiles, not from the samples.
  std::vector<double> durations(n);
  double duration = 0, programmedFeedTime = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = trajectory.profiles[i].duration();
    durations[i] = d;
    duration += d;
    const double feed = trajectory.info[i].feed;
    if (trajectory.segments[i].kind == SegmentKind::Dwell) {
      r.dwellTime += d;
    } else if (feed > 0) {
      r.feedTime += d;
      r.feedDistance += trajectory.segments[i].length;
      programmedFeedTime += feed * d;
    } else {
      r.rapidTime += d;
      r.rapidDistance += trajectory.segments[i].length;
    }
  }
  r.duration = duration;
  if (r.feedTime > 0) {
    r.meanFeed = r.feedDistance / r.feedTime;
    r.meanProgrammedFeed = programmedFeedTime / r.feedTime;
  }

  std::vector<Programmed> programmed;
  if (options.programmed) {
    programmed.reserve(options.programmed->moves.size());
    Vec3 at = options.programmed->start;
    for (const PathMove &move : options.programmed->moves) {
      programmed.push_back(prepare(at, move));
      at = move.to;
    }
    r.deviationChecked = true;
    r.tolerance = options.tolerance > 0 ? options.tolerance : trajectory.tolerance;
  }
  const double deviationAllowed = r.tolerance * (1 + kSlack) + 1e-9;

  auto violate = [&](ViolationKind kind, int axis, double t, uint32_t segment, double value, double limit) {
    ++r.violationCount;
    if (r.violations.size() < options.maxViolations)
      r.violations.push_back({kind, axis, t, segment, value, limit});
  };

  // The spindle: each change of speed, where the move that makes it starts.
  if (!options.spindleRpm.empty()) {
    r.spindleChecked = true;
    double t = 0, last = -1;
    bool any = false;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t move = trajectory.info[i].move;
      const double rpm = move < options.spindleRpm.size() ? std::abs(options.spindleRpm[move]) : 0;
      if (rpm > 0) {
        r.spindleMinRpm = any ? std::min(r.spindleMinRpm, rpm) : rpm;
        r.spindleMaxRpm = any ? std::max(r.spindleMaxRpm, rpm) : rpm;
        any = true;
      }
      if (rpm != last && rpm > 0) {
        if (rpm > machine.spindleMax)
          violate(ViolationKind::Spindle, -1, t, static_cast<uint32_t>(i), rpm, machine.spindleMax);
        else if (rpm < machine.spindleMin)
          violate(ViolationKind::Spindle, -1, t, static_cast<uint32_t>(i), rpm, machine.spindleMin);
      }
      last = rpm;
      t += durations[i];
    }
  }

  // Travel: each sample's axis positions through the kinematics, the tool
  // along +z (the rotary axes stay at 0).
  r.travelNotChecked = machine.whyNotThreeAxis();
  // A generic chain (a parallel-kinematic machine) through its solver, which
  // needs where the workpiece is to know where the joints are.
  if (machine.kinematics.chain == Chain::Generic)
    r.travelNotChecked = options.workOffsetMm ? ""
                                              : "the machine \"" + machine.name + "\" moves its joints through the "
                                                "solver '" + machine.kinematics.solver +
                                                    "', which needs where the program's origin is on it (--work-offset)";
  std::unique_ptr<Kinematics> kinematics;
  if (r.travelNotChecked.empty() && machine.kinematics.chain != Chain::Xyz) {
    std::string error;
    kinematics = makeKinematics(machine, error);
    if (!kinematics)
      r.travelNotChecked = error;
  }
  const bool checkTravel = r.travelNotChecked.empty() && !machine.axes.empty();
  // Whether the axes x, y, z are the tip's coordinates (else every sample's
  // joints are checked, as on a segment that tilts the tool).
  const bool cartesian = !kinematics || kinematics->linearJointsAreCartesian();
  r.axesAreTip = cartesian;
  r.workOffsetMm = options.workOffsetMm;
  const Vec3 offset = options.workOffsetMm.value_or(Vec3::Zero());
  // Per axis, taken once: the travel with its slack (positions beyond it
  // leave the travel) and the longest extent that fits it.
  struct AxisTravel {
    double low = 0, high = 0;  ///< a position below low or above high is outside the travel
    double longest = 0;        ///< an extent above it does not fit
    bool outside = false;      ///< in an excursion outside the travel (with a work offset)
    bool spanReported = false; ///< its extent was reported (without one)
  };
  std::vector<AxisTravel> travel(machine.axes.size());
  for (size_t k = 0; k < machine.axes.size(); ++k) {
    const Axis &axis = machine.axes[k];
    const double slack = 1e-9 * (1 + std::max(std::abs(axis.travelMin), std::abs(axis.travelMax)));
    travel[k].low = axis.travelMin - slack;
    travel[k].high = axis.travelMax + slack;
    travel[k].longest = axis.travelMax - axis.travelMin + slack;
  }
  // The lowest and highest position of each axis so far (SimReport::axisMin,
  // axisMax once the samples are done), and how many axes are outside.
  std::vector<double> lowest(machine.axes.size()), highest(machine.axes.size());
  size_t outsideCount = 0;
  Joints joints = Joints::Zero(static_cast<Eigen::Index>(machine.axes.size()));
  bool haveJoints = false;
  // One axis at position q: its range so far, and whether it leaves its
  // travel (with a work offset; once per excursion) or the program's extent
  // on it no longer fits the travel (without one).
  auto checkAxis = [&](size_t k, double q, double t, uint32_t sg) {
    AxisTravel &a = travel[k];
    if (!haveJoints)
      lowest[k] = highest[k] = q;
    lowest[k] = std::min(lowest[k], q);
    highest[k] = std::max(highest[k], q);
    if (options.workOffsetMm) {
      const bool out = q < a.low || q > a.high;
      if (out && !a.outside) {
        const Axis &axis = machine.axes[k];
        violate(ViolationKind::Travel, static_cast<int>(k), t, sg, q,
                q < axis.travelMin ? axis.travelMin : axis.travelMax);
      }
      outsideCount += size_t(out) - size_t(a.outside);
      a.outside = out;
    } else if (!a.spanReported && highest[k] - lowest[k] > a.longest) {
      const Axis &axis = machine.axes[k];
      violate(ViolationKind::Extent, static_cast<int>(k), t, sg, highest[k] - lowest[k],
              axis.travelMax - axis.travelMin);
      a.spanReported = true;
    }
  };
  // xyz (no kinematics made): the axes x, y, z are the tip's coordinates.
  // Most samples change nothing but the range: with a work offset, a
  // position within the travel while no axis is outside it; without one, a
  // position within the range so far. Those are taken here, with what
  // checkAxis would give; the others go through checkAxis.
  auto quietXyz = [&](const Vec3 &q) {
    if (options.workOffsetMm) {
      if (outsideCount > 0)
        return false;
      for (int k = 0; k < 3; ++k)
        if (q[k] < travel[k].low || q[k] > travel[k].high)
          return false;
      for (int k = 0; k < 3; ++k) {
        lowest[k] = std::min(lowest[k], q[k]);
        highest[k] = std::max(highest[k], q[k]);
      }
      return true;
    }
    for (int k = 0; k < 3; ++k)
      if (q[k] < lowest[k] || q[k] > highest[k])
        return false;
    return true;
  };
  // A segment that tilts the tool moves the machine's joints otherwise than
  // its tip: their velocity, acceleration and jerk are taken from the joints
  // at consecutive samples (differences over the sample period), each
  // against its axis's limits; the tip's own are not the axes'.
  struct JointSample {
    double t = 0;
    Joints q, v, a;
    bool hasV = false, hasA = false;  ///< v and a are differences of samples, not placeholders
  };
  std::vector<JointSample> history;  // the last two samples with joints
  bool outOfReach = false;           // the last sample's pose had no joints (a generic chain)
  r.jointMaxVelocity.assign(machine.axes.size(), 0);
  r.jointMaxAcceleration.assign(machine.axes.size(), 0);
  r.jointMaxJerk.assign(machine.axes.size(), 0);
  auto jointDynamics = [&](double t, uint32_t sg, bool tilted) {
    JointSample now;
    now.t = t;
    now.q = joints;
    now.v = now.a = Joints::Zero(joints.size());
    Joints jerk = Joints::Zero(joints.size());
    const bool withV = !history.empty() && t > history.back().t;
    if (withV)
      now.v = (now.q - history.back().q) / (t - history.back().t);
    const bool withA = withV && history.back().hasV;
    if (withA)
      now.a = (now.v - history.back().v) / (t - history.back().t);
    const bool withJ = withA && history.back().hasA;
    if (withJ)
      jerk = (now.a - history.back().a) / (t - history.back().t);
    now.hasV = withV;
    now.hasA = withA;
    if (tilted && withV) {
      r.tiltedSamples++;
      for (size_t k = 0; k < machine.axes.size(); ++k) {
        const Eigen::Index i = static_cast<Eigen::Index>(k);
        const Axis &axis = machine.axes[k];
        const double v = std::abs(now.v[i]), acc = std::abs(now.a[i]), j = std::abs(jerk[i]);
        r.jointMaxVelocity[k] = std::max(r.jointMaxVelocity[k], v);
        if (v > axis.velocity / 60 * (1 + kJointSlack) + 1e-6)
          violate(ViolationKind::Velocity, static_cast<int>(k), t, sg, v, axis.velocity / 60);
        if (withA) {
          r.jointMaxAcceleration[k] = std::max(r.jointMaxAcceleration[k], acc);
          if (acc > axis.acceleration * (1 + kJointSlack) + 1e-6)
            violate(ViolationKind::Acceleration, static_cast<int>(k), t, sg, acc, axis.acceleration);
        }
        if (withJ) {
          r.jointMaxJerk[k] = std::max(r.jointMaxJerk[k], j);
          if (j > axis.jerk * (1 + kJointSlack) + 1e-6)
            violate(ViolationKind::Jerk, static_cast<int>(k), t, sg, j, axis.jerk);
        }
      }
    }
    if (history.size() == 2)
      history.erase(history.begin());
    history.push_back(std::move(now));
  };
  // Where the tool axis goes next from arc length `along` of segment `seg`:
  // a little further along, or (a dwell) the next segment's start. Asked
  // only at a singular pose.
  auto poseAhead = [&](size_t seg, double along) -> std::optional<ToolPose> {
    const Segment &here = trajectory.segments[seg];
    if (here.length > 0) {
      const double s1 = std::min(here.length, along + 1e-3);
      return ToolPose{here.at(s1).p + offset, here.axisAt(s1)};
    }
    if (seg + 1 < trajectory.segments.size()) {
      const Segment &after = trajectory.segments[seg + 1];
      const double s1 = std::min(after.length, 1e-3);
      return ToolPose{after.at(s1).p + offset, after.axisAt(s1)};
    }
    return std::nullopt;
  };
  auto checkTravelAt = [&](const Vec3 &p, const Vec3 &toolAxis, bool tilted, double t, uint32_t sg, double along,
                           bool fromMiddle) {
    if (!checkTravel)
      return;
    const Vec3 tip = p + offset;
    if (!kinematics) {  // xyz
      if (haveJoints && quietXyz(tip))
        return;
      for (int k = 0; k < 3; ++k)
        checkAxis(size_t(k), tip[k], t, sg);
      haveJoints = true;
      return;
    }
    // The planner's choice at a rapid that turns the tool: the rotary axes
    // start again from the solution nearest the middle of their travel.
    Joints near = joints;
    if (fromMiddle)
      for (size_t k = 0; k < machine.axes.size(); ++k)
        if (machine.axes[k].rotary)
          near[static_cast<Eigen::Index>(k)] = 0;
    InverseResult ir = kinematics->inverse(ToolPose{tip, toolAxis}, haveJoints ? &near : nullptr);
    if (!ir.joints) {
      // A parallel-kinematic machine's joints are not known there: said
      // where the path leaves the solver's reach, and the differences start
      // again after it. (On the serial chains a pose only their tilt could
      // refuse: whyNotThreeAxis says so.)
      if (!cartesian) {
        if (!outOfReach)
          violate(ViolationKind::Reach, -1, t, sg, 0, 0);
        outOfReach = true;
        history.clear();
      }
      return;
    }
    outOfReach = false;
    if (const std::optional<ToolPose> ahead = ir.singular && tilted ? poseAhead(sg, along) : std::nullopt) {
      // The tool along a rotary axis leaves the other free: it is where the
      // tool axis goes next (as the planner set it).
      const InverseResult next = kinematics->inverse(*ahead, &*ir.joints);
      if (next.joints) {
        const InverseResult again = kinematics->inverse(ToolPose{tip, toolAxis}, &*next.joints);
        if (again.joints)
          ir = again;
      }
    }
    joints = *ir.joints;
    for (size_t k = 0; k < machine.axes.size(); ++k)
      checkAxis(k, joints[static_cast<Eigen::Index>(k)], t, sg);
    haveJoints = true;
    // A dwell where the joints turn with the tip still (the planner timed
    // the turn from the joints' limits): the differences start again after.
    if (trajectory.segments.size() > sg && trajectory.segments[sg].kind == SegmentKind::Dwell) {
      history.clear();
      return;
    }
    jointDynamics(t, sg, tilted || !cartesian);
  };

  // The segment under the samples, and what is known of it.
  size_t seg = 0;
  double segStart = 0;
  struct Current {
    double feed = 0, slowSpeed = 0, riseEnd = 0, fallStart = 0;
    bool capped = false, isShort = false;
    bool seen = false;  ///< some sample counted towards the lowest ratio
    double minRatio = 0;
    double minSpeed = 0;
    SlowReason minReason = SlowReason::Ramp;
  } cur;
  std::vector<SlowCandidate> candidates;
  auto enter = [&](size_t i) {
    const SegmentInfo &info = trajectory.info[i];
    const Profile &profile = trajectory.profiles[i];
    cur = Current{};
    cur.feed = info.feed;
    if (cur.feed <= 0)
      return;
    cur.slowSpeed = options.slowFraction * cur.feed;
    cur.capped = info.limits.v < cur.slowSpeed;
    cur.isShort = profile.peak() < info.limits.v * (1 - 1e-9);
    // Phases 0-2 rise, 3 cruises, 4-6 fall (Profile.h).
    const bool fromRest = i == 0 || info.stop != StopReason::None;
    const bool toRest = i + 1 == n || trajectory.info[i + 1].stop != StopReason::None;
    if (fromRest)
      cur.riseEnd = profile.phases[0].duration + profile.phases[1].duration + profile.phases[2].duration;
    cur.fallStart = kInf;
    if (toRest)
      cur.fallStart =
          durations[i] - (profile.phases[4].duration + profile.phases[5].duration + profile.phases[6].duration);
  };
  auto leave = [&](size_t i) {
    if (cur.feed > 0 && cur.seen && cur.minRatio < options.slowFraction) {
      SlowCandidate c;
      c.ratio = cur.minRatio;
      c.spot.move = trajectory.info[i].move;
      c.spot.segment = static_cast<uint32_t>(i);
      c.spot.speed = cur.minSpeed;
      c.spot.feed = cur.feed;
      c.spot.reason = cur.minReason;
      c.spot.limitedBy = trajectory.info[i].limitedBy;
      candidates.push_back(c);
    }
  };
  if (n > 0)
    enter(0);

  const double lastRegular = duration - 1e-9 * period;
  size_t lastJointSegment = std::numeric_limits<size_t>::max();  // the segment of the last sample's joints
  Sample s, prev;
  bool havePrev = false;
  for (size_t k = 0;; ++k) {
    double t = static_cast<double>(k) * period;
    const bool final = !(t < lastRegular);
    if (final)
      t = duration;
    double next = static_cast<double>(k + 1) * period;
    if (!(next < lastRegular))
      next = duration;
    const double weight = final ? 0 : next - t;

    s.t = t;
    if (n == 0) {
      s.p = trajectory.start;
      s.v = s.a = s.j = Vec3::Zero();
      s.speed = 0;
    } else {
      while (seg + 1 < n && (final || t >= segStart + durations[seg])) {
        leave(seg);
        segStart += durations[seg];
        ++seg;
        enter(seg);
      }
      // The end is the last profile's own end, not a difference of sums.
      const double local = final ? durations[seg] : t - segStart;
      const PathState ps = trajectory.profiles[seg].at(local);
      const PathPoint pp = trajectory.segments[seg].at(ps.s);
      s.segment = static_cast<uint32_t>(seg);
      s.p = pp.p;
      s.v = ps.v * pp.r1;
      s.a = ps.a * pp.r1 + ps.v * ps.v * pp.r2;
      s.j = ps.j * pp.r1 + 3 * ps.v * ps.a * pp.r2 + ps.v * ps.v * ps.v * pp.r3;
      s.speed = ps.v;

      const uint32_t sg = s.segment;
      // A segment that tilts the tool: the joints' dynamics are checked
      // instead (checkTravelAt), not the tip's.
      for (int a = 0; a < 3 && cartesian && !trajectory.segments[seg].tilted(); ++a) {
        const double v = std::abs(s.v[a]), acc = std::abs(s.a[a]), j = std::abs(s.j[a]);
        r.maxVelocity[a] = std::max(r.maxVelocity[a], v);
        r.maxAcceleration[a] = std::max(r.maxAcceleration[a], acc);
        r.maxJerk[a] = std::max(r.maxJerk[a], j);
        if (v > vAllowed[a])
          violate(ViolationKind::Velocity, a, t, sg, v, vMax[a]);
        if (acc > aAllowed[a])
          violate(ViolationKind::Acceleration, a, t, sg, acc, aMax[a]);
        if (j > jAllowed[a])
          violate(ViolationKind::Jerk, a, t, sg, j, jMax[a]);
        if (havePrev) {
          // A jump between samples: what no bounded jerk (acceleration)
          // could have done in the interval.
          const double dt = t - prev.t;
          const double da = std::abs(s.a[a] - prev.a[a]), dv = std::abs(s.v[a] - prev.v[a]);
          if (da > jAllowed[a] * dt + 1e-6)
            violate(ViolationKind::Jerk, a, t, sg, da / dt, jMax[a]);
          if (dv > aAllowed[a] * dt + 1e-6)
            violate(ViolationKind::Acceleration, a, t, sg, dv / dt, aMax[a]);
        }
      }

      if (cur.feed > 0) {
        if (s.speed > cur.feed * (1 + 1e-9) + 1e-9)
          violate(ViolationKind::Feed, -1, t, sg, s.speed, cur.feed);
        SlowReason reason = SlowReason::Ramp;
        const bool slow = s.speed < cur.slowSpeed;
        if (slow) {
          const SegmentInfo &info = trajectory.info[seg];
          if (cur.capped) {
            reason = SlowReason::Cap;
            r.slowCapTime[static_cast<size_t>(info.limitedBy)] += weight;
          } else if (cur.isShort) {
            reason = SlowReason::Short;
          }
          r.slowTime[static_cast<size_t>(reason)] += weight;
        }
        if (local >= cur.riseEnd && local <= cur.fallStart) {
          const double ratio = s.speed / cur.feed;
          r.minFeedRatio = std::min(r.minFeedRatio, ratio);
          if (!cur.seen || ratio < cur.minRatio) {
            cur.seen = true;
            cur.minRatio = ratio;
            cur.minSpeed = s.speed;
            cur.minReason = reason;
          }
        }
      }

      if (!programmed.empty()) {
        const SegmentInfo &info = trajectory.info[seg];
        double d = kInf;
        if (info.move < programmed.size())
          d = distanceTo(programmed[info.move], s.p);
        if (info.nextMove != info.move && info.nextMove < programmed.size())
          d = std::min(d, distanceTo(programmed[info.nextMove], s.p));
        if (d != kInf) {
          r.maxDeviation = std::max(r.maxDeviation, d);
          if (d > deviationAllowed)
            violate(ViolationKind::Deviation, -1, t, sg, d, r.tolerance);
        }
      }
    }

    {
      const Segment *here = n > 0 ? &trajectory.segments[seg] : nullptr;
      const bool tilted = here && here->tilted();
      const double along = tilted ? trajectory.profiles[seg].at(final ? durations[seg] : t - segStart).s : 0;
      const Vec3 toolAxis = tilted ? here->axisAt(along) : Vec3::UnitZ();
      const bool turning = tilted && trajectory.info[seg].feed == 0 && here->kind == SegmentKind::Line &&
                           here->axis0 != here->axis1;
      checkTravelAt(s.p, toolAxis, tilted, s.t, s.segment, along, turning && seg != lastJointSegment);
      lastJointSegment = seg;
    }
    if (onSample)
      onSample(s);
    prev = s;
    havePrev = true;
    ++r.samples;
    if (final)
      break;
  }
  if (n > 0)
    leave(seg);
  if (haveJoints) {
    r.axisMin = std::move(lowest);
    r.axisMax = std::move(highest);
  }

  // The end state: the last sample is the end.
  r.endPosition = s.p;
  const uint32_t lastSegment = n > 0 ? static_cast<uint32_t>(n - 1) : 0;
  const Vec3 end = n > 0 ? trajectory.segments[n - 1].end : trajectory.start;
  const double off = (s.p - end).norm();
  if (!(off <= kEndPositionTol))
    violate(ViolationKind::EndState, -1, s.t, lastSegment, off, kEndPositionTol);
  if (!(std::abs(s.speed) <= kEndSpeedTol) || !(s.a.norm() < kEndAccelerationTol)) {
    bool named = false;
    for (int a = 0; a < 3; ++a)
      if (std::abs(s.v[a]) > kEndSpeedTol || std::abs(s.a[a]) >= kEndAccelerationTol) {
        violate(ViolationKind::EndState, a, s.t, lastSegment, std::abs(s.v[a]), kEndSpeedTol);
        named = true;
      }
    if (!named) {  // spread over the axes, each within its share: name the fastest
      int a = 0;
      s.v.cwiseAbs().maxCoeff(&a);
      violate(ViolationKind::EndState, a, s.t, lastSegment, std::abs(s.v[a]), kEndSpeedTol);
    }
  }
  if (options.programmed) {
    const PathInput &in = *options.programmed;
    const Vec3 target = in.moves.empty() ? in.start : in.moves.back().to;
    const double miss = (s.p - target).norm();
    if (!(miss <= kProgrammedEndTol))
      violate(ViolationKind::EndState, -1, s.t, lastSegment, miss, kProgrammedEndTol);
  }

  // Slowest first; equal ratios in path order, so the list is deterministic.
  auto slower = [](const SlowCandidate &x, const SlowCandidate &y) {
    return x.ratio != y.ratio ? x.ratio < y.ratio : x.spot.segment < y.spot.segment;
  };
  const size_t keep = std::min(options.maxSlowSpots, candidates.size());
  std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(keep), candidates.end(),
                    slower);
  for (size_t i = 0; i < keep; ++i)
    r.slowest.push_back(candidates[i].spot);
  return r;
}

namespace {

std::string seconds(double t) { return formatFixed(t, 3) + " s"; }
std::string perMinute(double mmPerS) { return formatFixed(mmPerS * 60, 1) + " mm/min"; }
std::string percent(double fraction) { return formatFixed(fraction * 100, 1) + " %"; }

/// "mm", or "deg" for a rotary axis.
std::string unitOf(const Machine &machine, int axis) {
  return axis >= 0 && size_t(axis) < machine.axes.size() && machine.axes[size_t(axis)].rotary ? "deg" : "mm";
}

std::string axisName(const Machine &machine, int axis) {
  if (axis >= 0 && static_cast<size_t>(axis) < machine.axes.size())
    return machine.axes[static_cast<size_t>(axis)].name;
  return std::string(1, "xyz"[std::clamp(axis, 0, 2)]);
}

std::string reasonText(SlowReason reason, SpeedLimit limitedBy) {
  switch (reason) {
  case SlowReason::Ramp:
    return "speeding up or slowing down";
  case SlowReason::Short:
    return "too short to reach its speed";
  case SlowReason::Cap:
    break;
  }
  return "capped by " + std::string(speedLimitDescription(limitedBy));
}

} // namespace

std::string formatReport(const SimReport &report, const Trajectory &trajectory, const Machine &machine,
                         const std::function<std::string(uint32_t move)> &nameMove) {
  auto name = [&](uint32_t move) { return nameMove ? nameMove(move) : "move " + std::to_string(move); };
  std::string out;

  out += "machine: " + machine.name;
  if (!trajectory.machine.empty() && trajectory.machine != machine.name)
    out += " (trajectory planned for " + trajectory.machine + ")";
  out += " (cycle " + formatFixed(report.period * 1000, 3) + " ms, " + std::to_string(report.samples) +
         " samples, path tolerance " + formatFixed(trajectory.tolerance, 3) + " mm)\n";

  out += "cycle time: " + seconds(report.duration) + " (feed moves " + seconds(report.feedTime) + " over " +
         formatFixed(report.feedDistance, 1) + " mm, rapids " + seconds(report.rapidTime) + " over " +
         formatFixed(report.rapidDistance, 1) + " mm" +
         (report.dwellTime > 0 ? ", dwells " + seconds(report.dwellTime) : std::string()) + ")\n";

  if (report.feedTime > 0) {
    out += "feed on feed moves: mean " + perMinute(report.meanFeed) + " of " + perMinute(report.meanProgrammedFeed) +
           " programmed (" + percent(report.meanProgrammedFeed > 0 ? report.meanFeed / report.meanProgrammedFeed : 0) +
           "), lowest " + percent(report.minFeedRatio) + " between stops\n";
    const double slow = report.slowTime[0] + report.slowTime[1] + report.slowTime[2];
    out += "below " + formatTrimmed(report.slowFraction * 100, 3) + " % of the programmed feed: " + seconds(slow) + "\n";
    if (report.slowTime[static_cast<size_t>(SlowReason::Ramp)] > 0)
      out += "  speeding up or slowing down: " + seconds(report.slowTime[static_cast<size_t>(SlowReason::Ramp)]) +
             "\n";
    if (report.slowTime[static_cast<size_t>(SlowReason::Short)] > 0)
      out += "  segments too short to reach their speed: " +
             seconds(report.slowTime[static_cast<size_t>(SlowReason::Short)]) + "\n";
    for (size_t l = 0; l < 5; ++l)
      if (report.slowCapTime[l] > 0)
        out += "  capped by " + std::string(speedLimitDescription(static_cast<SpeedLimit>(l))) + ": " +
               seconds(report.slowCapTime[l]) + "\n";
    if (!report.slowest.empty()) {
      out += "slowest places:\n";
      for (const SlowSpot &spot : report.slowest)
        out += "  " + name(spot.move) + " (segment " + std::to_string(spot.segment) + "): " + perMinute(spot.speed) +
               " of " + perMinute(spot.feed) + " (" + percent(spot.feed > 0 ? spot.speed / spot.feed : 0) + "), " +
               reasonText(spot.reason, spot.limitedBy) +
               (spot.reason == SlowReason::Cap && spot.segment < trajectory.info.size() &&
                        trajectory.info[spot.segment].axis >= 0 &&
                        size_t(trajectory.info[spot.segment].axis) < trajectory.axisNames.size()
                    ? " (axis " + trajectory.axisNames[size_t(trajectory.info[spot.segment].axis)] + ")"
                    : std::string()) +
               "\n";
    }
  } else {
    out += "feed on feed moves: no feed moves\n";
  }

  if (report.axesAreTip)
    out += "axis peaks (of the limit):\n";
  for (size_t k = 0; k < 3 && k < machine.axes.size() && report.axesAreTip; ++k) {
    const Axis &axis = machine.axes[k];
    auto of = [](double value, double limit) { return limit > 0 ? " (" + percent(value / limit) + ")" : ""; };
    out += "  " + axis.name + ": |v| " + perMinute(report.maxVelocity[k]) +
           of(report.maxVelocity[k] * 60, axis.velocity) + ", |a| " + formatFixed(report.maxAcceleration[k], 1) +
           " mm/s^2" + of(report.maxAcceleration[k], axis.acceleration) + ", |j| " +
           formatFixed(report.maxJerk[k], 1) + " mm/s^3" + of(report.maxJerk[k], axis.jerk) + "\n";
  }
  if (report.tiltedSamples > 0) {
    // Where the tool tilts the axes are the joints (differences of samples).
    out += std::string(report.axesAreTip ? "joint peaks where the tool tilts (" : "joint peaks (") +
           std::to_string(report.tiltedSamples) + " samples; of the limit):\n";
    for (size_t k = 0; k < machine.axes.size() && k < report.jointMaxVelocity.size(); ++k) {
      const Axis &axis = machine.axes[k];
      const std::string unit = unitOf(machine, static_cast<int>(k));
      auto of = [](double value, double limit) { return limit > 0 ? " (" + percent(value / limit) + ")" : ""; };
      out += "  " + axis.name + ": |v| " + formatFixed(report.jointMaxVelocity[k] * 60, 1) + " " + unit + "/min" +
             of(report.jointMaxVelocity[k] * 60, axis.velocity) + ", |a| " +
             formatFixed(report.jointMaxAcceleration[k], 1) + " " + unit + "/s^2" +
             of(report.jointMaxAcceleration[k], axis.acceleration) + ", |j| " +
             formatFixed(report.jointMaxJerk[k], 1) + " " + unit + "/s^3" + of(report.jointMaxJerk[k], axis.jerk) +
             "\n";
    }
  }

  // Travel: the range each axis covers, against its travel.
  if (!report.travelNotChecked.empty()) {
    out += "travel: not checked (" + report.travelNotChecked + ")\n";
  } else if (report.axisMin.size() == machine.axes.size()) {
    auto mm = [](double v) { return formatFixed(v, 3); };
    if (report.workOffsetMm) {
      const Vec3 &o = *report.workOffsetMm;
      out += "travel (program origin at machine " + mm(o.x()) + ", " + mm(o.y()) + ", " + mm(o.z()) + " mm):";
    } else {
      out += "travel (program origin not given: extents only):";
    }
    for (size_t k = 0; k < machine.axes.size(); ++k) {
      const Axis &axis = machine.axes[k];
      const std::string unit = axis.rotary ? " deg" : " mm";
      out += std::string(k ? "," : "") + " " + axis.name + " ";
      if (report.workOffsetMm)
        out += mm(report.axisMin[k]) + " to " + mm(report.axisMax[k]) + unit + " in [" + mm(axis.travelMin) + ", " +
               mm(axis.travelMax) + "]";
      else
        out += mm(report.axisMax[k] - report.axisMin[k]) + " of " + mm(axis.travelMax - axis.travelMin) + unit;
    }
    out += "\n";
  }
  if (!report.spindleChecked)
    out += "spindle: not checked (the motion carries no spindle speeds)\n";
  else if (report.spindleMaxRpm == 0)
    out += "spindle: stopped throughout (machine " + formatTrimmed(machine.spindleMin, 6) + " to " +
           formatTrimmed(machine.spindleMax, 6) + " rev/min)\n";
  else
    out += "spindle: " + formatTrimmed(report.spindleMinRpm, 6) + " to " + formatTrimmed(report.spindleMaxRpm, 6) +
           " rev/min (machine " + formatTrimmed(machine.spindleMin, 6) + " to " + formatTrimmed(machine.spindleMax, 6) +
           " rev/min)\n";

  if (report.deviationChecked)
    out += "contour deviation: max " + formatFixed(report.maxDeviation, 4) + " mm (tolerance " +
           formatFixed(report.tolerance, 4) + " mm)\n";

  if (report.violationCount == 0) {
    out += "violations: none\n";
    return out;
  }
  out += "violations: " + std::to_string(report.violationCount) + " (showing " +
         std::to_string(report.violations.size()) + ")\n";
  for (const Violation &v : report.violations) {
    out += "  t=" + seconds(v.t) + ", ";
    if (v.segment < trajectory.info.size())
      out += name(trajectory.info[v.segment].move) + ", ";
    out += "segment " + std::to_string(v.segment);
    switch (v.kind) {
    case ViolationKind::Velocity:
      out += ", axis " + axisName(machine, v.axis) + ": velocity " + formatFixed(v.value * 60, 1) + " " +
             unitOf(machine, v.axis) + "/min > " + formatFixed(v.limit * 60, 1) + " " + unitOf(machine, v.axis) +
             "/min";
      break;
    case ViolationKind::Acceleration:
      out += ", axis " + axisName(machine, v.axis) + ": acceleration " + formatFixed(v.value, 1) + " " +
             unitOf(machine, v.axis) + "/s^2 > " + formatFixed(v.limit, 1) + " " + unitOf(machine, v.axis) + "/s^2";
      break;
    case ViolationKind::Jerk:
      out += ", axis " + axisName(machine, v.axis) + ": jerk " + formatFixed(v.value, 1) + " " +
             unitOf(machine, v.axis) + "/s^3 > " + formatFixed(v.limit, 1) + " " + unitOf(machine, v.axis) + "/s^3";
      break;
    case ViolationKind::Feed:
      out += ": speed " + perMinute(v.value) + " above the programmed feed " + perMinute(v.limit);
      break;
    case ViolationKind::Deviation:
      out += ": " + formatFixed(v.value, 6) + " mm from the programmed path (tolerance " + formatFixed(v.limit, 4) +
             " mm)";
      break;
    case ViolationKind::EndState:
      if (v.axis < 0)
        out += ": ends " + formatFixed(v.value, 9) + " mm from its end point (allowed " + formatFixed(v.limit, 9) +
               " mm)";
      else
        out += ", axis " + axisName(machine, v.axis) + ": not at rest at the end (" + perMinute(v.value) + ")";
      break;
    case ViolationKind::Travel: {
      const Axis *axis = v.axis >= 0 && static_cast<size_t>(v.axis) < machine.axes.size()
                             ? &machine.axes[static_cast<size_t>(v.axis)]
                             : nullptr;
      const std::string unit = axis && axis->rotary ? " deg" : " mm";
      out += ", axis " + axisName(machine, v.axis) + ": position " + formatFixed(v.value, 3) + unit +
             " outside the travel";
      if (axis)
        out += " [" + formatFixed(axis->travelMin, 3) + ", " + formatFixed(axis->travelMax, 3) + "]" + unit;
      break;
    }
    case ViolationKind::Extent:
      out += ", axis " + axisName(machine, v.axis) + ": the program spans " + formatFixed(v.value, 3) +
             " mm by here, more than the travel's " + formatFixed(v.limit, 3) + " mm (no program origin fits it)";
      break;
    case ViolationKind::Reach:
      out += ": the machine's solver finds no joints for the pose here (a strut out of reach or beyond its angle "
             "limits)";
      break;
    case ViolationKind::Spindle:
      out += ": spindle " + formatTrimmed(v.value, 6) + " rev/min " +
             (v.value > v.limit ? "above the machine's maximum " : "below the machine's minimum ") +
             formatTrimmed(v.limit, 6) + " rev/min";
      break;
    }
    out += "\n";
  }
  return out;
}

} // namespace stepnc::runtime
