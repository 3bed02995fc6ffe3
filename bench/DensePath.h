// The synthetic paths the motion benchmarks plan (MotionBench.cpp) and the
// plan dump compares planner versions on (PlanDump.cpp): `n` moves wandering
// in a 400 x 300 mm field, the kind of path dense CAM output gives: lines of
// 0.2 to 2 mm that turn by up to 10 degrees, every 20th a sharp corner,
// every 7th a tangent arc. The options add what a program also has, each
// without changing the path where it is off.
#pragma once

#include "runtime/Planner.h"

#include <cmath>
#include <random>

namespace stepnc::bench {

struct DensePathOptions {
  unsigned seed = 1;
  bool helices = false;     ///< moves rise or fall by up to 0.15 mm (arcs become helices)
  bool rapids = false;      ///< every 50th move a rapid
  bool stops = false;       ///< a programmed stop before every 997th move
  bool shortMoves = false;  ///< every 13th move a hundredth as long
  bool reversals = false;   ///< every other sharp corner turns back (179.5 degrees: the tool stops)
  bool wholeTurns = false;  ///< every 10th arc takes a whole turn more
};

inline runtime::PathInput densePath(int n, double feed, const DensePathOptions &options = {}) {
  using runtime::PathMove;
  using runtime::Vec3;
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> len(0.2, 2), turn(-0.17, 0.17), unit(0, 1);
  runtime::PathInput p;
  Vec3 at(200, 150, 0);
  double heading = 0;
  p.start = at;
  for (int i = 0; i < n; ++i) {
    PathMove m;
    m.feed = options.rapids && i % 50 == 7 ? 0 : feed;
    m.stopBefore = options.stops && i % 997 == 5;
    const double l = len(rng) * (options.shortMoves && i % 13 == 0 ? 0.01 : 1);
    const double dz = options.helices ? (unit(rng) - 0.5) * 0.3 : 0;
    if (i % 7 == 3) {
      // A tangent arc of radius l turning by up to 90 degrees.
      const bool ccw = unit(rng) < 0.5;
      const double side = ccw ? 1 : -1;
      const Vec3 centre = at + l * Vec3(-std::sin(heading) * side, std::cos(heading) * side, 0);
      const double sweep = 1.5 * unit(rng) + 0.1;
      const double a0 = std::atan2(at.y() - centre.y(), at.x() - centre.x()) + side * sweep;
      m.kind = PathMove::Kind::Arc;
      m.center = centre;
      m.ccw = ccw;
      m.turns = options.wholeTurns && i % 70 == 3 ? 1 : 0;
      at = centre + l * Vec3(std::cos(a0), std::sin(a0), 0) + Vec3(0, 0, dz);
      heading += side * sweep;
    } else {
      heading += i % 20 == 0 ? (options.reversals && i % 40 == 0 ? 3.133 : 1.5) : turn(rng);
      at += l * Vec3(std::cos(heading), std::sin(heading), 0) + Vec3(0, 0, dz);
    }
    // Stay in the field: turn back towards its middle.
    if (at.x() < 0 || at.x() > 400 || at.y() < 0 || at.y() > 300)
      heading = std::atan2(150 - at.y(), 200 - at.x());
    m.to = at;
    p.moves.push_back(m);
  }
  return p;
}

} // namespace stepnc::bench
