#include "ir/geom/Curves.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::ir {

namespace {

using ir::Node;
using ir::Vec3;

constexpr double kTwoPi = 2 * std::numbers::pi;

/// The counter-clockwise angle from a to b about c in the plane (x, y), in [0, 2pi).
double ccwAngle(const Vec3 &c, const Vec3 &a, const Vec3 &b) {
  const double start = std::atan2(a.y() - c.y(), a.x() - c.x());
  const double end = std::atan2(b.y() - c.y(), b.x() - c.x());
  double d = end - start;
  while (d < 0)
    d += kTwoPi;
  while (d >= kTwoPi)
    d -= kTwoPi;
  return d;
}

class Converter {
public:
  explicit Converter(ArcPlanes planes) : planes_(planes) {}

  CurveResult result;

  void curve(const Node &n, bool forward) {
    if (n.kind == ir::Kind::Polyline) {
      polyline(n, forward);
    } else if (n.kind == ir::Kind::Line) {
      line(n, forward);
    } else if (n.kind == ir::Kind::Circle) {
      fullCircle(n, forward);
    } else if (n.kind == ir::Kind::TrimmedCurve) {
      trimmed(n, forward);
    } else if (n.kind == ir::Kind::CompositeCurve) {
      composite(n, forward);
    } else if (n.kind == ir::Kind::Helix) {
      fail("an untrimmed helix has no ends: it must be a trimmed curve's basis");
    } else if (n.kind == ir::Kind::BSplineCurve) {
      spline(n, forward);
    } else {
      std::string message = "'";
      message += n.kindName();
      message += "' is not a curve";
      fail(std::move(message));
    }
  }

private:
  ArcPlanes planes_;

  /// The plane a circle or helix turns in: its axis along z (either way), or
  /// along x or y too when the caller allows the principal planes.
  std::optional<geom::ArcPlane> planeOf(const Node &n, bool &positive) {
    const Vec3 axis = n.vec("axis").value_or(Vec3::UnitZ());
    std::optional<geom::ArcPlane> plane = geom::ArcPlane::about(axis, positive);
    if (plane && (plane->isXY() || planes_ == ArcPlanes::Principal))
      return plane;
    fail(n.kindName() + " with its axis along " + formatTuple({axis.x(), axis.y(), axis.z()}, 6) +
         (planes_ == ArcPlanes::Principal
              ? ": only circles and helices about the x, y or z axis are supported (arcs in the XY, ZX and YZ "
                "planes)"
              : ": only circles and helices about the tool axis are supported"));
    return std::nullopt;
  }

  void fail(std::string message) {
    if (result.error.empty())
      result.error = std::move(message);
  }

  void addLine(const Vec3 &a, const Vec3 &b) {
    if ((b - a).norm() <= geom::kEps)
      return;
    result.pieces.push_back({false, a, b, Vec3::Zero(), true, 0});
  }

  /// Appends pieces [first, end) reversed in place when the caller walks the curve backwards.
  void reverseFrom(size_t first) {
    auto &p = result.pieces;
    std::reverse(p.begin() + static_cast<std::ptrdiff_t>(first), p.end());
    for (size_t i = first; i < p.size(); ++i) {
      std::swap(p[i].from, p[i].to);
      p[i].ccw = !p[i].ccw;
    }
  }

  /// Chords of the curve: each knot span cut in eight, each piece halved
  /// until its middle lies within kSplineChordTolerance of its chord.
  void spline(const Node &n, bool forward) {
    std::string error;
    const std::optional<BSpline> s = bspline(n, error);
    if (!s) {
      fail(error);
      return;
    }
    const size_t first = result.pieces.size();
    std::vector<double> cuts;
    for (size_t k = static_cast<size_t>(s->degree); k + 1 < s->knots.size() - static_cast<size_t>(s->degree); ++k) {
      const double a = std::max(s->knots[k], s->start), b = std::min(s->knots[k + 1], s->end);
      if (b > a)
        for (int i = 0; i < 8; ++i)
          cuts.push_back(a + (b - a) * i / 8);
    }
    cuts.push_back(s->end);
    Vec3 from = s->at(cuts.front());
    for (size_t i = 1; i < cuts.size(); ++i) {
      const Vec3 to = s->at(cuts[i]);
      chords(*s, cuts[i - 1], from, cuts[i], to, 0);
      from = to;
    }
    if (!forward)
      reverseFrom(first);
  }

