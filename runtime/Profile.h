// Jerk-limited speed profiles along one segment. A profile starts at speed v0
// with zero acceleration and is a list of phases of constant jerk; the
// planner's profiles have seven (jerk +J, 0, -J to accelerate, a cruise, then
// -J, 0, +J to slow down), some of them empty, and end with zero
// acceleration. Zero acceleration at both ends is what lets the next segment
// start its own profile without a jump in acceleration. A profile planned
// over a run of short segments is cut into slices, one per segment, that
// start and end with the acceleration the whole has there.
//
// The closed forms (REFERENCES: jerk-limited speed change with zero end
// accelerations): a change dv takes T = dv/A + A/J when dv >= A^2/J, else
// 2 sqrt(dv/J), over the distance (v0 + v1)/2 T.
#pragma once

#include <array>
#include <cstdint>

namespace stepnc::runtime {

struct Phase {
  double duration = 0;  ///< s
  double jerk = 0;      ///< mm/s^3, along the path
};

/// Path state at a time within a profile.
struct PathState {
  double s = 0;  ///< mm from the segment start
  double v = 0;  ///< mm/s
  double a = 0;  ///< mm/s^2
  double j = 0;  ///< mm/s^3
};

struct Profile {
  double v0 = 0;  ///< mm/s at the start
  /// mm/s^2 at the start: zero, except for a slice of a profile planned
  /// over a run of short segments (Planner.h), which starts where the
  /// previous slice ended.
  double a0 = 0;
  std::array<Phase, 7> phases{};

  double duration() const;
  /// The state at time t from the start (clamped to [0, duration]).
  PathState at(double t) const;
  /// The speed at the end.
  double v1() const;
  /// The acceleration at the end.
  double a1() const;
  /// The time at which the profile has covered distance s (clamped to the
  /// profile; the first such time where it dwells at zero speed).
  double timeAt(double s) const;
  /// The part of this profile from time t0 to t1: it starts with the speed
  /// and acceleration the whole has at t0.
  Profile slice(double t0, double t1) const;
  /// The highest speed reached.
  double peak() const;
};

/// Limits for the speed along one segment.
struct PathLimits {
  double v = 0;  ///< mm/s, the highest speed allowed
  double a = 0;  ///< mm/s^2, along the path
  double j = 0;  ///< mm/s^3, along the path
};

/// Time of a speed change of dv >= 0 with zero acceleration at both ends.
double rampTime(double dv, double a, double j);
/// Distance covered by the speed change from v0 to v1 (either way).
double rampDistance(double v0, double v1, double a, double j);
/// The highest speed reachable from v0 within distance `length` (or, read
/// backwards, the highest speed from which v0 can be reached).
double reachableSpeed(double v0, double length, double a, double j);
/// The fastest profile over `length` from v0 to v1 under `limits`. v0 and v1
/// must be reachable from each other within `length` (the look-ahead
/// passes ensure it); the profile rises to the highest peak speed that fits,
/// cruises, and falls, and covers exactly `length`.
Profile planProfile(double v0, double v1, double length, const PathLimits &limits);
/// A dwell's profile: at rest for `timeS` seconds, one cruise phase (slot 3,
/// as in the seven-phase profiles) at zero speed; the other phases empty.
Profile dwellProfile(double timeS);

} // namespace stepnc::runtime
