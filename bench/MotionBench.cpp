// Motion planning and playback speed (docs/performance.md):
//  - BM_Plan: planning throughput on a 100,000-move path of the kind dense
//    CAM output gives (short lines turning a little at each vertex, with
//    tangent arcs and sharper corners mixed in), in moves per second;
//  - BM_Simulate: the reference player sampling a trajectory of about one
//    hour at 1 kHz, with every check on; the time per run is the time to
//    simulate that hour;
//  - BM_Inverse: the inverse kinematics of the shipped 5-axis machines
//    (table-table, head-table) on 100,000 poses along a 5-axis path (the
//    tool tilting and turning smoothly), each from the joints before: what
//    writing and planning 5-axis moves costs per move in joint solving;
//  - BM_PlanFiveAxis: BM_Plan's path with the tool tilted along it, planned
//    on a 5-axis machine's joints;
//  - BM_PlanTripod: BM_Plan's path, the tool upright, planned on the shipped
//    linear tripod's joints (every segment through its inverse kinematics).
#include "bench/DensePath.h"
#include "runtime/Kinematics.h"
#include "runtime/Planner.h"
#include "runtime/Player.h"

#include <benchmark/benchmark.h>

#include <cmath>

using namespace stepnc;
using namespace stepnc::runtime;
using stepnc::bench::densePath;

