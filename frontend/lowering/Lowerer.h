// The lowering context shared by the lowering files (internal to
// frontend/lowering): symbols, resources lowered once, unit conversion and
// the helpers every construct uses.
#pragma once

#include "frontend/binding/Instance.h"
#include "frontend/lowering/Lowering.h"
#include "ir/Node.h"

#include <map>
#include <optional>
#include <set>
#include <string>

namespace stepnc::lowering {

using binding::Instance;
using ir::Node;
using ir::Value;
using ir::Vec3;

/// A rigid placement read from an axis2_placement_3d.
struct Placement {
  Vec3 at = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  Vec3 ref = Vec3::UnitX();
};

/// How a 3-axis machine reaches a feature that faces another way than +z
/// (docs/setups.md): the workpiece is turned so that face is up, a rotation
/// by multiples of 90 deg, and shifted so that the box around its raw piece
/// keeps its lowest corner where it was. Workpiece coordinates p become
/// rotation p + shift.
struct Turn {
  std::string face;  ///< the face that is up: "+x", "-x", "+y", "-y", "-z"
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3 shift = Vec3::Zero();
  Vec3 point(const Vec3 &p) const { return rotation * p + shift; }
  Vec3 direction(const Vec3 &d) const { return rotation * d; }
};

/// A raw piece's extent in its workpiece's coordinates: the box around its
/// BLOCK (exact when the block's axes are the workpiece's), for the values
/// lowering assumes from it.
struct RawExtent {
  Instance block;
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();
  /// The parameters t in [enter, exit] at which the line p + t d (d a unit
  /// vector) is inside the box, in x and y only (a line on the top face
  /// counts as inside); nullopt when it misses the box.
  std::optional<std::pair<double, double>> spanXY(const Vec3 &p, const Vec3 &d) const;
  /// The same in x, y and z.
  std::optional<std::pair<double, double>> span(const Vec3 &p, const Vec3 &d) const;
};

/// What a travel path's absent values may be assumed from: the frame of the
/// feature it belongs to and the raw piece it is cut in.
struct PathContext {
  Placement frame;
  std::optional<RawExtent> raw;
  bool openEnds = false;  ///< both ends open: the path may run across the raw piece
};

/// Copies real attribute `attribute` of `from` into `to` as `irName`, made with
/// `make` (Value::length, Value::angle, Value::ratio, ...), when it is present.
inline void copyReal(Node &to, std::string_view irName, const Instance &from, std::string_view attribute,
                     Value (*make)(double)) {
  if (auto v = from.real(attribute))
    to.set(std::string(irName), make(*v));
}

/// Copies boolean attribute `attribute` of `from` into `to` as `irName`, when present.
inline void copyFlag(Node &to, std::string_view irName, const Instance &from, std::string_view attribute) {
  if (auto b = from.boolean(attribute))
    to.set(std::string(irName), Value::boolean(*b));
}

/// Copies enumeration attribute `attribute` of `from` into `to` as the word
/// `irName`, when present.
inline void copyWord(Node &to, std::string_view irName, const Instance &from, std::string_view attribute) {
  if (auto w = from.enumeration(attribute))
    to.set(std::string(irName), Value::word(*w));
}

class Lowerer {
public:
  Lowerer(const binding::BoundFile &bound, DiagnosticEngine &diags, const LowerOptions &options)
      : bound_(bound), diags_(diags), options_(options) {}

  std::unique_ptr<ir::Module> run();

