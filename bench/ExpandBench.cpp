// Strategy expansion benchmarks: contour-parallel expansion of a pocket whose
// outline has N vertices (a wavy star, so that rings split and merge), and the
// geometry underneath it (one offset of the outline).
//
//   build/bin/stepnc-expand-bench [--benchmark_filter=...]
//
// bench/run-expand-bench.sh runs it with the corpus timing; docs/performance.md
// records the figures.
#include "geom/Geometry.h"
#include "ir/Node.h"
#include "passes/PassManager.h"
#include "passes/PassRegistry.h"
#include "support/Diagnostics.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

using namespace stepnc;

namespace {

/// A star-shaped outline of n vertices around the origin, radius 50 +- 8 mm.
std::vector<geom::Vec2> star(int n) {
  std::vector<geom::Vec2> pts;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * i / n;
    const double r = 50 + 8 * std::sin(7 * t) + 3 * std::cos(23 * t);
    pts.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  return pts;
}

ir::Node placed(ir::Kind kind, const ir::Vec3 &at) {
  ir::Node n(kind);
  n.set("at", ir::Value::point(at));
  n.set("axis", ir::Value::direction(ir::Vec3::UnitZ()));
  n.set("ref", ir::Value::direction(ir::Vec3::UnitX()));
  return n;
}

/// A module with one closed pocket of the star outline, rough milled with a
/// 10 mm end mill, contour parallel, 5 mm stepover, one level.
ir::Module pocketModule(int n) {
  ir::Module m;
  m.root.label = "BENCH";
  ir::Node wp(ir::Kind::Workpiece);
  wp.symbol = "%wp";
  wp.label = "WP";
  ir::Node pocket = placed(ir::Kind::ClosedPocket, {0, 0, 0});
  pocket.symbol = "%pocket";
  pocket.label = "POCKET";
  pocket.set("depth", ir::Value::length(5));
  pocket.set("bottom", ir::Value::word("planar"));
  ir::Node profile(ir::Kind::GeneralProfile);
  profile.set("closed", ir::Value::boolean(true));
  ir::Node poly(ir::Kind::Polyline);
  std::vector<geom::Vec2> pts = star(n);
  pts.push_back(pts.front());
  for (const geom::Vec2 &p : pts)
    poly.add(ir::Node(ir::Kind::Point)).set("at", ir::Value::point({p.x(), p.y(), 0}));
  profile.add(std::move(poly));
  pocket.add(std::move(profile));
  wp.add(std::move(pocket));
  m.root.add(std::move(wp));
  ir::Node tool(ir::Kind::Tool);
  tool.symbol = "%mill";
  tool.label = "MILL";
  tool.set("type", ir::Value::word("endmill"));
  tool.set("diameter", ir::Value::length(10));
  m.root.add(std::move(tool));
  ir::Node plan(ir::Kind::Workplan);
  plan.symbol = "@main";
  plan.label = "MAIN";
  ir::Node ws(ir::Kind::Workingstep);
  ws.symbol = "@rough";
  ws.label = "ROUGH";
  ws.set("feature", ir::Value::ref("%pocket"));
  ws.set("secplane", ir::Value::length(20));
  ir::Node op(ir::Kind::BottomAndSideRoughMilling);
  op.label = "ROUGH";
  op.set("tool", ir::Value::ref("%mill"));
  op.set("radial_depth", ir::Value::length(5));
  ir::Node tech(ir::Kind::Technology);
  tech.set("feed", ir::Value::feed(1000));
  tech.set("spindle", ir::Value::spindle(-6000));
  tech.set("feed_reference", ir::Value::word("tcp"));
  op.add(std::move(tech));
  ir::Node strategy(ir::Kind::Strategy);
  strategy.set("type", ir::Value::word("contour_parallel"));
  op.add(std::move(strategy));
  ws.add(std::move(op));
  plan.add(std::move(ws));
  m.root.add(std::move(plan));
  return m;
}

void runPipeline(benchmark::State &state, const char *pipelineText) {
  const ir::Module base = pocketModule(static_cast<int>(state.range(0)));
  std::string error;
  auto pipeline = passes::parsePipeline(pipelineText, error);
  if (!pipeline) {
    state.SkipWithError(error.c_str());
    return;
  }
  long long moves = 0;
  for (auto _ : state) {
    ir::Module m = base;
    DiagnosticCollector sink;
    DiagnosticEngine diags(sink);
    passes::PassManager manager{passes::PassManagerOptions{}};
    manager.add(*pipeline);
    if (!manager.run(m, diags)) {
      state.SkipWithError("the pipeline failed");
      return;
    }
    for (const auto &[pass, counters] : manager.stats())
      if (auto it = counters.find("moves"); pass == "expand-strategies" && it != counters.end())
        moves = it->second;
    benchmark::DoNotOptimize(m);
  }
  state.counters["moves"] = static_cast<double>(moves);
  state.counters["vertices"] = static_cast<double>(state.range(0));
}

void BM_ExpandContourParallel(benchmark::State &state) { runPipeline(state, "expand-strategies"); }
BENCHMARK(BM_ExpandContourParallel)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

void BM_ExpandAndVerify(benchmark::State &state) { runPipeline(state, "expand-strategies,verify-toolpaths"); }
BENCHMARK(BM_ExpandAndVerify)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

void BM_Offset(benchmark::State &state) {
  geom::Region r;
  geom::Loop l;
  const std::vector<geom::Vec2> pts = star(static_cast<int>(state.range(0)));
  for (size_t i = 0; i < pts.size(); ++i)
    l.segs.push_back(geom::Seg::line(pts[i], pts[(i + 1) % pts.size()]));
  r.loops.push_back(l);
  for (auto _ : state)
    benchmark::DoNotOptimize(geom::offset(r, -5));
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_Offset)->RangeMultiplier(10)->Range(100, 100000)->Unit(benchmark::kMillisecond)->Complexity();

} // namespace

BENCHMARK_MAIN();
