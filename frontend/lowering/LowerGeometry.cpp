// Lowering of geometry: points, directions, placements, planes, toleranced
// lengths, profiles, travel paths and curves.
#include "frontend/lowering/Lowerer.h"

#include "support/Format.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace stepnc::lowering {

namespace {

/// The slab method over the first `axes` coordinates.
std::optional<std::pair<double, double>> boxSpan(const Vec3 &lo, const Vec3 &hi, const Vec3 &p, const Vec3 &d,
                                                 int axes) {
  constexpr double kEps = 1e-9;
  double enter = -std::numeric_limits<double>::infinity(), exit = std::numeric_limits<double>::infinity();
  for (int i = 0; i < axes; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (p[i] < lo[i] - kEps || p[i] > hi[i] + kEps)
        return std::nullopt;
      continue;
    }
    double t0 = (lo[i] - p[i]) / d[i], t1 = (hi[i] - p[i]) / d[i];
    if (t0 > t1)
      std::swap(t0, t1);
    enter = std::max(enter, t0);
    exit = std::min(exit, t1);
  }
  if (enter > exit + kEps)
    return std::nullopt;
  return std::pair{enter, exit};
}

} // namespace

std::optional<std::pair<double, double>> RawExtent::spanXY(const Vec3 &p, const Vec3 &d) const {
  return boxSpan(min, max, p, d, 2);
}

std::optional<std::pair<double, double>> RawExtent::span(const Vec3 &p, const Vec3 &d) const {
  return boxSpan(min, max, p, d, 3);
}

std::optional<Vec3> Lowerer::point(const Instance &p) {
  if (!p || !p.isA("cartesian_point")) {
    if (p)
      unsupported(p, "a point was expected");
    return std::nullopt;
  }
  const std::vector<double> c = p.reals("coordinates");
  if (c.empty() || c.size() > 3) {
    missing(p, "coordinates", "must have 1 to 3 values");
    return std::nullopt;
  }
  return Vec3(c[0], c.size() > 1 ? c[1] : 0.0, c.size() > 2 ? c[2] : 0.0);
}

std::optional<Vec3> Lowerer::direction(const Instance &d) {
  if (!d || !d.isA("direction")) {
    if (d)
      unsupported(d, "a direction was expected");
    return std::nullopt;
  }
  const std::vector<double> r = d.reals("direction_ratios");
  Vec3 v(r.size() > 0 ? r[0] : 0.0, r.size() > 1 ? r[1] : 0.0, r.size() > 2 ? r[2] : 0.0);
  if (r.size() < 2 || v.norm() < 1e-12) {
    missing(d, "direction_ratios", "must be a non-zero vector");
    return std::nullopt;
  }
  return v.normalized();
}

