// Lowering of the program structure: project, workpieces, setups, workplans,
// workingsteps and NC functions, plus the helpers every lowering file uses.
#include "frontend/express/Builtin.h"
#include "frontend/lowering/Lowerer.h"
#include "frontend/part21/Writer.h"
#include "ir/Plausible.h"
#include "ir/Program.h"

#include "support/Format.h"
#include "support/Preimage.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::lowering {

// --- helpers -----------------------------------------------------------------

void Lowerer::unsupported(const Instance &inst, std::string_view what) {
  if (!reported_.insert(inst.index()).second)
    return;
  std::string entity(inst.entityName().empty() ? std::string_view("(unknown)") : inst.entityName());
  for (char &c : entity)
    if (c >= 'a' && c <= 'z')
      c = static_cast<char>(c - 32);
  diags_.error(inst.loc(), "not supported: " + entity + " at " + hashId(inst.id()) +
                               (what.empty() ? std::string() : " (" + std::string(what) + ")"))
      .entity(inst.id(), entity);
}

namespace {

/// "'depth' of round_hole #28": the attribute a diagnostic is about.
std::string attributeOf(const Instance &inst, std::string_view attribute) {
  std::string text = "'";
  text += attribute;
  text += "' of ";
  text += inst.entityName();
  text += ' ';
  text += hashId(inst.id());
  return text;
}

} // namespace

void Lowerer::missing(const Instance &inst, std::string_view attribute, std::string_view why) {
  std::string message = attributeOf(inst, attribute);
  message += ' ';
  message += why.empty() ? std::string_view("is needed to lower it") : why;
  diags_.error(inst.attrLoc(attribute), std::move(message)).entity(inst.id(), std::string(inst.entityName()));
}

void Lowerer::assumed(const Instance &inst, std::string_view attribute, std::string_view what) {
  // The diagnostic names the instance ("#28 ROUND_HOLE: 'depth' absent; ...").
  std::string message = "'";
  message += attribute;
  message += "' ";
  message += what;
  diags_.assumption(inst.attrLoc(attribute), std::move(message)).entity(inst.id(), std::string(inst.entityName()));
}

void Lowerer::fix(const Instance &inst, std::string_view attribute, std::string text) {
  if (const int i = inst.parameterIndex(attribute); i >= 0)
    fixAt(inst.id(), i, std::move(text));
}

void Lowerer::fixAt(uint64_t entityId, int parameter, std::string text) {
  (module_ ? module_->sourceFixes : pendingFixes_).push_back({entityId, parameter, std::move(text)});
}

std::string Lowerer::generalTolerance() {
  // The tightest global_tolerance of a workpiece lowering uses, else the
  // tolerance toolpaths are verified to without one.
  double tolerance = ir::kDefaultTolerance;
  bool given = false;
  for (size_t i = 0; i < bound_.file().entries().size(); ++i) {
    const Instance wp(bound_, i);
    if (!wp.isA("workpiece"))
      continue;
    if (auto t = wp.real("global_tolerance"); t && ir::isPlausibleTolerance(*t)) {
      tolerance = given ? std::min(tolerance, *t) : *t;
      given = true;
    }
  }
  const std::string value = real(tolerance);
  return newInstance("PLUS_MINUS_VALUE(" + value + ',' + value + ",4)");
}

std::string Lowerer::quoted(std::string_view text) {
  std::string out;
  p21::appendString(out, text);
  return out;
}

std::string Lowerer::real(double value) {
  std::string text;
  p21::appendReal(text, value);
  return text;
}

std::string Lowerer::depthPlane(double depth) {
  return newInstance("PLANE('depth'," + newInstance("AXIS2_PLACEMENT_3D(''," + newPoint(Vec3(0, 0, -depth)) + ",$,$)") +
                     ")");
}

std::string Lowerer::tolerancedLength(double value) {
  return newInstance("TOLERANCED_LENGTH_MEASURE(" + real(value) + "," + generalTolerance() + ")");
}

std::string Lowerer::placementAt(const Instance &original, const Vec3 &at) {
  Instance axis = original.ref("axis"), ref = original.ref("ref_direction");
  if (swapAxisAndRef_ && axis && ref)
    std::swap(axis, ref);
  return newInstance("AXIS2_PLACEMENT_3D(''," + newPoint(at) + "," + (axis ? hashId(axis.id()) : "$") + "," +
                     (ref ? hashId(ref.id()) : "$") + ")");
}

std::string Lowerer::newPlacement(const Vec3 &at, const std::optional<Vec3> &axis, const std::optional<Vec3> &ref) {
  auto direction = [&](const std::optional<Vec3> &d) {
    return d ? newInstance("DIRECTION(''," + triple(*d) + ")") : std::string("$");
  };
  return newInstance("AXIS2_PLACEMENT_3D(''," + newPoint(at) + "," + direction(axis) + "," + direction(ref) + ")");
}

std::string Lowerer::triple(const Vec3 &v) { return "(" + real(v.x()) + "," + real(v.y()) + "," + real(v.z()) + ")"; }