  void chords(const BSpline &s, double u0, const Vec3 &a, double u1, const Vec3 &b, int depth) {
    const double um = (u0 + u1) / 2;
    const Vec3 m = s.at(um);
    const Vec3 chord = b - a;
    const double len = chord.norm();
    const double off = len > 0 ? (m - a).cross(chord).norm() / len : (m - a).norm();
    if (off > kSplineChordTolerance && depth < 24) {
      chords(s, u0, a, um, m, depth + 1);
      chords(s, um, m, u1, b, depth + 1);
      return;
    }
    addLine(a, b);
  }

  void polyline(const Node &n, bool forward) {
    const size_t first = result.pieces.size();
    std::vector<const Node *> points = n.childrenOf(ir::Kind::Point);
    for (size_t i = 1; i < points.size(); ++i)
      addLine(*points[i - 1]->vec("at"), *points[i]->vec("at"));
    if (!forward)
      reverseFrom(first);
  }

  void line(const Node &n, bool forward) {
    const auto length = n.number("length");
    if (!length) {
      fail("a line without a length has no end: it must be trimmed");
      return;
    }
    const Vec3 a = *n.vec("at");
    const Vec3 b = a + *n.vec("dir") * *length;
    forward ? addLine(a, b) : addLine(b, a);
  }

  void fullCircle(const Node &n, bool forward) {
    bool positive = true;
    const std::optional<geom::ArcPlane> plane = planeOf(n, positive);
    if (!plane)
      return;
    const Vec3 c = *n.vec("at");
    const Vec3 start = c + *n.vec("ref") * *n.number("radius");
    const bool ccw = positive == forward;
    // A full circle: two half turns, so that each piece has distinct ends.
    const Vec3 s = plane->local(start), o = plane->local(2 * c - start);
    const Vec3 opposite = plane->world(Vec3(o.x(), o.y(), s.z()));
    result.pieces.push_back({true, start, opposite, c, ccw, 0, *plane});
    result.pieces.push_back({true, opposite, start, c, ccw, 0, *plane});
  }