  // --- shared helpers (Lowerer.cpp) ---------------------------------------
  /// Reports `not supported: <entity> at #id` (once per instance).
  void unsupported(const Instance &inst, std::string_view what = {});
  /// Reports a missing or invalid attribute that lowering needs.
  void missing(const Instance &inst, std::string_view attribute, std::string_view why = {});
  /// Reports what lowering assumed for attribute `attribute` of `inst` (absent
  /// or unusable in the file): `#28 round_hole: 'depth' <what>`, a warning
  /// (an error with --strict). `what` says what the file has, the value
  /// assumed and why: "absent; assumed 20 mm: ...".
  void assumed(const Instance &inst, std::string_view attribute, std::string_view what);
  /// Records the Part 21 text that says what was assumed for attribute
  /// `attribute` of `inst`, for the machine-optimised STEP-NC to write
  /// (ir::SourceFix); nothing for a complex instance.
  void fix(const Instance &inst, std::string_view attribute, std::string text);
  /// The same by parameter index (-1: the entity name; one past the last
  /// parameter: appended) of a simple instance.
  void fixAt(uint64_t entityId, int parameter, std::string text);
  /// What the write-back writes of tool `t` that the file leaves implicit:
  /// the milling subtype of an abstract cutting_tool, a cutting edge and its
  /// offset length from the tool's overall length.
  void writeToolExplicitly(const Instance &t);
  /// A new instance for the machine-optimised STEP-NC to write, `ENTITY(...)`
  /// (ir::Module::sourceInstances); returns the reference to it a fix or a
  /// later new instance uses ("#@3"). The same text is one instance.
  std::string newInstance(std::string text);
  /// The general tolerance as a new plus_minus_value (newInstance): what a
  /// toleranced length without a tolerance is read as (binding's tally).
  std::string generalTolerance();
  /// A new depth plane `depth` mm below a feature's origin (newInstance).
  std::string depthPlane(double depth);
  /// A new toleranced length of `value` mm with the general tolerance.
  std::string tolerancedLength(double value);
  /// A new axis2_placement_3d at `at` with the directions of `original`
  /// (as lowering reads them: swapped back where the file swaps them).
  std::string placementAt(const Instance &original, const Vec3 &at);
  /// A new axis2_placement_3d at `at` with new directions (`$` for none).
  std::string newPlacement(const Vec3 &at, const std::optional<Vec3> &axis, const std::optional<Vec3> &ref);
  /// A new cartesian_point at `at` (newInstance).
  std::string newPoint(const Vec3 &at);
  /// `value` as a Part 21 real; `v` as a Part 21 list of three.
  static std::string real(double value);
  static std::string triple(const Vec3 &v);
  /// `text` as a Part 21 string.
  static std::string quoted(std::string_view text);
  /// A fresh symbol with `sigil`, from a STEP-NC id string or a fallback.
  std::string symbolFor(char sigil, const std::optional<std::string> &label, std::string_view fallback);
  /// Sets origin and label from an instance.
  void stamp(Node &node, const Instance &inst, std::string_view labelAttribute = "its_id");

  // Unit conversion.
  /// A plane_angle_measure as an IR angle (deg), in the file's angle unit.
  Value angle(double planeAngle) const { return Value::angle(planeAngle * angleToDeg_); }
  /// Copies angle attribute `attribute` of `from` into `to` as `irName`, when present.
  void copyAngle(Node &to, std::string_view irName, const Instance &from, std::string_view attribute) const {
    if (auto v = from.real(attribute))
      to.set(std::string(irName), angle(*v));
  }
  double feedMmPerMin(double speedMeasure) const { return speedMeasure * feedToMmPerMin_; }
  double cuttingSpeedMmPerMin(double speedMeasure) const { return speedMeasure * cutspeedToMmPerMin_; }
  double spindleRevPerMin(double rotSpeed) const { return rotSpeed * spindleToRevPerMin_; }

  // --- geometry (LowerGeometry.cpp) ----------------------------------------
  std::optional<Vec3> point(const Instance &cartesianPoint);
  std::optional<Vec3> direction(const Instance &dir);
  /// axis2_placement_3d, with the standard's defaults and orthonormalised axes.
  std::optional<Placement> placement(const Instance &axis2);
  void setPlacement(Node &node, const Placement &p);
  /// The offset along z of the plane (elementary_surface) that attribute
  /// `attribute` of `owner` refers to: its location's z. Reports an absent or
  /// unusable plane itself (callers do not report again). A feature's plane
  /// may give its normal as `featureAxis`, the feature's axis in workpiece
  /// coordinates (reported).
  std::optional<double> planeHeight(const Instance &owner, std::string_view attribute, std::string_view role,
                                    const std::optional<Vec3> &featureAxis = std::nullopt);
  /// A toleranced_length_measure (or a plain length) as mm.
  std::optional<double> toleranced(const Instance &owner, std::string_view attribute);
  /// A profile (closed or open) as a profile node; null node kind on failure.
  std::optional<Node> profile(const Instance &profile);
  /// A travel path (linear_path, circular_path, general path) as a path node.
  /// With a context, a linear path's absent direction and distance are
  /// assumed from it (reported); without, they are errors.
  std::optional<Node> path(const Instance &travel, const PathContext *context = nullptr);
  /// Any bounded curve (polyline, trimmed curve, composite curve, circle,
  /// line, helix, B-spline) as a curve node.
  std::optional<Node> curve(const Instance &curve);

