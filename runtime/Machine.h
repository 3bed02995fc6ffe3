// The machine a program runs on: its axes with travel and dynamic limits, how
// they are chained (the kinematics), the spindle, and the controller's cycle
// time, look-ahead and path tolerance. Read from a human-edited TOML file
// (docs/machine-model.md); every value is checked, with the file, line and
// column of what is wrong.
//
// Kinematics: "xyz" (three linear axes in series, the default), the 5-axis
// chains "table-table", "head-table" and "head-head" (x, y, z and two rotary
// axes), "lathe" (x radial, z axial, c optional) and "generic" (any axes,
// moved by an external solver registered with runtime/Kinematics.h). The
// transforms themselves are in runtime/Kinematics.h; this file only
// describes and checks. Axes are kept by name in a list, linear x, y, z first
// where the chain has them, so that readers of linear axes (the planner, the
// player) need not know about rotary ones.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace stepnc::runtime {

/// How the axes are chained between the machine's base, the tool and the
/// workpiece.
enum class Chain : uint8_t {
  Xyz,         ///< three linear axes in series
  TableTable,  ///< x, y, z move the tool; two rotary axes turn the workpiece
  HeadTable,   ///< one rotary axis turns the tool, one turns the workpiece
  HeadHead,    ///< two rotary axes turn the tool
  Lathe,       ///< x radial, z along the spindle, c (optional) the spindle as an axis
  Generic,     ///< any axes; an external solver (runtime/Kinematics.h) moves them
};
inline constexpr Chain kChains[] = {Chain::Xyz,      Chain::TableTable, Chain::HeadTable,
                                    Chain::HeadHead, Chain::Lathe,      Chain::Generic};
/// The word in machine files: "table-table".
std::string_view chainName(Chain chain);
std::optional<Chain> chainNamed(std::string_view name);

struct Axis {
  std::string name;       ///< "x", "y", "z", "a", "b", "c" (generic chains: any)
  double travelMin = 0;   ///< mm (rotary: deg), machine coordinates
  double travelMax = 0;   ///< mm (rotary: deg)
  double velocity = 0;    ///< mm/min (rotary: deg/min), the axis's rapid and feed limit
  double acceleration = 0;  ///< mm/s^2 (rotary: deg/s^2)
  double jerk = 0;        ///< mm/s^3 (rotary: deg/s^3)
  /// The units above are deg, deg/min, deg/s^2, deg/s^3 instead of mm.
  /// (After the limits, so that {name, min, max, v, a, j} still builds a
  /// linear axis.)
  bool rotary = false;
  /// Rotary axes: the direction it turns about (a: +x, b: +y, c: +z;
  /// positive angles turn right-handed about it).
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  /// Rotary axes: a point on the axis's line with every axis at 0, in mm.
  /// A table axis's is in machine coordinates (where the tool tip is when
  /// x, y, z are 0); a head axis's is measured from the tool tip, which it
  /// carries.
  Eigen::Vector3d pivotMm = Eigen::Vector3d::Zero();
};

/// The kinematic chain as the file describes it.
struct KinematicsSpec {
  Chain chain = Chain::Xyz;
  /// 5-axis: the rotary axes that turn the tool, from the machine's base
  /// outwards (the last one carries the spindle).
  std::vector<std::string> head;
  /// 5-axis: the rotary axes that turn the workpiece, from the machine's base
  /// outwards (the last one carries the workpiece).
  std::vector<std::string> table;
  /// The tool's direction (unit, from its tip towards the spindle) with every
  /// axis at 0, in machine coordinates: +z for mills, +x for a lathe.
  Eigen::Vector3d toolAxis = Eigen::Vector3d::UnitZ();
  /// Whether the chain is one of the 5-axis chains (table-table, head-table,
  /// head-head): two rotary axes that turn the tool to the workpiece.
  bool fiveAxis() const { return chain == Chain::TableTable || chain == Chain::HeadTable || chain == Chain::HeadHead; }
  /// Lathe: programs give X as a diameter (G7, DIAMON); the x axis itself
  /// always moves in radius.
  bool diameterProgramming = false;
  /// Generic: the registered solver's name (runtime/Kinematics.h).
  std::string solver;
  /// Generic: numbers handed to the solver as they are, in file order.
  std::vector<std::pair<std::string, double>> parameters;
};

