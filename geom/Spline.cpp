#include "geom/Spline.h"

#include <algorithm>
#include <cmath>

namespace stepnc::geom {

namespace {

/// The derivative by chord length at points[first] of the circle through
/// it and the next two points in direction `dir` (+1 or -1): exact where the
/// run ends on a circle (a trochoid's guide at rest), second order
/// elsewhere; the chord's direction where the three are in line.
Vec2 endDerivative(const std::vector<Vec2> &points, size_t first, int dir) {
  const Vec2 a = points[first], b = points[size_t(long(first) + dir)], c = points[size_t(long(first) + 2 * dir)];
  const Vec2 ab = b - a, ac = c - a;
  const double chord = ab.norm();
  const double twiceArea = cross(ab, ac);
  if (std::abs(twiceArea) <= 1e-12 * chord * ac.norm())
    return ab / chord;
  // The centre, from a: the point equidistant from a, b and c.
  const Vec2 centre =
      (ac.squaredNorm() * Vec2(ab.y(), -ab.x()) - ab.squaredNorm() * Vec2(ac.y(), -ac.x())) / (-2 * twiceArea);
  const double radius = centre.norm();
  // Along the circle towards b; as fast as the arc to b is longer than its chord.
  Vec2 tangent(-centre.y(), centre.x());
  if (tangent.dot(ab) < 0)
    tangent = -tangent;
  const double angle = 2 * std::asin(std::min(1.0, chord / (2 * radius)));
  return tangent / radius * (radius * angle / chord);
}

} // namespace

std::vector<BezierPiece> splineThrough(const std::vector<Vec2> &p) {
  const size_t n = p.size() - 1; // pieces
  std::vector<double> h(n);
  std::vector<Vec2> slope(n); // of each chord, per unit of chord length
  for (size_t i = 0; i < n; ++i) {
    h[i] = (p[i + 1] - p[i]).norm();
    slope[i] = (p[i + 1] - p[i]) / h[i];
  }
  // Derivatives m at the points: continuity of the second derivative at each
  // inner point gives
  //   h[i] m[i-1] + 2 (h[i-1] + h[i]) m[i] + h[i-1] m[i+1] = 3 (h[i] slope[i-1] + h[i-1] slope[i]),
  // the ends are the parabola's. Solved by forward elimination and back
  // substitution (the system is diagonally dominant).
  std::vector<Vec2> m(n + 1);
  m[0] = endDerivative(p, 0, 1);
  m[n] = -endDerivative(p, n, -1);
  std::vector<double> upper(n + 1, 0.0);
  std::vector<Vec2> rhs(n + 1, Vec2::Zero());
  rhs[0] = m[0]; // row 0: m[0] given
  for (size_t i = 1; i < n; ++i) {
    const double lower = h[i], diag = 2 * (h[i - 1] + h[i]), up = h[i - 1];
    const Vec2 r = 3 * (h[i] * slope[i - 1] + h[i - 1] * slope[i]);
    const double pivot = diag - lower * upper[i - 1];
    upper[i] = up / pivot;
    rhs[i] = (r - lower * rhs[i - 1]) / pivot;
  }
  for (size_t i = n - 1; i >= 1; --i)
    m[i] = rhs[i] - upper[i] * m[i + 1];
  std::vector<BezierPiece> out(n);
  for (size_t i = 0; i < n; ++i)
    out[i] = {p[i] + m[i] * (h[i] / 3), p[i + 1] - m[i + 1] * (h[i] / 3)};
  return out;
}

Vec2 bezierAt(const Vec2 &a, const BezierPiece &p, const Vec2 &b, double t) {
  const double s = 1 - t;
  return s * s * s * a + 3 * s * s * t * p.c1 + 3 * s * t * t * p.c2 + t * t * t * b;
}

} // namespace stepnc::geom
