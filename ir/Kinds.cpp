// The feature-IR kind table. Attribute names follow ISO 14649 where it has a
// name for the quantity, shortened where the standard's is long; units are
// those of the value type (mm, deg, mm/min, rev/min, s). Placements are three
// attributes: `at` (origin), `axis` (local z), `ref` (local x).
#include "ir/Kinds.h"

#include <algorithm>

namespace stepnc::ir {

namespace {

using T = ValueType;

// Attribute groups shared by several kinds.
std::vector<AttrSpec> placement(bool required) {
  return {{"at", T::Point, required}, {"axis", T::Direction, required}, {"ref", T::Direction, required}};
}

template <class... Groups>
std::vector<AttrSpec> join(Groups &&...groups) {
  std::vector<AttrSpec> out;
  (out.insert(out.end(), groups.begin(), groups.end()), ...);
  return out;
}

const std::vector<AttrSpec> kFeatureCommon = join(placement(true), std::vector<AttrSpec>{{"depth", T::Length, true}});

const std::vector<AttrSpec> kOperationCommon = {
    {"tool", T::Ref, true},
    {"retract_plane", T::Length},
    {"start_point", T::Point},
    {"overcut", T::Length},
};

const std::vector<AttrSpec> kMillingStrategyCommon = {
    {"overlap", T::Ratio},
    {"multiple_passes", T::Flag},
};

const std::vector<AttrSpec> kDrillingOperation = {
    {"cutting_depth", T::Length},
    {"previous_diameter", T::Length},
    {"dwell_bottom", T::Time},
    {"feed_on_retract", T::Ratio},
};

std::vector<KindSpec> makeTable() {
  std::vector<KindSpec> t;
  auto add = [&](KindSpec k) { t.push_back(std::move(k)); };

  // Program structure.
  add({"project", "root", Sigil::None, true, {}, "workpiece tool setup workplan"});
  add({"workpiece", "resource", Sigil::Resource, true,
       {{"material", T::Text}, {"material_standard", T::Text}, {"global_tolerance", T::Length}},
       "rawpiece clamp feature"});
  add({"rawpiece", "resource", Sigil::None, false,
       join(std::vector<AttrSpec>{{"shape", T::Word, true, "block cylinder"},
                                  {"size", T::Point},
                                  {"diameter", T::Length},
                                  {"height", T::Length}},
            placement(true)),
       {}});
  add({"clamp", "resource", Sigil::None, false, {{"at", T::Point, true}}, {}});
  add({"setup", "resource", Sigil::Resource, true,
       join(placement(true), std::vector<AttrSpec>{{"secplane", T::Length, true}}), "workpiece_setup"});
  add({"workpiece_setup", "resource", Sigil::None, false,
       join(std::vector<AttrSpec>{{"workpiece", T::Ref, true}}, placement(true)), {}});
  add({"tool", "resource", Sigil::Resource, true,
       {{"type", T::Word, true,
         "endmill facemill ball_endmill bullnose_endmill tapered_endmill side_mill t_slot_mill "
         "twist_drill center_drill spot_drill tapered_drill reamer tapered_reamer tap "
         "boring_tool countersink counterbore cutting_tool"},
        {"diameter", T::Length},
        {"corner_radius", T::Length},
        {"tip_half_angle", T::Angle},
        {"circumference_angle", T::Angle},
        {"cutting_edge_length", T::Length},
        {"edge_center_vertical", T::Length},
        {"edge_center_horizontal", T::Length},
        {"overall_length", T::Length},
        {"flutes", T::Count},
        {"hand", T::Word, false, "left right neutral"},
        {"coolant_through", T::Flag},
        {"offset_length", T::Length},
        {"taper_angle", T::Angle},
        {"thread_pitch", T::Length}},
       {}});

  // Executables.
  add({"workplan", "executable", Sigil::Executable, true, {{"setup", T::Ref}}, "executable"});
  add({"workingstep", "executable", Sigil::Executable, true,
       {{"feature", T::Ref, true}, {"secplane", T::Length, true}}, "operation moves motion"});
  add({"program_stop", "executable", Sigil::None, true, {}, {}});
  add({"optional_stop", "executable", Sigil::None, true, {}, {}});
  add({"display_message", "executable", Sigil::None, true, {{"message", T::Text, true}}, {}});
  // A rapid movement is a workingstep of its own (ISO 14649-10), with explicit toolpaths.
  add({"rapid_movement", "executable", Sigil::Executable, true, {{"secplane", T::Length, true}}, "toolpath moves motion"});

  // Features (children of their workpiece).
  add({"planar_face", "feature", Sigil::Resource, true,
       join(kFeatureCommon, std::vector<AttrSpec>{{"travel", T::Length, true},
                                                  {"travel_dir", T::Direction, true},
                                                  {"width", T::Length, true},
                                                  {"width_dir", T::Direction, true}}),
       "profile island"});
  for (std::string_view pocket : {"closed_pocket", "open_pocket"})
    add({pocket, "feature", Sigil::Resource, true,
         join(kFeatureCommon, std::vector<AttrSpec>{{"slope", T::Angle},
                                                    {"bottom", T::Word, true, "planar radiused through general"},
                                                    {"bottom_radius", T::Length},
                                                    {"planar_radius", T::Length},
                                                    {"orthogonal_radius", T::Length}}),
         "profile island"});
  add({"round_hole", "feature", Sigil::Resource, true,
       join(kFeatureCommon,
            std::vector<AttrSpec>{{"diameter", T::Length, true},
                                  {"final_diameter", T::Length},
                                  {"taper_angle", T::Angle},
                                  {"bottom", T::Word, true, "through flat flat_with_radius conical spherical"},
                                  {"bottom_radius", T::Length},
                                  {"tip_angle", T::Angle},
                                  {"tip_radius", T::Length}}),
       {}});
  add({"slot", "feature", Sigil::Resource, true,
       join(kFeatureCommon, std::vector<AttrSpec>{{"end_1", T::Word, true, "open radiused flat woodruff loop"},
                                                  {"end_2", T::Word, true, "open radiused flat woodruff loop"},
                                                  {"end_radius", T::Length}}),
       "path profile"});
  add({"step", "feature", Sigil::Resource, true, kFeatureCommon, "path profile island"});
  // A boss standing in a pocket, face or step: the material to leave, by reference.
  add({"island", "island", Sigil::None, false, {{"feature", T::Ref, true}}, {}});
  add({"general_outside_profile", "feature", Sigil::Resource, true, kFeatureCommon, "path profile"});
  add({"boss", "feature", Sigil::Resource, true, join(kFeatureCommon, std::vector<AttrSpec>{{"slope", T::Angle}}),
       "profile"});

  // Profiles (cross sections and outlines, in the feature's frame).
  add({"rectangular_profile", "profile", Sigil::None, false,
       join(std::vector<AttrSpec>{{"width", T::Length, true}, {"length", T::Length, true}}, placement(false)), {}});
  add({"circular_profile", "profile", Sigil::None, false,
       join(std::vector<AttrSpec>{{"diameter", T::Length, true}}, placement(false)), {}});
  add({"linear_profile", "profile", Sigil::None, false, {{"length", T::Length, true}}, {}});
  add({"square_u_profile", "profile", Sigil::None, false,
       {{"width", T::Length, true},
        {"first_radius", T::Length},
        {"first_angle", T::Angle},
        {"second_radius", T::Length},
        {"second_angle", T::Angle}},
       {}});
  add({"rounded_u_profile", "profile", Sigil::None, false, {{"width", T::Length, true}}, {}});
  add({"vee_profile", "profile", Sigil::None, false,
       {{"profile_radius", T::Length}, {"profile_angle", T::Angle, true}, {"tilt_angle", T::Angle, true}}, {}});
  add({"partial_circular_profile", "profile", Sigil::None, false,
       {{"radius", T::Length, true}, {"sweep_angle", T::Angle, true}}, {}});
  add({"general_profile", "profile", Sigil::None, false, {{"closed", T::Flag, true}}, "curve"});

  // Paths and curves (feature travel paths, general profiles, toolpaths).
  add({"path", "path", Sigil::None, false, {}, "curve"});
  add({"line", "curve", Sigil::None, false, {{"at", T::Point, true}, {"dir", T::Direction, true}, {"length", T::Length}}, {}});
  add({"polyline", "curve", Sigil::None, false, {}, "point"});
  add({"point", "point", Sigil::None, false, {{"at", T::Point, true}, {"weight", T::Ratio}}, {}});
  add({"circle", "curve", Sigil::None, false,
       join(placement(true), std::vector<AttrSpec>{{"radius", T::Length, true}}), {}});
  add({"helix", "curve", Sigil::None, false,
       join(placement(true), std::vector<AttrSpec>{{"radius", T::Length, true}, {"pitch", T::Length, true}}), {}});
  add({"trimmed_curve", "curve", Sigil::None, false,
       {{"from_param", T::Ratio},
        {"to_param", T::Ratio},
        {"from_point", T::Point},
        {"to_point", T::Point},
        {"sense", T::Flag, true}},
       "curve"});
  add({"composite_curve", "curve", Sigil::None, false, {{"self_intersect", T::Flag}}, "segment"});
  add({"segment", "segment", Sigil::None, false,
       {{"transition", T::Word, true, "discontinuous continuous cont_same_gradient cont_same_gradient_same_curvature"},
        {"same_sense", T::Flag, true}},
       "curve"});
  // Control points in order (with weights when rational), then the knots.
  add({"b_spline_curve", "curve", Sigil::None, false,
       {{"degree", T::Count, true},
        {"form", T::Word, true, "uniform quasi_uniform bezier with_knots"},
        {"closed", T::Flag}},
       "point knot"});
  add({"knot", "knot", Sigil::None, false, {{"value", T::Ratio, true}, {"multiplicity", T::Count, true}}, {}});

  // Operations (the child of a workingstep).
  const char *millingChildren =
      "technology machine_functions strategy trochoidal_strategy plunge_strategy approach retract toolpath";
  for (std::string_view op : {"plane_rough_milling", "plane_finish_milling"})
    add({op, "operation", Sigil::None, true,
         join(kOperationCommon, std::vector<AttrSpec>{{"axial_depth", T::Length}, {"allowance_bottom", T::Length}}),
         millingChildren});
  for (std::string_view op : {"bottom_and_side_rough_milling", "bottom_and_side_finish_milling"})
    add({op, "operation", Sigil::None, true,
         join(kOperationCommon, std::vector<AttrSpec>{{"axial_depth", T::Length},
                                                      {"radial_depth", T::Length},
                                                      {"allowance_side", T::Length},
                                                      {"allowance_bottom", T::Length}}),
         millingChildren});
  for (std::string_view op : {"side_rough_milling", "side_finish_milling"})
    add({op, "operation", Sigil::None, true,
         join(kOperationCommon, std::vector<AttrSpec>{{"axial_depth", T::Length},
                                                      {"radial_depth", T::Length},
                                                      {"allowance_side", T::Length}}),
         millingChildren});
  add({"freeform_operation", "operation", Sigil::None, true, kOperationCommon, millingChildren});
  const char *drillingChildren = "technology machine_functions drilling_strategy approach retract toolpath";
  for (std::string_view op : {"drilling", "center_drilling", "counter_sinking", "reaming", "boring"})
    add({op, "operation", Sigil::None, true,
         join(kOperationCommon, kDrillingOperation,
              std::vector<AttrSpec>{{"spindle_stop_bottom", T::Flag}, {"depth_of_testcut", T::Length},
                                    {"waiting_position", T::Point}}),
         drillingChildren});
  add({"multistep_drilling", "operation", Sigil::None, true,
       join(kOperationCommon, kDrillingOperation,
            std::vector<AttrSpec>{{"retract_distance", T::Length},
                                  {"first_depth", T::Length},
                                  {"depth_increment", T::Length},
                                  {"dwell_step", T::Time}}),
       drillingChildren});
  for (std::string_view op : {"tapping", "thread_drilling"})
    add({op, "operation", Sigil::None, true,
         join(kOperationCommon, kDrillingOperation,
              std::vector<AttrSpec>{{"compensation_chuck", T::Flag}, {"helical_movement", T::Flag}}),
         drillingChildren});

  // Technology, machine functions, strategies.
  add({"technology", "technology", Sigil::None, false,
       {{"feed", T::Feed},
        {"feed_per_tooth", T::Length},
        {"cutting_speed", T::Feed},
        {"spindle", T::Spindle},
        {"feed_reference", T::Word, true, "tcp ccp"},
        {"sync_spindle_feed", T::Flag},
        {"inhibit_feed_override", T::Flag},
        {"inhibit_spindle_override", T::Flag}},
       {}});
  add({"machine_functions", "technology", Sigil::None, false,
       {{"coolant", T::Flag}, {"coolant_pressure", T::Ratio}, {"mist", T::Flag},
        {"through_spindle_coolant", T::Flag}, {"through_pressure", T::Ratio}, {"chip_removal", T::Flag}},
       {}});
  add({"strategy", "strategy", Sigil::None, false,
       join(std::vector<AttrSpec>{{"type", T::Word, true,
                                   "unidirectional bidirectional contour_parallel contour_spiral "
                                   "contour_bidirectional bidirectional_contour center_milling explicit"}},
            kMillingStrategyCommon,
            std::vector<AttrSpec>{{"feed_dir", T::Direction},
                                  {"stepover_dir", T::Word, false, "left right"},
                                  {"stroke_connection", T::Word, false, "straightline loop_back degouge lift_shift_plunge"},
                                  {"rotation", T::Word, false, "cw ccw"},
                                  {"cutmode", T::Word, false, "climb conventional"},
                                  {"spiral_cutmode_change", T::Flag}}),
       {}});
  // Pattern strategies (stepnc's extension schema, docs/pattern-strategies.md):
  // a motif repeated along the path of their one child `strategy`, the guide.
  add({"trochoidal_strategy", "strategy", Sigil::None, false,
       join(kMillingStrategyCommon,
            std::vector<AttrSpec>{{"radius", T::Length, true},
                                  {"step", T::Length, true},
                                  {"rotation", T::Word, false, "cw ccw"},
                                  {"cutmode", T::Word, false, "climb conventional"}}),
       "strategy"});
  add({"plunge_strategy", "strategy", Sigil::None, false,
       join(kMillingStrategyCommon,
            std::vector<AttrSpec>{{"clearance", T::Length, true},
                                  {"retract_offset", T::Length, true},
                                  {"bottom_radius", T::Length, true},
                                  {"radial_step", T::Length, true},
                                  {"link_radius", T::Length, true}}),
       "strategy"});
  add({"drilling_strategy", "strategy", Sigil::None, false,
       {{"reduced_cut_at_start", T::Ratio}, {"reduced_feed_at_start", T::Ratio}, {"depth_of_start", T::Length},
        {"reduced_cut_at_end", T::Ratio}, {"reduced_feed_at_end", T::Ratio}, {"depth_of_end", T::Length}},
       {}});
  for (std::string_view ar : {"approach", "retract"})
    add({ar, "strategy", Sigil::None, false,
         {{"type", T::Word, true,
           "plunge_toolaxis plunge_ramp plunge_helix plunge_zigzag retract_angle retract_tangent along_path"},
          {"tool_orientation", T::Direction},
          {"angle", T::Angle},
          {"radius", T::Length},
          {"width", T::Length},
          {"travel_length", T::Length}},
         {}});

  // Explicit toolpaths (freeform operations). `rapid`: the toolpath's speed
  // is the ISO 14649 speed name `rapid` (its moves are rapids).
  add({"toolpath", "toolpath", Sigil::None, false,
       {{"role", T::Word, true, "approach lift connect non_contact contact trajectory_path"},
        {"required", T::Flag, true},
        {"speed_ratio", T::Ratio},
        {"rapid", T::Flag},
        {"reversed", T::Flag}},
       "curve technology machine_functions"});

  // Toolpath IR: what strategy expansion makes of a workingstep. `moves` holds
  // the state in force for every move under it (tool, spindle, coolant, the
  // setup whose workpiece coordinates the points are in, the security plane as
  // a height in those coordinates); each move ends at `to` and starts where
  // the previous one ended. An arc whose `to` is at another height than its
  // start is a helix; `turns` counts full turns made before the last arc to
  // `to`, which is itself a whole turn when `to` is over the start in the plane.
  // `role` marks what a move is for: positioning rapids, approach, plunge,
  // cut, link between cuts, retract.
  add({"moves", "toolpath", Sigil::None, false,
       {{"tool", T::Ref, true},
        {"spindle", T::Spindle, true},
        {"coolant", T::Word, true, "off flood mist through_tool"},
        {"setup", T::Ref},
        {"secplane", T::Length, true}},
       "move"});
  const char *roles = "position approach plunge cut link retract";
  add({"rapid", "move", Sigil::None, false, {{"to", T::Point, true}, {"role", T::Word, false, roles}}, {}});
  // `nominal`: where a move compensated for tool deflection is predicted to
  // take the bent tool (docs/deflection-compensation.md); `nominal_center`:
  // the centre of the arc it is predicted to follow, where the programmed
  // arc's is moved (the offset changes along it).
  // `smooth`: the line is a chord of a curvature-continuous curve through
  // its end points (a trochoid, docs/pattern-strategies.md), as are its
  // neighbours marked so; a target with splines may write the run of them
  // as a spline through the same points.
  add({"linear", "move", Sigil::None, false,
       {{"to", T::Point, true},
        {"feed", T::Feed, true},
        {"role", T::Word, false, roles},
        {"nominal", T::Point},
        {"smooth", T::Flag}},
       {}});
  add({"arc", "move", Sigil::None, false,
       {{"to", T::Point, true},
        {"center", T::Point, true},
        {"dir", T::Word, true, "cw ccw"},
        {"turns", T::Count},
        {"feed", T::Feed, true},
        {"role", T::Word, false, roles},
        {"nominal", T::Point},
        {"nominal_center", T::Point}},
       {}});

  // Motion IR: what plan-motion makes of the moves (docs/motion.md). `motion`
  // holds the segments that follow the moves of its executable; `from` is
  // where the first starts. Segments are exact plain numbers (shortest round
  // trip) in mm, s, radians, mm/s, mm/s^2, mm/s^3, except `feed` (mm/min).
  // `move` and `next` count the program's moves from 0 in program order.
  add({"motion", "motion", Sigil::None, false,
       {{"machine", T::Text, true},
        {"tolerance", T::Length, true},
        {"time", T::Time, true},
        {"from", T::Reals, true}},
       "motion_segment"});
  add({"motion_segment", "motion_segment", Sigil::None, false,
       {{"shape", T::Word, true, "line arc blend"},
        {"to", T::Reals, true},
        {"center", T::Reals},
        {"dir", T::Word, false, "cw ccw"},
        {"sweep", T::Real},
        {"points", T::Reals},
        {"length", T::Real, true},
        {"feed", T::Real},
        {"move", T::Count, true},
        {"next", T::Count},
        {"stop", T::Word, false, "start reversal tiny program"},
        {"limited_by", T::Word, true, "feed machine_feed axis_velocity acceleration jerk"},
        {"limits", T::Reals, true},
        {"v0", T::Real, true},
        {"a0", T::Real},
        {"phases", T::Reals, true}},
       {}});
  return t;
}

} // namespace

const std::vector<KindSpec> &allKinds() {
  static const std::vector<KindSpec> table = makeTable();
  return table;
}

const KindSpec *findKind(std::string_view kind) {
  for (const KindSpec &k : allKinds())
    if (k.kind == kind)
      return &k;
  return nullptr;
}

bool childAllowed(const KindSpec &parent, const KindSpec &child) {
  return inList(parent.children, child.kind) || inList(parent.children, child.category);
}

bool inList(std::string_view list, std::string_view word) {
  while (!list.empty()) {
    const size_t space = list.find(' ');
    if (list.substr(0, space) == word)
      return true;
    list = space == std::string_view::npos ? std::string_view() : list.substr(space + 1);
  }
  return false;
}

std::string joinWords(std::string_view list) {
  std::string out;
  for (size_t space; (space = list.find(' ')) != std::string_view::npos; list.remove_prefix(space + 1)) {
    out += list.substr(0, space);
    out += list.find(' ', space + 1) == std::string_view::npos ? " or " : ", ";
  }
  return out += list;
}

bool isNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

char sigilChar(Sigil s) {
  switch (s) {
  case Sigil::Resource: return '%';
  case Sigil::Executable: return '@';
  case Sigil::None: return '\0';
  }
  return '\0';
}

bool isSymbol(std::string_view s) {
  return s.size() >= 2 && (s[0] == '%' || s[0] == '@') && std::all_of(s.begin() + 1, s.end(), isNameChar);
}

bool wordAllowed(const AttrSpec &a, std::string_view word) {
  if (a.words.empty())
    return !word.empty() && std::all_of(word.begin(), word.end(), isNameChar);
  return inList(a.words, word);
}

std::string allowedChildren(const KindSpec &parent) {
  return parent.children.empty() ? "no children" : joinWords(parent.children);
}



const AttrSpec *findAttr(const KindSpec &kind, std::string_view name) {
  for (const AttrSpec &a : kind.attrs)
    if (a.name == name)
      return &a;
  return nullptr;
}

} // namespace stepnc::ir