std::string Lowerer::newPoint(const Vec3 &at) { return newInstance("CARTESIAN_POINT(''," + triple(at) + ")"); }

std::string Lowerer::newInstance(std::string text) {
  std::vector<std::string> &instances = module_ ? module_->sourceInstances : pendingInstances_;
  auto it = std::find(instances.begin(), instances.end(), text);
  if (it == instances.end())
    it = instances.insert(instances.end(), std::move(text));
  return "#@" + std::to_string(it - instances.begin());
}

std::string Lowerer::symbolFor(char sigil, const std::optional<std::string> &label, std::string_view fallback) {
  std::string base;
  if (label) {
    bool underscore = false;
    for (unsigned char c : *label) {
      if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) {
        base.push_back(static_cast<char>(c));
        underscore = false;
      } else if (c >= 'A' && c <= 'Z') {
        base.push_back(static_cast<char>(c + 32));
        underscore = false;
      } else if (!underscore && !base.empty()) {
        base.push_back('_');
        underscore = true;
      }
    }
    while (!base.empty() && base.back() == '_')
      base.pop_back();
  }
  if (base.empty())
    base = std::string(fallback);
  if (base[0] >= '0' && base[0] <= '9')
    base = std::string(fallback) + "_" + base;
  std::string symbol = std::string(1, sigil) + base;
  for (int n = 2; symbols_.count(symbol); ++n)
    symbol = std::string(1, sigil) + base + "_" + std::to_string(n);
  symbols_.insert(symbol);
  return symbol;
}

void Lowerer::stamp(Node &node, const Instance &inst, std::string_view labelAttribute) {
  node.origin.entityId = inst.id();
  node.origin.loc = inst.loc();
  if (!labelAttribute.empty())
    if (std::optional<std::string> label = inst.string(labelAttribute))
      node.label = *label;
}

Node *Lowerer::findResource(const std::string &symbol) {
  for (Node &c : module_->root.children)
    if (c.symbol == symbol)
      return &c;
  return nullptr;
}

// --- resources ---------------------------------------------------------------

