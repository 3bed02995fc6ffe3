#include "ir/geom/AmShape.h"

#include "geom/Boolean.h"
#include "ir/geom/Curves.h"
#include "ir/geom/FeatureShape.h"
#include "support/Format.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::ir {

using geom::Loop;
using geom::Region;
using geom::Vec2;

namespace {

constexpr double kPi = std::numbers::pi;
/// Half the side of the square a faceted solid's sections are clipped from,
/// and of the box that tells a bounded solid from an unbounded one (mm).
constexpr double kFar = 1e5;
/// Sides of the polygon a channel's circular section is drawn with: drawn
/// around the circle (never inside it).
constexpr int kDiscSides = 32;

Region polygonRegion(const std::vector<Vec2> &ccw) {
  Region r;
  if (ccw.size() >= 3) {
    Loop l = geom::polygon(ccw);
    if (l.area() > 1e-12)
      r.loops.push_back(std::move(l));
  }
  return r;
}

/// The convex polygon `poly` (counter-clockwise) cut to the half plane
/// n . p <= c.
std::vector<Vec2> clipHalfPlane(const std::vector<Vec2> &poly, const Vec2 &n, double c) {
  std::vector<Vec2> out;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec2 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double da = n.dot(a) - c, db = n.dot(b) - c;
    if (da <= 0)
      out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0))
      out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

/// The corners of the polytope of half spaces n . p <= n . a (with a box
/// of half side kFar): every point where three planes meet inside all.
std::vector<Vec3> polytopeCorners(const std::vector<std::pair<Vec3, Vec3>> &planes) {
  std::vector<std::pair<Vec3, Vec3>> all = planes;
  for (int axis = 0; axis < 3; ++axis)
    for (double s : {-1.0, 1.0}) {
      Vec3 n = Vec3::Zero();
      n[axis] = s;
      all.push_back({n * kFar, n});
    }
  std::vector<Vec3> corners;
  for (size_t i = 0; i < all.size(); ++i)
    for (size_t j = i + 1; j < all.size(); ++j)
      for (size_t k = j + 1; k < all.size(); ++k) {
        Eigen::Matrix3d m;
        m.row(0) = all[i].second;
        m.row(1) = all[j].second;
        m.row(2) = all[k].second;
        if (std::abs(m.determinant()) < 1e-9)
          continue;
        const Vec3 rhs(all[i].second.dot(all[i].first), all[j].second.dot(all[j].first),
                       all[k].second.dot(all[k].first));
        const Vec3 p = m.partialPivLu().solve(rhs);
        bool inside = true;
        for (const auto &[a, n] : all)
          if (n.dot(p - a) > 1e-7 * std::max(1.0, p.norm())) {
            inside = false;
            break;
          }
        if (inside && std::none_of(corners.begin(), corners.end(), [&](const Vec3 &c) { return (c - p).norm() < 1e-7; }))
          corners.push_back(p);
      }
  return corners;
}

/// The points of the channel's polyline as the disc centres of its tube:
/// each segment sampled finely enough that the hull of its discs misses the
/// tube between samples by far less than the chord tolerance.
void addTubeSlab(const VoidTube &v, double z0, double z1, double margin, std::vector<Region> &parts) {
  const double r = v.radius;
  const double grow = margin + kVoidChordTolerance;
  for (size_t i = 0; i + 1 < v.points.size(); ++i) {
    const Vec3 &a = v.points[i], &b = v.points[i + 1];
    if (std::min(a.z(), b.z()) > z1 + r || std::max(a.z(), b.z()) < z0 - r)
      continue;
    const double len = (b - a).norm();
    const int n = std::max(2, static_cast<int>(std::ceil(len / (r / 8))) + 1);
    std::vector<double> ts;
    for (int s = 0; s < n; ++s)
      ts.push_back(static_cast<double>(s) / (n - 1));
    // Where the axis crosses the slab's faces: the discs' radius changes
    // slope there.
    if (std::abs(b.z() - a.z()) > 1e-12)
      for (double z : {z0, z1}) {
        const double t = (z - a.z()) / (b.z() - a.z());
        if (t > 0 && t < 1)
          ts.push_back(t);
      }
    std::vector<Vec2> pts;
    for (double t : ts) {
      const Vec3 c = a + (b - a) * t;
      const double dz = c.z() < z0 ? z0 - c.z() : c.z() > z1 ? c.z() - z1 : 0.0;
      if (dz >= r)
        continue;
      const double rho = (std::sqrt(r * r - dz * dz) + grow) / std::cos(kPi / kDiscSides);
      for (int k = 0; k < kDiscSides; ++k) {
        const double phi = 2 * kPi * k / kDiscSides;
        pts.push_back(Vec2(c.x(), c.y()) + rho * Vec2(std::cos(phi), std::sin(phi)));
      }
    }
    if (pts.size() >= 3) {
      Region piece = polygonRegion(geom::convexHull(std::move(pts)));
      if (!piece.empty())
        parts.push_back(std::move(piece));
    }
  }
}

