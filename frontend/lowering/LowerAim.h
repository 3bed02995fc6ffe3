// The AP238 AIM lowering's state, shared by its two files: LowerAim.cpp
// (the program: workplans, workingsteps, tools, technology, toolpaths, units)
// and LowerAimFeatures.cpp (machining features and the operations left to
// stepnc's strategies). Internal to the lowering library.
#pragma once

#include "frontend/lowering/Lowerer.h"

#include <map>
#include <set>

namespace stepnc::lowering {

namespace aim {

/// The dimensions of a unit, in the base quantities AP238 files use.
struct Dims {
  int length = 0, time = 0, angle = 0, revolution = 0;
  bool operator==(const Dims &) const = default;
};

/// A unit as a factor to stepnc's base units (mm, s, deg, rev) and its dimensions.
struct UnitValue {
  double factor = 1;
  Dims dims;
  std::string error;  ///< why the unit could not be read (empty when it could)
};

constexpr Dims kLength{1, 0, 0, 0}, kTime{0, 1, 0, 0}, kAngle{0, 0, 1, 0}, kRevolution{0, 0, 0, 1};
constexpr Dims kFeed{1, -1, 0, 0}, kFeedPerRev{1, 0, 0, -1}, kRotation{0, -1, 0, 1};

/// "a length", "a speed (length per time)", ...
std::string dimsText(const Dims &d);

/// A name as AP238 writers spell property and item names: lower case, '_' as ' '.
std::string normalName(std::string_view s);

struct Measure {
  std::string name;  ///< the item's name, normalised
  double value = 0;  ///< in stepnc's base units (UnitValue::factor applied)
  Dims dims;
  double written = 0;  ///< as the file writes it
  double factor = 1;   ///< its unit's UnitValue::factor
  /// The value in a unit `scale` times the base unit's inverse (mm/min from
  /// mm/s: 60), the factors combined first: 5 in/min is 127 mm/min exactly
  /// (5 x 25.4), where 5 x (25.4 / 60) x 60 is not.
  double scaled(double scale) const { return written * (factor * scale); }
};

} // namespace aim

class AimLowerer {
public:
  AimLowerer(const binding::BoundFile &bound, DiagnosticEngine &diags, const LowerOptions &options)
      : bound_(bound), diags_(diags), base_(bound, diags, options) {}

  std::unique_ptr<ir::Module> run();

private:
  // --- the file's relationships, indexed once ---------------------------------
  void index();
  /// The related_method of every action_method_relationship of entity `kind`
  /// (and, when given, of that name) whose relating_method is `from`, in
  /// sequence order when sequenced.
  std::vector<Instance> related(const Instance &from, std::string_view kind, std::string_view name = {}) const;
  /// The representations of the properties named `property` of `of`.
  std::vector<Instance> propertyRepresentations(const Instance &of, std::string_view property, bool resource) const;
  /// Every property of `of` with its representation: (property name, representation).
  std::vector<std::pair<std::string, Instance>> properties(const Instance &of, bool resource) const;

  // --- units and values ---------------------------------------------------------
  aim::UnitValue unit(const Instance &u);
  /// A measure_representation_item (or measure_with_unit) in base units.
  std::optional<aim::Measure> measure(const Instance &item);
  /// The factor of the unit of dimensions `dims` that a representation's
  /// context assigns; nullopt when it assigns none.
  std::optional<double> contextFactor(const Instance &representation, const aim::Dims &dims);
  /// The length unit of a representation's context (mm when it says none: an assumption).
  double lengthFactor(const Instance &representation);
  /// The first descriptive item's text of a property, lower case.
  std::optional<std::string> word(const Instance &of, std::string_view property);

  // --- the program ----------------------------------------------------------------
  Instance mainWorkplan();
  void workpiece();
  void executable(const Instance &exe, Node &parent);
  std::optional<Node> workplan(const Instance &wp);
  std::optional<Node> workingstep(const Instance &ws);
  std::optional<Node> rapidMovement(const Instance &rm);
  std::optional<Node> operation(const Instance &op);
  std::optional<std::string> tool(const Instance &tool);
  Node technology(const Instance &tech);
  Node machineFunctions(const Instance &mf);
  void toolpaths(const Instance &owner, Node &parent);
  std::optional<Node> toolpath(const Instance &tp);
  /// The symbol of a workingstep's feature: its machining feature, else a
  /// toolpath feature (a frame) when the step's toolpaths give its path.
  std::optional<std::string> stepFeature(const Instance &ws, bool followsToolpaths);
  std::string toolpathFeature(const Instance &ws, const Instance &feature);
  /// The curve of a toolpath's 'basic curve' representation, in mm.
  std::optional<Node> basicCurve(const Instance &tp);
  void scaleLengths(Node &n, double factor);
  void trimByPoints(Node &n, double angleToRad);
  void highest(const Node &curve);

