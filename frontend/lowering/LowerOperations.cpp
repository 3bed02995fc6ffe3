// Lowering of operations (ISO 14649-10/11/12): milling, drilling-type and
// turning operations with their technology, machine functions, strategies
// and approach/retract, explicit toolpaths; and the tools they use (ISO
// 14649-111 and -121).
#include "frontend/lowering/Lowerer.h"
#include "frontend/lowering/ToolBodies.h"
#include "frontend/express/Schema.h"
#include "ir/Plausible.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace stepnc::lowering {

namespace {

// ARM entity -> IR operation kind (the IR keeps the ARM's names). Order
// matters only for readability: each entity is concrete, so exactly one matches.
constexpr std::pair<std::string_view, ir::Kind> kOperations[] = {
    {"plane_rough_milling", ir::Kind::PlaneRoughMilling},
    {"plane_finish_milling", ir::Kind::PlaneFinishMilling},
    {"bottom_and_side_rough_milling", ir::Kind::BottomAndSideRoughMilling},
    {"bottom_and_side_finish_milling", ir::Kind::BottomAndSideFinishMilling},
    {"side_rough_milling", ir::Kind::SideRoughMilling},
    {"side_finish_milling", ir::Kind::SideFinishMilling},
    {"freeform_operation", ir::Kind::FreeformOperation},
    {"drilling", ir::Kind::Drilling},
    {"center_drilling", ir::Kind::CenterDrilling},
    {"counter_sinking", ir::Kind::CounterSinking},
    {"multistep_drilling", ir::Kind::MultistepDrilling},
    {"reaming", ir::Kind::Reaming},
    {"boring", ir::Kind::Boring},
    {"tapping", ir::Kind::Tapping},
    {"thread_drilling", ir::Kind::ThreadDrilling},
    // ISO 14649-12 turning operations.
    {"contouring_rough", ir::Kind::ContouringRough},
    {"contouring_finish", ir::Kind::ContouringFinish},
    {"facing_rough", ir::Kind::FacingRough},
    {"facing_finish", ir::Kind::FacingFinish},
    {"grooving_rough", ir::Kind::GroovingRough},
    {"grooving_finish", ir::Kind::GroovingFinish},
    {"cutting_in", ir::Kind::CuttingIn},
    {"threading_rough", ir::Kind::ThreadingRough},
    {"threading_finish", ir::Kind::ThreadingFinish},
    {"knurling", ir::Kind::Knurling}};

// ISO 14649-121 turning tool body entity -> IR tool type.
constexpr std::pair<std::string_view, std::string_view> kTurningBodies[] = {
    {"general_turning_tool", "turning_tool"},
    {"turning_threading_tool", "threading_tool"},
    {"grooving_tool", "grooving_tool"},
    {"knurling_tool", "knurling_tool"}};

// ISO 14649-12 turning strategy entity -> IR turning_strategy type; most
// specific first.
constexpr std::pair<std::string_view, std::string_view> kTurningStrategies[] = {
    {"unidirectional_perpendicular", "unidirectional_perpendicular"},
    {"unidirectional_diagonal", "unidirectional_diagonal"},
    {"bidirectional_turning", "bidirectional"},
    {"contour_turning", "contour"},
    {"thread_strategy", "thread"},
    {"multistep_grooving_strategy", "multistep_grooving"},
    {"grooving_strategy", "grooving"},
    {"explicit_turning_strategy", "explicit"}};

constexpr std::pair<std::string_view, std::string_view> kStrategies[] = {
    {"unidirectional", "unidirectional"},       {"bidirectional", "bidirectional"},
    {"contour_parallel", "contour_parallel"},   {"contour_spiral", "contour_spiral"},
    {"contour_bidirectional", "contour_bidirectional"}, {"bidirectional_contour", "bidirectional_contour"},
    {"center_milling", "center_milling"},       {"explicit_strategy", "explicit"}};

} // namespace