std::optional<std::string> Lowerer::workpiece(const Instance &wp) {
  if (!wp)
    return std::nullopt;
  if (auto it = lowered_.find(wp.index()); it != lowered_.end())
    return it->second;
  Node node(ir::Kind::Workpiece);
  stamp(node, wp);
  node.symbol = symbolFor('%', wp.string("its_id"), "workpiece");
  if (Instance material = wp.ref("its_material")) {
    if (auto id = material.string("material_identifier"))
      node.set("material", Value::string(*id));
    if (auto standard = material.string("standard_identifier"))
      node.set("material_standard", Value::string(*standard));
  }
  if (auto tol = wp.real("global_tolerance")) {
    // The verifier checks toolpaths to this tolerance; a value no machined
    // part is toleranced to (some generators write 50 mm) would let it pass
    // gouges and uncut floors.
    if (ir::isPlausibleTolerance(*tol))
      node.set("global_tolerance", Value::length(*tol));
    else {
      assumed(wp, "global_tolerance",
              formatShortest(*tol) + " mm is no machining tolerance (it must be at least " +
                  formatTrimmed(ir::kPlausibleMinTolerance, 4) + " and at most " +
                  formatTrimmed(ir::kPlausibleMaxTolerance, 4) + " mm); not used: toolpaths are verified to 0.01 mm "
                  "(verify-toolpaths<tolerance=...> sets another)");
      fix(wp, "global_tolerance", "$");  // OPTIONAL: what is not used is not given
    }
  }
  if (Instance bounding = rawBounding(wp)) {
    if (bounding.isA("block")) {
      Node raw(ir::Kind::Rawpiece);
      stamp(raw, bounding, "");
      raw.set("shape", Value::word("block"));
      auto x = bounding.real("x"), y = bounding.real("y"), z = bounding.real("z");
      if (x && y && z)
        raw.set("size", Value::point(Vec3(*x, *y, *z)));
      else
        missing(bounding, !x ? "x" : !y ? "y" : "z");
      if (auto p = placement(bounding.ref("position")))
        setPlacement(raw, *p);
      node.add(std::move(raw));
    } else if (bounding.isA("right_circular_cylinder")) {
      // A bar for turning: its axis1_placement's location and axis, its
      // height along the axis and its radius.
      Node raw(ir::Kind::Rawpiece);
      stamp(raw, bounding, "");
      raw.set("shape", Value::word("cylinder"));
      auto r = bounding.real("radius"), h = bounding.real("height");
      if (r && h) {
        raw.set("diameter", Value::length(2 * *r));
        raw.set("height", Value::length(*h));
      } else {
        missing(bounding, !r ? "radius" : "height");
      }
      Placement p;
      if (Instance a = bounding.ref("position")) {
        if (Instance location = a.ref("location"))
          if (auto at = point(location))
            p.at = *at;
        if (Instance axis = a.ref("axis"))
          if (auto v = direction(axis))
            p.axis = *v;
        p.ref = std::abs(p.axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
        p.ref = (p.ref - p.ref.dot(p.axis) * p.axis).normalized();
      } else {
        missing(bounding, "position");
      }
      setPlacement(raw, p);
      node.add(std::move(raw));
    } else {
      unsupported(bounding, "raw piece shape");
    }
  }
  for (const Instance &clamp : wp.refs("clamping_positions"))
    if (auto p = point(clamp)) {
      Node c(ir::Kind::Clamp);
      stamp(c, clamp, "");
      c.set("at", Value::point(*p));
      node.add(std::move(c));
    }
  const std::string symbol = node.symbol;
  lowered_[wp.index()] = symbol;
  module_->root.add(std::move(node));
  return symbol;
}

Instance Lowerer::rawBounding(const Instance &wp) {
  // The bounding geometry of its_rawpiece (the stock the part is made from),
  // else the part's own bounding geometry (the stock is taken to be the part's
  // envelope, as most files mean when they give no raw piece).
  Instance bounding;
  if (Instance raw = wp.ref("its_rawpiece"))
    bounding = raw.ref("its_bounding_geometry");
  if (!bounding)
    bounding = wp.ref("its_bounding_geometry");
  return bounding;
}

std::optional<std::string> Lowerer::setup(const Instance &s) {
  if (!s)
    return std::nullopt;
  if (auto it = lowered_.find(s.index()); it != lowered_.end())
    return it->second;
  Node node(ir::Kind::Setup);
  stamp(node, s);
  node.symbol = symbolFor('%', s.string("its_id"), "setup");
  Placement origin;
  if (Instance o = s.ref("its_origin"))
    if (auto p = placement(o))
      origin = *p;
  setPlacement(node, origin);
  if (auto h = planeHeight(s, "its_secplane", "security plane"))
    node.set("secplane", Value::length(*h));
  for (const Instance &ws : s.refs("its_workpiece_setup")) {
    Node w(ir::Kind::WorkpieceSetup);
    stamp(w, ws, "");
    if (auto wp = workpiece(ws.ref("its_workpiece")))
      w.set("workpiece", Value::ref(*wp));
    else
      missing(ws, "its_workpiece");
    if (auto p = placement(ws.ref("its_origin")))
      setPlacement(w, *p);
    else
      setPlacement(w, Placement());
    node.add(std::move(w));
  }
  const std::string symbol = node.symbol;
  lowered_[s.index()] = symbol;
  module_->root.add(std::move(node));
  return symbol;
}

// --- executables -------------------------------------------------------------

std::optional<Node> Lowerer::workingstep(const Instance &ws) {
  return workingstep(ws, ws.ref("its_feature"), "its_feature", ws.string("its_id").value_or(""));
}

std::optional<Node> Lowerer::workingstep(const Instance &ws, const Instance &featureInstance, std::string_view attribute,
                                         const std::string &name) {
  Node node(ir::Kind::Workingstep);
  stamp(node, ws);
  node.symbol = symbolFor('@', name, "ws");
  const std::optional<std::string> f = feature(featureInstance);
  if (f)
    node.set("feature", Value::ref(*f));
  else
    missing(ws, attribute);
  const Node *featureNode = f ? ir::findFeature(*module_, *f) : nullptr;
  // A turned feature's axis is the turning axis, either way: a lathe turns
  // the part about it, no re-clamping (docs/turning.md).
  const bool onTop = !featureNode || featureNode->is(ir::Trait::Turning) ||
                     (featureNode->vec("axis").value_or(Vec3::UnitZ()) - Vec3::UnitZ()).norm() < 1e-9;
  if (onTop)
    if (auto h = planeHeight(ws, "its_secplane", "security plane"))
      node.set("secplane", Value::length(*h));
  if (Instance op = ws.ref("its_operation")) {
    use_ = {op, featureInstance};
    std::optional<Node> lowered = operation(op);
    use_ = {};
    if (lowered)
      node.add(std::move(*lowered));
  } else {
    missing(ws, "its_operation");
  }
  if (!onTop && !placeOnFace(ws, node))
    return std::nullopt;
  return node;
}

std::optional<Node> Lowerer::workplan(const Instance &wp) {
  if (!workplansOnStack_.insert(wp.index()).second) {
    diags_.error(wp.loc(), "workplan " + hashId(wp.id()) + " contains itself").entity(wp.id(), "WORKPLAN");
    return std::nullopt;
  }
  Node node(ir::Kind::Workplan);
  stamp(node, wp);
  node.symbol = symbolFor('@', wp.string("its_id"), "workplan");
  const Instance outerSetup = setupInForce_;
  const std::string outerSymbol = setupSymbolInForce_;
  if (Instance s = wp.ref("its_setup"))
    if (auto sym = setup(s)) {
      node.set("setup", Value::ref(*sym));
      setupInForce_ = s;
      setupSymbolInForce_ = *sym;
    }
  for (const Instance &exe : wp.refs("its_elements"))
    executable(exe, node);
  setupInForce_ = outerSetup;
  setupSymbolInForce_ = outerSymbol;
  workplansOnStack_.erase(wp.index());
  return node;
}

bool Lowerer::executable(const Instance &exe, Node &parent) {
  if (exe.isA("machining_workingstep") || exe.isA("am_workingstep")) {
    if (auto ws = workingstep(exe)) {
      reclampBefore(*ws, parent);
      parent.add(std::move(*ws));
    }
    return true;
  }
  if (exe.isA("turning_workingstep")) {
    // One turning operation over several features (ISO 14649-12): a
    // workingstep each, in the order listed, the same operation (their
    // surfaces are not joined into one pass yet: said).
    const std::vector<Instance> features = exe.refs("its_features");
    if (features.empty()) {
      missing(exe, "its_features");
      return true;
    }
    const std::string id = exe.string("its_id").value_or("");
    std::string names;
    for (size_t i = 0; i < features.size(); ++i) {
      const std::string name = features.size() == 1 ? id : id + " " + std::to_string(i + 1);
      if (auto ws = workingstep(exe, features[i], "its_features", name)) {
        if (features.size() > 1)
          ws->label = id + ": " + features[i].string("its_id").value_or(hashId(features[i].id()));
        names += (names.empty() ? "" : ", ") + ws->symbol;
        reclampBefore(*ws, parent);
        parent.add(std::move(*ws));
      }
    }
    if (features.size() > 1)
      assumed(exe, "its_features",
              "lists " + std::to_string(features.size()) + " features: machined one after the other with its "
              "operation, a workingstep each (" + names + "); stepnc does not join their surfaces into one pass yet");
    return true;
  }
  if (exe.isA("workplan")) {
    if (auto wp = workplan(exe))
      parent.add(std::move(*wp));
    return true;
  }
  for (auto [entity, kind] : {std::pair{"program_stop", ir::Kind::ProgramStop}, {"optional_stop", ir::Kind::OptionalStop}})
    if (exe.isA(entity)) {
      Node n{kind};
      stamp(n, exe);
      parent.add(std::move(n));
      return true;
    }
  if (exe.isA("rapid_movement")) {
    Node n(ir::Kind::RapidMovement);
    stamp(n, exe);
    n.symbol = symbolFor('@', exe.string("its_id"), "rapid");
    if (const Node *c = clamping_.empty() ? nullptr : findResource(clamping_); c && c->has("face_up")) {
      diags_.error(exe.loc(), "rapid movement " + hashId(exe.id()) + " follows workingsteps machined with the " +
                                  "workpiece re-clamped " + *c->text("face_up") + " face up; its toolpath, in " +
                                  "workpiece coordinates, is not turned with it yet (docs/setups.md)")
          .entity(exe.id(), std::string(exe.entityName()));
      return true;
    }
    if (auto h = planeHeight(exe, "its_secplane", "security plane"))
      n.set("secplane", Value::length(*h));
    if (Instance list = exe.ref("its_toolpath"))
      toolpaths(list, n);
    parent.add(std::move(n));
    return true;
  }
  if (exe.isA("display_message")) {
    Node n(ir::Kind::DisplayMessage);
    stamp(n, exe);
    n.set("message", Value::string(exe.string("its_text").value_or("")));
    parent.add(std::move(n));
    return true;
  }
  unsupported(exe, "executable");
  return false;
}

namespace {

/// Every angle (plane_angle_measure) lowering reads, by entity and attribute:
/// what chooseAngleUnit looks at.
constexpr std::pair<std::string_view, std::string_view> kAngles[] = {
    {"milling_tool_dimension", "tool_tip_half_angle"},
    {"milling_tool_dimension", "tool_circumference_angle"},
    {"tapered_drill", "taper_angle"},
    {"tapered_reamer", "taper_angle"},
    {"tapered_tap", "taper_angle"},
    {"tapered_endmill", "taper_angle"},
    {"conical_hole_bottom", "tip_angle"},
    {"angle_taper", "angle"},
    {"pocket", "slope"},
    {"boss", "slope"},
    {"am_extruded_feature", "draft_angle"},
    {"deposition_head", "nozzle_angle"},
    {"deposition_strategy", "infill_angle"},
    {"deposition_strategy", "layer_rotation"},
    {"deposition_strategy", "seam_shift"},
    {"square_u_profile", "first_angle"},
    {"square_u_profile", "second_angle"},
    {"vee_profile", "profile_angle"},
    {"vee_profile", "tilt_angle"},
    {"partial_circular_profile", "sweep_angle"},
    {"plunge_ramp", "angle"},
    {"plunge_helix", "angle"},
    {"plunge_zigzag", "angle"},
    {"ap_retract_angle", "angle"},
    {"turning_tool_dimension", "side_cutting_edge_angle"},
    {"turning_tool_dimension", "end_cutting_edge_angle"},
    {"turning_threading_tool", "threading_angle"},
    {"unidirectional_diagonal", "path_return_angle"},
    {"contour_turning", "path_return_angle"},
    {"diagonal_knurl", "helix_angle"},
    {"diamond_knurl", "helix1_angle"},
    {"diamond_knurl", "helix2_angle"},
};

} // namespace

namespace {

/// The value that, multiplied by `factor`, gives exactly `target`: what a
/// converted value is written as so that reading it back gives the value used.
double readsBackAs(double target, double factor) {
  return preimage(target, target / factor, [factor](double v) { return v * factor; });
}

} // namespace

void Lowerer::chooseAngleUnit(const std::vector<Instance> &withAngles) {
  using Angle = UnitConventions::Angle;
  if (options_.units.angles != Angle::Auto) {
    angleToDeg_ = options_.units.angles == Angle::Radian ? 180 / std::numbers::pi : 1.0;
    writtenAngleToDeg_ = angleToDeg_;  // the unit an option gives stays the file's
    return;
  }
  // Radians when every angle is below 2 pi and none is a whole number of
  // degrees: 0.349066 (20 deg) and 1.570796 (90 deg) read as radians; one
  // angle of 31 or 118 keeps the whole file in degrees. A file with no angle,
  // or only zeros, stays in degrees.
  std::optional<std::pair<Instance, std::string_view>> example;
  double exampleValue = 0;
  for (const Instance &inst : withAngles) {
    for (const auto &[entity, attribute] : kAngles) {
      if (!inst.isA(entity))
        continue;
      std::optional<double> v = inst.real(attribute);
      if (!v || *v == 0)
        continue;
      const double a = std::abs(*v);
      if (a > 2 * std::numbers::pi + 1e-9 || std::abs(a - std::round(a)) < 1e-9)
        return;  // degrees
      if (!example) {
        example = std::pair{inst, attribute};
        exampleValue = *v;
      }
    }
  }
  if (!example)
    return;
  angleToDeg_ = 180 / std::numbers::pi;
  // The write-back writes every angle in degrees (ir::SourceFix).
  for (const Instance &inst : withAngles)
    for (const auto &[entity, attribute] : kAngles)
      if (inst.isA(entity))
        if (std::optional<double> v = inst.real(attribute))
          fix(inst, attribute, real(readsBackAs(*v * angleToDeg_, 1.0)));
  const auto &[inst, attribute] = *example;
  diags_
      .assumption(inst.attrLoc(attribute),
                  "angles read as radians: every angle in the file is below 2 pi and none is a whole number of "
                  "degrees (" + std::string(attribute) + " " + formatFixed(exampleValue, 6) + " = " +
                      formatFixed(exampleValue * 180 / std::numbers::pi, 4) + " deg)")
      .entity(inst.id(), std::string(inst.entityName()));
}

namespace {

/// The readings of speed_measure and rot_speed_measure, the standard's first.
constexpr UnitReading kSpeedReadings[] = {{"m/s", 60000}, {"mm/min", 1}, {"m/min", 1000}, {"mm/s", 60}};
constexpr UnitReading kSpindleReadings[] = {{"rev/s", 60}, {"rev/min", 1}};

/// One value of the file to be read: where it is and the tool it turns.
struct SpeedValue {
  Instance tech;
  std::string_view attribute;
  double value;
  double toolDiameter;  ///< mm, 0 when not known
  double spindle = 0;   ///< the technology's spindle speed as written, 0 when none
  int64_t flutes = 0;   ///< the tool's, 0 when not known
};

/// The reading under which every value is plausible, else the one under
/// which most are (the first on ties: the standard's).
template <size_t N, class Plausible>
size_t chooseReading(const UnitReading (&readings)[N], const std::vector<SpeedValue> &values, Plausible plausible) {
  size_t best = 0, bestCount = 0;
  for (size_t r = 0; r < N; ++r) {
    size_t count = 0;
    for (const SpeedValue &v : values)
      count += plausible(v, v.value * readings[r].factor) ? 1 : 0;
    if (count == values.size())
      return r;
    if (count > bestCount) {
      best = r;
      bestCount = count;
    }
  }
  return best;
}

} // namespace

std::span<const UnitReading> speedReadings() { return kSpeedReadings; }
std::span<const UnitReading> spindleReadings() { return kSpindleReadings; }

void Lowerer::chooseSpeedUnits(const std::vector<Instance> &operations) {
  // Every technology an operation uses, with its tool's diameter.
  std::vector<SpeedValue> feeds, cutspeeds, spindles;
  for (const Instance &op : operations) {
    Instance tech = op.ref("its_technology");
    if (!tech)
      continue;
    Instance body = op.ref("its_tool").ref("its_tool_body");
    double diameter = 0;
    if (Instance dim = body.ref("dimension"))
      diameter = dim.real("diameter").value_or(0);
    const double spindle = tech.real("spindle").value_or(0);
    const int64_t flutes = body.integer("number_of_teeth").value_or(0);
    for (auto [attribute, list] : {std::pair{"feedrate", &feeds}, {"cutspeed", &cutspeeds}, {"spindle", &spindles}})
      if (auto v = tech.real(attribute); v && *v != 0)
        list->push_back({tech, attribute, *v, diameter, spindle, flutes});
    // A turning technology's speeds are in its spindle speed select (the
    // diameter they act on is the workpiece's, not known here).
    Instance speed = tech.ref("spindle_speed");
    for (auto [attribute, list] :
         {std::pair{"rot_speed", &spindles}, {"speed", &cutspeeds}, {"max_speed", &spindles}})
      if (auto v = speed.real(attribute); v && *v != 0)
        list->push_back({speed, attribute, *v, 0.0, 0.0, 0});
  }
  // Plausible: spindle speeds of 10 to 60000 rev/min that give a cutting
  // speed of 1 to 1500 m/min on the tool, when its diameter is known;
  // cutting speeds likewise; feeds of 1 mm/min to 60 m/min that, with the
  // spindle speed read as chosen and the tool's flutes, load each tooth
  // with no more than ir::kPlausibleChipLoadShare of the tool's diameter
  // (the bound check-limits holds the program to).
  const UnitConventions &u = options_.units;
  auto plausibleCutspeed = [](double mmPerMin) { return mmPerMin >= 1000 && mmPerMin <= 1.5e6; };
  auto plausibleSpindle = [&](const SpeedValue &v, double n) {
    n = std::abs(n);
    return n >= 10 && n <= 60000 && (v.toolDiameter <= 0 || plausibleCutspeed(std::numbers::pi * v.toolDiameter * n));
  };
  const size_t spindle = chooseReading(kSpindleReadings, spindles, plausibleSpindle);
  const double revPerMin = u.rotSpeedToRevPerMin > 0 ? u.rotSpeedToRevPerMin : kSpindleReadings[spindle].factor;
  // The feed per tooth `f` (mm/min) gives on v's tool, 0 when not known.
  auto chipLoad = [&](const SpeedValue &v, double f) {
    const double n = std::abs(v.spindle) * revPerMin;
    return v.flutes > 0 && n > 0 ? std::abs(f) / (static_cast<double>(v.flutes) * n) : 0.0;
  };
  auto plausibleFeed = [&](const SpeedValue &v, double f) {
    f = std::abs(f);
    return f >= 1 && f <= 60000 && (v.toolDiameter <= 0 || chipLoad(v, f) <= ir::kPlausibleChipLoadShare * v.toolDiameter);
  };
  const size_t feed = chooseReading(kSpeedReadings, feeds, plausibleFeed);
  const size_t cutspeed = chooseReading(kSpeedReadings, cutspeeds,
                                        [&](const SpeedValue &, double vc) { return plausibleCutspeed(std::abs(vc)); });
  feedToMmPerMin_ = u.feedToMmPerMin > 0 ? u.feedToMmPerMin : kSpeedReadings[feed].factor;
  cutspeedToMmPerMin_ = u.cutspeedToMmPerMin > 0 ? u.cutspeedToMmPerMin : kSpeedReadings[cutspeed].factor;
  spindleToRevPerMin_ = u.rotSpeedToRevPerMin > 0 ? u.rotSpeedToRevPerMin : kSpindleReadings[spindle].factor;
  // Says which reading was taken when it is not the standard's, with a
  // value the standard's reading makes implausible (`plausible`).
  auto report = [&](const std::vector<SpeedValue> &values, const UnitReading &chosen, const UnitReading &standard,
                    std::string_view what, std::string_view unit, auto plausible) {
    if (chosen.factor == standard.factor || values.empty())
      return;
    const SpeedValue *example = &values.front();
    for (const SpeedValue &v : values)
      if (!plausible(v, v.value * standard.factor)) {
        example = &v;
        break;
      }
    const SpeedValue &v = *example;
    const double asStandard = std::abs(v.value) * standard.factor;
    std::string detail;
    if (v.attribute == std::string_view("feedrate") && asStandard >= 1 && asStandard <= 60000)
      if (const double fz = chipLoad(v, asStandard); fz > 0)
        detail = " mm/min, " + formatFixed(fz, 4) + " mm per tooth on its " + formatFixed(v.toolDiameter, 4) +
                 " mm tool";
    diags_
        .assumption(v.tech.attrLoc(v.attribute),
                    std::string(what) + " read as " + std::string(chosen.name) + ", not " + std::string(standard.name) +
                        ": as " + std::string(standard.name) + " they are not what a machine does (" +
                        std::string(v.attribute) + " " + formatFixed(v.value, 4) + " of " + hashId(v.tech.id()) +
                        ": " + formatFixed(std::abs(v.value) * chosen.factor, 1) + " " + std::string(unit) + "; as " +
                        std::string(standard.name) + ", " + formatFixed(asStandard, 1) + detail + ")")
        .entity(v.tech.id(), std::string(v.tech.entityName()));
  };
  if (u.feedToMmPerMin <= 0)
    report(feeds, kSpeedReadings[feed], kSpeedReadings[0], "feeds", "mm/min", plausibleFeed);
  if (u.cutspeedToMmPerMin <= 0)
    report(cutspeeds, kSpeedReadings[cutspeed], kSpeedReadings[0], "cutting speeds", "mm/min",
           [&](const SpeedValue &, double vc) { return plausibleCutspeed(std::abs(vc)); });
  if (u.rotSpeedToRevPerMin <= 0)
    report(spindles, kSpindleReadings[spindle], kSpindleReadings[0], "spindle speeds", "rev/min", plausibleSpindle);
  // The write-back writes a quantity whose reading was assumed in the
  // standard's unit, every value converted: read again, the file needs no
  // assumption. A reading an option gave stays the file's.
  writtenUnits_ = {feedToMmPerMin_, cutspeedToMmPerMin_, spindleToRevPerMin_};
  auto convert = [&](const std::vector<SpeedValue> &values, double option, double chosen, double standard,
                     double &written) {
    if (option > 0 || chosen == standard)
      return;
    written = standard;
    for (const SpeedValue &v : values)
      fix(v.tech, v.attribute, real(readsBackAs(v.value * chosen, standard)));
  };
  convert(feeds, u.feedToMmPerMin, feedToMmPerMin_, kSpeedReadings[0].factor, writtenUnits_.feedToMmPerMin);
  convert(cutspeeds, u.cutspeedToMmPerMin, cutspeedToMmPerMin_, kSpeedReadings[0].factor,
          writtenUnits_.cutspeedToMmPerMin);
  convert(spindles, u.rotSpeedToRevPerMin, spindleToRevPerMin_, kSpindleReadings[0].factor,
          writtenUnits_.spindleToRevPerMin);
  // A spindle speed that no reading makes plausible with the others: say
  // what it gives on its tool (feeds and cutting speeds are checked as they
  // are lowered).
  for (const SpeedValue &v : spindles) {
    const double n = std::abs(v.value) * spindleToRevPerMin_;
    if (plausibleSpindle(v, n))
      continue;
    diags_
        .warning(v.tech.attrLoc(v.attribute),
                 "spindle " + formatFixed(v.value, 4) + " read as " + formatFixed(n, 1) + " rev/min" +
                     (v.toolDiameter > 0 ? ", a cutting speed of " +
                                               formatFixed(std::numbers::pi * v.toolDiameter * n / 1000, 1) +
                                               " m/min on its " + formatFixed(v.toolDiameter, 4) + " mm tool"
                                         : std::string()) +
                     ": not what a machine does, in this or any unit the file's other speeds allow")
        .entity(v.tech.id(), std::string(v.tech.entityName()));
  }
}

void Lowerer::choosePlacementReading(const std::vector<Instance> &placements) {
  // Swapped when every placement that gives both directions has its axis
  // horizontal and its ref_direction along z: such a file has no frame with
  // z up, not even its raw piece's or its setup's, yet places depths and
  // heights along z. A file with one frame whose axis is z keeps the
  // standard's reading for all of them.
  Instance first;
  size_t swapped = 0;
  for (const Instance &a : placements) {
    std::optional<Vec3> axis, ref;
    if (Instance i = a.ref("axis"))
      axis = direction(i);
    if (Instance r = a.ref("ref_direction"))
      ref = direction(r);
    if (!axis || !ref)
      continue;
    if (std::abs(axis->z()) > 1e-9 || std::abs(std::abs(ref->z()) - 1) > 1e-9)
      return;
    if (!swapped++)
      first = a;
  }
  if (swapped < 2)
    return;
  swapAxisAndRef_ = true;
  for (const Instance &a : placements) {
    const Instance axis = a.ref("axis"), ref = a.ref("ref_direction");
    if (axis && ref) {
      fix(a, "axis", hashId(ref.id()));
      fix(a, "ref_direction", hashId(axis.id()));
    }
  }
  diags_
      .assumption(first.loc(),
                  "every AXIS2_PLACEMENT_3D of the file that gives both directions (" + std::to_string(swapped) +
                      ", the raw piece's and the setup's included) has a horizontal axis and its ref_direction "
                      "along z, though its depths and heights are given along z: read with axis and "
                      "ref_direction swapped (z up), as the generator evidently meant")
      .entity(first.id(), std::string(first.entityName()));
}

std::unique_ptr<ir::Module> Lowerer::run() {
  const auto &entries = bound_.file().entries();
  // One pass over the file: the program's roots, and what the units are
  // chosen from (the instances with angles, the operations' technologies).
  // Entities looked up by name once, not per instance.
  const express::Model &model = bound_.model();
  auto entity = [&](std::string_view name) { return model.findEntity(bound_.schema(), name); };
  const express::EntityId projectEntity = entity("project"), workplanEntity = entity("workplan"),
                          operationEntity = entity("machining_operation"),
                          placementEntity = entity("axis2_placement_3d");
  std::vector<express::EntityId> angleEntities;
  for (const auto &a : kAngles)
    if (express::EntityId e = entity(a.first); e != express::kNone)
      angleEntities.push_back(e);
  auto is = [&](size_t i, express::EntityId e) { return e != express::kNone && bound_.isA(i, e); };
  std::vector<Instance> projects, workplans, withAngles, operations, placements;
  for (size_t i = 0; i < entries.size(); ++i) {
    if (is(i, placementEntity))
      placements.emplace_back(bound_, i);
    else if (is(i, projectEntity))
      projects.emplace_back(bound_, i);
    else if (is(i, workplanEntity))
      workplans.emplace_back(bound_, i);
    else if (is(i, operationEntity))
      operations.emplace_back(bound_, i);
    else if (std::ranges::any_of(angleEntities, [&](express::EntityId e) { return is(i, e); }))
      withAngles.emplace_back(bound_, i);
  }
  chooseAngleUnit(withAngles);
  chooseSpeedUnits(operations);
  choosePlacementReading(placements);
  module_ = std::make_unique<ir::Module>();
  module_->sourceName = std::string(bound_.file().source().name());
  module_->sourceUnits = writtenUnits_;
  module_->sourceInstances = std::move(pendingInstances_);  // what pendingFixes_ refer to
  for (const binding::BoundFile::Fix &f : bound_.fixes())
    module_->sourceFixes.push_back({f.id, f.parameter, f.generalTolerance ? generalTolerance() : f.text});
  module_->sourceFixes.insert(module_->sourceFixes.end(), pendingFixes_.begin(), pendingFixes_.end());
  Instance main;
  if (projects.empty()) {
    // No PROJECT names the main workplan: a workplan that is no other
    // workplan's element can only be the top of the program. With one such
    // workplan that is what the file means; with none or several, it says
    // nothing.
    std::set<size_t> elements;
    for (const Instance &wp : workplans)
      for (const Instance &exe : wp.refs("its_elements"))
        elements.insert(exe.index());
    std::vector<Instance> tops;
    for (const Instance &wp : workplans)
      if (!elements.count(wp.index()))
        tops.push_back(wp);
    if (tops.size() != 1) {
      auto diag = diags_.error(
          bound_.file().loc(0),
          workplans.empty() ? std::string("no PROJECT instance: there is no workplan to lower")
          : tops.empty()    ? std::string("no PROJECT instance, and every workplan is an element of another: none "
                                          "is the main workplan")
                            : "no PROJECT instance, and " + std::to_string(tops.size()) +
                               " workplans are not elements of another: which is the main workplan is not said");
      for (const Instance &wp : tops)
        diag.note(wp.loc(), "workplan " + hashId(wp.id()) + " is not an element of another workplan");
      return nullptr;
    }
    main = tops[0];
    diags_.assumption(main.loc(), "no PROJECT: workplan " + hashId(main.id()) + " taken as the main workplan")
        .entity(main.id(), "WORKPLAN");
    stamp(module_->root, main);
  } else {
    if (projects.size() > 1)
      diags_.error(projects[1].loc(), "a second PROJECT instance; only one workplan can be lowered")
          .entity(projects[1].id(), "PROJECT")
          .note(projects[0].loc(), "the first PROJECT is here");
    const Instance &project = projects[0];
    stamp(module_->root, project);
    projectWorkpieces_ = project.refs("its_workpieces");
    for (const Instance &wp : projectWorkpieces_)
      workpiece(wp);
    main = project.ref("main_workplan");
    if (!main) {
      missing(project, "main_workplan");
      return std::move(module_);
    }
  }
  std::optional<Node> plan = workplan(main);
  // Resources first, in a fixed order: workpieces, tools, setups; then the plan.
  std::vector<Node> ordered;
  for (ir::Kind kind : {ir::Kind::Workpiece, ir::Kind::Tool, ir::Kind::Setup})
    for (Node &c : module_->root.children)
      if (c.kind == kind)
        ordered.push_back(std::move(c));
  module_->root.children = std::move(ordered);
  if (plan)
    module_->root.add(std::move(*plan));
  if (projects.empty()) {
    // Said above; the write-back writes the project it took the file for.
    std::set<uint64_t> workpieces;
    for (const Node &c : module_->root.children)
      if (c.kind == ir::Kind::Workpiece && c.origin.entityId)
        workpieces.insert(c.origin.entityId);
    std::string list;
    for (uint64_t id : workpieces)
      list += (list.empty() ? "" : ",") + hashId(id);
    newInstance("PROJECT(" + quoted(main.string("its_id").value_or("")) + "," + hashId(main.id()) + ",(" + list +
                "),$,$,$)");
  }
  // Tools no operation uses: what the file leaves implicit of them is
  // written too, so that the written file reads without assumptions.
  for (size_t i = 0; i < entries.size(); ++i)
    if (const Instance t(bound_, i); t.isA("cutting_tool") && !lowered_.count(i))
      writeToolExplicitly(t);
  return std::move(module_);
}

std::unique_ptr<ir::Module> lowerToFeatureIR(const binding::BoundFile &bound, DiagnosticEngine &diags,
                                             const LowerOptions &options) {
  if (express::isAimSchema(bound.schema()))
    return lowerAimToFeatureIR(bound, diags, options);
  Lowerer lowerer(bound, diags, options);
  return lowerer.run();
}

} // namespace stepnc::lowering
