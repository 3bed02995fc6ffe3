// Lowering of manufacturing features (ISO 14649-10): planar faces, pockets,
// round holes, slots, steps, general outside profiles and bosses; and the
// turned features of ISO 14649-12 (docs/turning.md). A feature is lowered
// once, under its workpiece, and referred to by symbol.
#include "frontend/lowering/Lowerer.h"

#include "support/Format.h"

#include <cmath>
#include <numbers>
#include <tuple>

namespace stepnc::lowering {

namespace {

// `depth` is a plane in the feature's frame: the feature goes down to it.
void setDepth(Lowerer &l, Node &n, const Instance &f) {
  std::optional<double> z = l.planeHeight(f, "depth", "feature depth", n.vec("axis"));
  if (!z)
    return;
  if (*z > 1e-9) {
    // The depth plane lies below the feature's origin, at negative z of its
    // frame; some generators write its distance instead.
    l.assumed(f.ref("depth"), "position",
              "places the floor " + formatFixed(*z, 4) + " mm above the feature's origin, where no floor can be; "
              "read as a depth of " + formatFixed(*z, 4) + " mm below it");
    l.fix(f, "depth", l.depthPlane(*z));  // a plane of its own: the file's may be shared
    *z = -*z;
  }
  n.set("depth", Value::length(-*z));
}

std::string describe(const Instance &inst) { return hashId(inst.id()) + " " + std::string(inst.entityName()); }

} // namespace

void Lowerer::slotDepthFromProfile(Node &slot, const Instance &f) {
  const std::optional<double> depth = slot.number("depth");
  if (!depth || *depth > 0)
    return;  // absent (reported) or given
  // A partial circular profile is as deep as its arc: the sagitta
  // r (1 - cos(sweep / 2)), its chord at the slot's top.
  Instance shape = f.ref("swept_shape");
  if (!shape.isA("partial_circular_profile"))
    return;
  const std::optional<double> r = toleranced(shape, "radius");
  const std::optional<double> sweep = shape.real("sweep_angle");
  if (!r || !sweep)
    return;
  const double sweepDeg = angle(*sweep).number;
  const double sagitta = *r * (1 - std::cos(sweepDeg / 2 * std::numbers::pi / 180));
  if (!(sweepDeg > 0 && sweepDeg <= 180 && sagitta > 1e-6))
    return;
  slot.set("depth", Value::length(sagitta));
  assumed(f, "depth",
          "its plane gives a depth of " + formatFixed(*depth, 4) + " mm; assumed " + formatFixed(sagitta, 4) +
              " mm, the depth of its swept shape " + describe(shape) + " (radius " + formatFixed(*r, 4) +
              " mm, sweep " + formatFixed(sweepDeg, 4) + " deg)");
}

Instance Lowerer::featureWorkpiece(const Instance &f) {
  if (Instance wp = f.ref("its_workpiece"))
    return wp;
  if (projectWorkpieces_.size() != 1)
    return {};
  assumed(f, "its_workpiece", "absent; assumed " + describe(projectWorkpieces_[0]) + ", the project's only workpiece");
  fix(f, "its_workpiece", hashId(projectWorkpieces_[0].id()));
  return projectWorkpieces_[0];
}

std::optional<RawExtent> Lowerer::rawExtent(const Instance &wp) {
  Instance block = wp ? rawBounding(wp) : Instance();
  if (!block || !block.isA("block"))
    return std::nullopt;
  auto x = block.real("x"), y = block.real("y"), z = block.real("z");
  if (!x || !y || !z)
    return std::nullopt;
  Placement p;
  if (Instance at = block.ref("position")) {
    auto placed = placement(at);
    if (!placed)
      return std::nullopt;
    p = *placed;
  }
  // ISO 14649-10: the block's placement is a corner; x, y, z run along its axes.
  const Vec3 ey = p.axis.cross(p.ref);
  RawExtent e;
  e.block = block;
  e.min = e.max = p.at;
  for (int i = 1; i < 8; ++i) {
    const Vec3 c = p.at + ((i & 1) ? *x : 0.0) * p.ref + ((i & 2) ? *y : 0.0) * ey + ((i & 4) ? *z : 0.0) * p.axis;
    e.min = e.min.cwiseMin(c);
    e.max = e.max.cwiseMax(c);
  }
  return e;
}

namespace {

/// The rotation taking a placement's axes (ref, axis x ref, axis) to its parent's.
Eigen::Matrix3d rotation(const Placement &p) {
  Eigen::Matrix3d r;
  r.col(0) = p.ref;
  r.col(1) = p.axis.cross(p.ref);
  r.col(2) = p.axis;
  return r;
}

} // namespace

void Lowerer::placeProfileOnce(const Instance &profileInstance, Node &profile, const Placement &frame,
                               const Instance &workpiece) {
  const std::optional<Vec3> at = profile.vec("at");
  std::optional<RawExtent> raw = rawExtent(workpiece);
  if (!at || !raw || at->head<2>().isZero(1e-9))
    return;
  const Eigen::Matrix3d r = rotation(frame);
  const Vec3 composed = frame.at + r * *at;
  auto insideXY = [&](const Vec3 &q) {
    return q.x() >= raw->min.x() - 1e-6 && q.x() <= raw->max.x() + 1e-6 && q.y() >= raw->min.y() - 1e-6 &&
           q.y() <= raw->max.y() + 1e-6;
  };
  // The feature's own placement written again (its origin and axis) is
  // the same mistake, whether or not the composed origin leaves the block.
  const std::optional<Vec3> axis = profile.vec("axis");
  const bool featureAgain = (*at - frame.at).norm() < 1e-6 && axis && (*axis - frame.axis).norm() < 1e-6;
  const bool outsideComposed = !insideXY(composed) && insideXY(*at);
  if (!featureAgain && !outsideComposed)
    return;
  // Read in workpiece coordinates, the profile's placement relative to the feature is:
  const Vec3 relative = r.transpose() * (*at - frame.at);
  profile.set("at", Value::point(relative));
  if (axis)
    profile.set("axis", Value::direction(r.transpose() * *axis));
  if (auto ref = profile.vec("ref"))
    profile.set("ref", Value::direction(r.transpose() * *ref));
  // Written back in the feature's frame, as ISO 14649 places a profile.
  fix(profileInstance, "placement",
      newPlacement(relative, axis ? profile.vec("axis") : std::nullopt,
                   profileInstance.ref("placement").ref("ref_direction") ? profile.vec("ref") : std::nullopt));
  if (!outsideComposed) {
    assumed(profileInstance, "placement",
            "origin " + formatTuple({at->x(), at->y(), at->z()}, 4) + " mm and axis " +
                formatTuple({axis->x(), axis->y(), axis->z()}, 4) + " are the feature's own placement, in "
                "workpiece coordinates; read as the feature's frame (ISO 14649 places a profile in it)");
    return;
  }
  assumed(profileInstance, "placement",
          "origin " + formatTuple({at->x(), at->y(), at->z()}, 4) +
              " mm, placed in the feature's frame as ISO 14649 has it, lies at " +
              formatTuple({composed.x(), composed.y(), composed.z()}, 4) + " mm, outside the raw piece " +
              describe(raw->block) + "; read in workpiece coordinates (where it lies inside), as the generator "
              "evidently wrote it: " + formatTuple({relative.x(), relative.y(), relative.z()}, 4) +
              " mm from the feature's origin");
}

std::optional<std::string> Lowerer::feature(const Instance &f) {
  if (!f)
    return std::nullopt;
  if (auto it = lowered_.find(f.index()); it != lowered_.end())
    return it->second;
  Node n;
  std::vector<Instance> bosses;
  const Instance wpInstance = featureWorkpiece(f);
  Placement frame;  // the feature's, identity when it has none
  auto commonPlacement = [&] {
    if (auto p = placement(f.ref("feature_placement"))) {
      frame = *p;
      setPlacement(n, *p);
    } else {
      missing(f, "feature_placement");
    }
  };
  auto commonPlacementAndDepth = [&] {
    commonPlacement();
    setDepth(*this, n, f);
  };
  auto length = [&](std::string_view irName, std::string_view attribute) {
    if (auto v = toleranced(f, attribute))
      n.set(std::string(irName), Value::length(*v));
  };
  auto addProfile = [&](std::string_view attribute, bool required) {
    if (auto p = profile(f.ref(attribute))) {
      placeProfileOnce(f.ref(attribute), *p, frame, wpInstance);
      n.add(std::move(*p));
    } else if (required) {
      missing(f, attribute);
    }
  };
  // A taper_select: a diameter_taper's final diameter as `finalDiameter`,
  // an angle_taper's angle as `taper_angle`.
  auto addTaper = [&](std::string_view attribute, std::string_view finalDiameter, std::string_view what) {
    Instance taper = f.ref(attribute);
    if (!taper)
      return;
    if (taper.isA("diameter_taper")) {
      if (auto d = toleranced(taper, "final_diameter"))
        n.set(std::string(finalDiameter), Value::length(*d));
    } else if (taper.isA("angle_taper")) {
      if (auto a = taper.real("angle"))
        n.set("taper_angle", angle(*a));
    } else {
      unsupported(taper, what);
    }
  };
  auto addPath = [&](std::string_view attribute, bool required) {
    if (auto p = path(f.ref(attribute)))
      n.add(std::move(*p));
    else if (required)
      missing(f, attribute);
  };

  if (f.isA("planar_face")) {
    n.kind = ir::Kind::PlanarFace;
    commonPlacementAndDepth();
    Instance travel = f.ref("course_of_travel");
    if (travel && travel.isA("linear_path")) {
      if (auto len = toleranced(travel, "distance"))
        n.set("travel", Value::length(*len));
      if (auto d = direction(travel.ref("its_direction")))
        n.set("travel_dir", Value::direction(*d));
    } else {
      missing(f, "course_of_travel", "must be a LINEAR_PATH");
    }
    // The removal boundary is a line from the profile's origin along its x
    // axis (the feature's, when the profile has no placement of its own); the
    // face is that line swept along the course of travel.
    if (Instance boundary = f.ref("removal_boundary")) {
      if (auto w = toleranced(boundary, "profile_length"))
        n.set("width", Value::length(*w));
      else
        missing(boundary, "profile_length");
      Vec3 across = Vec3::UnitX();
      if (Instance at = boundary.ref("placement"))
        if (auto p = placement(at))
          across = p->ref;
      n.set("width_dir", Value::direction(across));
    } else {
      missing(f, "removal_boundary");
    }
    addProfile("face_boundary", false);
    bosses = f.refs("its_boss");
  } else if (f.isA("closed_pocket") || f.isA("open_pocket")) {
    const bool closed = f.isA("closed_pocket");
    n.kind = closed ? ir::Kind::ClosedPocket : ir::Kind::OpenPocket;
    commonPlacementAndDepth();
    copyAngle(n, "slope", f, "slope");
    Instance bottom = f.ref("bottom_condition");
    if (bottom.isA("planar_pocket_bottom_condition")) {
      n.set("bottom", Value::word("planar"));
    } else if (bottom.isA("through_pocket_bottom_condition")) {
      n.set("bottom", Value::word("through"));
    } else if (bottom.isA("radiused_pocket_bottom_condition")) {
      n.set("bottom", Value::word("radiused"));
      if (auto r = toleranced(bottom, "floor_radius"))
        n.set("bottom_radius", Value::length(*r));
    } else if (bottom.isA("general_pocket_bottom_condition")) {
      n.set("bottom", Value::word("general"));
    } else if (bottom) {
      unsupported(bottom, "pocket bottom condition");
    } else {
      missing(f, "bottom_condition");
    }
    length("planar_radius", "planar_radius");
    length("orthogonal_radius", "orthogonal_radius");
    addProfile(closed ? "feature_boundary" : "open_boundary", true);
    if (!closed)
      addProfile("wall_boundary", false);
    bosses = f.refs("its_boss");
  } else if (f.isA("round_hole")) {
    n.kind = ir::Kind::RoundHole;
    commonPlacement();
    Instance bottomCondition = f.ref("bottom_condition");
    if (!f.ref("depth") && bottomCondition.isA("through_bottom_condition")) {
      // A through hole goes through the raw piece along its axis, from where
      // the axis enters it to where it leaves. A placement inside the raw
      // piece moves up to the entry: drilling from there never rapids into
      // material the file does not say is gone.
      std::optional<RawExtent> raw = rawExtent(wpInstance);
      auto span = raw ? raw->span(frame.at, -frame.axis) : std::nullopt;
      if (span && span->first <= 1e-6 && span->second > 1e-6) {
        const double depth = span->second - std::min(0.0, span->first);
        std::string what = "absent; assumed " + formatFixed(depth, 4) +
                           " mm: a through hole, along its axis through the raw piece " + describe(raw->block);
        if (span->first < -1e-6) {
          const Vec3 was = frame.at;
          frame.at += frame.axis * -span->first;
          setPlacement(n, frame);
          fix(f, "feature_placement", placementAt(f.ref("feature_placement"), frame.at));
          what += ", from where its axis enters it, " + formatTuple({frame.at.x(), frame.at.y(), frame.at.z()}, 4) +
                  " mm (its placement " + formatTuple({was.x(), was.y(), was.z()}, 4) + " mm is inside the raw piece)";
        }
        n.set("depth", Value::length(depth));
        assumed(f, "depth", what);
        fix(f, "depth", depthPlane(depth));
      } else {
        missing(f, "depth",
                raw ? "is needed to lower it: the hole's placement is not inside the raw piece, so how deep it goes "
                      "through cannot be assumed"
                    : "is needed to lower it: a through hole's depth is assumed only from a BLOCK raw piece");
      }
    } else {
      setDepth(*this, n, f);
    }
    if (auto d = toleranced(f, "diameter"))
      n.set("diameter", Value::length(*d));
    else
      missing(f, "diameter");
    addTaper("change_in_diameter", "final_diameter", "hole taper");
    const Instance &bottom = bottomCondition;
    if (bottom.isA("through_bottom_condition")) {
      n.set("bottom", Value::word("through"));
    } else if (bottom.isA("flat_with_radius_hole_bottom")) {
      n.set("bottom", Value::word("flat_with_radius"));
      if (auto r = toleranced(bottom, "corner_radius"))
        n.set("bottom_radius", Value::length(*r));
    } else if (bottom.isA("flat_hole_bottom")) {
      n.set("bottom", Value::word("flat"));
    } else if (bottom.isA("conical_hole_bottom")) {
      n.set("bottom", Value::word("conical"));
      if (auto a = bottom.real("tip_angle"))
        n.set("tip_angle", angle(*a));
      if (auto r = toleranced(bottom, "tip_radius"))
        n.set("tip_radius", Value::length(*r));
    } else if (bottom.isA("spherical_hole_bottom")) {
      n.set("bottom", Value::word("spherical"));
      if (auto r = toleranced(bottom, "radius"))
        n.set("bottom_radius", Value::length(*r));
    } else if (bottom) {
      unsupported(bottom, "hole bottom condition");
    } else {
      missing(f, "bottom_condition");
    }
  } else if (f.isA("slot")) {
    n.kind = ir::Kind::Slot;
    commonPlacementAndDepth();
    std::vector<Instance> ends = f.refs("end_conditions");
    for (size_t i = 0; i < 2; ++i) {
      std::string word = "open";
      if (i < ends.size()) {
        const Instance &e = ends[i];
        if (e.isA("radiused_slot_end_type"))
          word = "radiused";
        else if (e.isA("flat_slot_end_type"))
          word = "flat";
        else if (e.isA("woodruff_slot_end_type")) {
          word = "woodruff";
          if (auto r = toleranced(e, "radius"))
            n.set("end_radius", Value::length(*r));
        } else if (e.isA("loop_slot_end_type"))
          word = "loop";
        else if (!e.isA("open_slot_end_type"))
          unsupported(e, "slot end type");
      }
      n.set(i == 0 ? "end_1" : "end_2", Value::word(word));
    }
    PathContext context;
    context.frame = frame;
    context.raw = rawExtent(wpInstance);
    context.openEnds = n.text("end_1") == "open" && n.text("end_2") == "open";
    if (auto p = path(f.ref("course_of_travel"), &context))
      n.add(std::move(*p));
    else
      missing(f, "course_of_travel");
    addProfile("swept_shape", true);
    slotDepthFromProfile(n, f);
  } else if (f.isA("step")) {
    n.kind = ir::Kind::Step;
    commonPlacementAndDepth();
    addPath("open_boundary", true);
    addProfile("wall_boundary", false);
    bosses = f.refs("its_boss");
  } else if (f.isA("general_outside_profile")) {
    n.kind = ir::Kind::GeneralOutsideProfile;
    commonPlacementAndDepth();
    addPath("profile_swept_shape", false);
    addProfile("feature_boundary", true);
  } else if (f.isA("toolpath_feature")) {
    // ISO 14649-10: a feature that is no more than the toolpaths that
    // machine it. Its depth plane says nothing the IR keeps: the steps'
    // moves are checked for the safety rules only.
    n.kind = ir::Kind::ToolpathFeature;
    commonPlacement();
  } else if (f.isA("outer_diameter") || f.isA("outer_diameter_to_shoulder")) {
    // ISO 14649-12 turned features: placed on the turning axis (their
    // placement's z); their profiles lie in its XZ half plane and are kept
    // as the file places them (docs/turning.md).
    const bool shoulder = f.isA("outer_diameter_to_shoulder");
    n.kind = shoulder ? ir::Kind::OuterDiameterToShoulder : ir::Kind::OuterDiameter;
    commonPlacement();
    if (auto d = toleranced(f, "diameter_at_placement"))
      n.set("diameter", Value::length(*d));
    else
      missing(f, "diameter_at_placement");
    if (shoulder) {
      if (auto profile = this->profile(f.ref("v_shape_boundary")))
        n.add(std::move(*profile));
      else
        missing(f, "v_shape_boundary");
    } else {
      length("length", "feature_length");
      if (!n.has("length"))
        missing(f, "feature_length");
      addTaper("reduced_size", "reduced_diameter", "taper of an outer diameter");
    }
  } else if (f.isA("defined_thread")) {
    // A thread on the turning axis: its diameters and length; the pitch
    // follows from them and the form (docs/turning.md).
    n.kind = ir::Kind::Thread;
    commonPlacement();
    length("major_diameter", "major_diameter");
    if (!n.has("major_diameter"))
      missing(f, "major_diameter");
    length("pitch_diameter", "pitch_diameter");
    length("minor_diameter", "minor_diameter");
    if (Instance partial = f.ref("partial_profile")) {
      if (auto l = toleranced(partial, "effective_length"))
        n.set("length", Value::length(*l));
      else
        missing(partial, "effective_length");
    } else {
      missing(f, "partial_profile");
    }
    if (Instance starts = f.ref("number_of_threads"))
      if (auto v = starts.real("its_parameter_value")) {
        if (*v >= 1 && *v <= 100 && *v == std::floor(*v))
          n.set("starts", Value::integer(static_cast<int64_t>(*v)));
        else
          missing(starts, "its_parameter_value", "is not a number of thread starts (a whole number from 1)");
      }
    if (Instance hand = f.ref("thread_hand")) {
      std::string h = hand.string("descriptive_string").value_or("");
      std::transform(h.begin(), h.end(), h.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (h == "right" || h == "left")
        n.set("hand", Value::word(h));
      else
        missing(hand, "descriptive_string", "is not a thread's hand (right or left)");
    }
    if (auto inner = f.boolean("inner_or_outer_thread"))
      n.set("inner", Value::boolean(*inner));
    if (Instance form = f.ref("form"))
      if (auto text = form.string("descriptive_string"))
        n.set("form", Value::string(*text));
  } else if (f.isA("knurl")) {
    // Its pattern by its subtype, the surface it is pressed into by its base
    // feature, its extent by its partial profile (docs/turning.md).
    n.kind = ir::Kind::Knurl;
    commonPlacement();
    if (auto base = feature(f.ref("base_feature")))
      n.set("base", Value::ref(*base));
    else
      missing(f, "base_feature");
    if (Instance partial = f.ref("partial_profile"))
      if (auto l = toleranced(partial, "effective_length"))
        n.set("length", Value::length(*l));
    length("tooth_depth", "tooth_depth");
    length("diametral_pitch", "diametral_pitch");
    length("root_fillet", "root_fillet");
    length("major_diameter", "major_diameter");
    length("nominal_diameter", "nominal_diameter");
    if (auto teeth = f.integer("number_of_teeth"))
      n.set("teeth", Value::integer(*teeth));
    const char *pattern = f.isA("straight_knurl")  ? "straight"
                          : f.isA("diagonal_knurl") ? "diagonal"
                          : f.isA("diamond_knurl")  ? "diamond"
                                                    : "tool";
    n.set("pattern", Value::word(pattern));
    copyAngle(n, "helix_angle", f, f.isA("diamond_knurl") ? "helix1_angle" : "helix_angle");
    copyAngle(n, "helix2_angle", f, "helix2_angle");
  } else if (f.isA("thread")) {
    unsupported(f, "thread (a catalogue thread gives its size by a reference to a standard; stepnc turns defined "
                   "threads, whose diameters the file gives)");
    return std::nullopt;
  } else if (f.isA("revolved_feature")) {
    static constexpr std::tuple<std::string_view, ir::Kind, std::string_view> kRevolved[] = {
        {"revolved_flat", ir::Kind::RevolvedFlat, "flat_edge_shape"},
        {"revolved_round", ir::Kind::RevolvedRound, "rounded_edge_shape"},
        {"groove", ir::Kind::Groove, "sweep"},
        {"general_revolution", ir::Kind::GeneralRevolution, "outer_edge_profile"}};
    std::string_view shape;
    for (const auto &[entity, kind, attribute] : kRevolved)
      if (f.isA(entity)) {
        n.kind = kind;
        shape = attribute;
      }
    if (shape.empty()) {
      unsupported(f, "feature");
      return std::nullopt;
    }
    commonPlacement();
    length("radius", "radius");
    if (!n.has("radius"))
      missing(f, "radius");
    if (Instance side = f.ref("material_side"))
      if (auto d = direction(side))
        n.set("material_side", Value::direction(*d));
    if (auto profile = this->profile(f.ref(shape)))
      n.add(std::move(*profile));
    else
      missing(f, shape);
  } else if (f.isA("am_feature")) {
    if (!additiveFeature(f, n))
      return std::nullopt;
  } else if (f.isA("boss")) {
    n.kind = ir::Kind::Boss;
    commonPlacementAndDepth();
    copyAngle(n, "slope", f, "slope");
    addProfile("its_boundary", true);
  } else {
    unsupported(f, "feature");
    return std::nullopt;
  }
  stamp(n, f);
  n.symbol = symbolFor('%', f.string("its_id"), n.kindName());
  lowered_[f.index()] = n.symbol;
  // Bosses are features of their own; the pocket, face or step refers to them
  // as islands, the material its machining must leave.
  for (const Instance &b : bosses) {
    if (!b.isA("boss")) {
      unsupported(b, "boss");
      continue;
    }
    if (auto sym = feature(b)) {
      Node island(ir::Kind::Island);
      stamp(island, b, "");
      island.set("feature", Value::ref(*sym));
      n.add(std::move(island));
    }
  }
  const std::string symbol = n.symbol;
  std::optional<std::string> wp = workpiece(wpInstance);
  Node *owner = wp ? findResource(*wp) : nullptr;
  if (!owner) {
    missing(f, "its_workpiece");
    return symbol;
  }
  owner->add(std::move(n));
  return symbol;
}

} // namespace stepnc::lowering
