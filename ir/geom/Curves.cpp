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

/// The counter-clockwise angle from a to b about c in the plane, in [0, 2pi).
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

/// The circle or helix axis must be along z (either way): pieces are circular in the plane.
bool axisAlongZ(const Node &n, bool &positive, std::string &error) {
  const Vec3 axis = n.vec("axis").value_or(Vec3::UnitZ());
  if (std::abs(std::abs(axis.z()) - 1) > 1e-9) {
    error = n.kindName() + " with its axis along " + formatTuple({axis.x(), axis.y(), axis.z()}, 6) +
            ": only circles and helices about the tool axis are supported";
    return false;
  }
  positive = axis.z() > 0;
  return true;
}

class Converter {
public:
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
      fail("B-spline curves are not expanded into moves yet");
    } else {
      fail("'" + n.kindName() + "' is not a curve");
    }
  }

private:
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
    if (!axisAlongZ(n, positive, result.error))
      return;
    const Vec3 c = *n.vec("at");
    const Vec3 start = c + *n.vec("ref") * *n.number("radius");
    const bool ccw = positive == forward;
    // A full circle: two half turns, so that each piece has distinct ends.
    const Vec3 opposite = 2 * c - start;
    result.pieces.push_back({true, start, Vec3(opposite.x(), opposite.y(), start.z()), c, ccw, 0});
    result.pieces.push_back({true, Vec3(opposite.x(), opposite.y(), start.z()), start, c, ccw, 0});
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
      if (!axisAlongZ(*basis, positive, result.error))
        return;
      const Vec3 c = *basis->vec("at");
      const bool ccw = positive == alongBasis;
      int64_t turns = 0;
      if (basis->kind == ir::Kind::Helix) {
        // The angle travelled follows from the rise: |dz| / |pitch| turns.
        const double pitch = std::abs(*basis->number("pitch"));
        const double total = pitch > 0 ? std::abs(b.z() - a.z()) / pitch * kTwoPi : 0;
        // The last partial arc: a whole turn when the ends meet in the plane.
        double partial = ccwAngle(c, a, b);
        if (!ccw && partial > 0)
          partial = kTwoPi - partial;
        if (partial < 1e-9)
          partial = kTwoPi;
        turns = std::max<int64_t>(0, std::llround((total - partial) / kTwoPi));
      }
      result.pieces.push_back({true, a, b, c, ccw, turns});
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

CurveResult curvePieces(const ir::Node &curve) {
  Converter c;
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
