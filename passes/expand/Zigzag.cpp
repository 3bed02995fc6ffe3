// Parallel strokes: the paths of bidirectional (zigzag) and unidirectional
// milling, and the zigzag inside the ring of the mixed strategies. Strokes
// run in the feed direction, are clipped to the centre area, and on faces run
// from edge to edge and past the ends by the tool radius (overtravel).
#include "passes/expand/Expand.h"

#include <algorithm>
#include <cmath>

namespace stepnc::passes::expand {

Vec2 strokeDirection(const Node &feature, const ir::FeatureShape &s, const Node *strategy) {
  if (strategy)
    if (auto d = strategy->vec("feed_dir"); d && d->head<2>().norm() > 1e-9)
      return s.frame.mapDir(d->head<2>()).normalized();
  if (auto d = feature.vec("travel_dir"))
    return s.frame.mapDir(d->head<2>()).normalized();
  return s.frame.x;
}

std::vector<Path2D> strokes(const Region &area, const Vec2 &dir, double stepover, bool bidirectional,
                            double overtravel) {
  std::vector<Path2D> out;
  if (area.empty())
    return out;
  const Vec2 across(-dir.y(), dir.x());
  double lo = 1e300, hi = -1e300, along0 = 1e300, along1 = -1e300;
  for (const Loop &l : area.loops)
    for (const Seg &sg : l.segs)
      for (double t = 0; t <= 1.0; t += 0.125) {
        const Vec2 q = sg.at(t);
        lo = std::min(lo, q.dot(across));
        hi = std::max(hi, q.dot(across));
        along0 = std::min(along0, q.dot(dir));
        along1 = std::max(along1, q.dot(dir));
      }
  // For faces the area is already grown by the radius: strokes run from
  // edge to edge of the face, the first and last a radius inside its sides.
  // Otherwise the outer strokes run a hair inside the area, not along its
  // boundary, where clipping could lose them.
  const double inset = overtravel > 0 ? overtravel : 1e-6;
  const double width = std::max(0.0, hi - lo - 2 * inset);
  const int n = std::max(1, static_cast<int>(std::ceil(width / stepover - 1e-9)) + 1);
  const double pitch = n > 1 ? width / (n - 1) : 0;
  bool forward = true;
  for (int i = 0; i < n; ++i) {
    const double c = n > 1 ? lo + inset + pitch * i : (lo + hi) / 2;
    const Vec2 p0 = across * c + dir * (along0 - 1);
    const Vec2 p1 = across * c + dir * (along1 + 1);
    std::vector<Seg> pieces = geom::clip(area, forward ? p0 : p1, forward ? p1 : p0);
    for (Seg &sg : pieces)
      out.push_back({sg});
    if (bidirectional)
      forward = !forward;
  }
  return out;
}

} // namespace stepnc::passes::expand