/// A curve node's pieces as a polyline in its coordinates, arcs cut into
/// chords within kVoidChordTolerance.
std::optional<std::vector<Vec3>> polylineOf(const Node &curve, std::string &error) {
  CurveResult cr = curvePieces(curve, ArcPlanes::Principal);
  if (!cr.error.empty()) {
    error = cr.error;
    return std::nullopt;
  }
  std::vector<Vec3> pts;
  for (const CurvePiece &p : cr.pieces) {
    if (pts.empty())
      pts.push_back(p.from);
    if (!p.arc) {
      pts.push_back(p.to);
      continue;
    }
    const Vec3 from = p.plane.local(p.from), to = p.plane.local(p.to), c = p.plane.local(p.center);
    const Vec2 u = from.head<2>() - c.head<2>(), w = to.head<2>() - c.head<2>();
    const double r = u.norm();
    double sweep = std::atan2(geom::cross(u, w), u.dot(w));
    if (p.ccw && sweep <= 1e-12)
      sweep += 2 * kPi;
    if (!p.ccw && sweep >= -1e-12)
      sweep -= 2 * kPi;
    sweep += (p.ccw ? 2 * kPi : -2 * kPi) * static_cast<double>(p.turns);
    const double step = r > kVoidChordTolerance ? 2 * std::acos(1 - kVoidChordTolerance / r) : kPi / 4;
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(sweep) / step)));
    const double a0 = std::atan2(u.y(), u.x());
    for (int k = 1; k <= n; ++k) {
      const double t = static_cast<double>(k) / n, phi = a0 + sweep * t;
      const Vec3 local(c.x() + r * std::cos(phi), c.y() + r * std::sin(phi), from.z() + (to.z() - from.z()) * t);
      pts.push_back(p.plane.world(local));
    }
  }
  return pts;
}

/// The radii [inner, outer] at which the meridian (x the radius, y the
/// height) is solid at height z.
std::vector<std::pair<double, double>> meridianSpans(const Loop &meridian, double z) {
  Region r;
  r.loops.push_back(meridian);
  const geom::Box b = meridian.box();
  std::vector<std::pair<double, double>> spans;
  for (const geom::Seg &s : geom::clip(r, Vec2(b.lo.x() - 1, z), Vec2(b.hi.x() + 1, z)))
    spans.push_back({std::min(s.a.x(), s.b.x()), std::max(s.a.x(), s.b.x())});
  return spans;
}

/// Annuli about the origin, one per span (a disc when it reaches the axis),
/// overlapping spans merged first.
Region annuli(std::vector<std::pair<double, double>> spans) {
  std::sort(spans.begin(), spans.end());
  std::vector<std::pair<double, double>> merged;
  for (const auto &s : spans)
    if (!merged.empty() && s.first <= merged.back().second + 1e-9)
      merged.back().second = std::max(merged.back().second, s.second);
    else if (s.second > s.first + 1e-9)
      merged.push_back(s);
  Region r;
  for (const auto &[inner, outer] : merged) {
    r.loops.push_back(geom::circleLoop(Vec2::Zero(), outer, true));
    if (inner > 1e-6)
      r.loops.push_back(geom::circleLoop(Vec2::Zero(), inner, false));
  }
  return r;
}

} // namespace

