// Kinematic transforms: from a machine's joint values (its axes' positions,
// mm for linear axes and deg for rotary ones, in Machine::axes order) to the
// tool's pose in the workpiece's frame (forward), and back (inverse). Built
// from a Machine's KinematicsSpec: xyz, the 5-axis chains table-table,
// head-table and head-head (any two of a, b, c), and the lathe. A generic
// chain (a parallel-kinematic machine, a hexapod) is moved by a solver
// registered by name: the runtime's own (the linear tripod with a tilting
// table, runtime/TripodKinematics.h) or one the program linking this library
// registers.
//
// Conventions (docs/machine-model.md): with every axis at 0 the workpiece's
// frame is the machine's, and the tool's tip is at (x, y, z); so on a 5-axis
// chain with its rotary axes at 0 a 3-axis program's positions are the
// joints'. Positive angles turn right-handed about the axis's direction (a
// table turns the workpiece, a head the tool); a machine that counts the
// other way writes its rotary axis's direction in the solver's terms or
// negates its programs' angles.
#pragma once

#include "runtime/Machine.h"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::runtime {

/// Joint values in Machine::axes order: mm for linear axes, deg for rotary;
/// on the stack (at most kMaxJoints), so that the planner's inverse
/// kinematics at every sample allocate nothing.
using Joints = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJoints, 1>;

/// Where the tool is, in the workpiece's frame.
struct ToolPose {
  Eigen::Vector3d tipMm = Eigen::Vector3d::Zero();  ///< the tool tip (the controlled point)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< unit, from the tip towards the spindle
};

/// What an inverse transform found.
struct InverseResult {
  std::optional<Joints> joints;  ///< nullopt when the pose cannot be reached
  /// The pose is at a singularity (the tool along a rotary axis, a lathe's
  /// tip on the spindle axis): one rotary axis was free, and kept the value
  /// it has in `near` (or 0 without one).
  bool singular = false;
  /// Every solution found leaves some axis's travel; `joints` is the nearest
  /// to `near` anyway.
  bool outsideTravel = false;
  std::string why;  ///< for nullopt: why the pose cannot be reached
};

/// How a serial chain's joints move with the tool near joints q, to first
/// order (Kinematics::rates): with the tip moving at dp (mm per unit, in the
/// workpiece's frame) and the tool's direction at dk (per unit,
/// perpendicular to it), the joints move at map * (dp, dk): mm and deg per
/// unit.
struct JointRates {
  Eigen::Matrix3d tipTurn = Eigen::Matrix3d::Identity();  ///< Kinematics::tipTurn at q
  Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxJoints, 6> map;
  Joints of(const Eigen::Vector3d &dp, const Eigen::Vector3d &dk) const {
    return map.leftCols<3>() * dp + map.rightCols<3>() * dk;
  }
};

