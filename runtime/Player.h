// The reference player: samples a trajectory at the controller cycle and
// checks it against the machine. Per axis it reports position, velocity,
// acceleration and jerk at each sample, the cycle time, the actual feed along
// the path compared with the programmed feed (where it falls below, and
// which limit made it), and every limit violation.
//
// A dwell segment holds the tool at its point, every derivative zero, for
// its profile's duration; its time counts in the cycle time, apart from the
// feed moves' and the rapids'.
//
// Values are the analytic derivatives at the sample times. Each is also
// checked against its neighbour sample, |a(t+T) - a(t)| <= j_max T, so a jump
// between samples (a curvature step, a profile that does not join) cannot hide
// between two samples. On a segment that tilts the tool the axes are the
// joints: their velocity, acceleration and jerk are the differences of the
// joints (inverse kinematics) between consecutive samples, checked against
// every axis's limits, rotary ones included.
//
// Travel and spindle: each sample's position is mapped through the machine's
// kinematics (runtime/Kinematics.h; rotary axes at 0, tool along +z, or on a
// segment that tilts the tool along its axis there) to its axes' positions; on an xyz machine it is the axes' position, compared with
// bounds taken once. With the program origin's place on the machine given
// (SimOptions::workOffsetMm) each is checked against its travel; without
// it, only that the program's extent on each axis fits the travel somewhere.
// The spindle speed of each programmed move, when the caller knows it (the
// native format does not carry it), is checked against the machine's range.
#pragma once

#include "runtime/Machine.h"
#include "runtime/Planner.h"
#include "runtime/Trajectory.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::runtime {

struct Sample {
  double t = 0;        ///< s from the start
  uint32_t segment = 0;
  Vec3 p = Vec3::Zero();  ///< mm
  Vec3 v = Vec3::Zero();  ///< mm/s
  Vec3 a = Vec3::Zero();  ///< mm/s^2
  Vec3 j = Vec3::Zero();  ///< mm/s^3
  double speed = 0;    ///< mm/s along the path
};

enum class ViolationKind : uint8_t {
  Velocity,      ///< |v| of an axis above its limit
  Acceleration,  ///< |a| above the limit, or a jump of v between samples
  Jerk,          ///< |j| above the limit, or a jump of a between samples
  Feed,          ///< speed along the path above the programmed feed
  Deviation,     ///< further from the programmed path than the tolerance
  EndState,      ///< not at rest at the programmed end point (see Violation::value)
  Travel,        ///< an axis's position (machine coordinates) outside its travel
  Extent,        ///< the program's extent on an axis is longer than its travel: no program origin fits
  Spindle,       ///< a move's spindle speed outside the machine's range
  /// A parallel-kinematic machine's solver finds no joints for the pose (a
  /// strut out of reach or beyond its angle limits): reported where the
  /// path leaves the reach, once per excursion.
  Reach,
};
std::string_view violationKindName(ViolationKind kind);

struct Violation {
  ViolationKind kind = ViolationKind::Velocity;
  int axis = -1;       ///< index in Machine::axes; -1 when not per axis
  double t = 0;        ///< s
  uint32_t segment = 0;
  /// What was measured: mm/s, mm/s^2, mm/s^3 for the axis limits (a jump
  /// between samples as its rate, the difference over the interval), mm/s
  /// for Feed, mm for Deviation. EndState: with axis -1 the distance in mm
  /// from where the motion should end; with axis 0-2 that axis has not come
  /// to rest, value its |v| in mm/s (the axis may instead still accelerate).
  /// Travel: the axis's position (mm, or deg for a rotary axis) when it
  /// leaves its travel, limit the bound it crosses. Extent: the extent so far
  /// (mm), limit the travel's length. Spindle: rev/min, limit the bound of
  /// the machine's range that it is beyond; t is where the move starts.
  double value = 0;
  double limit = 0;    ///< what was allowed, in the same unit
};

/// Why the speed on a feed move is below the programmed feed.
enum class SlowReason : uint8_t {
  Cap,       ///< the segment's speed cap (SegmentInfo::limitedBy says which limit)
  Ramp,      ///< speeding up or slowing down for a neighbouring segment or a stop
  Short,     ///< the segment is too short to reach its cap and leave it again
};

struct SlowSpot {
  uint32_t move = 0;       ///< the programmed move
  uint32_t segment = 0;
  double speed = 0;        ///< mm/s, the lowest there
  double feed = 0;         ///< mm/s programmed
  SlowReason reason = SlowReason::Cap;
  SpeedLimit limitedBy = SpeedLimit::Feed;  ///< for Cap
};