bool Lowerer::toolFromUse(const Instance &t, Node &n) {
  const Instance &op = use_.operation, &f = use_.feature;
  if (!op || !f)
    return false;
  std::string_view type;
  std::optional<double> diameter;
  std::string why;
  if (op.isA("drilling_type_operation") && f.isA("round_hole")) {
    type = op.isA("reaming")                                  ? "reamer"
           : op.isA("tapping") || op.isA("thread_drilling")   ? "tap"
           : op.isA("boring_operation")                       ? "boring_tool"
           : op.isA("center_drilling")                        ? "center_drill"
                                                              : "twist_drill";
    diameter = toleranced(f, "diameter");
    why = "the diameter of the hole " + hashId(f.id()) + " it makes";
  } else if (op.isA("milling_type_operation") && f.isA("slot")) {
    Instance shape = f.ref("swept_shape");
    if (!shape.isA("square_u_profile") && !shape.isA("rounded_u_profile"))
      return false;
    const std::optional<double> width = toleranced(shape, "width");
    const double allowance = op.real("allowance_side").value_or(0.0);
    if (!width)
      return false;
    type = "endmill";
    diameter = *width - 2 * allowance;
    why = "the width " + formatFixed(*width, 4) + " mm of the slot " + hashId(f.id()) + " it mills" +
          (allowance > 0 ? " less twice the side allowance " + formatFixed(allowance, 4) + " mm" : "");
  }
  if (type.empty() || !diameter || *diameter <= 0)
    return false;
  n.set("type", Value::word(std::string(type)));
  n.set("diameter", Value::length(*diameter));
  // The body as ISO 14649-111 writes it: the entity of the tool type, its
  // dimension the diameter; a boring tool also says whether it may retract
  // with the spindle turning (not forbidden: what the program does).
  std::string entity = express::upper(toolBodyEntity(type));
  fix(t, "its_tool_body",
      newInstance(entity + "(" + newInstance("MILLING_TOOL_DIMENSION(" + real(*diameter) + ",$,$,$,$,$,$)") +
                  ",$,$,$,$" + (type == "boring_tool" ? ",.F.)" : ")")));
  assumed(t, "its_tool_body",
          "absent (no type, no dimension); assumed from its use by " + hashId(op.id()) + " " +
              std::string(op.entityName()) + ": type " + std::string(type) + ", diameter " +
              formatFixed(*diameter, 4) + " mm (" + why + ")");
  return true;
}

void Lowerer::turningToolBody(const Instance &body, Node &n) {
  if (Instance dim = body.ref("dimension")) {
    copyReal(n, "corner_radius", dim, "nose_radius", Value::length);
    copyReal(n, "cutting_edge_length", dim, "cutting_edge_length", Value::length);
    copyAngle(n, "side_edge_angle", dim, "side_cutting_edge_angle");
    copyAngle(n, "end_edge_angle", dim, "end_cutting_edge_angle");
    copyReal(n, "diameter", dim, "circle_diameter", Value::length);  // a round insert's
  } else {
    missing(body, "dimension");
  }
  if (auto hand = body.enumeration("hand_of_tool"))
    n.set("hand", Value::word(*hand));
  copyReal(n, "max_cutting_depth", body, "maximum_cutting_depth", Value::length);
  if (body.isA("grooving_tool")) {
    copyReal(n, "cutting_width", body, "cutting_width", Value::length);
    copyReal(n, "corner_radius", body, "corner_radius", Value::length);
  } else if (body.isA("turning_threading_tool")) {
    copyReal(n, "thread_pitch", body, "threading_pitch", Value::length);
    copyAngle(n, "thread_angle", body, "threading_angle");
  } else if (body.isA("knurling_tool")) {
    copyReal(n, "cutting_width", body, "cutting_length", Value::length);
    copyReal(n, "knurl_pitch", body, "pitch", Value::length);
    if (auto pattern = body.enumeration("knurl_pattern_type"); pattern && (*pattern == "straight" ||
                                                                         *pattern == "diagonal" || *pattern == "diamond"))
      n.set("knurl_pattern", Value::word(*pattern));
  }
}

void Lowerer::writeToolExplicitly(const Instance &t) {
  // An abstract cutting_tool (binding read it as written) is the milling
  // cutting tool its body describes: ISO 14649-111 makes drills, taps and
  // reamers milling cutting tools too. The subtype adds two optional
  // attributes after the four of cutting_tool.
  if (t.entityName() == "cutting_tool" && t.parameterIndex("its_tool_body") >= 0) {
    fixAt(t.id(), -1, "MILLING_CUTTING_TOOL");
    for (int extra : {4, 5})
      fixAt(t.id(), extra, "$");
  }
  // A cutting edge the file leaves out or lists none of, or one without its
  // offset length: the tool's overall assembly length is the length from
  // the gauge line to the tip, which is what the edge's offset length says.
  const std::optional<double> overall = t.real("overall_assembly_length");
  if (!overall || *overall <= 0)
    return;
  const std::string length = real(*overall);
  const std::vector<Instance> edges = t.refs("its_cutting_edge");
  if (edges.empty())
    fix(t, "its_cutting_edge", "(" + newInstance("CUTTING_COMPONENT(" + length + ",$,$,$,$)") + ")");
  for (const Instance &edge : edges)
    if (!edge.real("tool_offset_length") && edge.isA("cutting_component"))
      fix(edge, "tool_offset_length", length);
}