  void trimmed(const Node &n, bool forward) {
    const Node *basis = n.children.empty() ? nullptr : &n.children.front();
    const auto from = n.vec("from_point");
    const auto to = n.vec("to_point");
    if (!basis || !from || !to) {
      fail("a trimmed curve needs its basis curve and both trimming points (trimming by parameter alone is "
           "not supported)");
      return;
    }
    // ISO 10303-42: the curve runs from the first trimming point to the second,
    // along the basis when the sense agrees, against it otherwise.
    const bool sense = n.flag("sense").value_or(true);
    const Vec3 a = forward ? *from : *to;
    const Vec3 b = forward ? *to : *from;
    const bool alongBasis = sense == forward;
    if (basis->kind == ir::Kind::Line || basis->kind == ir::Kind::Polyline) {
      addLine(a, b);
    } else if (basis->kind == ir::Kind::Circle || basis->kind == ir::Kind::Helix) {
      bool positive = true;
      const std::optional<geom::ArcPlane> plane = planeOf(*basis, positive);
      if (!plane)
        return;
      // In the plane's coordinates: (first, second) in the plane, then along its normal.
      const Vec3 cw = *basis->vec("at");
      const Vec3 c = plane->local(cw), la = plane->local(a), lb = plane->local(b);
      const double radius = basis->number("radius").value_or(0);
      for (const Vec3 &end : {a, b})
        if (const double off = (plane->local(end) - c).head<2>().norm() - radius; std::abs(off) > kArcEndTolerance) {
          const std::string where = plane->isXY() ? formatTuple({end.x(), end.y()}, 4)
                                                  : formatTuple({end.x(), end.y(), end.z()}, 4);
          fail("the trimmed " + basis->kindName() + " ends at " + where + " mm, " + formatFixed(std::abs(off), 4) +
               " mm " + (off > 0 ? "outside" : "inside") + " its circle of radius " + formatFixed(radius, 4) +
               " mm (more than " + formatShortest(kArcEndTolerance) + " mm): no arc has both ends there");
          return;
        }
      const bool ccw = positive == alongBasis;
      int64_t turns = 0;
      if (basis->kind == ir::Kind::Helix) {
        // The angle travelled follows from the rise: |dz| / |pitch| turns.
        const double pitch = std::abs(*basis->number("pitch"));
        const double rise = std::abs(lb.z() - la.z());
        const double risen = pitch > 0 ? rise / pitch : 0;  // turns
        if (!(risen <= kMaxHelixTurns)) {
          fail("the trimmed helix rises " + formatFixed(rise, 3) + " mm at a pitch of " + formatShortest(pitch) +
               " mm: " + formatFixed(risen, 0) + " turns, more than " + formatFixed(kMaxHelixTurns, 0) +
               " (is the pitch in the file's length unit?)");
          return;
        }
        const double total = risen * kTwoPi;
        // The last partial arc: a whole turn when the ends meet in the plane.
        double partial = ccwAngle(c, la, lb);
        if (!ccw && partial > 0)
          partial = kTwoPi - partial;
        if (partial < 1e-9)
          partial = kTwoPi;
        turns = std::max<int64_t>(0, std::llround((total - partial) / kTwoPi));
      }
      result.pieces.push_back({true, a, b, cw, ccw, turns, *plane});
    } else {
      fail("trimmed " + basis->kindName() + " curves are not supported");
    }
  }

  void composite(const Node &n, bool forward) {
    const size_t first = result.pieces.size();
    for (const Node *segment : n.childrenOf(ir::Kind::Segment))
      if (!segment->children.empty())
        curve(segment->children.front(), segment->flag("same_sense").value_or(true));
    if (!forward)
      reverseFrom(first);
  }
};

} // namespace

Vec3 BSpline::at(double u) const {
  // De Boor's algorithm in homogeneous coordinates (w x, w y, w z, w).
  const int p = degree;
  const size_t n = points.size();
  u = std::clamp(u, start, end);
  // The span k with knots[k] <= u < knots[k + 1], within [p, n - 1].
  size_t k = static_cast<size_t>(p);
  while (k + 1 < n && knots[k + 1] <= u)
    ++k;
  std::vector<Eigen::Vector4d> d(static_cast<size_t>(p) + 1);
  for (int j = 0; j <= p; ++j) {
    const size_t i = k - static_cast<size_t>(p) + static_cast<size_t>(j);
    d[static_cast<size_t>(j)] << points[i] * weights[i], weights[i];
  }
  for (int r = 1; r <= p; ++r)
    for (int j = p; j >= r; --j) {
      const size_t i = k - static_cast<size_t>(p) + static_cast<size_t>(j);
      const double den = knots[i + static_cast<size_t>(p) + 1 - static_cast<size_t>(r)] - knots[i];
      const double alpha = den > 0 ? (u - knots[i]) / den : 0;
      d[static_cast<size_t>(j)] = (1 - alpha) * d[static_cast<size_t>(j) - 1] + alpha * d[static_cast<size_t>(j)];
    }
  const Eigen::Vector4d &h = d[static_cast<size_t>(p)];
  return h.head<3>() / h[3];
}

