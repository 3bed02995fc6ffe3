// The cubic spline the backends write for smooth runs (geom/Spline.h): it
// passes through every point, is curvature continuous where pieces meet,
// and on points sampled from a circle stays closer to it than the chords do
// (4.7 um), the end pieces included.
#include "geom/Spline.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace stepnc::geom;

namespace {

/// The second derivative of a piece by chord length, at t = 0 or 1.
Vec2 secondDerivative(const Vec2 &a, const BezierPiece &p, const Vec2 &b, bool atEnd) {
  const double h = (b - a).norm();
  return (atEnd ? 6 * (b - 2 * p.c2 + p.c1) : 6 * (p.c2 - 2 * p.c1 + a)) / (h * h);
}

} // namespace

TEST_CASE("the spline through points interpolates them with continuous curvature", "[geom]") {
  // Uneven points on a curve with a change of curvature: part of a trochoid.
  std::vector<Vec2> pts;
  for (int k = 0; k <= 40; ++k) {
    const double t = 0.17 * k + 0.01 * (k % 3);
    pts.emplace_back(0.15 * t + 3 * std::cos(t), 3 * std::sin(t));
  }
  const std::vector<BezierPiece> pieces = splineThrough(pts);
  REQUIRE(pieces.size() == pts.size() - 1);
  for (size_t i = 0; i + 1 < pieces.size(); ++i) {
    CHECK((bezierAt(pts[i], pieces[i], pts[i + 1], 1) - pts[i + 1]).norm() < 1e-12);
    // Tangent: the control points on either side of a point are in line with it, at the chord lengths' ratio.
    const Vec2 in = (pts[i + 1] - pieces[i].c2) / (pts[i + 1] - pts[i]).norm();
    const Vec2 out = (pieces[i + 1].c1 - pts[i + 1]) / (pts[i + 2] - pts[i + 1]).norm();
    CHECK((in - out).norm() < 1e-9);
    const Vec2 before = secondDerivative(pts[i], pieces[i], pts[i + 1], true);
    const Vec2 after = secondDerivative(pts[i + 1], pieces[i + 1], pts[i + 2], false);
    CHECK((before - after).norm() < 1e-9 * std::max(1.0, before.norm()));
  }
}

TEST_CASE("on points of a circle the spline keeps far closer to it than the chords", "[geom]") {
  // 56 points per turn of radius 3: chords stray 3 (1 - cos(pi / 56)) = 4.7 um.
  const double r = 3;
  const int n = 56;
  std::vector<Vec2> pts;
  for (int k = 0; k <= n; ++k)
    pts.emplace_back(r * std::cos(2 * std::numbers::pi * k / n), r * std::sin(2 * std::numbers::pi * k / n));
  const std::vector<BezierPiece> pieces = splineThrough(pts);
  double worst = 0;
  for (size_t i = 0; i < pieces.size(); ++i)
    for (double t = 0; t <= 1; t += 0.05)
      worst = std::max(worst, std::abs(bezierAt(pts[i], pieces[i], pts[i + 1], t).norm() - r));
  INFO("largest distance from the circle " << worst << " mm");
  // 1.24 um: a cubic by chord length cannot follow a circle exactly; the
  // end pieces as well as the rest (the ends take the circle's tangent).
  CHECK(worst < 1.5e-6);
}
