// Lowering of AP238 AIM machining features and of the operations whose path
// stepnc's strategies make (docs/ap238.md).
//
// Features follow ISO 10303-238's mapping of the ISO 14649 features onto the
// machining feature AIC (ISO 10303-522), whose WHERE rules the AIM long form
// spells out:
//
//   feature F: (... FEATURE_DEFINITION() INSTANCED_FEATURE() ROUND_HOLE() ...)
//   F <- property_definition <- *_definition_representation ->
//     shape_representation_with_parameters: 'orientation' (its placement),
//     'fillet radius', ...
//   F <- product_definition_shape <- shape_aspect 'diameter occurrence'
//     <- shape_defining_relationship (related) -> circular_closed_profile
//     (relating), whose own property definitions give 'diameter'
//   the same for 'hole depth occurrence' / 'pocket depth occurrence' (a linear
//   path_feature_component: 'distance'), 'bottom condition occurrence' (a
//   hole_bottom or pocket_bottom, its kind in its description), 'closed
//   boundary occurrence' (a rectangular_closed_profile: 'length', 'width',
//   'corner radius').
//
// Operations without toolpaths are the ARM's operations: the entity and its
// description name the kind ('bottom_and_side_milling_operation' described
// 'roughing'), action properties give its parameters and
// machining_strategy_relationships named 'machining', 'approach' and
// 'retract' its strategies, whose descriptions name them.
#include "frontend/lowering/LowerAim.h"
#include "support/Format.h"

#include <cmath>

