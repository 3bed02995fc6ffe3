// A planned motion: segments with their speed profiles, played one after the
// other from `start`. This is what the planner produces, the native format
// writes and the player samples. A dwell is a segment too (SegmentKind::Dwell,
// its wait its profile's duration), so every sum of durations counts it.
#pragma once

#include "runtime/Profile.h"
#include "runtime/Segment.h"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::runtime {

/// What capped a segment's speed below the programmed feed (or, for rapids,
/// what set the rapid speed).
enum class SpeedLimit : uint8_t {
  Feed,          ///< the programmed feed
  MachineFeed,   ///< the controller's max_feed
  AxisVelocity,  ///< an axis's velocity limit along the segment's direction
  Acceleration,  ///< an axis's acceleration limit on the segment's curvature
  Jerk,          ///< an axis's jerk limit on the segment's curvature or its change
};
inline constexpr SpeedLimit kSpeedLimits[] = {SpeedLimit::Feed, SpeedLimit::MachineFeed, SpeedLimit::AxisVelocity,
                                              SpeedLimit::Acceleration, SpeedLimit::Jerk};
std::string_view speedLimitName(SpeedLimit limit);  ///< the word in files: "axis_velocity"
std::optional<SpeedLimit> speedLimitNamed(std::string_view name);
/// For people: "an axis's velocity limit".
std::string_view speedLimitDescription(SpeedLimit limit);

/// Why a segment starts with zero speed.
enum class StopReason : uint8_t {
  None,
  Start,     ///< the first segment
  Reversal,  ///< the path turns back on itself (no blend can stay in tolerance)
  Tiny,      ///< the pieces are too short to blend within tolerance
  Program,   ///< a tool change, a change of setup or spindle, a stop in the program
  Dwell,     ///< a dwell segment (the tool waits there), or the segment after one
};
inline constexpr StopReason kStopReasons[] = {StopReason::None, StopReason::Start,   StopReason::Reversal,
                                              StopReason::Tiny, StopReason::Program, StopReason::Dwell};
std::string_view stopReasonName(StopReason reason);
std::optional<StopReason> stopReasonNamed(std::string_view name);

struct SegmentInfo {
  PathLimits limits;                    ///< v, a, j along the path used to plan it
  SpeedLimit limitedBy = SpeedLimit::Feed;
  double feed = 0;                      ///< mm/s programmed; 0 for rapids
  uint32_t move = 0;                    ///< index of the programmed move it follows
  uint32_t nextMove = 0;                ///< blends: the move it joins to (else = move)
  StopReason stop = StopReason::None;   ///< why the segment starts at rest
  /// Which of the machine's axes (Machine::axes index) set the cap when
  /// limitedBy is an axis's velocity, acceleration or jerk; -1 otherwise.
  int8_t axis = -1;
  /// Lathes (Frame::Zxy): the spindle's speed at the segment's start and at
  /// its end, rev/min (negative: turning the other way, M4), changing
  /// linearly with time in between.
  double spindle0 = 0, spindle1 = 0;
  /// Lathes: a thread pass, which starts when the spindle passes its index
  /// and moves with its turning (the spindle keeps its speed throughout).
  bool sync = false;
};

/// What the three coordinates of a trajectory's points are. A mill's are its
/// x, y, z. A lathe's are z, x, y (x the radius, y always 0): the ZX plane's
/// own coordinates (geom/ArcPlane.h), so that the lathe's arcs, which turn in
/// that plane, are arcs about the third coordinate as every reader of
/// segments takes them, counter-clockwise as G3 in G18 (seen from +y).
enum class Frame : uint8_t { Xyz, Zxy };

struct Trajectory {
  std::string machine;    ///< the machine's name
  double tolerance = 0;   ///< mm, the path tolerance blends kept
  double cycleTime = 0.001;  ///< s, the machine's interpolation period
  /// Zxy for a lathe, whose segments also carry the spindle (SegmentInfo).
  Frame frame = Frame::Xyz;
  /// The names of the axes SegmentInfo::axis counts ("x", ..., "c").
  std::vector<std::string> axisNames;
  /// Planned on a 5-axis machine's joints: where every joint is at each
  /// segment's end (Machine::axes order, mm and deg; axisNames.size() values
  /// per segment, machine coordinates with the workpiece's origin at the
  /// plan's work offset). Empty otherwise.
  std::vector<double> joints;
  Vec3 start = Vec3::Zero();
  std::vector<Segment> segments;
  std::vector<Profile> profiles;  ///< one per segment
  std::vector<SegmentInfo> info;  ///< one per segment

  double duration() const;
};

} // namespace stepnc::runtime