struct SimOptions {
  double period = 0;  ///< s between samples; 0 = the machine's cycle time
  /// The programmed path, for the contour deviation check (none without it).
  const PathInput *programmed = nullptr;
  double tolerance = 0;    ///< mm; 0 = the trajectory's tolerance
  /// Speed below this fraction of the programmed feed counts as slow.
  double slowFraction = 0.95;
  size_t maxViolations = 20;  ///< violations kept in the report (all are counted)
  size_t maxSlowSpots = 10;   ///< slowest places kept
  /// Where the program's origin is on the machine (mm, machine coordinates
  /// with the rotary axes at 0): positions are then checked against the
  /// travel. Unknown (stepnc does not know the setups' work offsets yet): only
  /// the program's extent is checked.
  std::optional<Vec3> workOffsetMm;
  /// Per programmed move (SegmentInfo::move), its spindle speed in rev/min
  /// (the sign, the direction, is ignored; 0 = stopped, allowed). Empty: the
  /// spindle is not checked.
  std::vector<double> spindleRpm;
};

struct SimReport {
  double duration = 0;      ///< s, the whole trajectory
  size_t samples = 0;
  double feedTime = 0;      ///< s on feed moves
  double rapidTime = 0;     ///< s on rapids
  double dwellTime = 0;     ///< s waiting at rest in dwells
  double feedDistance = 0;  ///< mm on feed moves
  double rapidDistance = 0;
  double meanFeed = 0;      ///< mm/s, feed distance / feed time
  double meanProgrammedFeed = 0;  ///< mm/s, time-weighted programmed feed on feed moves
  double minFeedRatio = 1;  ///< lowest speed / programmed feed on feed moves (between the stops)
  double slowTime[3] = {0, 0, 0};  ///< s below slowFraction, by SlowReason
  double slowCapTime[5] = {0, 0, 0, 0, 0};  ///< s of Cap, by SpeedLimit
  std::vector<SlowSpot> slowest;  ///< the slowest feed segments, slowest first
  Vec3 maxVelocity = Vec3::Zero();      ///< |v| per axis
  Vec3 maxAcceleration = Vec3::Zero();  ///< |a| per axis
  Vec3 maxJerk = Vec3::Zero();          ///< |j| per axis
  double maxDeviation = 0;  ///< mm; 0 without a programmed path
  Vec3 endPosition = Vec3::Zero();
  /// Per machine axis, the lowest and highest position the samples reach
  /// (mm or deg): machine coordinates with a work offset, else the
  /// program's. Empty when the travel was not checked.
  std::vector<double> axisMin, axisMax;
  std::string travelNotChecked;  ///< why the travel was not checked (empty when it was)
  /// Segments that tilt the tool (5-axis): the samples on them, and per
  /// machine axis the largest |v|, |a|, |j| of the joints there (mm or deg,
  /// per s, s^2, s^3; by differences between samples).
  size_t tiltedSamples = 0;
  /// Whether the axes x, y, z are the tip's coordinates (the tip's peaks are
  /// theirs); false on a parallel-kinematic machine, whose every sample is
  /// checked on its joints (tiltedSamples counts them all).
  bool axesAreTip = true;
  std::vector<double> jointMaxVelocity, jointMaxAcceleration, jointMaxJerk;
  std::optional<Vec3> workOffsetMm;  ///< as given: positions checked, else extents only
  bool spindleChecked = false;
  double spindleMinRpm = 0, spindleMaxRpm = 0;  ///< over moves with the spindle turning (when checked)
  // The settings the figures were taken with, for the report's wording.
  double period = 0;         ///< s between samples
  double slowFraction = 0;   ///< of the programmed feed, below which speed counts as slow
  bool deviationChecked = false;  ///< a programmed path was given
  double tolerance = 0;      ///< mm, the deviation allowed (when checked)
  size_t violationCount = 0;
  std::vector<Violation> violations;  ///< the first maxViolations
};

/// Samples `trajectory` from t = 0 to its end (the last sample is the end
/// state) and checks it. `onSample`, when given, sees every sample.
SimReport simulate(const Trajectory &trajectory, const Machine &machine, const SimOptions &options = {},
                   const std::function<void(const Sample &)> &onSample = {});

/// The report as a programmer reads it: cycle time, feed statistics, where
/// and why the feed falls, peak axis values against their limits,
/// violations. `nameMove` names a programmed move (e.g. its workingstep).
std::string formatReport(const SimReport &report, const Trajectory &trajectory, const Machine &machine,
                         const std::function<std::string(uint32_t move)> &nameMove = {});

} // namespace stepnc::runtime