std::optional<BSpline> bspline(const ir::Node &curve, std::string &error) {
  BSpline s;
  s.degree = static_cast<int>(curve.count("degree").value_or(0));
  for (const Node *pt : curve.childrenOf(ir::Kind::Point)) {
    s.points.push_back(pt->vec("at").value_or(Vec3::Zero()));
    s.weights.push_back(pt->number("weight").value_or(1.0));
  }
  const int p = s.degree;
  const int n = static_cast<int>(s.points.size());
  if (p < 1 || n < p + 1) {
    error = "a B-spline of degree " + std::to_string(p) + " needs more than " + std::to_string(p) +
            " control points, it has " + std::to_string(n);
    return std::nullopt;
  }
  for (double w : s.weights)
    if (!(w > 0) || !std::isfinite(w)) {
      error = "a rational B-spline's weights must be positive";
      return std::nullopt;
    }
  // ISO 10303-42's knot vectors for the forms that do not list their knots.
  const std::string form = curve.text("form").value_or("with_knots");
  const int last = n - 1;  // the upper index of the control points
  if (form == "with_knots") {
    for (const Node *k : curve.childrenOf(ir::Kind::Knot))
      for (int64_t m = 0; m < k->count("multiplicity").value_or(0); ++m)
        s.knots.push_back(k->number("value").value_or(0));
  } else if (form == "uniform") {
    for (int i = -p; i <= last + 1; ++i)
      s.knots.push_back(i);
  } else if (form == "quasi_uniform") {
    const int spans = last - p + 1;
    s.knots.insert(s.knots.end(), static_cast<size_t>(p), 0.0);
    for (int i = 0; i <= spans; ++i)
      s.knots.push_back(i);
    s.knots.insert(s.knots.end(), static_cast<size_t>(p), static_cast<double>(spans));
  } else {  // bezier: pieces of degree p, end knots p + 1 times, inner ones p times
    if (last % p != 0) {
      error = "a piecewise Bezier curve of degree " + std::to_string(p) + " needs a multiple of " + std::to_string(p) +
              " points and one more, it has " + std::to_string(n);
      return std::nullopt;
    }
    const int pieces = last / p;
    s.knots.push_back(0);
    for (int i = 0; i <= pieces; ++i)
      s.knots.insert(s.knots.end(), static_cast<size_t>(p), static_cast<double>(i));
    s.knots.push_back(pieces);
  }
  if (s.knots.size() != static_cast<size_t>(n + p + 1)) {
    error = "a B-spline of degree " + std::to_string(p) + " with " + std::to_string(n) + " control points needs " +
            std::to_string(n + p + 1) + " knots (counted with their multiplicities), it has " +
            std::to_string(s.knots.size());
    return std::nullopt;
  }
  if (!std::is_sorted(s.knots.begin(), s.knots.end())) {
    error = "a B-spline's knots must not decrease";
    return std::nullopt;
  }
  s.start = s.knots[static_cast<size_t>(p)];
  s.end = s.knots[static_cast<size_t>(n)];
  if (!(s.end > s.start)) {
    error = "a B-spline's knots leave it no parameter range";
    return std::nullopt;
  }
  return s;
}

CurveResult curvePieces(const ir::Node &curve, ArcPlanes planes) {
  Converter c(planes);
  c.curve(curve, true);
  return std::move(c.result);
}

std::vector<geom::Seg> planarSegs(const std::vector<CurvePiece> &pieces) {
  std::vector<geom::Seg> out;
  for (const CurvePiece &p : pieces) {
    const geom::Vec2 a = p.from.head<2>();
    const geom::Vec2 b = p.to.head<2>();
    const geom::Vec2 c = p.center.head<2>();
    if (!p.arc) {
      if ((b - a).norm() > geom::kEps)
        out.push_back(geom::Seg::line(a, b));
      continue;
    }
    const double r = (a - c).norm();
    for (int64_t t = 0; t < p.turns; ++t)
      for (const geom::Seg &s : geom::circle(c, r, p.ccw, a))
        out.push_back(s);
    // Ends that meet in the plane close a last whole turn.
    if ((b - a).norm() <= geom::kEps) {
      for (const geom::Seg &s : geom::circle(c, r, p.ccw, a))
        out.push_back(s);
      continue;
    }
    out.push_back(geom::Seg::arc(a, b, c, p.ccw));
  }
  return out;
}

} // namespace stepnc::ir
