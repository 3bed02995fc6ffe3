// Writes the plans of synthetic paths (DensePath.h) on both shipped machines,
// every number in hexadecimal floating point, so that two versions of the
// planner can be compared bit for bit or within a bound
// (bench/compare-plans.py; docs/performance.md says how speed passes use it).
//
//   stepnc-plan-dump OUT.txt [MOVES]
#include "bench/DensePath.h"
#include "runtime/Planner.h"

#include <cstdio>
#include <cstdlib>
#include <string>

using namespace stepnc;
using namespace stepnc::runtime;

namespace {

void dump(FILE *f, const Trajectory &t) {
  std::fprintf(f, "N %zu\n", t.segments.size());
  for (size_t i = 0; i < t.segments.size(); ++i) {
    const Segment &s = t.segments[i];
    std::fprintf(f, "S %d %a %a %a %a %a %a %a", int(s.kind), s.start.x(), s.start.y(), s.start.z(), s.end.x(),
                 s.end.y(), s.end.z(), s.length);
    switch (s.kind) {
    case SegmentKind::Line:
    case SegmentKind::Dwell:  // its point is its start and end
      break;
    case SegmentKind::Arc:
      std::fprintf(f, " %a %a %a %a %a %d", s.center.x(), s.center.y(), s.radius, s.startAngle, s.sweep, int(s.ccw));
      break;
    case SegmentKind::Blend:
      for (const Vec3 &c : s.ctrl)
        std::fprintf(f, " %a %a %a", c.x(), c.y(), c.z());
      for (const double a : s.arcTable)
        std::fprintf(f, " %a", a);
      break;
    }
    const SegmentInfo &in = t.info[i];
    std::fprintf(f, "\nI %a %a %a %d %a %u %u %d\n", in.limits.v, in.limits.a, in.limits.j, int(in.limitedBy), in.feed,
                 in.move, in.nextMove, int(in.stop));
    const Profile &p = t.profiles[i];
    std::fprintf(f, "P %a %a", p.v0, p.a0);
    for (const Phase &ph : p.phases)
      std::fprintf(f, " %a %a", ph.duration, ph.jerk);
    std::fprintf(f, "\n");
  }
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: stepnc-plan-dump OUT.txt [MOVES]\n");
    return 2;
  }
  const int moves = argc == 3 ? std::atoi(argv[2]) : 20000;
  FILE *f = std::fopen(argv[1], "w");
  if (!f) {
    std::perror(argv[1]);
    return 1;
  }
  for (const char *name : {"hsc-3axis", "conventional-3axis"}) {
    std::unique_ptr<SourceFile> file;
    DiagnosticCollector collector;
    DiagnosticEngine diags(collector);
    const Machine machine = *loadMachine(name, file, diags);
    // The benchmark's path, then one with everything a program adds, then
    // the same at a feed the axes cannot follow around the arcs.
    const bench::DensePathOptions all{7, true, true, true, true, true, true};
    const std::pair<bench::DensePathOptions, double> paths[] = {{{}, 3000}, {all, 3000}, {all, 12000}};
    for (const auto &[options, feed] : paths) {
      std::fprintf(f, "# %s seed %u feed %g\n", name, options.seed, feed);
      dump(f, plan(bench::densePath(moves, feed, options), machine));
    }
  }
  return std::fclose(f) == 0 ? 0 : 1;
}