namespace stepnc::lowering {

using namespace aim;

namespace {

bool isIdentity(const Placement &p) {
  return p.at.norm() < 1e-9 && (p.axis - Vec3::UnitZ()).norm() < 1e-9 && (p.ref - Vec3::UnitX()).norm() < 1e-9;
}

} // namespace

// --- features ----------------------------------------------------------------------

AimLowerer::Parameters AimLowerer::parameters(const Instance &of) {
  Parameters p;
  auto defs = propertyDefs_.find(of.index());
  if (defs == propertyDefs_.end())
    return p;
  for (size_t d : defs->second) {
    auto reps = definitionReps_.find(d);
    if (reps == definitionReps_.end())
      continue;
    for (size_t r : reps->second) {
      const Instance rep = at(r).ref("used_representation");
      for (const Instance &item : rep.refs("items")) {
        const std::string name = normalName(item.string("name").value_or(""));
        if (item.isA("measure_representation_item")) {
          if (std::optional<Measure> m = measure(item))
            p.measures.emplace(name, *m);
        } else if (item.isA("axis2_placement_3d")) {
          if (std::optional<Placement> placement = base_.placement(item)) {
            placement->at *= lengthFactor(rep);
            p.placements.emplace(name, *placement);
          }
        } else if (item.isA("direction")) {
          if (std::optional<Vec3> dir = base_.direction(item))
            p.directions.emplace(name, *dir);
        }
      }
    }
  }
  return p;
}

std::vector<Instance> AimLowerer::components(const Instance &feature, std::string_view occurrence) {
  std::vector<Instance> out;
  auto defs = propertyDefs_.find(feature.index());
  if (defs == propertyDefs_.end())
    return out;
  for (size_t d : defs->second) {
    auto aspects = aspectsOf_.find(d);
    if (aspects == aspectsOf_.end())
      continue;
    for (size_t a : aspects->second) {
      if (normalName(at(a).string("description").value_or("")) != occurrence)
        continue;
      if (auto rels = aspectRelationsTo_.find(a); rels != aspectRelationsTo_.end())
        for (size_t r : rels->second)
          if (Instance c = at(r).ref("relating_shape_aspect")) {
            out.push_back(c);
            break;
          }
    }
  }
  return out;
}

Instance AimLowerer::component(const Instance &feature, std::string_view occurrence) {
  std::vector<Instance> all = components(feature, occurrence);
  return all.empty() ? Instance() : all.front();
}

std::optional<double> AimLowerer::required(const Instance &of, const Parameters &p, std::string_view name,
                                           const Dims &dims) {
  auto it = p.measures.find(std::string(name));
  if (it == p.measures.end()) {
    base_.missing(of, std::string(name),
                  "is not given: no representation of the " + std::string(of.entityName()) +
                      "'s property definitions has a measure item of that name");
    return std::nullopt;
  }
  if (!(it->second.dims == dims)) {
    wrongUnit(of, of.loc(), name, dims, it->second.dims);
    return std::nullopt;
  }
  return it->second.value;
}

bool AimLowerer::componentLength(const Instance &f, std::string_view occurrence, std::string_view entity,
                                 std::string_view item, Node &n, const char *attribute) {
  const Instance c = component(f, occurrence);
  if (!c.isA(entity)) {
    base_.missing(f, std::string(occurrence),
                  "is not given: no " + std::string(entity) + " of that occurrence gives the feature's " + attribute);
    return false;
  }
  const std::optional<double> v = required(c, parameters(c), item, kLength);
  if (v)
    n.set(attribute, Value::length(*v));
  return v.has_value();
}

bool AimLowerer::isLoweredFeature(const Instance &f) {
  if (f.isA("round_hole"))
    return true;
  if (f.isA("slot"))
    return component(f, "swept shape occurrence").isA("square_u_profile") &&
           normalName(component(f, "course of travel occurrence").string("description").value_or("")) == "linear";
  return f.isA("pocket") && normalName(f.string("description").value_or("")) == "closed rectangular";
}

std::optional<std::string> AimLowerer::machiningFeature(const Instance &f) {
  if (auto it = lowered_.find(f.index()); it != lowered_.end())
    return it->second;
  if (reported_.count(f.index()))
    return std::nullopt;  // said when the first step using it was lowered
  reported_.insert(f.index());
  Node n;
  const Parameters own = parameters(f);
  auto placement = own.placements.find("orientation");
  if (placement == own.placements.end()) {
    base_.missing(f, "orientation",
                  "is not given: the feature's shape_representation_with_parameters places it by an "
                  "axis2_placement_3d named 'orientation'");
    return std::nullopt;
  }
  const bool ok = f.isA("round_hole") ? roundHole(f, n) : f.isA("slot") ? slot(f, n) : pocket(f, n);
  if (!ok)
    return std::nullopt;
  base_.setPlacement(n, placement->second);
  base_.stamp(n, f, "");
  std::optional<std::string> label = f.string("name");
  if (label && !label->empty())
    n.label = *label;
  n.symbol = base_.symbolFor('%', label, n.kindName());
  lowered_[f.index()] = n.symbol;
  for (Node &c : module_->root.children)
    if (c.symbol == workpieceSymbol_)
      c.add(std::move(n));
  return lowered_[f.index()];
}

bool AimLowerer::roundHole(const Instance &f, Node &n) {
  n.kind = ir::Kind::RoundHole;
  bool ok = componentLength(f, "diameter occurrence", "circular_closed_profile", "diameter", n, "diameter");
  ok = componentLength(f, "hole depth occurrence", "path_feature_component", "distance", n, "depth") && ok;
  if (component(f, "change in diameter occurrence"))
    base_.unsupported(f, "a tapered round hole ('change in diameter occurrence')");
  // The bottom's kind (its description), the IR's word for it and the one
  // value that kind requires.
  struct Bottom {
    std::string_view kind, word, item;
    const char *attribute;
    Dims dims;
  };
  static const Bottom kBottoms[] = {
      {"through", "through", {}, nullptr, {}},
      {"flat", "flat", {}, nullptr, {}},
      {"flat with radius", "flat_with_radius", "corner radius", "bottom_radius", kLength},
      {"spherical", "spherical", "radius", "bottom_radius", kLength},
      {"conical", "conical", "tip angle", "tip_angle", kAngle}};
  const Instance bottom = component(f, "bottom condition occurrence");
  if (!bottom.isA("hole_bottom")) {
    base_.missing(f, "bottom condition occurrence",
                  "is not given: a round hole's bottom is a hole_bottom its 'bottom condition occurrence' uses");
    return false;
  }
  const std::string kind = normalName(bottom.string("description").value_or(""));
  const Bottom *row = nullptr;
  for (const Bottom &r : kBottoms)
    if (r.kind == kind)
      row = &r;
  if (!row) {
    base_.unsupported(bottom, "hole bottom '" + kind + "'");
    return false;
  }
  n.set("bottom", Value::word(std::string(row->word)));
  const Parameters b = parameters(bottom);
  if (row->attribute) {
    if (auto v = required(bottom, b, row->item, row->dims))
      n.set(row->attribute, row->dims == kAngle ? Value::angle(*v) : Value::length(*v));
    else
      ok = false;
  }
  if (auto r = b.value("tip radius", kLength); r && kind == "conical")
    n.set("tip_radius", Value::length(*r));
  return ok;
}

bool AimLowerer::pocket(const Instance &f, Node &n) {
  n.kind = ir::Kind::ClosedPocket;
  bool ok = true;
  const Parameters own = parameters(f);
  if (auto r = own.value("fillet radius", kLength))
    n.set("planar_radius", Value::length(*r));
  ok = componentLength(f, "pocket depth occurrence", "path_feature_component", "distance", n, "depth") && ok;
  const Instance bottom = component(f, "bottom condition occurrence");
  const std::string kind = normalName(bottom.string("description").value_or(""));
  if (!bottom) {
    // ISO 14649's default: a pocket with a flat floor.
    n.set("bottom", Value::word("planar"));
  } else if (kind == "planar" || kind == "through") {
    n.set("bottom", Value::word(kind));
  } else {
    base_.unsupported(bottom, "pocket bottom '" + kind + "'");
    ok = false;
  }
  const Instance boundary = component(f, "closed boundary occurrence");
  if (!boundary.isA("rectangular_closed_profile")) {
    base_.missing(f, "closed boundary occurrence",
                  "is not given: a closed rectangular pocket's boundary is a rectangular_closed_profile its "
                  "'closed boundary occurrence' uses");
    return false;
  }
  const Parameters p = parameters(boundary);
  Node profile(ir::Kind::RectangularProfile);
  base_.stamp(profile, boundary, "");
  const std::optional<double> width = required(boundary, p, "width", kLength),
                              length = required(boundary, p, "length", kLength);
  if (!width || !length)
    return false;
  profile.set("width", Value::length(*width));
  profile.set("length", Value::length(*length));
  if (auto o = p.placements.find("orientation"); o != p.placements.end() && !isIdentity(o->second))
    base_.setPlacement(profile, o->second);
  if (auto r = p.value("corner radius", kLength))
    n.set("orthogonal_radius", Value::length(*r));
  n.add(std::move(profile));
  return ok;
}

bool AimLowerer::slot(const Instance &f, Node &n) {
  // A straight slot of square U section (isLoweredFeature): its course of
  // travel a linear path feature component, its depth the profile's.
  n.kind = ir::Kind::Slot;
  bool ok = true;
  const Instance course = component(f, "course of travel occurrence");
  const Parameters c = parameters(course);
  Node path(ir::Kind::Path);
  base_.stamp(path, course, "");
  Node line(ir::Kind::Line);
  line.set("at", Value::point(Vec3::Zero()));
  line.set("dir", Value::direction(c.directions.empty() ? Vec3::UnitX() : c.directions.begin()->second.normalized()));
  if (auto d = required(course, c, "distance", kLength))
    line.set("length", Value::length(*d));
  else
    ok = false;
  path.add(std::move(line));
  const Instance shape = component(f, "swept shape occurrence");
  const Parameters s = parameters(shape);
  Node profile(ir::Kind::SquareUProfile);
  base_.stamp(profile, shape, "");
  const std::optional<double> width = required(shape, s, "width", kLength), depth = required(shape, s, "depth", kLength);
  if (!width || !depth)
    return false;
  profile.set("width", Value::length(*width));
  n.set("depth", Value::length(*depth));
  for (const auto &[item, attribute, dims] : {std::tuple{"first radius", "first_radius", kLength},
                                              {"first angle", "first_angle", kAngle},
                                              {"second radius", "second_radius", kLength},
                                              {"second angle", "second_angle", kAngle}})
    if (auto v = s.value(item, dims))
      profile.set(attribute, dims == kAngle ? Value::angle(*v) : Value::length(*v));
  // Its ends, in the order of their occurrences; a slot that gives fewer is open there.
  const std::vector<Instance> ends = components(f, "end condition occurrence");
  if (ends.size() > 2) {
    base_.missing(f, "end condition occurrence", "is given " + std::to_string(ends.size()) + " times: a slot has two ends");
    return false;
  }
  for (size_t i = 0; i < 2; ++i) {
    std::string word = "open";
    if (i < ends.size()) {
      word = normalName(ends[i].string("description").value_or(""));
      if (word == "woodruff") {
        if (auto r = required(ends[i], parameters(ends[i]), "radius", kLength))
          n.set("end_radius", Value::length(*r));
        else
          ok = false;
      } else if (word != "open" && word != "radiused" && word != "flat" && word != "loop") {
        base_.unsupported(ends[i], "slot end '" + word + "'");
        ok = false;
        continue;
      }
    }
    n.set(i == 0 ? "end_1" : "end_2", Value::word(word));
  }
  n.add(std::move(path));
  n.add(std::move(profile));
  return ok;
}

// --- operations left to stepnc's strategies ------------------------------------------

namespace {

/// An operation entity with the description that says which ARM operation it is.
struct OperationRow {
  std::string_view entity, description;
  ir::Kind kind;
};

/// The kind of the first row whose entity `op` is and whose description it has.
template <size_t N>
std::optional<ir::Kind> operationKind(const Instance &op, const std::string &description,
                                      const OperationRow (&rows)[N]) {
  for (const OperationRow &r : rows)
    if (op.isA(r.entity) && description == r.description)
      return r.kind;
  return std::nullopt;
}

} // namespace

std::optional<ir::Kind> AimLowerer::strategyOperationKind(const Instance &op) {
  static const OperationRow kRows[] = {
      {"drilling_operation", "drilling", ir::Kind::Drilling},
      {"drilling_operation", "center drilling", ir::Kind::CenterDrilling},
      {"drilling_operation", "counter sinking", ir::Kind::CounterSinking},
      {"drilling_operation", "multistep drilling", ir::Kind::MultistepDrilling},
      {"boring_operation", "boring", ir::Kind::Boring},
      {"boring_operation", "reaming", ir::Kind::Reaming},
      {"tapping_operation", "tapping", ir::Kind::Tapping},
      {"tapping_operation", "thread drilling", ir::Kind::ThreadDrilling},
      {"bottom_and_side_milling_operation", "roughing", ir::Kind::BottomAndSideRoughMilling},
      {"bottom_and_side_milling_operation", "finishing", ir::Kind::BottomAndSideFinishMilling},
      {"plane_milling_operation", "roughing", ir::Kind::PlaneRoughMilling},
      {"plane_milling_operation", "finishing", ir::Kind::PlaneFinishMilling},
      {"side_milling_operation", "roughing", ir::Kind::SideRoughMilling},
      {"side_milling_operation", "finishing", ir::Kind::SideFinishMilling},
  };
  const std::string description = normalName(op.string("description").value_or(""));
  if (std::optional<ir::Kind> kind = operationKind(op, description, kRows))
    return kind;
  report(op, op.loc(),
         "a " + std::string(op.entityName()) + " described '" + description +
             "' without toolpaths: not an operation stepnc's strategies make (docs/ap238.md)");
  return std::nullopt;
}

std::optional<ir::Kind> AimLowerer::turningOperationKind(const Instance &op) {
  static const OperationRow kRows[] = {
      {"contouring_turning_operation", "roughing", ir::Kind::ContouringRough},
      {"contouring_turning_operation", "finishing", ir::Kind::ContouringFinish},
      {"facing_turning_operation", "roughing", ir::Kind::FacingRough},
      {"facing_turning_operation", "finishing", ir::Kind::FacingFinish},
      {"grooving_turning_operation", "roughing", ir::Kind::GroovingRough},
      {"grooving_turning_operation", "finishing", ir::Kind::GroovingFinish},
      {"threading_turning_operation", "roughing", ir::Kind::ThreadingRough},
      {"threading_turning_operation", "finishing", ir::Kind::ThreadingFinish},
  };
  if (op.isA("knurling_turning_operation"))
    return ir::Kind::Knurling;
  const std::string description = normalName(op.string("description").value_or(""));
  if (std::optional<ir::Kind> kind = operationKind(op, description, kRows))
    return kind;
  report(op, op.loc(),
         "a " + std::string(op.entityName()) + " described '" + description +
             "': not a turning operation of ISO 14649-12 (roughing or finishing; docs/turning.md)");
  return std::nullopt;
}

std::optional<Measure> AimLowerer::propertyMeasure(const Instance &of, std::string_view property) {
  for (const Instance &rep : propertyRepresentations(of, property, false))
    for (const Instance &item : rep.refs("items"))
      if (item.isA("measure_representation_item"))
        return measure(item);
  return std::nullopt;
}

void AimLowerer::operationParameters(const Instance &op, Node &n) {
  struct Row {
    std::string_view property;
    const char *attribute;
    Dims dims;
  };
  static const Row kRows[] = {
      {"retract plane", "retract_plane", kLength},         {"overcut length", "overcut", kLength},
      {"axial cutting depth", "axial_depth", kLength},     {"radial cutting depth", "radial_depth", kLength},
      {"allowance side", "allowance_side", kLength},       {"allowance bottom", "allowance_bottom", kLength},
      {"cutting depth", "cutting_depth", kLength},         {"previous diameter", "previous_diameter", kLength},
      {"dwell time bottom", "dwell_bottom", kTime},        {"feedrate on retract", "feed_on_retract", Dims{}},
      {"retract distance", "retract_distance", kLength},   {"first depth", "first_depth", kLength},
      {"depth of step", "depth_increment", kLength},       {"dwell time step", "dwell_step", kTime},
      {"testcut depth", "depth_of_testcut", kLength},
  };
  const ir::KindSpec &spec = ir::specOf(n.kind);
  for (auto &[property, rep] : properties(op, false)) {
    const Row *row = nullptr;
    for (const Row &r : kRows)
      if (property == r.property)
        row = &r;
    if (!row) {
      if (property == "spindle stop") {
        if (auto w = word(op, property))
          n.set("spindle_stop_bottom", Value::boolean(*w == "spindle stop at bottom"));
      } else if (property == "cut start point" || property == "waiting position") {
        for (const Instance &item : rep.refs("items"))
          if (item.isA("cartesian_point"))
            if (std::optional<Vec3> p = base_.point(item))
              n.set(property == "cut start point" ? "start_point" : "waiting_position",
                    Value::point(*p * lengthFactor(rep)));
      } else if (property != "tool direction" && reported_.insert(rep.index()).second) {
        diags_.remark(rep.loc(), "operation property '" + property + "' is not read by stepnc")
            .entity(rep.id(), entityUpper(rep));
      }
      continue;
    }
    if (!ir::findAttr(spec, row->attribute)) {
      diags_.remark(rep.loc(), "operation property '" + property + "' does not apply to a " +
                                   std::string(n.kindName()) + "; not read")
          .entity(rep.id(), entityUpper(rep));
      continue;
    }
    std::optional<Measure> m = propertyMeasure(op, property);
    if (!m)
      continue;
    if (!(m->dims == row->dims)) {
      wrongUnit(rep, rep.loc(), property, row->dims, m->dims);
      continue;
    }
    if (row->dims == kLength)
      n.set(row->attribute, Value::length(m->value));
    else if (row->dims == kTime)
      n.set(row->attribute, Value::time(m->value));
    else
      n.set(row->attribute, Value::ratio(m->value));
  }
}

void AimLowerer::strategies(const Instance &op, Node &n) {
  // The machining strategy: a milling_type_strategy or drilling_type_strategy.
  for (const Instance &s : related(op, "machining_strategy_relationship", "machining")) {
    const std::string d = normalName(s.string("description").value_or(""));
    if (s.isA("drilling_type_strategy")) {
      Node ds(ir::Kind::DrillingStrategy);
      base_.stamp(ds, s, "");
      static const std::pair<std::string_view, const char *> kDrilling[] = {
          {"reduced cut at start", "reduced_cut_at_start"}, {"reduced feedrate at start", "reduced_feed_at_start"},
          {"depth of start", "depth_of_start"},             {"reduced cut at end", "reduced_cut_at_end"},
          {"reduced feedrate at end", "reduced_feed_at_end"}, {"depth of end", "depth_of_end"}};
      for (const auto &[property, attribute] : kDrilling)
        if (std::optional<Measure> m = propertyMeasure(s, property)) {
          const bool length = std::string_view(attribute).starts_with("depth");
          if (length ? m->dims == kLength : m->dims == Dims{})
            ds.set(attribute, length ? Value::length(m->value) : Value::ratio(m->value));
          else
            wrongUnit(s, s.loc(), property, length ? kLength : Dims{}, m->dims);
        }
      n.add(std::move(ds));
      continue;
    }
    static const std::pair<std::string_view, std::string_view> kTypes[] = {
        {"unidirectional", "unidirectional"},         {"bidirectional", "bidirectional"},
        {"contour parallel", "contour_parallel"},     {"contour spiral", "contour_spiral"},
        {"contour bidirectional", "contour_bidirectional"}, {"bidirectional contour", "bidirectional_contour"},
        {"center milling", "center_milling"}};
    std::string_view type;
    for (const auto &[name, irType] : kTypes)
      if (d == name)
        type = irType;
    if (!s.isA("milling_type_strategy") || type.empty()) {
      base_.unsupported(s, "machining strategy '" + d + "'");
      continue;
    }
    Node ms(ir::Kind::Strategy);
    base_.stamp(ms, s, "");
    ms.set("type", Value::word(std::string(type)));
    if (std::optional<Measure> m = propertyMeasure(s, "overlap ratio"))
      ms.set("overlap", Value::ratio(m->value));
    if (auto w = word(s, "multiple passes"))
      ms.set("multiple_passes", Value::boolean(*w == "multiple passes allowed"));
    for (const Instance &rep : propertyRepresentations(s, "feed direction", false))
      for (const Instance &item : rep.refs("items"))
        if (item.isA("direction"))
          if (auto dir = base_.direction(item))
            ms.set("feed_dir", Value::direction(*dir));
    if (auto w = word(s, "stepover direction"); w && (*w == "left" || *w == "right"))
      ms.set("stepover_dir", Value::word(*w));
    static const std::pair<std::string_view, std::string_view> kConnections[] = {
        {"straight line", "straightline"}, {"lift shift plunge", "lift_shift_plunge"},
        {"degouge", "degouge"},            {"loop back", "loop_back"}};
    if (auto w = word(s, "connection strategy"))
      for (const auto &[name, irWord] : kConnections)
        if (*w == name)
          ms.set("stroke_connection", Value::word(std::string(irWord)));
    if (auto w = word(s, "rotation direction"); w && (*w == "clockwise" || *w == "counterclockwise"))
      ms.set("rotation", Value::word(*w == "clockwise" ? "cw" : "ccw"));
    if (auto w = word(s, "cutmode"); w && (*w == "climb" || *w == "conventional"))
      ms.set("cutmode", Value::word(*w));
    n.add(std::move(ms));
  }
  // Approach and retract.
  for (auto [name, irKind] : {std::pair{"approach", ir::Kind::Approach}, {"retract", ir::Kind::Retract}})
    for (const Instance &s : related(op, "machining_strategy_relationship", name)) {
      static const std::pair<std::string_view, std::string_view> kTypes[] = {
          {"plunge toolaxis", "plunge_toolaxis"},
          {"plunge ramp", "plunge_ramp"},
          {"plunge helix", "plunge_helix"},
          {"plunge zigzag", "plunge_zigzag"},
          {"along path", "along_path"},
          {"approach retract angle", "retract_angle"},
          {"approach retract tangent", "retract_tangent"}};
      const std::string d = normalName(s.string("description").value_or(""));
      std::string_view type;
      for (const auto &[word, irType] : kTypes)
        if (d == word)
          type = irType;
      if (type.empty()) {
        base_.unsupported(s, "approach or retract strategy '" + d + "'");
        continue;
      }
      Node a(irKind);
      base_.stamp(a, s, "");
      a.set("type", Value::word(std::string(type)));
      struct Row {
        std::string_view property;
        const char *attribute;
        Dims dims;
      };
      static const Row kRows[] = {{"plunge angle", "angle", kAngle},    {"travel angle", "angle", kAngle},
                                  {"plunge radius", "radius", kLength}, {"travel radius", "radius", kLength},
                                  {"plunge width", "width", kLength},   {"travel length", "travel_length", kLength}};
      for (const Row &r : kRows)
        if (std::optional<Measure> m = propertyMeasure(s, r.property)) {
          if (!(m->dims == r.dims))
            wrongUnit(s, s.loc(), r.property, r.dims, m->dims);
          else
            a.set(r.attribute, r.dims == kAngle ? Value::angle(m->value) : Value::length(m->value));
        }
      for (const Instance &rep : propertyRepresentations(s, "tool orientation", false))
        for (const Instance &item : rep.refs("items"))
          if (item.isA("direction"))
            if (auto dir = base_.direction(item))
              a.set("tool_orientation", Value::direction(*dir));
      n.add(std::move(a));
    }
}

} // namespace stepnc::lowering