/// A deposition head's codes (a machine file's [deposition] table,
/// docs/additive.md): the blocks that switch the energy and the material on
/// and off and set them, in the syntax of the target named, where `{power}`
/// (W), `{powder}` (g/min) and `{wire}` (mm/min) stand for the value; the
/// most the head's source and feeders give.
struct DepositionCodes {
  std::string target;  ///< the target the codes are written for ("rs274", "siemens-840d")
  std::string energyOn, energyOff, power, powder, wire;
  double maxPower = 0;  ///< W
  std::optional<double> maxPowder;  ///< g/min
  std::optional<double> maxWire;    ///< mm/min
};

/// The most axes a machine's kinematics moves (a hexapod has 6, a hybrid
/// machine a few more): joint vectors (runtime::Joints) live on the stack.
inline constexpr int kMaxJoints = 8;

struct Machine {
  std::string name;
  KinematicsSpec kinematics;
  /// In the kinematics' order: xyz x, y, z; 5-axis x, y, z, then the head's
  /// rotary axes and the table's, each from the base outwards; lathe x, z
  /// and c when there is one; generic as the file lists them.
  std::vector<Axis> axes;
  double spindleMin = 0;   ///< rev/min
  double spindleMax = 0;   ///< rev/min
  double spindlePower = 0;  ///< kW at the spindle
  std::optional<double> spindleTorque;  ///< N m, when the file gives it
  /// rev/min per second, how fast the spindle changes speed, when the file
  /// gives it (a lathe's constant surface speed follows it).
  std::optional<double> spindleAcceleration;
  double cycleTime = 0.001;    ///< s, the interpolator's period
  int lookahead = 100;         ///< segments the planner may look ahead
  double pathTolerance = 0.01;  ///< mm, how far blending may leave the programmed path
  /// deg, how far the planner's orientation smoothing may turn the tool axis
  /// away from each move's even turn (docs/five-axis.md, "Motion")
  double orientationTolerance = 0.01;
  std::optional<double> maxFeed;  ///< mm/min along the path, when lower than the axes allow
  /// The processes it does: "milling" (and drilling), "turning",
  /// "deposition" (the file's `processes`, else from its kinematics and its
  /// deposition head).
  std::vector<std::string> processes;
  /// A machine with a deposition head: its codes.
  std::optional<DepositionCodes> deposition;

  const Axis *axis(std::string_view axisName) const;
  /// Index of the named axis in `axes`, or -1.
  int axisIndex(std::string_view axisName) const;

  /// Why the planner and the player (which move x, y, z only, axes 0-2)
  /// cannot run a 3-axis program on this machine; empty when they can. They
  /// can on xyz, and on a 5-axis chain whose rotary axes may stay at 0 with
  /// the tool along +z: its x, y, z are then the program's (runtime/Kinematics.h).
  std::string whyNotThreeAxis() const;
};

/// A lathe as the planner and the player take it: three linear axes in the
/// order of a lathe trajectory's coordinates (Frame::Zxy, Trajectory.h): its
/// z, its x (radius), and a y that never moves (given x's limits). The rest
/// (name, spindle, controller) is the lathe's.
Machine latheFrameMachine(const Machine &lathe);

/// Reads and checks a machine description. Reports every problem found
/// (unknown keys, missing or out-of-range values, a chain naming an axis it
/// does not have, TOML syntax) at its place in the file; returns nullopt when
/// there was one.
std::optional<Machine> readMachine(const SourceFile &file, DiagnosticEngine &diags);

/// The machines shipped in machines/ (built into stepnc), by file stem:
/// "conventional-3axis", "hsc-3axis", "lathe-2axis", "table-table-5axis".
std::vector<std::string> shippedMachineNames();

/// A machine named on a command line: a file, else a shipped machine's
/// name. `file` keeps the text diagnostics point into.
std::optional<Machine> loadMachine(const std::string &spec, std::unique_ptr<SourceFile> &file,
                                   DiagnosticEngine &diags);

} // namespace stepnc::runtime