Region AmShape::section(double z) const {
  if (form == Form::Revolved)
    return annuli(meridianSpans(profile, z));
  if (form == Form::Extruded) {
    Region base;
    base.loops.push_back(profile);
    const double inset = z * draftTan;
    return std::abs(inset) < 1e-12 ? base : geom::offset(base, -inset);
  }
  std::vector<Vec2> poly = {{-kFar, -kFar}, {kFar, -kFar}, {kFar, kFar}, {-kFar, kFar}};
  for (const auto &[a, n] : planes) {
    const Vec2 nxy(n.x(), n.y());
    const double c = n.dot(a) - n.z() * z;
    if (nxy.norm() < 1e-12) {
      if (c < -1e-9)
        return {};
      continue;
    }
    poly = clipHalfPlane(poly, nxy, c);
    if (poly.size() < 3)
      return {};
  }
  return polygonRegion(poly);
}

Region AmShape::slab(double z0, double z1) const {
  // Above the top (the allowance's layers), the top face.
  z0 = std::clamp(z0, 0.0, height);
  z1 = std::clamp(z1, z0, height);
  if (form == Form::Extruded)
    return section(draftTan >= 0 ? z0 : z1);
  if (form == Form::Revolved) {
    // The spans at both heights, at the meridian's corners between them,
    // and every tenth of the layer (its arcs' widest points within 1 %).
    std::vector<double> heights = {z0, z1};
    for (const geom::Seg &s : profile.segs)
      if (s.a.y() > z0 && s.a.y() < z1)
        heights.push_back(s.a.y());
    for (int k = 1; k < 10; ++k)
      heights.push_back(z0 + (z1 - z0) * k / 10);
    std::vector<std::pair<double, double>> spans;
    for (double z : heights)
      for (const auto &span : meridianSpans(profile, std::clamp(z, 1e-9, height - 1e-9)))
        spans.push_back(span);
    return annuli(std::move(spans));
  }
  std::vector<Vec2> pts;
  for (double z : {z0, z1})
    for (const geom::Loop &l : section(z).loops)
      for (const geom::Seg &s : l.segs)
        pts.push_back(s.a);
  for (const Vec3 &c : corners)
    if (c.z() > z0 && c.z() < z1)
      pts.push_back({c.x(), c.y()});
  return polygonRegion(geom::convexHull(std::move(pts)));
}

Region AmShape::voidsIn(double z0, double z1, double margin) const {
  std::vector<Region> parts;
  for (const VoidTube &v : voids)
    addTubeSlab(v, z0, z1, margin, parts);
  if (parts.empty())
    return {};
  return geom::uniteAll(parts);
}

