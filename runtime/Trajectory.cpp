#include "runtime/Trajectory.h"

namespace stepnc::runtime {

std::string_view speedLimitName(SpeedLimit limit) {
  switch (limit) {
  case SpeedLimit::Feed: return "feed";
  case SpeedLimit::MachineFeed: return "machine_feed";
  case SpeedLimit::AxisVelocity: return "axis_velocity";
  case SpeedLimit::Acceleration: return "acceleration";
  case SpeedLimit::Jerk: return "jerk";
  }
  return "feed";
}

std::string_view speedLimitDescription(SpeedLimit limit) {
  switch (limit) {
  case SpeedLimit::Feed: return "the programmed feed";
  case SpeedLimit::MachineFeed: return "the machine's max feed";
  case SpeedLimit::AxisVelocity: return "an axis's velocity limit";
  case SpeedLimit::Acceleration: return "axis acceleration on the path's curvature";
  case SpeedLimit::Jerk: return "axis jerk on the path's curvature";
  }
  return "the programmed feed";
}

std::string_view stopReasonName(StopReason reason) {
  switch (reason) {
  case StopReason::None: return "none";
  case StopReason::Start: return "start";
  case StopReason::Reversal: return "reversal";
  case StopReason::Tiny: return "tiny";
  case StopReason::Program: return "program";
  case StopReason::Dwell: return "dwell";
  }
  return "none";
}

std::optional<SpeedLimit> speedLimitNamed(std::string_view name) {
  for (SpeedLimit l : kSpeedLimits)
    if (speedLimitName(l) == name)
      return l;
  return std::nullopt;
}

std::optional<StopReason> stopReasonNamed(std::string_view name) {
  for (StopReason r : kStopReasons)
    if (stopReasonName(r) == name)
      return r;
  return std::nullopt;
}

double Trajectory::duration() const {
  double t = 0;
  for (const Profile &p : profiles)
    t += p.duration();
  return t;
}

} // namespace stepnc::runtime