  // --- features (LowerFeatures.cpp) ------------------------------------------
  /// The workpiece a feature is cut in: its_workpiece, or when that is absent
  /// the project's only workpiece (reported as assumed). Null when neither.
  Instance featureWorkpiece(const Instance &feature);
  /// A slot whose depth plane gives no depth takes the depth of its swept
  /// shape where the shape has one (a partial circular profile), reported.
  void slotDepthFromProfile(Node &slot, const Instance &feature);
  /// The raw piece of a workpiece as an extent; nullopt when it has no block.
  std::optional<RawExtent> rawExtent(const Instance &workpiece);
  /// A polyline `curve` of closed profile shape `shape` whose last point is
  /// not its first: closed with its first point again, with a warning.
  void closePolyline(const Instance &shape, Node &curve);
  /// Whether the file writes every placement with axis and ref_direction
  /// swapped (then `placement` reads them swapped), with a warning.
  void choosePlacementReading(const std::vector<Instance> &placements);
  /// ISO 14649 places a profile in its feature's frame; some generators write
  /// the profile's placement in workpiece coordinates (the feature's own
  /// placement again, say), which composed with the feature's puts it
  /// elsewhere. When the composed origin lies outside the raw piece of
  /// `workpiece` and the placement read in workpiece coordinates inside, the
  /// latter is taken: `profile` is placed relative to `frame`, with a warning.
  void placeProfileOnce(const Instance &profileInstance, Node &profile, const Placement &frame,
                        const Instance &workpiece);

  /// The feature's symbol, lowering it under its workpiece the first time.
  std::optional<std::string> feature(const Instance &feature);

  // --- features on other faces (LowerClampings.cpp) -------------------------
  /// The turn that brings a feature whose axis is `axis` (workpiece
  /// coordinates, not +z) up on a 3-axis machine: nullopt when the axis is
  /// along no face of a box (that needs an indexed 5-axis machine).
  static std::optional<Turn> turnFor(const Vec3 &axis, const std::optional<RawExtent> &raw);
  /// Workingstep `ws` (lowered into `step`) machines a feature facing
  /// another way than +z: the step gets the feature, its workpiece and a
  /// setup turned that face up, its security plane read in that setup, its
  /// explicit toolpaths turned with it. False after an error.
  bool placeOnFace(const Instance &ws, Node &step);
  /// The stop, with a message to the operator, before `step` when it is
  /// machined in another clamping than the step before it.
  void reclampBefore(const Node &step, Node &parent);

  // --- operations (LowerOperations.cpp) --------------------------------------
  std::optional<Node> operation(const Instance &op);
  std::optional<std::string> tool(const Instance &tool);
  /// A tool the file gives no body for (no type, no dimension), assumed
  /// from its use (use_): a hole's diameter for the hole-making tool, a
  /// slot's width less the side allowances for the end mill that mills it.
  /// False (nothing assumed) when the use does not say.
  bool toolFromUse(const Instance &tool, Node &n);
  /// The dimensions of an ISO 14649-121 turning tool body.
  void turningToolBody(const Instance &body, Node &n);
  /// Adds the toolpaths of a toolpath_list as children of `parent`.
  void toolpaths(const Instance &list, Node &parent);
  /// An operation's its_tool_direction into `n` (tool_direction and its
  /// direction or angles).
  void toolDirection(const Instance &d, Node &n);
  /// Sets `axis` on each point of a toolpath's polyline `basic` from its
  /// tool axis curve `axes` (ISO 14649-11 its_toolaxis, a polyline of
  /// directions beside it); reports what does not fit, naming the tool
  /// axis curve as `attribute` (the ARM's its_toolaxis; AP238's property).
  void toolAxes(const Instance &tp, const Instance &axes, Node &basic, std::string_view attribute = "its_toolaxis");

  // --- additive (LowerAdditive.cpp) -----------------------------------------
  /// An added feature (am_feature) into `n`; false after reporting.
  bool additiveFeature(const Instance &f, Node &n);
  /// An additive operation: a deposition_operation (am_twod_operation) with
  /// its technology and strategy; others are reported.
  std::optional<Node> additiveOperation(const Instance &op);
  /// A deposition head (stepnc_additive) as a tool node.
  std::optional<std::string> depositionHead(const Instance &t);