AmShapeResult amShape(const Module &module, const Node &feature) {
  AmShape s;
  s.symbol = feature.symbol;
  const std::string name = feature.kindName() + " " + feature.symbol;
  s.frame.origin = feature.vec("at").value_or(Vec3::Zero());
  s.frame.z = feature.vec("axis").value_or(Vec3::UnitZ()).normalized();
  Vec3 ref = feature.vec("ref").value_or(Vec3::UnitX());
  ref -= s.frame.z * ref.dot(s.frame.z);
  if (ref.norm() < 1e-9)
    return {std::nullopt, name + ": its ref direction is along its axis"};
  s.frame.x = ref.normalized();
  s.frame.y = s.frame.z.cross(s.frame.x);
  const std::string shape = feature.text("shape").value_or("");
  // The closed profile child, counter-clockwise (an extruded feature's
  // base, a revolved one's meridian); false with `error` set.
  std::string error;
  auto readProfile = [&](std::string_view what) {
    std::optional<Loop> l = closedProfileLoop(module, feature, error);
    if (!l)
      return false;
    if (l->area() < 0)
      l->reverse();
    if (l->area() < 1e-9) {
      error = name + ": its " + std::string(what) + " encloses no area";
      return false;
    }
    // A loop that crosses itself bounds no solid.
    const std::vector<geom::Seg> &segs = l->segs;
    for (size_t i = 0; i < segs.size(); ++i)
      for (size_t j = i + 2; j < segs.size(); ++j) {
        if (i == 0 && j + 1 == segs.size())
          continue;  // the last meets the first where the loop closes
        if (!geom::intersect(segs[i], segs[j]).empty()) {
          const Vec2 at = geom::intersect(segs[i], segs[j]).front();
          error = name + ": its " + std::string(what) + " crosses itself near (" + formatFixed(at.x(), 3) + ", " +
                  formatFixed(at.y(), 3) + ")";
          return false;
        }
      }
    s.profile = std::move(*l);
    return true;
  };
  if (shape == "extruded") {
    s.form = AmShape::Form::Extruded;
    if (!readProfile("profile"))
      return {std::nullopt, error};
    const std::optional<double> h = feature.number("height");
    if (!h || !(*h > 0))
      return {std::nullopt, name + ": an extruded added feature needs a height above 0"};
    s.height = *h;
    const double draft = feature.number("draft").value_or(0);
    if (!(std::abs(draft) < 80))
      return {std::nullopt, name + ": its draft of " + formatShortest(draft) +
                                " deg is outside (-80, 80) deg: no wall leans that far"};
    s.draftTan = std::tan(draft * kPi / 180);
    // Walls leaning in must not meet below the top.
    if (s.draftTan > 0 && s.section(s.height).empty())
      return {std::nullopt, name + ": its walls, leaning in by " + formatShortest(draft) +
                                " deg, meet below its height of " + formatShortest(s.height) + " mm"};
  } else if (shape == "revolved") {
    s.form = AmShape::Form::Revolved;
    if (!readProfile("meridian"))
      return {std::nullopt, error};
    const geom::Box b = s.profile.box();
    if (b.lo.x() < -1e-6)
      return {std::nullopt, name + ": its meridian reaches " + formatShortest(-b.lo.x()) +
                                " mm past the axis (x < 0): x is the distance from the axis"};
    if (std::abs(b.lo.y()) > 1e-6)
      return {std::nullopt, name + ": its meridian starts " + formatShortest(b.lo.y()) +
                                " mm above its placement: the base (y = 0) is where it is built from"};
    s.height = b.hi.y();
  } else if (shape == "faceted") {
    s.form = AmShape::Form::Faceted;
    for (const Node *p : feature.childrenOf(Kind::BoundingPlane))
      s.planes.push_back({p->vec("at").value_or(Vec3::Zero()), p->vec("normal").value_or(Vec3::UnitZ()).normalized()});
    if (s.planes.size() < 4)
      return {std::nullopt, name + ": a faceted added feature needs at least 4 bounding planes"};
    s.corners = polytopeCorners(s.planes);
    if (s.corners.empty())
      return {std::nullopt, name + ": its bounding planes enclose no solid"};
    double lo = 1e300, hi = -1e300;
    for (const Vec3 &c : s.corners) {
      if (c.cwiseAbs().maxCoeff() > kFar * (1 - 1e-9))
        return {std::nullopt, name + ": its bounding planes do not close the solid (it reaches to infinity)"};
      lo = std::min(lo, c.z());
      hi = std::max(hi, c.z());
    }
    if (std::abs(lo) > 1e-6)
      return {std::nullopt, name + ": its solid starts " + formatShortest(lo) +
                                " mm from its placement along its axis: the base (z = 0) is where it is built from"};
    s.height = hi;
    if (feature.number("height") && std::abs(*feature.number("height") - hi) > 1e-6)
      return {std::nullopt, name + ": its height " + formatShortest(*feature.number("height")) +
                                " mm is not its bounding planes' " + formatShortest(hi) + " mm"};
    if (s.height < 1e-6)
      return {std::nullopt, name + ": its bounding planes enclose a flat solid"};
  } else {
    return {std::nullopt, name + " has no shape stepnc builds (an extruded, revolved or faceted added feature of "
                                 "stepnc's extension, docs/additive.md)"};
  }
  for (const Node *v : feature.childrenOf(Kind::AmVoid)) {
    VoidTube t;
    t.label = v->label.empty() ? v->symbol : v->label;
    t.radius = v->number("diameter").value_or(0) / 2;
    if (!(t.radius > 0))
      return {std::nullopt, name + ": its void '" + t.label + "' has no diameter"};
    if (v->children.empty())
      return {std::nullopt, name + ": its void '" + t.label + "' has no guide curve"};
    std::optional<std::vector<Vec3>> pts = polylineOf(v->children.front(), error);
    if (!pts)
      return {std::nullopt, name + ": the guide of its void '" + t.label + "': " + error};
    if (pts->size() < 2)
      return {std::nullopt, name + ": the guide of its void '" + t.label + "' has no length"};
    t.points = std::move(*pts);
    s.voids.push_back(std::move(t));
  }
  return {std::move(s), ""};
}

} // namespace stepnc::ir
