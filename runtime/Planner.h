// The motion planner: programmed moves (lines, arcs, helices; rapids and
// feeds) become a trajectory the machine can follow within every axis limit.
//
//  1. Geometry. Each move becomes a segment. Where two segments meet with a
//     change of direction or of curvature, both are cut back and joined by a
//     quintic blend that matches position, tangent and curvature at each end
//     and stays within the path tolerance; where the path turns back on
//     itself the tool stops instead. Chains of short lines keep the curve's
//     curvature at each line's middle.
//  2. Speed caps. Each segment gets the highest speed, and the path
//     acceleration and jerk, that keep every axis within its limits given
//     the segment's direction, curvature and change of curvature, and never
//     above the programmed feed.
//  3. Runs. Consecutive segments too short to reach their caps on their
//     own, with similar caps, share one profile (the least of their limits),
//     cut at their ends; elsewhere a segment is a run of its own.
//  4. Look-ahead. A backward then a forward pass over the whole path bound
//     the speed where runs meet by what the neighbouring runs can reach
//     with jerk-limited speed changes (closed forms, Profile.h).
//  5. Profiles. Each run gets its fastest seven-phase profile between those
//     speeds, with zero acceleration at both ends.
//
// A path that tilts the tool (5-axis, PlanOptions::kinematics) is planned on
// the tool tip's path, as a controller with tool-centre-point control runs
// it, with step 2's caps taken from every joint: the joints at points along
// each segment (inverse kinematics), their derivatives with respect to the
// tip's path by finite differences; the joint whose limit is lowest is
// recorded (SegmentInfo::axis).
//
// A dwell stops the tool: the move before it ends at rest, the move after
// it starts from rest, and between them a dwell segment (SegmentKind::Dwell,
// stop reason Dwell, as the segment after it) holds the tool at the point
// for the dwell's time.
#pragma once

#include "runtime/Kinematics.h"
#include "runtime/Machine.h"
#include "runtime/Trajectory.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace stepnc::runtime {

/// A programmed move. A dwell waits at `to`, which is where the move before
/// it ends (the start for the first move), for `dwellS` seconds.
struct PathMove {
  enum class Kind : uint8_t { Line, Arc, Dwell } kind = Kind::Line;
  Vec3 to = Vec3::Zero();
  Vec3 center = Vec3::Zero();  ///< arcs: the axis parallel to z through it
  bool ccw = true;
  int64_t turns = 0;           ///< arcs: whole turns before the last arc to `to`
  double feed = 0;             ///< mm/min; 0 = rapid (the axes' speed)
  bool stopBefore = false;     ///< the tool is at rest before this move
  double dwellS = 0;           ///< dwells: s the tool waits
  /// The tool axis at the move's end (5-axis; the tip's path is `to`'s):
  /// it turns evenly from the one before along the move.
  Vec3 axis = Vec3::UnitZ();
};

struct PathInput {
  Vec3 start = Vec3::Zero();  ///< where the tool is, at rest
  Vec3 startAxis = Vec3::UnitZ();
  std::vector<PathMove> moves;
};

struct PlanOptions {
  /// mm; blends stay this close to the programmed path (default: the
  /// machine's path tolerance).
  double tolerance = 0;
  /// A 5-axis machine's kinematics and where the workpiece's origin is on
  /// it (machine coordinates with every axis at 0): the segments that tilt
  /// the tool are capped by every joint's limits, the joints found by the
  /// inverse kinematics along them. Without it the path is the axes'.
  const Kinematics *kinematics = nullptr;
  Vec3 workOffset = Vec3::Zero();
  /// deg; how far the orientation smoothing may take the tool axis from each
  /// move's even turn on its great circle (docs/five-axis.md, "Motion"): a
  /// junction whose two sides turn at rates too far apart to share one
  /// within it is not smoothed. 0: no smoothing; nullopt: the machine's
  /// orientation tolerance.
  std::optional<double> axisToleranceDeg;
};

/// Plans the moves on the machine. Moves of zero length and dwells of no
/// time are skipped; the trajectory ends at rest at the last move's end.
Trajectory plan(const PathInput &input, const Machine &machine, const PlanOptions &options = {});

} // namespace stepnc::runtime