std::optional<std::string> Lowerer::tool(const Instance &t) {
  if (!t)
    return std::nullopt;
  if (auto it = lowered_.find(t.index()); it != lowered_.end())
    return it->second;
  if (t.isA("deposition_head"))
    return depositionHead(t);
  if (!t.isA("cutting_tool")) {
    unsupported(t, "tool");
    return std::nullopt;
  }
  Node n(ir::Kind::Tool);
  stamp(n, t);
  n.symbol = symbolFor('%', t.string("its_id"), "tool");
  Instance body = t.ref("its_tool_body");
  std::string_view type = "cutting_tool";
  for (const auto &[entity, word] : kToolBodies)
    if (body.isA(entity)) {
      type = word;
      break;
    }
  for (const auto &[entity, word] : kTurningBodies)
    if (body.isA(entity))
      type = word;
  if (body && type == "cutting_tool")
    unsupported(body, "tool body");
  n.set("type", Value::word(std::string(type)));
  if (body.isA("turning_machine_tool_body")) {
    turningToolBody(body, n);
    if (t.isA("turning_machine_tool"))
      copyReal(n, "min_cutting_diameter", t, "minimum_cutting_diameter", Value::length);
  } else if (body) {
    if (Instance dim = body.ref("dimension")) {
      copyReal(n, "diameter", dim, "diameter", Value::length);
      copyReal(n, "corner_radius", dim, "edge_radius", Value::length);
      copyAngle(n, "tip_half_angle", dim, "tool_tip_half_angle");
      copyAngle(n, "circumference_angle", dim, "tool_circumference_angle");
      copyReal(n, "cutting_edge_length", dim, "cutting_edge_length", Value::length);
      copyReal(n, "edge_center_vertical", dim, "edge_center_vertical", Value::length);
      copyReal(n, "edge_center_horizontal", dim, "edge_center_horizontal", Value::length);
    } else {
      missing(body, "dimension");
    }
    if (auto teeth = body.integer("number_of_teeth"))
      n.set("flutes", Value::integer(*teeth));
    if (auto hand = body.enumeration("hand_of_cut"))
      n.set("hand", Value::word(*hand));
    copyFlag(n, "coolant_through", body, "coolant_through_tool");
    copyAngle(n, "taper_angle", body, "taper_angle");
  } else if (!toolFromUse(t, n)) {
    missing(t, "its_tool_body");
  }
  copyReal(n, "overall_length", t, "overall_assembly_length", Value::length);
  copyReal(n, "holder_diameter", t, "tool_holder_diameter_for_spindle_orientation", Value::length);
  writeToolExplicitly(t);
  std::vector<Instance> edges = t.refs("its_cutting_edge");
  if (!edges.empty())
    if (auto offset = edges[0].real("tool_offset_length"))
      n.set("offset_length", Value::length(*offset));
  const std::string symbol = n.symbol;
  lowered_[t.index()] = symbol;
  module_->root.add(std::move(n));
  return symbol;
}

