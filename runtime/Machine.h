// The machine a program runs on: its axes with travel and dynamic limits, the
// spindle, and the controller's cycle time, look-ahead and path tolerance.
// Read from a human-edited TOML file (docs/machine-model.md); every value is
// checked, with the file, line and column of what is wrong.
//
// Kinematics: "xyz", three linear axes in series, is the only structure so
// far. Axes are kept by name in a list so that rotary axes (and the
// kinematic transforms they need) can be added without changing the readers
// of linear ones.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::runtime {

struct Axis {
  std::string name;       ///< "x", "y", "z"
  double travelMin = 0;   ///< mm, machine coordinates
  double travelMax = 0;   ///< mm
  double velocity = 0;    ///< mm/min, the axis's rapid and feed limit
  double acceleration = 0;  ///< mm/s^2
  double jerk = 0;        ///< mm/s^3
};

struct Machine {
  std::string name;
  std::string kinematics = "xyz";
  std::vector<Axis> axes;  ///< in the kinematics' order
  double spindleMin = 0;   ///< rev/min
  double spindleMax = 0;   ///< rev/min
  double spindlePower = 0;  ///< kW at the spindle
  std::optional<double> spindleTorque;  ///< N m, when the file gives it
  double cycleTime = 0.001;    ///< s, the interpolator's period
  int lookahead = 100;         ///< segments the planner may look ahead
  double pathTolerance = 0.01;  ///< mm, how far blending may leave the programmed path
  std::optional<double> maxFeed;  ///< mm/min along the path, when lower than the axes allow

  const Axis *axis(std::string_view axisName) const;
};

/// Reads and checks a machine description. Reports every problem found
/// (unknown keys, missing or out-of-range values, TOML syntax) at its place
/// in the file; returns nullopt when there was one.
std::optional<Machine> readMachine(const SourceFile &file, DiagnosticEngine &diags);

/// The machines shipped in machines/ (built into stepnc), by file stem:
/// "hsc-3axis", "conventional-3axis".
std::vector<std::string> shippedMachineNames();

/// A machine named on a command line: a file, else a shipped machine's
/// name. `file` keeps the text diagnostics point into.
std::optional<Machine> loadMachine(const std::string &spec, std::unique_ptr<SourceFile> &file,
                                   DiagnosticEngine &diags);

} // namespace stepnc::runtime