std::optional<Placement> Lowerer::placement(const Instance &a) {
  if (!a)
    return std::nullopt;
  if (!a.isA("axis2_placement_3d")) {
    unsupported(a, "an axis2_placement_3d was expected");
    return std::nullopt;
  }
  Placement p;
  if (Instance location = a.ref("location")) {
    auto at = point(location);
    if (!at)
      return std::nullopt;  // point() said why
    p.at = *at;
  } else if (!a.ref("axis") && !a.ref("ref_direction")) {
    // A placement with no location and no directions is its parent frame.
    assumed(a, "location", "absent (and no axis or ref_direction); assumed (0, 0, 0): the frame it is placed in");
    fix(a, "location", newInstance("CARTESIAN_POINT('',(0.,0.,0.))"));
  } else {
    missing(a, "location");
    return std::nullopt;
  }
  Instance axisInstance = a.ref("axis"), refInstance = a.ref("ref_direction");
  if (swapAxisAndRef_ && axisInstance && refInstance)
    std::swap(axisInstance, refInstance);  // choosePlacementReading says why
  if (axisInstance)
    if (auto v = direction(axisInstance))
      p.axis = *v;
  Vec3 ref = Vec3::UnitX();
  if (refInstance)
    if (auto v = direction(refInstance))
      ref = *v;
  // ISO 10303-42: the x axis is the ref direction projected normal to z; when
  // it is (nearly) parallel to z, the standard's default takes over.
  Vec3 x = ref - ref.dot(p.axis) * p.axis;
  if (x.norm() < 1e-9) {
    const Vec3 fallback = std::abs(p.axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    x = fallback - fallback.dot(p.axis) * p.axis;
  }
  p.ref = x.normalized();
  return p;
}

void Lowerer::setPlacement(Node &node, const Placement &p) {
  node.set("at", Value::point(p.at));
  node.set("axis", Value::direction(p.axis));
  node.set("ref", Value::direction(p.ref));
}

std::optional<double> Lowerer::planeHeight(const Instance &owner, std::string_view attribute, std::string_view role,
                                           const std::optional<Vec3> &featureAxis) {
  Instance plane = owner.ref(attribute);
  if (!plane) {
    missing(owner, attribute);
    return std::nullopt;
  }
  if (!plane.isA("plane")) {
    unsupported(plane, std::string(role) + " must be a PLANE");
    return std::nullopt;
  }
  std::optional<Placement> p = placement(plane.ref("position"));
  if (!p) {
    missing(plane, "position");
    return std::nullopt;
  }
  if (std::abs(std::abs(p->axis.z()) - 1.0) > 1e-9 && std::abs(std::abs(p->ref.z()) - 1.0) < 1e-9 &&
      std::abs(p->axis.z()) < 1e-9) {
    // A plane of heights whose placement gives a horizontal normal and its
    // ref_direction along z: the two written the wrong way round (the height
    // is read from the location's z either way).
    assumed(plane.ref("position"), "axis",
            "(" + formatFixed(p->axis.x(), 4) + ", " + formatFixed(p->axis.y(), 4) + ", " +
                formatFixed(p->axis.z(), 4) + ") makes " + std::string(role) + " " + hashId(plane.id()) +
                " vertical; its ref_direction is along z: read with the two swapped, the plane normal to z");
  } else if (featureAxis && std::abs(featureAxis->z()) < 1 - 1e-9 &&
             std::abs(std::abs(p->axis.dot(*featureAxis)) - 1.0) < 1e-6) {
    // A plane in the feature's frame whose normal is written as the
    // feature's axis in workpiece coordinates (a feature on a side face):
    // the plane is normal to the feature's axis either way.
    std::string what = formatTuple({p->axis.x(), p->axis.y(), p->axis.z()}, 4);
    what += " is the feature's axis in workpiece coordinates; ";
    what += role;
    what += " " + hashId(plane.id()) + " read as normal to the feature's axis, " + formatFixed(p->at.z(), 4) +
            " mm along it in the feature's frame";
    assumed(plane.ref("position"), "axis", what);
  } else if (std::abs(std::abs(p->axis.z()) - 1.0) > 1e-9) {
    char normal[96];
    std::snprintf(normal, sizeof normal, "(%g, %g, %g)", p->axis.x(), p->axis.y(), p->axis.z());
    unsupported(plane, std::string(role) + " whose normal " + normal + " is not the z axis");
    return std::nullopt;
  }
  return p->at.z();
}

std::optional<double> Lowerer::toleranced(const Instance &owner, std::string_view attribute) {
  if (Instance t = owner.ref(attribute)) {
    if (t.isA("toleranced_length_measure"))
      return t.real("theoretical_size");
    if (t.isA("numeric_parameter"))
      return t.real("its_parameter_value");
    unsupported(t, "a length was expected");
    return std::nullopt;
  }
  return owner.real(attribute);
}

std::optional<Node> Lowerer::profile(const Instance &p) {
  if (!p)
    return std::nullopt;
  auto withPlacement = [&](Node &n) {
    if (Instance a = p.ref("placement"))
      if (auto pl = placement(a))
        setPlacement(n, *pl);
  };
  auto length = [&](Node &n, std::string_view irName, std::string_view attribute, bool required) {
    if (auto v = toleranced(p, attribute))
      n.set(std::string(irName), Value::length(*v));
    else if (required)
      missing(p, attribute);
  };
  auto angleOf = [&](Node &n, std::string_view irName, std::string_view attribute, bool required) {
    if (auto v = p.real(attribute))
      n.set(std::string(irName), angle(*v));
    else if (required)
      missing(p, attribute);
  };
  Node n;
  if (p.isA("rectangular_closed_profile")) {
    n.kind = ir::Kind::RectangularProfile;
    length(n, "width", "profile_width", true);
    length(n, "length", "profile_length", true);
    withPlacement(n);
  } else if (p.isA("circular_closed_profile")) {
    n.kind = ir::Kind::CircularProfile;
    length(n, "diameter", "diameter", true);
    withPlacement(n);
  } else if (p.isA("linear_profile")) {
    n.kind = ir::Kind::LinearProfile;
    length(n, "length", "profile_length", true);
  } else if (p.isA("square_u_profile")) {
    n.kind = ir::Kind::SquareUProfile;
    length(n, "width", "width", true);
    length(n, "first_radius", "first_radius", false);
    angleOf(n, "first_angle", "first_angle", false);
    length(n, "second_radius", "second_radius", false);
    angleOf(n, "second_angle", "second_angle", false);
    // Walls at angles the file leaves out are vertical (what the slot's
    // shape is made with); the write-back says so in the file's angle unit.
    // A radius left out stays so: the schema's positive length cannot say
    // a sharp corner.
    for (std::string_view wall : {"first_angle", "second_angle"})
      if (!p.real(wall))
        fix(p, wall, real(90.0 / writtenAngleToDeg_));
  } else if (p.isA("rounded_u_profile")) {
    n.kind = ir::Kind::RoundedUProfile;
    length(n, "width", "width", true);
  } else if (p.isA("vee_profile")) {
    n.kind = ir::Kind::VeeProfile;
    length(n, "profile_radius", "profile_radius", false);
    angleOf(n, "profile_angle", "profile_angle", true);
    angleOf(n, "tilt_angle", "tilt_angle", true);
  } else if (p.isA("partial_circular_profile")) {
    n.kind = ir::Kind::PartialCircularProfile;
    length(n, "radius", "radius", true);
    angleOf(n, "sweep_angle", "sweep_angle", true);
  } else if (p.isA("general_closed_profile") || p.isA("general_profile")) {
    n.kind = ir::Kind::GeneralProfile;
    const bool closed = p.isA("general_closed_profile");
    n.set("closed", Value::boolean(closed));
    if (auto c = curve(p.ref(closed ? "closed_profile_shape" : "its_profile"))) {
      if (closed)
        closePolyline(p.ref("closed_profile_shape"), *c);
      n.add(std::move(*c));
    } else
      missing(p, closed ? "closed_profile_shape" : "its_profile");
  } else {
    unsupported(p, "profile");
    return std::nullopt;
  }
  stamp(n, p, "");
  return n;
}

std::optional<Node> Lowerer::path(const Instance &t, const PathContext *context) {
  if (!t)
    return std::nullopt;
  Node n(ir::Kind::Path);
  stamp(n, t, "");
  Placement pl;
  if (Instance a = t.ref("placement"))
    if (auto p = placement(a))
      pl = *p;
  if (t.isA("linear_path")) {
    Node line(ir::Kind::Line);
    stamp(line, t, "");
    line.set("at", Value::point(pl.at));
    std::optional<Vec3> dir = direction(t.ref("its_direction"));
    if (!dir && context && !t.ref("its_direction")) {
      // Along the feature's x axis: the direction its frame is written for.
      dir = Vec3::UnitX();
      assumed(t, "its_direction", "absent; assumed (1, 0, 0), the x axis of the feature's frame");
      fix(t, "its_direction", newInstance("DIRECTION('',(1.,0.,0.))"));
    }
    if (dir)
      line.set("dir", Value::direction(*dir));
    else
      missing(t, "its_direction");
    std::optional<double> length = toleranced(t, "distance");
    if (!length && dir && context && context->openEnds && context->raw && !t.ref("distance")) {
      // Open at both ends: the path runs to where it leaves the raw piece.
      const Placement &f = context->frame;
      const Vec3 y = f.axis.cross(f.ref);
      auto toWorkpiece = [&](const Vec3 &v) { return Vec3(v.x() * f.ref + v.y() * y + v.z() * f.axis); };
      const Vec3 from = f.at + toWorkpiece(pl.at), along = toWorkpiece(*dir).normalized();
      if (auto span = context->raw->spanXY(from, along); span && span->second > 1e-6) {
        length = span->second;
        assumed(t, "distance",
                "absent; assumed " + formatFixed(*length, 4) + " mm, to where the path leaves the raw piece " +
                    hashId(context->raw->block.id()) + " " + std::string(context->raw->block.entityName()) +
                    " (both ends of the slot are open)");
        fix(t, "distance", tolerancedLength(*length));
      }
    }
    if (length)
      line.set("length", Value::length(*length));
    else
      missing(t, "distance");
    n.add(std::move(line));
    return n;
  }
  if (t.isA("general_path")) {
    if (auto c = curve(t.ref("swept_path")))
      n.add(std::move(*c));
    else
      missing(t, "swept_path");
    return n;
  }
  unsupported(t, "travel path");
  return std::nullopt;
}

void Lowerer::closePolyline(const Instance &shape, Node &curve) {
  if (curve.kind != ir::Kind::Polyline || curve.children.size() < 3)
    return;
  const std::optional<Vec3> first = curve.children.front().vec("at"), last = curve.children.back().vec("at");
  if (!first || !last || (*first - *last).norm() <= 1e-6)
    return;
  Node closing = curve.children.front();
  curve.add(std::move(closing));
  assumed(shape, "points",
          "end at " + formatTuple({last->x(), last->y(), last->z()}, 4) + " mm, not at the first point " +
              formatTuple({first->x(), first->y(), first->z()}, 4) +
              " mm, in a closed profile: closed with a line back to the first point");
}

std::optional<Node> Lowerer::curve(const Instance &c) {
  if (!c)
    return std::nullopt;
  Node n;
  if (c.isA("polyline")) {
    n.kind = ir::Kind::Polyline;
    for (const Instance &p : c.refs("points"))
      if (auto v = point(p)) {
        Node pt(ir::Kind::Point);
        stamp(pt, p, "");
        pt.set("at", Value::point(*v));
        n.add(std::move(pt));
      }
  } else if (c.isA("line")) {
    n.kind = ir::Kind::Line;
    if (auto at = point(c.ref("pnt")))
      n.set("at", Value::point(*at));
    else
      missing(c, "pnt");
    Instance vec = c.ref("dir");
    if (auto d = vec ? direction(vec.ref("orientation")) : std::nullopt) {
      n.set("dir", Value::direction(*d));
      if (auto m = vec.real("magnitude"))
        n.set("length", Value::length(*m));
    } else {
      missing(c, "dir");
    }
  } else if (c.isA("circle") || c.isA("helix")) {
    n.kind = c.isA("circle") ? ir::Kind::Circle : ir::Kind::Helix;
    if (auto p = placement(c.ref("position")))
      setPlacement(n, *p);
    else
      missing(c, "position");
    if (auto r = c.real("radius"))
      n.set("radius", Value::length(*r));
    else
      missing(c, "radius");
    if (n.kind == ir::Kind::Helix) {
      if (auto pitch = c.real("pitch"))
        n.set("pitch", Value::length(*pitch));
      else
        missing(c, "pitch");
    }
  } else if (c.isA("trimmed_curve")) {
    n.kind = ir::Kind::TrimmedCurve;
    // Each trim is a point and/or a parameter; keep what is given.
    for (std::string_view which : {"trim_1", "trim_2"}) {
      const std::string side = which == "trim_1" ? "from" : "to";
      const p21::Value *set = c.attr(which);
      if (!set || set->kind != p21::ValueKind::List)
        continue;
      for (const p21::Value &v : c.values().children(*set)) {
        if (v.kind == p21::ValueKind::Reference) {
          if (auto pt = point(c.follow(v)))
            n.set(side + "_point", Value::point(*pt));
        } else if (v.kind == p21::ValueKind::Typed && v.count == 1) {
          const p21::Value &inner = c.values().children(v)[0];
          if (inner.kind == p21::ValueKind::Real || inner.kind == p21::ValueKind::Integer)
            n.set(side + "_param", Value::ratio(inner.kind == p21::ValueKind::Real ? inner.real
                                                                                 : static_cast<double>(inner.integer)));
        }
      }
    }
    n.set("sense", Value::boolean(c.boolean("sense_agreement").value_or(true)));
    if (auto basis = curve(c.ref("basis_curve")))
      n.add(std::move(*basis));
    else
      missing(c, "basis_curve");
  } else if (c.isA("composite_curve")) {
    n.kind = ir::Kind::CompositeCurve;
    for (const Instance &s : c.refs("segments")) {
      Node seg(ir::Kind::Segment);
      stamp(seg, s, "");
      seg.set("transition", Value::word(s.enumeration("transition").value_or("continuous")));
      seg.set("same_sense", Value::boolean(s.boolean("same_sense").value_or(true)));
      if (auto parent = curve(s.ref("parent_curve")))
        seg.add(std::move(*parent));
      else
        missing(s, "parent_curve");
      n.add(std::move(seg));
    }
  } else if (c.isA("b_spline_curve")) {
    n.kind = ir::Kind::BSplineCurve;
    if (auto degree = c.integer("degree"))
      n.set("degree", Value::integer(*degree));
    else
      missing(c, "degree");
    const char *form = c.isA("b_spline_curve_with_knots") ? "with_knots"
                       : c.isA("bezier_curve")            ? "bezier"
                       : c.isA("quasi_uniform_curve")     ? "quasi_uniform"
                                                          : "uniform";
    n.set("form", Value::word(form));
    if (auto closed = c.enumeration("closed_curve"); closed == "t" || closed == "f")
      n.set("closed", Value::boolean(*closed == "t"));
    const std::vector<Instance> points = c.refs("control_points_list");
    const std::vector<double> weights = c.isA("rational_b_spline_curve") ? c.reals("weights_data") : std::vector<double>{};
    if (!weights.empty() && weights.size() != points.size())
      missing(c, "weights_data", "must have one weight per control point");
    for (size_t i = 0; i < points.size(); ++i)
      if (auto v = point(points[i])) {
        Node pt(ir::Kind::Point);
        stamp(pt, points[i], "");
        pt.set("at", Value::point(*v));
        if (i < weights.size() && weights.size() == points.size())
          pt.set("weight", Value::ratio(weights[i]));
        n.add(std::move(pt));
      }
    if (c.isA("b_spline_curve_with_knots")) {
      const std::vector<double> knots = c.reals("knots");
      const std::vector<double> multiplicities = c.reals("knot_multiplicities");
      if (knots.size() != multiplicities.size())
        missing(c, "knot_multiplicities", "must have one multiplicity per knot");
      for (size_t i = 0; i < knots.size() && i < multiplicities.size(); ++i) {
        Node k(ir::Kind::Knot);
        k.set("value", Value::ratio(knots[i]));
        k.set("multiplicity", Value::integer(static_cast<int64_t>(multiplicities[i])));
        n.add(std::move(k));
      }
    }
  } else {
    unsupported(c, "curve");
    return std::nullopt;
  }
  stamp(n, c, "");
  return n;
}

} // namespace stepnc::lowering