/// A machine's kinematic transform. Implementations are immutable after
/// construction and safe to call from several threads.
class Kinematics {
public:
  virtual ~Kinematics() = default;
  /// The chain's name ("table-table"; a generic solver's own name).
  virtual std::string_view name() const = 0;
  /// Number of joints (= Machine::axes.size()).
  virtual size_t jointCount() const = 0;
  /// The tool's pose at `joints`.
  virtual ToolPose forward(const Joints &joints) const = 0;
  /// Joint values that put the tool at `pose`. Where there are several
  /// (two branches of a 5-axis chain, rotary angles 360 deg apart), the
  /// solution inside every axis's travel nearest to `near` (the previous
  /// joints; 0 when null) is taken; at a singularity the free rotary axis
  /// keeps its value from `near`.
  virtual InverseResult inverse(const ToolPose &pose, const Joints *near = nullptr) const = 0;
  /// Where the joints x, y, z are the tip turned and moved by the rotary
  /// axes (the serial chains: a table turning the workpiece, a head
  /// offsetting the tip by its angles alone): the rotation M with which, at
  /// joints q and the tool's direction held, a move dp of the tip in the
  /// workpiece's frame moves x, y, z by M dp. The planner bounds the joints'
  /// curvature from the path's own through it. nullopt (the default) where
  /// they are not (parallel kinematics).
  virtual std::optional<Eigen::Matrix3d> tipTurn(const Joints &q) const {
    (void)q;
    return std::nullopt;
  }
  /// The joints' rates at q (JointRates) where the chain has them in closed
  /// form and q is not within `minSine` of a singularity (the sine of the
  /// angle between the tool and the direction along which a rotary axis is
  /// free, where the rates grow without bound). nullopt (the default) where
  /// not: the planner then samples the joints.
  virtual std::optional<JointRates> rates(const Joints &q, double minSine) const {
    (void)q;
    (void)minSine;
    return std::nullopt;
  }
  /// inverse() and, where it has them, rates() at the solution (nullopt at a
  /// singular pose): one call, which the serial chains make cheaper than two
  /// (the rotations are the inverse's).
  virtual InverseResult inverseWithRates(const ToolPose &pose, const Joints *near, double minSine,
                                         std::optional<JointRates> &rates) const {
    InverseResult r = inverse(pose, near);
    rates = r.joints && !r.singular ? this->rates(*r.joints, minSine) : std::nullopt;
    return r;
  }
  /// The tool direction, in the workpiece's frame, along which (or against
  /// which) a rotary axis is free, where that is one fixed direction (the
  /// serial 5-axis chains: the outer rotary axis's); nullopt otherwise.
  virtual std::optional<Eigen::Vector3d> singularDirection() const { return std::nullopt; }
  /// Whether the linear joints (the first three) are the tool tip's x, y, z
  /// in machine coordinates while the tool is along +z: true on the serial
  /// chains, where a 3-axis program's positions are the axes'; false on a
  /// parallel-kinematic machine, whose sliders move otherwise than the tip
  /// even on a straight line (the planner and the player then take every
  /// segment's joints through the inverse kinematics).
  virtual bool linearJointsAreCartesian() const { return true; }
};

/// A number a solver reads from `[kinematics.parameters]`: its name, unit,
/// range and meaning, so that a machine file naming the solver is checked
/// where it is read (a missing, unknown or out-of-range parameter reported
/// at its place in the file).
struct SolverParameter {
  std::string name;
  std::string unit;  ///< "mm", "deg"
  double min = 0, max = 0;
  std::string meaning;
};

/// Makes a solver for a generic chain; `error` says why not when it returns
/// null (a parameter missing, the axes not what it moves).
using KinematicsFactory = std::function<std::unique_ptr<Kinematics>(const Machine &machine, std::string &error)>;

/// Registers the solver a generic chain names by `solver = "NAME"` (a
/// parallel-kinematic machine's, say). Registering a name again replaces
/// it. Returns false when the name is empty. `parameters`, when given, are
/// every parameter the solver reads (readMachine checks a file naming it
/// against them); without them the file's parameters are handed over as
/// they are.
bool registerKinematicsSolver(const std::string &name, KinematicsFactory factory,
                              std::optional<std::vector<SolverParameter>> parameters = std::nullopt);

/// The parameters a registered solver declared; nullopt when it is not
/// registered or declared none.
std::optional<std::vector<SolverParameter>> kinematicsSolverParameters(const std::string &name);

/// Whether a solver of that name is registered.
bool kinematicsSolverRegistered(const std::string &name);

/// The names registered so far, sorted.
std::vector<std::string> kinematicsSolverNames();

/// The transform of `machine`'s chain; null with `error` set when its
/// generic solver is not registered or refuses the machine.
std::unique_ptr<Kinematics> makeKinematics(const Machine &machine, std::string &error);

/// Lathes: the X a program writes for a radius, and the radius for a
/// programmed X (a diameter when the machine programs diameters).
double programmedX(const Machine &machine, double radiusMm);
double radiusFromProgrammedX(const Machine &machine, double programmedXMm);

} // namespace stepnc::runtime
