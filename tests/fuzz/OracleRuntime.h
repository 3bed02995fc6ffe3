// The check the motion fuzz targets share (Oracle.h has the rest): a
// trajectory plays to a finite report.
#pragma once

#include "runtime/Machine.h"
#include "runtime/Player.h"
#include "runtime/Trajectory.h"
#include "tests/fuzz/Oracle.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace stepnc::fuzz {

/// At most this many samples per play: a trajectory of days would otherwise
/// take the fuzzer's whole timeout.
inline constexpr double kMaxPlaySamples = 200'000;

/// Plays `trajectory` on `machine` as `stepnc sim` does, at a period long
/// enough for at most kMaxPlaySamples samples; its duration and the report
/// must be finite (tag `tag`).
inline void checkPlays(const runtime::Trajectory &trajectory, const runtime::Machine &machine, std::string_view tag,
                       std::string_view input) {
  auto finite = [](const runtime::Vec3 &v) {
    return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
  };
  const double duration = trajectory.duration();
  if (!std::isfinite(duration) || duration < 0) {
    violation(tag, "a trajectory has no finite duration", std::to_string(duration) + " s\n--- input ---\n" + clip(input));
    return;
  }
  runtime::SimOptions options;
  options.period = std::max(machine.cycleTime, duration / kMaxPlaySamples);
  const runtime::SimReport report = runtime::simulate(trajectory, machine, options);
  if (!std::isfinite(report.duration) || !finite(report.endPosition) || !finite(report.maxVelocity) ||
      !finite(report.maxAcceleration) || !finite(report.maxJerk))
    violation(tag, "the player's report is not finite", "--- input ---\n" + clip(input));
}

} // namespace stepnc::fuzz
