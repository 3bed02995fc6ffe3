// The cubic spline through a run of points: curvature continuous, read by
// chord length, as cubic Bézier pieces, one between each two points. The
// backends write it for controllers that take splines (docs/backends.md),
// through the same points as the lines it replaces.
#pragma once

#include "geom/Geometry.h"

#include <vector>

namespace stepnc::geom {

/// The two inner control points of one cubic Bézier piece; its ends are the
/// two points it joins.
struct BezierPiece {
  Vec2 c1 = Vec2::Zero(), c2 = Vec2::Zero();
};

/// The C2 cubic spline through `points` (at least three, no two equal in
/// succession), parameterised by chord length, its end derivatives those of
/// the circle through the three points at each end (exact where the curve
/// the points come from ends on a circle): one piece per pair of
/// neighbouring points.
std::vector<BezierPiece> splineThrough(const std::vector<Vec2> &points);

/// The point at t in [0, 1] of the Bézier piece from a to b.
Vec2 bezierAt(const Vec2 &a, const BezierPiece &p, const Vec2 &b, double t);

} // namespace stepnc::geom