  // --- machining features and strategies (LowerAimFeatures.cpp) ---------------
  /// What a feature or feature component gives in the representations of its
  /// property definitions (shape_representation_with_parameters and the
  /// like): measures, placements and directions by item name; lengths in mm.
  struct Parameters {
    std::map<std::string, aim::Measure> measures;
    std::map<std::string, Placement> placements;
    std::map<std::string, Vec3> directions;
    /// The measure `name` when there is one of dimensions `dims`.
    std::optional<double> value(std::string_view name, const aim::Dims &dims) const {
      auto it = measures.find(std::string(name));
      return it != measures.end() && it->second.dims == dims ? std::optional(it->second.value) : std::nullopt;
    }
  };
  Parameters parameters(const Instance &of);
  /// The feature component that an occurrence of `feature` described
  /// `occurrence` ('diameter occurrence') uses: the relating shape aspect of
  /// the shape_aspect_relationship whose related shape aspect is the
  /// occurrence. Invalid when the feature has none.
  Instance component(const Instance &feature, std::string_view occurrence);
  /// Every such component, in the order of the occurrences in the file.
  std::vector<Instance> components(const Instance &feature, std::string_view occurrence);
  /// The length `item` of the `entity` that the occurrence `occurrence` of
  /// feature `f` uses, set as `attribute` of `n`; false after a located error.
  bool componentLength(const Instance &f, std::string_view occurrence, std::string_view entity,
                       std::string_view item, Node &n, const char *attribute);
  /// Whether stepnc lowers a feature of this kind (round holes, closed
  /// rectangular pockets, straight slots of square U section).
  bool isLoweredFeature(const Instance &f);
  /// The IR feature of a machining feature, under the workpiece; its symbol.
  std::optional<std::string> machiningFeature(const Instance &f);
  bool roundHole(const Instance &f, Node &n);
  bool pocket(const Instance &f, Node &n);
  bool slot(const Instance &f, Node &n);
  /// A length, angle, time or ratio the component or feature must give.
  std::optional<double> required(const Instance &of, const Parameters &p, std::string_view name, const aim::Dims &dims);
  /// The IR kind of an operation whose path stepnc's strategies make, from its
  /// entity and description ('roughing', 'center drilling'); nullopt after a
  /// located error when stepnc has none.
  std::optional<ir::Kind> strategyOperationKind(const Instance &op);
  /// The IR kind of a lathe operation (ISO 14649-12) from its entity and
  /// description; nullopt after a located error.
  std::optional<ir::Kind> turningOperationKind(const Instance &op);
  /// The operation's action properties (retract plane, allowances, depths, ...).
  void operationParameters(const Instance &op, Node &n);
  /// Its machining, approach and retract strategies
  /// (machining_strategy_relationships named so).
  void strategies(const Instance &op, Node &n);
  /// The value of the first measure item of a property of an action method.
  std::optional<aim::Measure> propertyMeasure(const Instance &of, std::string_view property);

  /// The height (mm) of a workingstep's 'security plane' property: a plane
  /// whose placement's location gives it; nullopt when there is none.
  std::optional<double> securityPlane(const Instance &ws);
  /// An error about `inst` at `at` ("#64 CONTOURING_TURNING_OPERATION: ...").
  void report(const Instance &inst, SourceLoc at, std::string message);
  /// "'what': expected a length, its unit is a time", at `inst`.
  void wrongUnit(const Instance &inst, SourceLoc at, std::string_view what, const aim::Dims &expected,
                 const aim::Dims &found);
  static std::string entityUpper(const Instance &inst) { return express::upper(inst.entityName()); }
  /// Says which executables, operations and toolpaths of the file the
  /// program leaves out because no relationship holds them.
  void reportUnreached();
  /// `rep` and the representations representation_relationships tie to it.
  std::vector<Instance> withRelated(const Instance &rep) const;
  Instance at(size_t index) const { return Instance(bound_, index); }

  const binding::BoundFile &bound_;
  DiagnosticEngine &diags_;
  Lowerer base_;  ///< the ARM lowering's geometry and helpers (curves, symbols, reports)
  std::unique_ptr<ir::Module> module_;

  // The indexes hold instance indices, not decoded instances: an index entry
  // is decoded again when lowering follows it, and a large file's indexes
  // stay small.
  using Index = std::map<size_t, std::vector<size_t>>;
  Index byRelating_;                         ///< action_method_relationships by relating_method
  std::set<size_t> sequenced_;               ///< executables some workplan sequences
  Index actionProps_;                        ///< action_property by definition
  Index resourceProps_;                      ///< resource_property by resource
  Index propReps_;                           ///< *_property_representation by property
  Index repRelated_;                         ///< representations related to one, both ways
  Index componentsOf_;                       ///< resources an action_resource_relationship ties to a tool
  std::map<size_t, size_t> toolOf_;          ///< machining_tool by operation (usage)
  std::map<size_t, size_t> featureOfProcess_;  ///< feature by machining_feature_process
  Index propertyDefs_;                       ///< property_definition (and subtypes) by definition
  Index definitionReps_;                     ///< property_definition_representation by definition
  Index aspectsOf_;                          ///< shape_aspect by of_shape
  Index aspectRelationsTo_;                  ///< shape_aspect_relationship by related_shape_aspect
  std::set<size_t> workplansOnStack_;        ///< cycle guard for nested workplans
  std::set<size_t> reached_;                 ///< executables, operations and toolpaths the program reaches
  std::set<size_t> held_;                    ///< action methods some relationship relates to another
  std::vector<size_t> methods_;              ///< every executable, operation and toolpath of the file
  std::vector<Instance> projects_, workplanProcesses_, projectWorkpieces_;
  std::map<size_t, aim::UnitValue> units_;
  std::map<size_t, std::string> lowered_;  ///< instance -> symbol (tools, features)
  std::set<size_t> reported_;
  std::string workpieceSymbol_;
  std::optional<double> highestZ_;  ///< the highest point of any toolpath (mm)
};


} // namespace stepnc::lowering
