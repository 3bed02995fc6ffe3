// Lowering of manufacturing features (ISO 14649-10): planar faces, pockets,
// round holes, slots, steps, general outside profiles and bosses. A feature is
// lowered once, under its workpiece, and referred to by symbol.
#include "frontend/lowering/Lowerer.h"

namespace stepnc::lowering {

namespace {

// `depth` is a plane in the feature's frame: the feature goes down to it.
void setDepth(Lowerer &l, Node &n, const Instance &f) {
  if (auto z = l.planeHeight(f, "depth", "feature depth"))
    n.set("depth", Value::length(-*z));
}

} // namespace

std::optional<std::string> Lowerer::feature(const Instance &f) {
  if (!f)
    return std::nullopt;
  if (auto it = lowered_.find(f.index()); it != lowered_.end())
    return it->second;
  Node n;
  std::vector<Instance> bosses;
  auto commonPlacementAndDepth = [&] {
    if (auto p = placement(f.ref("feature_placement")))
      setPlacement(n, *p);
    else
      missing(f, "feature_placement");
    setDepth(*this, n, f);
  };
  auto length = [&](std::string_view irName, std::string_view attribute) {
    if (auto v = toleranced(f, attribute))
      n.set(std::string(irName), Value::length(*v));
  };
  auto addProfile = [&](std::string_view attribute, bool required) {
    if (auto p = profile(f.ref(attribute)))
      n.add(std::move(*p));
    else if (required)
      missing(f, attribute);
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
    copyReal(n, "slope", f, "slope", Value::angle);
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
    commonPlacementAndDepth();
    if (auto d = toleranced(f, "diameter"))
      n.set("diameter", Value::length(*d));
    else
      missing(f, "diameter");
    if (Instance taper = f.ref("change_in_diameter")) {
      if (taper.isA("diameter_taper")) {
        if (auto d = toleranced(taper, "final_diameter"))
          n.set("final_diameter", Value::length(*d));
      } else if (taper.isA("angle_taper")) {
        if (auto a = taper.real("angle"))
          n.set("taper_angle", Value::angle(*a));
      } else {
        unsupported(taper, "hole taper");
      }
    }
    Instance bottom = f.ref("bottom_condition");
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
        n.set("tip_angle", Value::angle(*a));
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
    addPath("course_of_travel", true);
    addProfile("swept_shape", true);
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
  } else if (f.isA("boss")) {
    n.kind = ir::Kind::Boss;
    commonPlacementAndDepth();
    copyReal(n, "slope", f, "slope", Value::angle);
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
  std::optional<std::string> wp = workpiece(f.ref("its_workpiece"));
  Node *owner = wp ? findResource(*wp) : nullptr;
  if (!owner) {
    missing(f, "its_workpiece");
    return symbol;
  }
  owner->add(std::move(n));
  return symbol;
}

} // namespace stepnc::lowering
