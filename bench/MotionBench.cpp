// Motion planning and playback speed (docs/performance.md):
//  - BM_Plan: planning throughput on a 100,000-move path of the kind dense
//    CAM output gives (short lines turning a little at each vertex, with
//    tangent arcs and sharper corners mixed in), in moves per second;
//  - BM_Simulate: the reference player sampling a trajectory of about one
//    hour at 1 kHz, with every check on; the time per run is the time to
//    simulate that hour.
#include "runtime/Planner.h"
#include "runtime/Player.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

using namespace stepnc;
using namespace stepnc::runtime;

namespace {

Machine hsc() {
  std::unique_ptr<SourceFile> file;
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  return *loadMachine("hsc-3axis", file, diags);
}

/// `n` moves wandering in a 400 x 300 mm field: lines of 0.2 to 2 mm that
/// turn by up to 10 degrees, every 20th a sharp corner, every 7th a tangent arc.
PathInput densePath(int n, double feed) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> len(0.2, 2), turn(-0.17, 0.17), unit(0, 1);
  PathInput p;
  Vec3 at(200, 150, 0);
  double heading = 0;
  p.start = at;
  for (int i = 0; i < n; ++i) {
    PathMove m;
    m.feed = feed;
    const double l = len(rng);
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
      at = centre + l * Vec3(std::cos(a0), std::sin(a0), 0);
      heading += side * sweep;
    } else {
      heading += i % 20 == 0 ? 1.5 : turn(rng);
      at += l * Vec3(std::cos(heading), std::sin(heading), 0);
    }
    // Stay in the field: turn back towards its middle.
    if (at.x() < 0 || at.x() > 400 || at.y() < 0 || at.y() > 300)
      heading = std::atan2(150 - at.y(), 200 - at.x());
    m.to = at;
    p.moves.push_back(m);
  }
  return p;
}

void BM_Plan(benchmark::State &state) {
  const Machine m = hsc();
  const PathInput path = densePath(int(state.range(0)), 3000);
  size_t segments = 0;
  for (auto _ : state) {
    Trajectory t = plan(path, m);
    segments = t.segments.size();
    benchmark::DoNotOptimize(t);
  }
  state.SetItemsProcessed(state.iterations() * int64_t(path.moves.size()));
  state.counters["segments_out"] = double(segments);
}
BENCHMARK(BM_Plan)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_Simulate(benchmark::State &state) {
  const Machine m = hsc();
  // Slow enough that the path lasts about an hour.
  const PathInput path = densePath(60000, 1000);
  const Trajectory t = plan(path, m);
  SimReport r;
  for (auto _ : state) {
    r = simulate(t, m);
    benchmark::DoNotOptimize(r);
  }
  state.counters["motion_s"] = r.duration;
  state.counters["samples"] = double(r.samples);
  state.counters["violations"] = double(r.violationCount);
  state.SetItemsProcessed(state.iterations() * int64_t(r.samples));
}
BENCHMARK(BM_Simulate)->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