namespace {

// Feeds, cutting speeds and spindle speeds whose unit the ARM leaves implicit
// are read in the unit chosen for the file (Lowerer::chooseSpeedUnits). A
// converted value still far outside what machines do: say so, as read.
void checkPlausible(Lowerer &l, const Instance &tech, std::string_view attribute, double value, double low,
                    double high, const char *unit) {
  if (value == 0.0 || (std::abs(value) >= low && std::abs(value) <= high))
    return;
  char text[200];
  std::snprintf(text, sizeof text, "%s %g read as %.1f %s, outside %g..%g %s: the file may use another unit",
                std::string(attribute).c_str(), *tech.real(attribute), value, unit, low, high, unit);
  std::string entity(tech.entityName());
  std::transform(entity.begin(), entity.end(), entity.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  l.diags().warning(tech.attrLoc(attribute), text).entity(tech.id(), entity);
}

/// A strategy node of `kind` whose `type` is the word `table` gives the
/// first entity `strategy` is (the table lists the most specific first);
/// none, after saying so, when it is none of them.
template <size_t N>
std::optional<Node> typedStrategy(Lowerer &l, const Instance &strategy,
                                  const std::pair<std::string_view, std::string_view> (&table)[N], ir::Kind kind,
                                  std::string_view what) {
  const auto row = std::ranges::find_if(table, [&](const auto &r) { return strategy.isA(r.first); });
  if (row == std::end(table)) {
    l.unsupported(strategy, what);
    return std::nullopt;
  }
  Node s(kind);
  l.stamp(s, strategy, "");
  s.set("type", Value::word(std::string(row->second)));
  return s;
}

/// What every 2.5D milling strategy has: overlap and multiple passes.
void commonStrategyAttributes(Lowerer &l, Node &s, const Instance &strategy) {
  if (auto o = strategy.real("overlap")) {
    s.set("overlap", Value::ratio(*o));
    if (*o > 1.0)
      l.diags()
          .warning(strategy.attrLoc("overlap"),
                   "overlap " + formatFixed(*o, 4) +
                       " is more than 1: ISO 14649 gives it as a ratio (0.5 = 50 %); read as written, the file may "
                       "mean percent")
          .entity(strategy.id(), std::string(strategy.entityName()));
  }
  copyFlag(s, "multiple_passes", strategy, "allow_multiple_passes");
}

/// A 2.5D milling strategy: an ordinary one as `strategy`, a pattern
/// strategy (stepnc's extension schema) as `trochoidal_strategy` or
/// `plunge_strategy` with its guide as child. None, after a diagnostic, for
/// a strategy stepnc does not know.
std::optional<Node> millingStrategy(Lowerer &l, const Instance &strategy) {
  const bool trochoidal = strategy.isA("trochoidal_milling");
  if (trochoidal || strategy.isA("plunge_milling")) {
    Node p(trochoidal ? ir::Kind::TrochoidalStrategy : ir::Kind::PlungeStrategy);
    l.stamp(p, strategy, "");
    commonStrategyAttributes(l, p, strategy);
    if (trochoidal) {
      copyReal(p, "radius", strategy, "trochoid_radius", Value::length);
      copyReal(p, "step", strategy, "step_per_revolution", Value::length);
      copyWord(p, "rotation", strategy, "rotation_direction");
      copyWord(p, "cutmode", strategy, "cutmode");
    } else {
      copyReal(p, "clearance", strategy, "clearance_height", Value::length);
      copyReal(p, "retract_offset", strategy, "retract_offset", Value::length);
      copyReal(p, "bottom_radius", strategy, "plunge_bottom_radius", Value::length);
      copyReal(p, "radial_step", strategy, "radial_step", Value::length);
      copyReal(p, "link_radius", strategy, "link_radius", Value::length);
    }
    Instance guide = strategy.ref("guide");
    if (guide.isA("pattern_strategy")) {
      l.diags()
          .error(strategy.attrLoc("guide"), "the guide of a pattern strategy is an ordinary 2.5D strategy, found " +
                                                std::string(guide.entityName()))
          .entity(strategy.id(), std::string(strategy.entityName()));
      return std::nullopt;
    }
    if (!guide) {
      l.missing(strategy, "guide");
      return std::nullopt;
    }
    std::optional<Node> g = millingStrategy(l, guide);
    if (!g)
      return std::nullopt;
    p.add(std::move(*g));
    return p;
  }
  std::optional<Node> typed = typedStrategy(l, strategy, kStrategies, ir::Kind::Strategy, "machining strategy");
  if (!typed)
    return std::nullopt;
  Node &s = *typed;
  commonStrategyAttributes(l, s, strategy);
  if (Instance fd = strategy.ref("feed_direction"))
    if (auto d = l.direction(fd))
      s.set("feed_dir", Value::direction(*d));
  copyWord(s, "stepover_dir", strategy, "stepover_direction");
  if (auto w = strategy.enumeration("its_stroke_connection_strategy"))
    s.set("stroke_connection", Value::word(*w == "straghtline" ? "straightline" : *w));  // the ARM's spelling
  copyWord(s, "rotation", strategy, "rotation_direction");
  copyWord(s, "cutmode", strategy, "cutmode");
  copyFlag(s, "spiral_cutmode_change", strategy, "spiral_cutmode_change");
  return typed;
}

/// A turning technology (ISO 14649-12): a constant spindle speed, or a
/// constant cutting speed (CSS) clamped by a maximum spindle speed; a feed
/// per revolution, or per minute.
Node turningTechnology(Lowerer &l, const Instance &tech) {
  Node n(ir::Kind::Technology);
  if (auto f = tech.real("feedrate"))
    n.set("feed", Value::feed(l.feedMmPerMin(*f)));
  if (auto f = tech.real("feedrate_per_revolution")) {
    if (*f <= 0)
      l.missing(tech, "feedrate_per_revolution", "is not positive: a feed per revolution is a length (mm) above 0");
    else if (*f < ir::kPlausibleMinFeedPerRev || *f > ir::kPlausibleMaxFeedPerRev)
      l.missing(tech, "feedrate_per_revolution",
                "is " + formatShortest(*f) + " mm/rev, outside what a lathe feeds (" +
                    formatShortest(ir::kPlausibleMinFeedPerRev) + " to " + formatShortest(ir::kPlausibleMaxFeedPerRev) +
                    " mm per revolution)");
    else
      n.set("feed_per_rev", Value::feedPerRev(*f));
  }
  Instance speed = tech.ref("spindle_speed");
  if (speed.isA("const_spindle_speed")) {
    if (auto s = speed.real("rot_speed")) {
      const double rpm = l.spindleRevPerMin(*s);
      n.set("spindle", Value::spindle(rpm));
      checkPlausible(l, speed, "rot_speed", rpm, ir::kPlausibleMinSpindleRpm, ir::kPlausibleMaxSpindleRpm, "rev/min");
    } else {
      l.missing(speed, "rot_speed");
    }
  } else if (speed.isA("const_cutting_speed")) {
    if (auto v = speed.real("speed")) {
      const double mmPerMin = l.cuttingSpeedMmPerMin(*v);
      n.set("cutting_speed", Value::feed(mmPerMin));
      checkPlausible(l, speed, "speed", mmPerMin, 1000 * ir::kPlausibleMinCuttingSpeedMPerMin,
                     1000 * ir::kPlausibleMaxCuttingSpeedMPerMin, "mm/min");
    } else {
      l.missing(speed, "speed");
    }
    if (auto m = speed.real("max_speed"))
      n.set("spindle_max", Value::spindle(std::abs(l.spindleRevPerMin(*m))));
  } else if (speed) {
    l.unsupported(speed, "spindle speed");
  } else {
    l.missing(tech, "spindle_speed");
  }
  const std::optional<std::string> reference = tech.enumeration("feedrate_reference");
  n.set("feed_reference", Value::word(reference.value_or("tcp")));
  if (!reference)
    l.fix(tech, "feedrate_reference", ".TCP.");
  copyFlag(n, "sync_spindle_feed", tech, "sync_spindle_and_z_feed");
  copyFlag(n, "inhibit_feed_override", tech, "inhibit_feedrate_override");
  copyFlag(n, "inhibit_spindle_override", tech, "inhibit_spindle_override");
  return n;
}

/// A turning strategy (ISO 14649-12) with the attributes of its type.
std::optional<Node> turningStrategy(Lowerer &l, const Instance &strategy) {
  std::optional<Node> typed =
      typedStrategy(l, strategy, kTurningStrategies, ir::Kind::TurningStrategy, "turning strategy");
  if (!typed)
    return std::nullopt;
  Node &s = *typed;
  copyReal(s, "overcut", strategy, "overcut_length", Value::length);
  copyFlag(s, "multiple_passes", strategy, "allow_multiple_passes");
  if (std::vector<double> depths = strategy.reals("cutting_depth"); !depths.empty())
    s.set("cutting_depths", Value::reals(std::move(depths)));
  for (auto [irName, attribute] : {std::pair{"feed_dir", "feed_direction"}, {"back_path_dir", "back_path_direction"},
                                   {"stepover_dir", "stepover_direction"}})
    if (Instance d = strategy.ref(attribute))
      if (auto v = l.direction(d))
        s.set(irName, Value::direction(*v));
  for (auto [irName, attribute] :
       {std::pair{"back_path_feed", "back_path_feed"}, {"lift_feed", "lift_feed"}, {"downward_feed", "downward_feed"}})
    if (auto v = strategy.real(attribute))
      s.set(irName, Value::feed(l.feedMmPerMin(*v)));
  copyReal(s, "lift_height", strategy, "lift_height", Value::length);
  l.copyAngle(s, "return_angle", strategy, "path_return_angle");
  copyReal(s, "variable_depth", strategy, "variable_depth", Value::ratio);
  copyReal(s, "variable_downward_feed", strategy, "variable_downward_feed", Value::ratio);
  copyWord(s, "infeed", strategy, "cut_in_amount_function");
  copyWord(s, "thread_side", strategy, "threading_direction");
  copyReal(s, "travel_distance", strategy, "travel_distance", Value::length);
  copyReal(s, "retract_distance", strategy, "retract_distance", Value::length);
  return typed;
}

Node technology(Lowerer &l, const Instance &tech) {
  if (tech.isA("turning_technology"))
    return turningTechnology(l, tech);
  Node n(ir::Kind::Technology);
  if (auto f = tech.real("feedrate")) {
    const double feed = l.feedMmPerMin(*f);
    n.set("feed", Value::feed(feed));
    checkPlausible(l, tech, "feedrate", feed, ir::kPlausibleMinFeedMmPerMin, ir::kPlausibleMaxFeedMmPerMin, "mm/min");
  }
  if (auto fz = tech.real("feedrate_per_tooth"))
    n.set("feed_per_tooth", Value::length(*fz));
  if (auto vc = tech.real("cutspeed")) {
    const double speed = l.cuttingSpeedMmPerMin(*vc);
    n.set("cutting_speed", Value::feed(speed));
    checkPlausible(l, tech, "cutspeed", speed, 1000 * ir::kPlausibleMinCuttingSpeedMPerMin,
                   1000 * ir::kPlausibleMaxCuttingSpeedMPerMin, "mm/min");
  }
  if (auto s = tech.real("spindle")) {
    const double rpm = l.spindleRevPerMin(*s);
    n.set("spindle", Value::spindle(rpm));
    checkPlausible(l, tech, "spindle", rpm, ir::kPlausibleMinSpindleRpm, ir::kPlausibleMaxSpindleRpm, "rev/min");
  }
  const std::optional<std::string> reference = tech.enumeration("feedrate_reference");
  n.set("feed_reference", Value::word(reference.value_or("tcp")));
  if (!reference)
    l.fix(tech, "feedrate_reference", ".TCP.");  // binding said: read as absent (the tool's centre point)
  copyFlag(n, "sync_spindle_feed", tech, "synchronize_spindle_with_feed");
  copyFlag(n, "inhibit_feed_override", tech, "inhibit_feedrate_override");
  copyFlag(n, "inhibit_spindle_override", tech, "inhibit_spindle_override");
  return n;
}

Node machineFunctions(const Instance &mf) {
  Node n(ir::Kind::MachineFunctions);
  for (std::string_view flag : {"coolant", "mist", "through_spindle_coolant", "chip_removal"})
    copyFlag(n, flag, mf, flag);
  // Turning machine functions name the coolant's kind, and the supports.
  if (auto type = mf.enumeration("coolant_type"); type && mf.boolean("coolant").value_or(false)) {
    if (*type == "mist")
      n.set("mist", Value::boolean(true));
    else if (*type == "through_tool")
      n.set("through_spindle_coolant", Value::boolean(true));
  }
  for (std::string_view flag : {"tail_stock", "steady_rest", "follow_rest"})
    copyFlag(n, flag, mf, flag);
  copyReal(n, "coolant_pressure", mf, "coolant_pressure", Value::ratio);
  copyReal(n, "through_pressure", mf, "through_pressure", Value::ratio);
  return n;
}

} // namespace

std::optional<Node> Lowerer::operation(const Instance &op) {
  if (op.isA("am_operation"))
    return additiveOperation(op);
  std::optional<ir::Kind> kind;
  for (auto [entity, k] : kOperations)
    if (op.isA(entity)) {
      kind = k;
      break;
    }
  if (!kind) {
    unsupported(op, "operation");
    return std::nullopt;
  }
  Node n(*kind);
  stamp(n, op);
  if (auto sym = tool(op.ref("its_tool")))
    n.set("tool", Value::ref(*sym));
  else
    missing(op, "its_tool");
  auto length = [&](std::string_view irName, std::string_view attribute) {
    copyReal(n, irName, op, attribute, Value::length);
  };
  auto position = [&](std::string_view irName, std::string_view attribute) {
    if (Instance at = op.ref(attribute))
      if (auto p = point(at))
        n.set(std::string(irName), Value::point(*p));
  };
  length("retract_plane", "retract_plane");
  position("start_point", "start_point");
  if (Instance direction = op.ref("its_tool_direction"))
    toolDirection(direction, n);
  length("overcut", "overcut_length");
  length("axial_depth", "axial_cutting_depth");
  length("radial_depth", "radial_cutting_depth");
  length("allowance_side", "allowance_side");
  length("allowance_bottom", "allowance_bottom");
  // Drilling-type operations.
  length("cutting_depth", "cutting_depth");
  length("previous_diameter", "previous_diameter");
  copyReal(n, "dwell_bottom", op, "dwell_time_bottom", Value::time);
  copyReal(n, "feed_on_retract", op, "feed_on_retract", Value::ratio);
  copyFlag(n, "spindle_stop_bottom", op, "spindle_stop_at_bottom");
  length("depth_of_testcut", "depth_of_testcut");
  position("waiting_position", "waiting_position");
  length("retract_distance", "retract_distance");
  length("first_depth", "first_depth");
  length("depth_increment", "depth_of_step");
  copyReal(n, "dwell_step", op, "dwell_time_step", Value::time);
  copyFlag(n, "compensation_chuck", op, "compensation_chuck");
  copyFlag(n, "helical_movement", op, "helical_movement_on_forward");
  // Turning operations.
  length("x_return", "x_return_amount");
  length("z_return", "z_return_amount");
  length("return_amount", "return_amount");
  length("allowance", "allowance");
  copyReal(n, "feed_ratio", op, "variable_feedrate", Value::ratio);
  if (op.isA("cutting_in")) {
    if (auto d = toleranced(op, "depth"))
      n.set("depth", Value::length(*d));
    else
      missing(op, "depth");
    if (Instance d = op.ref("cut_in_direction"))
      if (auto v = direction(d))
        n.set("direction", Value::direction(*v));
  }
  if (Instance dwell = op.ref("dwell_type")) {
    if (dwell.isA("dwell_time"))
      copyReal(n, "dwell", dwell, "time", Value::time);
    else if (dwell.isA("dwell_revolution"))
      copyReal(n, "dwell_revolutions", dwell, "revolution", Value::ratio);
  }

  if (Instance tech = op.ref("its_technology")) {
    n.add(technology(*this, tech));
  } else {
    // Nothing given is still a technology: resolve-feeds assumes the spindle
    // speed and the feed from the tool and the workpiece material, and says so.
    Node empty(ir::Kind::Technology);
    empty.set("feed_reference", Value::word("tcp"));
    n.add(std::move(empty));
    assumed(op, "its_technology",
            "absent; assumed a technology that gives no feed or speed (resolve-feeds assumes them from the tool "
            "and the workpiece material)");
  }
  if (Instance mf = op.ref("its_machine_functions"))
    n.add(machineFunctions(mf));
  else  // binding said: read as absent (no coolant, no chip removal)
    fix(op, "its_machine_functions", newInstance("MILLING_MACHINE_FUNCTIONS(.F.,$,$,.F.,$,(),.F.,$,$,())"));
  if (Instance strategy = op.ref("its_machining_strategy")) {
    if (strategy.isA("turning_machining_strategy")) {
      if (auto lowered = turningStrategy(*this, strategy))
        n.add(std::move(*lowered));
    } else if (strategy.isA("drilling_type_strategy")) {
      Node d(ir::Kind::DrillingStrategy);
      stamp(d, strategy, "");
      for (std::string_view ratio :
           {"reduced_cut_at_start", "reduced_feed_at_start", "reduced_cut_at_end", "reduced_feed_at_end"})
        copyReal(d, ratio, strategy, ratio, Value::ratio);
      copyReal(d, "depth_of_start", strategy, "depth_of_start", Value::length);
      copyReal(d, "depth_of_end", strategy, "depth_of_end", Value::length);
      n.add(std::move(d));
    } else if (auto lowered = millingStrategy(*this, strategy)) {
      n.add(std::move(*lowered));
    }
  }
  for (auto [which, irKind] : {std::pair{"approach", ir::Kind::Approach}, {"retract", ir::Kind::Retract}}) {
    Instance ar = op.ref(which);
    if (!ar)
      continue;
    Node a{irKind};
    stamp(a, ar, "");
    std::string_view type;
    for (std::string_view t : {"plunge_toolaxis", "plunge_ramp", "plunge_helix", "plunge_zigzag", "along_path"})
      if (ar.isA(t))
        type = t;
    if (ar.isA("ap_retract_angle"))
      type = "retract_angle";
    if (ar.isA("ap_retract_tangent"))
      type = "retract_tangent";
    if (type.empty()) {
      unsupported(ar, "approach or retract strategy");
      continue;
    }
    a.set("type", Value::word(std::string(type)));
    if (Instance o = ar.ref("tool_orientation"))
      if (auto d = direction(o))
        a.set("tool_orientation", Value::direction(*d));
    copyAngle(a, "angle", ar, "angle");
    for (std::string_view attribute : {"radius", "width", "travel_length"})
      copyReal(a, attribute, ar, attribute, Value::length);
    n.add(std::move(a));
  }
  if (Instance list = op.ref("its_toolpath"))
    toolpaths(list, n);
  return n;
}

void Lowerer::toolDirection(const Instance &d, Node &n) {
  if (d.isA("three_axes_tilted_tool")) {
    n.set("tool_direction", Value::word("tilted"));
    if (auto axis = direction(d.ref("its_tool_direction")))
      n.set("tilted_axis", Value::direction(*axis));
    else
      missing(d, "its_tool_direction");
  } else if (d.isA("five_axes_var_tilt_yaw")) {
    n.set("tool_direction", Value::word("varying"));
  } else if (d.isA("five_axes_const_tilt_yaw")) {
    n.set("tool_direction", Value::word("constant"));
    copyAngle(n, "tilt", d, "tilt_angle");
    copyAngle(n, "yaw", d, "yaw_angle");
    if (!n.has("tilt"))
      missing(d, "tilt_angle");
    if (!n.has("yaw"))
      missing(d, "yaw_angle");
  } else {
    unsupported(d, "tool direction");
  }
}

void Lowerer::toolAxes(const Instance &tp, const Instance &axes, Node &basic, std::string_view attribute) {
  // ISO 14649-11: its_toolaxis has the parameter range of basiccurve. Read
  // as the generators of such files write it: a polyline beside the
  // basiccurve's, each point, taken as a vector from the origin, the tool
  // axis at the basiccurve's point of the same index.
  if (basic.kind != ir::Kind::Polyline || !axes.isA("polyline")) {
    unsupported(tp, "a tool axis curve that is not a polyline beside a polyline basiccurve");
    return;
  }
  const std::vector<Instance> points = axes.refs("points");
  if (points.size() != basic.children.size()) {
    missing(tp, attribute,
            "has " + std::to_string(points.size()) + " points and basiccurve " +
                std::to_string(basic.children.size()) + ": each point of the path needs its tool axis");
    return;
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const std::optional<Vec3> v = point(points[i]);
    if (!v)
      continue;  // reported by point()
    if (!(v->norm() > 1e-9)) {
      missing(points[i], "coordinates", "is (0, 0, 0): a tool axis is a direction");
      continue;
    }
    basic.children[i].set("axis", Value::direction(v->normalized()));
  }
}

void Lowerer::toolpaths(const Instance &list, Node &parent) {
  for (const Instance &tp : list.refs("its_list")) {
    const bool feedstop = tp.isA("feedstop");
    if (!feedstop && !tp.isA("cutter_location_trajectory")) {
      unsupported(tp, "toolpath");
      continue;
    }
    Node n(ir::Kind::Toolpath);
    stamp(n, tp, "");
    n.set("role", Value::word(tp.enumeration("its_type").value_or("trajectory_path")));
    n.set("required", Value::boolean(tp.boolean("its_priority").value_or(true)));
    if (feedstop) {
      // A dwell where the path before it ends (ISO 14649-10 feedstop).
      const std::optional<double> dwell = tp.real("dwell");
      if (!dwell || !(*dwell >= 0)) {
        missing(tp, "dwell", dwell ? "is negative: a feedstop waits 0 s or more" : "");
        continue;
      }
      n.set("dwell", Value::time(*dwell));
      parent.add(std::move(n));
      continue;
    }
    if (auto r = tp.real("its_speed"))
      n.set("speed_ratio", Value::ratio(*r));
    else if (tp.enumeration("its_speed") == "rapid")
      n.set("rapid", Value::boolean(true));
    else if (tp.attr("its_speed") && !tp.attr("its_speed")->isUnset())
      unsupported(tp, "toolpath speed profile other than a ratio or rapid");
    if (auto dir = tp.boolean("its_direction"))
      n.set("reversed", Value::boolean(!*dir));
    if (Instance tech = tp.ref("its_technology"))
      n.add(technology(*this, tech));
    if (Instance mf = tp.ref("its_machine_functions"))
      n.add(machineFunctions(mf));
    if (tp.ref("surface_normal"))
      unsupported(tp, "surface normal curves");
    if (auto c = curve(tp.ref("basiccurve"))) {
      if (Instance axes = tp.ref("its_toolaxis"))
        toolAxes(tp, axes, *c);
      n.add(std::move(*c));
    } else {
      missing(tp, "basiccurve");
    }
    parent.add(std::move(n));
  }
}

} // namespace stepnc::lowering
