// Contour-parallel paths: the rings of contour_parallel and contour_spiral,
// the single outer ring of side milling and of the mixed strategies, and the
// wall pass after a pattern strategy's motif. Rings are the boundaries of the
// centre area shrunk again and again by the stepover (geom::offset keeps
// lines as lines and arcs as arcs); their direction follows the cut mode.
#include "passes/expand/Expand.h"

#include <algorithm>
#include <cmath>

namespace stepnc::passes::expand {

namespace {

/// The smallest interior angle at a convex corner of the region (pi when none).
double sharpestCorner(const Region &r) {
  double sharpest = kPi;
  for (const Loop &l : r.loops)
    for (size_t i = 0; i < l.segs.size(); ++i) {
      const Seg &s = l.segs[i], &t = l.segs[(i + 1) % l.segs.size()];
      const Vec2 u = s.tangent(1), v = t.tangent(0);
      const double turn = std::atan2(geom::cross(u, v), u.dot(v));
      // Outer loops run counter-clockwise: a left turn is a convex corner of the area.
      if (turn > 1e-6)
        sharpest = std::min(sharpest, kPi - turn);
    }
  return sharpest;
}

} // namespace

Loop startNearest(const Loop &l, const Vec2 &p) {
  size_t best = 0;
  double bestDist = 1e300;
  Vec2 bestPoint = l.segs.front().a;
  for (size_t i = 0; i < l.segs.size(); ++i) {
    const Vec2 q = geom::closestPoint(l.segs[i], p);
    if (double d = (q - p).norm(); d < bestDist - 1e-9) {
      bestDist = d;
      best = i;
      bestPoint = q;
    }
  }
  Loop out;
  const Seg &s = l.segs[best];
  auto split = [&](const Vec2 &a, const Vec2 &b) {
    Seg piece = s;
    piece.a = a;
    piece.b = b;
    return piece;
  };
  const bool inside = (bestPoint - s.a).norm() > 1e-7 && (bestPoint - s.b).norm() > 1e-7;
  if (inside)
    out.segs.push_back(split(bestPoint, s.b));
  else if ((bestPoint - s.b).norm() <= 1e-7)
    ++best, bestPoint = l.segs[best % l.segs.size()].a;
  const size_t first = inside ? best + 1 : best;
  for (size_t k = 0; k < l.segs.size(); ++k) {
    const size_t i = (first + k) % l.segs.size();
    if (inside && i == best)
      break;
    out.segs.push_back(l.segs[i]);
  }
  if (inside)
    out.segs.push_back(split(s.a, bestPoint));
  return out;
}

double ringCoverLimit(const ir::FeatureShape &s, double radius) {
  return radius * (1 + std::sin(sharpestCorner(s.target) / 2)) * 0.98;
}

std::vector<Path2D> rings(const Region &centres, double stepover, bool followOrientation, bool all, double radius) {
  std::vector<Region> shells;
  for (Region r = centres; !r.empty(); r = geom::offset(r, -stepover)) {
    shells.push_back(r);
    if (!all || shells.size() > 10000)
      break;
  }
  // The innermost shell's middle may lie further than a radius from its
  // ring (a strip narrower than the stepover): one more thin ring round the
  // middle, at the deepest offset that still leaves an area.
  if (all && !shells.empty()) {
    double lo = 0, hi = stepover;
    for (int i = 0; i < 30 && hi - lo > 1e-4; ++i) {
      const double mid = (lo + hi) / 2;
      (geom::offset(shells.back(), -mid).empty() ? hi : lo) = mid;
    }
    if (lo > radius * 0.9) {
      Region middle = geom::offset(shells.back(), -std::max(lo - std::min(0.1 * radius, lo / 2), 0.0));
      if (!middle.empty())
        shells.push_back(std::move(middle));
    }
  }
  std::vector<Path2D> out;
  for (auto it = shells.rbegin(); it != shells.rend(); ++it)
    for (Loop l : it->loops) {
      if (!followOrientation)
        l.reverse();
      out.push_back(std::move(l.segs));
    }
  return out;
}

} // namespace stepnc::passes::expand
