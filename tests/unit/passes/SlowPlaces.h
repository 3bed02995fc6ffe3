// Where the machine slows down on a program: the places a pass must not add.
// The module's program is planned on a machine and played at its cycle; a
// sample on a feed move below a fraction of the programmed feed is a slow
// place (a corner, a stop, a step in the path).
#pragma once

#include "ir/motion/MotionIR.h"
#include "runtime/Planner.h"
#include "runtime/Player.h"
#include "tests/unit/runtime/ShippedMachine.h"

#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace stepnc::test {

/// The sampled positions where the program runs a feed move below
/// `fraction` of its programmed feed.
inline std::vector<ir::Vec3> slowPlaces(const ir::Module &module, const runtime::Machine &machine, double fraction) {
  const ir::ProgramPath program = ir::programPath(module);
  const runtime::Trajectory trajectory = runtime::plan(program.path, machine);
  std::vector<ir::Vec3> out;
  runtime::simulate(trajectory, machine, {}, [&](const runtime::Sample &s) {
    const double feed = trajectory.info[s.segment].feed; // mm/s; 0 on rapids
    if (feed > 0 && s.speed < fraction * feed)
      out.push_back(s.p);
  });
  return out;
}

/// The places of `after` farther than `reach` mm from every place of
/// `before`.
inline std::vector<ir::Vec3> placesAdded(const std::vector<ir::Vec3> &before, const std::vector<ir::Vec3> &after,
                                         double reach) {
  std::map<std::pair<long, long>, std::vector<ir::Vec3>> grid; // cells of `reach`
  const auto cell = [&](const ir::Vec3 &p) {
    return std::pair<long, long>(std::lround(std::floor(p.x() / reach)), std::lround(std::floor(p.y() / reach)));
  };
  for (const ir::Vec3 &p : before)
    grid[cell(p)].push_back(p);
  std::vector<ir::Vec3> out;
  for (const ir::Vec3 &p : after) {
    const auto [cx, cy] = cell(p);
    bool near = false;
    for (long x = cx - 1; x <= cx + 1 && !near; ++x)
      for (long y = cy - 1; y <= cy + 1 && !near; ++y)
        if (const auto it = grid.find({x, y}); it != grid.end())
          for (const ir::Vec3 &q : it->second)
            near = near || (q - p).norm() <= reach;
    if (!near)
      out.push_back(p);
  }
  return out;
}

} // namespace stepnc::test