  const binding::BoundFile &bound() const { return bound_; }
  DiagnosticEngine &diags() { return diags_; }

private:
  std::optional<std::string> workpiece(const Instance &wp);
  /// The BLOCK (or other bounding geometry) that stands for a workpiece's raw piece.
  static Instance rawBounding(const Instance &wp);
  std::optional<std::string> setup(const Instance &setup);
  bool executable(const Instance &exe, Node &parent);
  std::optional<Node> workingstep(const Instance &ws);
  /// A workingstep of `ws` machining `featureInstance` (its `attribute`),
  /// its symbol from `name`.
  std::optional<Node> workingstep(const Instance &ws, const Instance &featureInstance, std::string_view attribute,
                                  const std::string &name);
  std::optional<Node> workplan(const Instance &wp);
  Node *findResource(const std::string &symbol);
  /// The copies placeOnFace makes, each once per face (LowerClampings.cpp).
  std::string turnedWorkpiece(const std::string &workpiece, const Turn &turn, const std::optional<RawExtent> &raw);
  std::string turnedFeature(const std::string &feature, const Turn &turn, const std::string &workpiece);
  std::string turnedSetup(const std::string &workpiece, const Turn &turn, const std::optional<RawExtent> &raw,
                          const Instance &stepInstance);
  /// The security plane of `owner` (attribute its_secplane) as a height in
  /// the turned setup; reports what it assumes.
  std::optional<double> turnedSecplane(const Instance &owner, const Turn &turn, const std::optional<RawExtent> &raw);
  /// The height of `owner`'s security plane in the turned setup when it is
  /// parallel to the face and outside it; none (and nothing said) otherwise.
  std::optional<double> faceSecplane(const Instance &owner, const Turn &turn, const std::optional<RawExtent> &raw);
  /// Decides how the file's angles are read (options_.units.angles), from
  /// the instances that have angles.
  void chooseAngleUnit(const std::vector<Instance> &withAngles);
  /// Decides how the file's feeds, cutting speeds and spindle speeds are
  /// read, from the machining operations' technologies and tools.
  void chooseSpeedUnits(const std::vector<Instance> &operations);

  const binding::BoundFile &bound_;
  DiagnosticEngine &diags_;
  const LowerOptions &options_;
  std::unique_ptr<ir::Module> module_;
  std::set<std::string> symbols_;
  std::map<size_t, std::string> lowered_;  ///< instance index -> symbol of its resource node
  std::set<size_t> reported_;              ///< instances already reported unsupported
  std::set<size_t> workplansOnStack_;      ///< cycle guard for nested workplans
  /// The file's setup in force (the nearest enclosing workplan's), and the
  /// setup the last machined step was in (reclampBefore).
  Instance setupInForce_;
  std::string setupSymbolInForce_, clamping_;
  std::map<std::string, std::string> turned_;  ///< symbol + " " + face -> the turned copy's symbol
  std::set<std::pair<size_t, std::string>> secplanesAssumed_;  ///< (plane, face) reported once
  int64_t workOffsets_ = 1;                  ///< work offsets used: the file's own is 1
  std::vector<ir::SourceFix> pendingFixes_;  ///< fix() before the module exists
  std::vector<std::string> pendingInstances_;  ///< newInstance() before the module exists
  std::vector<Instance> projectWorkpieces_;  ///< the project's its_workpieces
  double angleToDeg_ = 1.0;                  ///< plane_angle_measure to deg
  bool swapAxisAndRef_ = false;              ///< choosePlacementReading
  /// The operation being lowered and the feature it machines (toolFromUse).
  struct Use {
    Instance operation, feature;
  } use_;
  double feedToMmPerMin_ = 60000.0;          ///< a technology's feedrate to mm/min
  double cutspeedToMmPerMin_ = 60000.0;      ///< its cutspeed to mm/min
  double spindleToRevPerMin_ = 60.0;         ///< its spindle to rev/min
  /// The units the write-back writes speeds in: the reading's, except where
  /// the reading was assumed (then the standard's, every value converted).
  ir::SourceUnits writtenUnits_;
  /// Angles the write-back writes to deg: the reading's, except where
  /// radians were assumed (then every angle is converted to degrees).
  double writtenAngleToDeg_ = 1.0;
};

/// Lowers an AP238 AIM file (LowerAim.cpp): the same IR from the ARM's
/// mapped form.
std::unique_ptr<ir::Module> lowerAimToFeatureIR(const binding::BoundFile &bound, DiagnosticEngine &diags,
                                                const LowerOptions &options);

} // namespace stepnc::lowering
