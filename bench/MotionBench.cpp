// Motion planning and playback speed (docs/performance.md):
//  - BM_Plan: planning throughput on a 100,000-move path of the kind dense
//    CAM output gives (short lines turning a little at each vertex, with
//    tangent arcs and sharper corners mixed in), in moves per second;
//  - BM_Simulate: the reference player sampling a trajectory of about one
//    hour at 1 kHz, with every check on; the time per run is the time to
//    simulate that hour.
#include "bench/DensePath.h"
#include "runtime/Planner.h"
#include "runtime/Player.h"

#include <benchmark/benchmark.h>

using namespace stepnc;
using namespace stepnc::runtime;
using stepnc::bench::densePath;

namespace {

Machine hsc() {
  std::unique_ptr<SourceFile> file;
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  return *loadMachine("hsc-3axis", file, diags);
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