namespace {

Machine shipped(const std::string &name) {
  std::unique_ptr<SourceFile> file;
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  return *loadMachine(name, file, diags);
}

Machine hsc() { return shipped("hsc-3axis"); }

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

/// Poses along a 5-axis path over a 100 x 80 mm field, the tool leaning up
/// to 60 deg from +z and turning round it (a swarf-like sweep), about a
/// point `centre` of the workpiece.
std::vector<ToolPose> fiveAxisPoses(int count, const Eigen::Vector3d &centre) {
  std::vector<ToolPose> poses;
  poses.reserve(size_t(count));
  for (int i = 0; i < count; ++i) {
    const double t = double(i) / count;
    const double lean = (10 + 50 * (0.5 + 0.5 * std::sin(6.283185307179586 * 7 * t))) * 0.017453292519943295;
    const double turn = 6.283185307179586 * 3 * t;
    ToolPose p;
    p.tipMm = centre + Eigen::Vector3d(50 * std::sin(6.283185307179586 * 5 * t), 40 * std::cos(6.283185307179586 * 4 * t),
                                       -10 * t);
    p.axis = Eigen::Vector3d(std::sin(lean) * std::cos(turn), std::sin(lean) * std::sin(turn), std::cos(lean));
    poses.push_back(p);
  }
  return poses;
}

void inverseBench(benchmark::State &state, const std::string &machine, const Eigen::Vector3d &centre) {
  const Machine m = shipped(machine);
  std::string error;
  const std::unique_ptr<Kinematics> k = makeKinematics(m, error);
  const std::vector<ToolPose> poses = fiveAxisPoses(int(state.range(0)), centre);
  size_t solved = 0;
  for (auto _ : state) {
    Joints near = Joints::Zero(Eigen::Index(k->jointCount()));
    solved = 0;
    for (const ToolPose &p : poses) {
      const InverseResult r = k->inverse(p, &near);
      if (r.joints) {
        near = *r.joints;
        ++solved;
      }
    }
    benchmark::DoNotOptimize(near);
  }
  state.SetItemsProcessed(state.iterations() * int64_t(poses.size()));
  state.counters["solved"] = double(solved);
}

void BM_InverseTableTable(benchmark::State &state) {
  inverseBench(state, "table-table-5axis", Eigen::Vector3d(250, 225, -200));
}
BENCHMARK(BM_InverseTableTable)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_InverseHeadTable(benchmark::State &state) {
  inverseBench(state, "head-table-5axis", Eigen::Vector3d(300, 250, -250));
}
BENCHMARK(BM_InverseHeadTable)->Arg(100000)->Unit(benchmark::kMillisecond);

/// Plans `path` for every iteration of `state` (timed) and returns the last
/// plan; counts the moves and the segments made.
Trajectory planTimed(benchmark::State &state, const PathInput &path, const Machine &m, const PlanOptions &options) {
  size_t segments = 0;
  for (auto _ : state) {
    Trajectory t = plan(path, m, options);
    segments = t.segments.size();
    benchmark::DoNotOptimize(t);
  }
  state.SetItemsProcessed(state.iterations() * int64_t(path.moves.size()));
  state.counters["segments_out"] = double(segments);
  // Planned once more, untimed, for the caller (each timed plan freed as
  // BM_Plan's is, so that both pay the same for fresh memory).
  return plan(path, m, options);
}

/// Plays a plan once (not timed), every violation kept, and counts them:
/// all, and the joints' velocity, acceleration or jerk.
SimReport playOnce(benchmark::State &state, const Trajectory &t, const Machine &m, const PlanOptions &options) {
  SimOptions sim;
  sim.workOffsetMm = options.workOffset;
  sim.maxViolations = size_t(1) << 30;  // every one kept, to count them by kind
  const SimReport report = simulate(t, m, sim);
  size_t dynamics = 0;
  double worst = 0;  // the largest excess over a joint's limit, %
  for (const Violation &v : report.violations)
    if (v.kind == ViolationKind::Velocity || v.kind == ViolationKind::Acceleration || v.kind == ViolationKind::Jerk) {
      ++dynamics;
      worst = std::max(worst, 100 * (std::abs(v.value) / v.limit - 1));
    }
  state.counters["violations"] = double(report.violationCount);
  state.counters["joint_limits"] = double(dynamics);
  state.counters["worst_over_pct"] = worst;
  return report;
}

/// BM_PlanFiveAxis: the same 100,000-move path as BM_Plan with the tool
/// tilted along it (leaning 5 to 35 deg and turning round +z), planned on
/// the shipped table-table machine's joints: the inverse kinematics at
/// points along every segment and each joint's limits (PlanOptions::
/// kinematics). Compared per move with BM_Plan (docs/performance.md).
void BM_PlanFiveAxis(benchmark::State &state) {
  const Machine m = shipped("table-table-5axis");
  std::string error;
  const std::unique_ptr<Kinematics> k = makeKinematics(m, error);
  PathInput path = densePath(int(state.range(0)), 3000);
  const size_t n = path.moves.size();
  for (size_t i = 0; i < n; ++i) {
    const double t = double(i) / double(n);
    const double lean = (5 + 30 * (0.5 + 0.5 * std::sin(6.283185307179586 * 7 * t))) * 0.017453292519943295;
    const double turn = 6.283185307179586 * 3 * t;
    path.moves[i].axis = Eigen::Vector3d(std::sin(lean) * std::cos(turn), std::sin(lean) * std::sin(turn), std::cos(lean));
  }
  PlanOptions options;
  options.kinematics = k.get();
  options.workOffset = Eigen::Vector3d(200, 200, -250);
  // The plan played once: its joints within their limits (the path is wider
  // than the travel: "violations" counts those too).
  const SimReport report = playOnce(state, planTimed(state, path, m, options), m, options);
  state.counters["motion_s"] = report.duration;
}
BENCHMARK(BM_PlanFiveAxis)->Arg(100000)->Unit(benchmark::kMillisecond);

/// BM_PlanTripod: BM_Plan's 100,000-move path, the tool upright, planned on
/// the shipped linear tripod (a parallel-kinematic machine, whose sliders
/// follow no straight line of the tip): every segment's joints from the
/// solver, each slider's limits. The 400 x 300 mm field centred on the
/// table, 50 mm up; played once, the violations counted.
void BM_PlanTripod(benchmark::State &state) {
  const Machine m = shipped("linear-tripod-5axis");
  std::string error;
  const std::unique_ptr<Kinematics> k = makeKinematics(m, error);
  const PathInput path = densePath(int(state.range(0)), 3000);
  PlanOptions options;
  options.kinematics = k.get();
  options.workOffset = Eigen::Vector3d(-200, -150, 50);
  const SimReport report = playOnce(state, planTimed(state, path, m, options), m, options);
  size_t travel = 0;
  for (const Violation &v : report.violations)
    travel += v.kind == ViolationKind::Travel;
  state.counters["travel"] = double(travel);
  state.counters["motion_s"] = report.duration;
}
BENCHMARK(BM_PlanTripod)->Arg(100000)->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
