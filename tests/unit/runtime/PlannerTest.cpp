// The motion planner, checked on sampled output (the reference player at
// 1 kHz): on stress paths every axis keeps its velocity, acceleration and
// jerk limits, the path stays within tolerance, the feed is never exceeded
// and the tool ends at rest where the program ends; and the plan is not lazy:
// long lines reach the feed, and simple paths take within 2 % of a lower
// bound computed here, independently of the planner.
#include "runtime/Kinematics.h"
#include "runtime/Planner.h"
#include "runtime/Player.h"
#include "tests/unit/runtime/ShippedMachine.h"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>

using namespace stepnc;
using namespace stepnc::runtime;

namespace {

constexpr double kPi = 3.14159265358979323846;

PathMove line(double x, double y, double z, double feed) {
  PathMove m;
  m.to = Vec3(x, y, z);
  m.feed = feed;
  return m;
}

PathMove arc(double x, double y, double z, double cx, double cy, bool ccw, double feed, int64_t turns = 0) {
  PathMove m;
  m.kind = PathMove::Kind::Arc;
  m.to = Vec3(x, y, z);
  m.center = Vec3(cx, cy, 0);
  m.ccw = ccw;
  m.feed = feed;
  m.turns = turns;
  return m;
}

PathMove dwell(const Vec3 &at, double timeS) {
  PathMove m;
  m.kind = PathMove::Kind::Dwell;
  m.to = at;
  m.dwellS = timeS;
  return m;
}

/// Plans and plays `path`; every check of the issue holds.
SimReport check(const PathInput &path, const Machine &machine) {
  const Trajectory t = plan(path, machine);
  SimOptions options;
  options.programmed = &path;
  const SimReport r = simulate(t, machine, options);
  INFO("machine " << machine.name << ", " << t.segments.size() << " segments, " << r.duration << " s");
  for (const Violation &v : r.violations)
    INFO("violation " << violationKindName(v.kind) << " axis " << v.axis << " t=" << v.t << " segment " << v.segment
                      << ": " << v.value << " > " << v.limit);
  CHECK(r.violationCount == 0);
  CHECK(r.maxDeviation <= machine.pathTolerance);
  const Vec3 end = path.moves.empty() ? path.start : path.moves.back().to;
  CHECK((r.endPosition - end).norm() < 1e-9);
  for (int k = 0; k < 3; ++k) {
    CHECK(r.maxVelocity[k] <= machine.axes[k].velocity / 60 * (1 + 1e-6));
    CHECK(r.maxAcceleration[k] <= machine.axes[k].acceleration * (1 + 1e-6));
    CHECK(r.maxJerk[k] <= machine.axes[k].jerk * (1 + 1e-6));
  }
  return r;
}

/// Rest-to-rest time over `length` for one axis-like motion with limits v,
/// a, j, from the kinematics of the seven-phase profile: each speed change
/// to vp is a jerk phase of tj = min(a/j, sqrt(vp/j)), a constant-
/// acceleration phase of vp/(j tj) - tj, and a jerk phase of tj.
double restToRest(double length, double v, double a, double j) {
  auto rise = [&](double vp, double &dist) {
    const double tj = std::min(a / j, std::sqrt(vp / j));
    const double peakA = j * tj;
    const double ta = vp / peakA - tj;
    // Speed at the phase ends, then distance by the trapezoidal rule on each
    // (exact for the quadratic pieces' mean, which is symmetric here).
    const double time = 2 * tj + ta;
    dist = vp * time / 2;  // the speed curve is point-symmetric about its middle
    return time;
  };
  double d = 0;
  double tRise = rise(v, d);
  if (2 * d <= length)
    return 2 * tRise + (length - 2 * d) / v;
  double lo = 0, hi = v;
  for (int i = 0; i < 200; ++i) {
    const double mid = (lo + hi) / 2;
    rise(mid, d);
    (2 * d <= length ? lo : hi) = mid;
  }
  tRise = rise(lo, d);
  return 2 * tRise;
}

} // namespace

TEST_CASE("a long line reaches the feed and takes the time-optimal time", "[planner]") {
  const Machine m = test::shippedMachine("hsc-3axis");
  PathInput p;
  p.moves.push_back(line(300, 0, 0, 3000));
  const SimReport r = check(p, m);
  const Trajectory t = plan(p, m);
  CHECK(t.profiles[0].peak() == Approx(50));
  const double bound = restToRest(300, 50, m.axes[0].acceleration, m.axes[0].jerk);
  CHECK(r.duration >= bound * (1 - 1e-9));
  CHECK(r.duration <= bound * 1.02);
  CHECK(r.duration == Approx(bound).epsilon(1e-9));  // one line: the planner is optimal
}

TEST_CASE("a diagonal line is limited by its binding axis", "[planner]") {
  const Machine m = test::shippedMachine("conventional-3axis");
  PathInput p;
  p.moves.push_back(line(200, 100, -50, 0));  // a rapid: the axes' own speeds
  const SimReport r = check(p, m);
  // z is the slowest axis along this direction: it reaches its limit.
  const Vec3 dir = Vec3(200, 100, -50).normalized();
  const double v = std::min({m.axes[0].velocity / 60 / dir.x(), m.axes[1].velocity / 60 / dir.y(),
                             m.axes[2].velocity / 60 / -dir.z()});
  CHECK(r.maxVelocity.cwiseQuotient(dir.cwiseAbs()).minCoeff() == Approx(v).epsilon(1e-6));
}

TEST_CASE("a rectangle takes within 2 % of the unrolled-perimeter lower bound", "[planner]") {
  const Machine m = test::shippedMachine("hsc-3axis");
  PathInput p;
  for (auto [x, y] : {std::pair{400.0, 0.0}, {400.0, 300.0}, {0.0, 300.0}, {0.0, 0.0}})
    p.moves.push_back(line(x, y, 0, 3000));
  const SimReport r = check(p, m);
  // No path round the rectangle at 3000 mm/min with these limits is faster
  // than its perimeter as one straight line (x and y have the same limits).
  const double bound = restToRest(1400, 50, m.axes[0].acceleration, m.axes[0].jerk);
  CHECK(r.duration >= bound);
  CHECK(r.duration <= bound * 1.02);
  CHECK(r.feedTime == Approx(r.duration));
}

TEST_CASE("stress paths hold every bound on both shipped machines", "[planner]") {
  for (const std::string name : {"hsc-3axis", "conventional-3axis"}) {
    const Machine m = test::shippedMachine(name);
    SECTION(name + ": tiny zigzag") {
      PathInput p;
      for (int i = 0; i < 400; ++i)
        p.moves.push_back(line(0.05 * (i + 1), (i % 2) * 0.02, 0, 6000));
      check(p, m);
    }
    SECTION(name + ": dense short segments on a circle") {
      PathInput p;
      p.start = Vec3(20, 0, 0);
      for (int i = 1; i <= 3000; ++i) {
        const double a = 2 * kPi * i / 3000;
        p.moves.push_back(line(20 * std::cos(a), 20 * std::sin(a), 0, 4000));
      }
      check(p, m);
    }
    SECTION(name + ": small arcs and S-bends") {
      PathInput p;
      double x = 0;
      for (int i = 0; i < 100; ++i) {
        const double r = 0.2 + 0.3 * (i % 3);
        p.moves.push_back(arc(x + 2 * r, 0, 0, x + r, 0, i % 2 == 0, 5000));
        x += 2 * r;
        p.moves.push_back(line(x + 1, 0, 0, 5000));
        x += 1;
      }
      check(p, m);
    }
    SECTION(name + ": sharp reversals and near-reversals") {
      PathInput p;
      for (int i = 0; i < 50; ++i) {
        p.moves.push_back(line(10, 0.01 * i, 0, 8000));
        p.moves.push_back(line(0, 0.01 * i + (i % 2) * 0.001, 0, 8000));
      }
      check(p, m);
    }
    SECTION(name + ": helices, plunges and rapids") {
      PathInput p;
      p.start = Vec3(50, 50, 20);
      p.moves.push_back(line(50, 50, 2, 0));
      p.moves.push_back(arc(50, 50, -4, 47, 50, true, 1200, 1));  // two turns down
      p.moves.push_back(line(80, 50, -4, 2400));
      p.moves.push_back(arc(90, 60, -4, 80, 60, true, 2400));
      p.moves.push_back(line(90, 60, 20, 0));
      p.moves.push_back(line(0, 0, 20, 0));
      check(p, m);
    }
    SECTION(name + ": random lines and arcs") {
      std::mt19937 rng(2026);
      std::uniform_real_distribution<double> step(-5, 5), small(0.01, 3), feed(100, 12000), pick(0, 1);
      PathInput p;
      Vec3 at(100, 100, 0);
      p.start = at;
      for (int i = 0; i < 300; ++i) {
        if (pick(rng) < 0.5) {
          const double s = pick(rng) < 0.3 ? 0.05 : 1.0;
          at += Vec3(step(rng) * s, step(rng) * s, pick(rng) < 0.2 ? step(rng) * 0.2 : 0);
          p.moves.push_back(line(at.x(), at.y(), at.z(), pick(rng) < 0.1 ? 0 : feed(rng)));
        } else {
          const double r = small(rng), a0 = 2 * kPi * pick(rng), sweep = 2 * kPi * pick(rng);
          const Vec3 c = at - r * Vec3(std::cos(a0), std::sin(a0), 0);
          const bool ccw = pick(rng) < 0.5;
          const double a1 = a0 + (ccw ? sweep : -sweep);
          at = Vec3(c.x() + r * std::cos(a1), c.y() + r * std::sin(a1), at.z());
          p.moves.push_back(arc(at.x(), at.y(), at.z(), c.x(), c.y(), ccw, feed(rng)));
        }
      }
      check(p, m);
    }
  }
}

TEST_CASE("the tool stops where the program says and at reversals", "[planner]") {
  const Machine m = test::shippedMachine("hsc-3axis");
  PathInput p;
  p.moves.push_back(line(10, 0, 0, 3000));
  p.moves.push_back(line(0, 0, 0, 3000));  // straight back
  PathMove change = line(0, 10, 0, 3000);
  change.stopBefore = true;  // e.g. a tool change
  p.moves.push_back(change);
  const Trajectory t = plan(p, m);
  REQUIRE(t.segments.size() == 3);
  CHECK(t.info[0].stop == StopReason::Start);
  CHECK(t.info[1].stop == StopReason::Reversal);
  CHECK(t.info[2].stop == StopReason::Program);
  for (const Profile &prof : t.profiles)
    CHECK(prof.v0 == 0);
  check(p, m);
}

TEST_CASE("a dwell holds the tool at rest at its point for exactly its time", "[planner][dwell]") {
  // A 40 mm line along x at 3000 mm/min, with half a second's dwell at its
  // middle: the tool runs 20 mm rest to rest, waits, and runs 20 mm rest to
  // rest. Without the dwell it is one 40 mm run. So the dwell costs its time
  // and the stop it forces, two 20 mm runs instead of one of 40 mm, each
  // time-optimal (restToRest: computed here, not by the planner).
  const Machine m = test::shippedMachine("hsc-3axis");
  const double a = m.axes[0].acceleration, j = m.axes[0].jerk;
  const Vec3 middle(20, 0, 0);
  PathInput without;
  without.moves = {line(20, 0, 0, 3000), line(40, 0, 0, 3000)};
  PathInput dwelt;
  dwelt.moves = {line(20, 0, 0, 3000), dwell(middle, 0.5), line(40, 0, 0, 3000)};
  PathInput stopped = without;  // a programmed stop at the dwell's point instead
  stopped.moves[1].stopBefore = true;
  const Trajectory tw = plan(without, m), td = plan(dwelt, m), ts = plan(stopped, m);

  REQUIRE(td.segments.size() == 3);
  const Segment &d = td.segments[1];
  CHECK(d.kind == SegmentKind::Dwell);
  CHECK(d.start == middle);
  CHECK(d.end == middle);
  CHECK(d.length == 0);
  CHECK(td.info[1].move == 1);
  CHECK(td.info[1].nextMove == 1);
  CHECK(td.info[1].stop == StopReason::Dwell);
  CHECK(td.info[2].stop == StopReason::Dwell);
  CHECK(td.info[2].move == 2);
  CHECK(td.profiles[0].v1() == 0);
  CHECK(td.profiles[0].a1() == 0);
  CHECK(td.profiles[1].v0 == 0);
  CHECK(td.profiles[1].a0 == 0);
  CHECK(td.profiles[1].duration() == 0.5);
  CHECK(td.profiles[1].at(0.25).s == 0);
  CHECK(td.profiles[2].v0 == 0);
  CHECK(td.profiles[2].a0 == 0);
  // The moves are planned as with a programmed stop there.
  REQUIRE(ts.segments.size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    const Profile &p = td.profiles[k == 0 ? 0 : 2], &q = ts.profiles[k];
    for (size_t i = 0; i < p.phases.size(); ++i) {
      CHECK(p.phases[i].duration == q.phases[i].duration);
      CHECK(p.phases[i].jerk == q.phases[i].jerk);
    }
  }
  // Total time: without the dwell, plus the dwell, plus the stop.
  const double one = restToRest(40, 50, a, j), two = 2 * restToRest(20, 50, a, j), stop = two - one;
  INFO("without " << tw.duration() << " s, with the dwell " << td.duration() << " s, the stop " << stop << " s");
  CHECK(stop > 0.01);
  CHECK(tw.duration() == Approx(one).epsilon(1e-9));
  CHECK(td.duration() == Approx(tw.duration() + 0.5 + stop).epsilon(1e-9));
  CHECK(td.duration() == Approx(ts.duration() + 0.5).epsilon(1e-14));

  // Played at 1 kHz: every limit kept, and from the first line's end to the
  // second's start (0.5 s) the tool is exactly at the middle, at rest; it
  // moves just before and just after.
  const SimReport r = check(dwelt, m);
  CHECK(r.dwellTime == 0.5);
  CHECK(r.duration == Approx(td.duration()).epsilon(1e-14));
  const double t0 = td.profiles[0].duration(), t1 = t0 + 0.5;
  size_t atRest = 0;
  bool movedBefore = false, movedAfter = false;
  simulate(td, m, {}, [&](const Sample &s) {
    if (s.t > t0 && s.t < t1) {
      ++atRest;
      CHECK(s.segment == 1);
      CHECK(s.p == middle);
      CHECK(s.speed == 0);
      CHECK(s.v == Vec3::Zero());
      CHECK(s.a == Vec3::Zero());
      CHECK(s.j == Vec3::Zero());
    }
    movedBefore = movedBefore || (s.t > t0 - 0.002 && s.t < t0 && s.speed > 0);
    movedAfter = movedAfter || (s.t > t1 && s.t < t1 + 0.002 && s.speed > 0);
  });
  CHECK(atRest >= 499);
  CHECK(atRest <= 501);
  CHECK(movedBefore);
  CHECK(movedAfter);
}

TEST_CASE("dwells at the start, at the end, in a row and of no time", "[planner][dwell]") {
  const Machine m = test::shippedMachine("conventional-3axis");
  // Before the first move and after the last: the trajectory starts and
  // ends with them; two in a row stay two, each with its move.
  PathInput p;
  p.start = Vec3(0, 0, 5);
  p.moves = {dwell(p.start, 0.25), line(30, 0, 5, 1200), dwell(Vec3(30, 0, 5), 0.5), dwell(Vec3(30, 0, 5), 0.75)};
  const Trajectory t = plan(p, m);
  REQUIRE(t.segments.size() == 4);
  const SegmentKind kinds[] = {SegmentKind::Dwell, SegmentKind::Line, SegmentKind::Dwell, SegmentKind::Dwell};
  for (size_t k = 0; k < 4; ++k) {
    INFO("segment " << k);
    CHECK(t.segments[k].kind == kinds[k]);
    CHECK(t.info[k].stop == StopReason::Dwell);
    CHECK(t.info[k].move == k);
  }
  CHECK(t.segments[0].start == p.start);
  CHECK(t.segments[3].end == Vec3(30, 0, 5));
  CHECK(t.duration() == Approx(0.25 + t.profiles[1].duration() + 0.5 + 0.75).epsilon(1e-14));
  const SimReport r = check(p, m);
  CHECK(r.dwellTime == 1.5);
  CHECK(r.feedTime == Approx(t.profiles[1].duration()).epsilon(1e-14));
  CHECK(r.rapidTime == 0);
  CHECK_THAT(formatReport(r, t, m), Catch::Contains(", dwells 1.500 s)\n"));

  // A dwell of no time is none: the corner is blended as without it.
  PathInput none;
  none.moves = {line(20, 0, 0, 3000), dwell(Vec3(20, 0, 0), 0), line(20, 20, 0, 3000)};
  PathInput without;
  without.moves = {line(20, 0, 0, 3000), line(20, 20, 0, 3000)};
  const Trajectory tn = plan(none, m), tw = plan(without, m);
  REQUIRE(tn.segments.size() == tw.segments.size());
  CHECK(tn.duration() == tw.duration());
}

TEST_CASE("a curve written as short lines takes within 5 % of its lower bound", "[planner]") {
  // A 20 mm circle as 300, 3,000 and 30,000 chords (0.42 to 0.0042 mm) at
  // 4000 mm/min. Blends share the curve's curvature at the chords' middles,
  // and runs of short segments share one profile, so neither the lines'
  // zero curvature nor a stop of acceleration at every junction holds the
  // speed down. Bound: the polyline's length as one straight rest-to-rest
  // move with the path acceleration and jerk x and y allow together (sqrt 2
  // times one axis's); the circle's curvature caps, sqrt(a R) and
  // (j R^2)^(1/3), are far above the feed here. Measured: 3.2, 2.7 and
  // 1.9 % above it.
  const Machine m = test::shippedMachine("hsc-3axis");
  for (const int n : {300, 3000, 30000}) {
    PathInput p;
    p.start = Vec3(20, 0, 0);
    double length = 0;
    for (int i = 1; i <= n; ++i) {
      const double a = 2 * kPi * i / n;
      const PathMove mv = line(20 * std::cos(a), 20 * std::sin(a), 0, 4000);
      length += (mv.to - (p.moves.empty() ? p.start : p.moves.back().to)).norm();
      p.moves.push_back(mv);
    }
    INFO(n << " chords");
    const SimReport r = check(p, m);
    const double bound =
        restToRest(length, 4000.0 / 60, std::sqrt(2.0) * m.axes[0].acceleration, std::sqrt(2.0) * m.axes[0].jerk);
    CHECK(r.duration >= bound);
    CHECK(r.duration <= 1.05 * bound);
  }
}

namespace {

/// A blend as the planner makes one (Planner.cpp, blendPoints): from a point
/// with unit tangent t0 and curvature vector k0 to one with t1 and k1, end
/// derivatives scaled by the chord.
Segment plannerLikeBlend(const Vec3 &p0, const Vec3 &t0, const Vec3 &k0, const Vec3 &p1, const Vec3 &t1,
                         const Vec3 &k1) {
  const double m = (p1 - p0).norm();
  std::array<Vec3, 6> c;
  c[0] = p0;
  c[5] = p1;
  c[1] = c[0] + t0 * (m / 5);
  c[2] = 2 * c[1] - c[0] + k0 * (m * m / 20);
  c[4] = c[5] - t1 * (m / 5);
  c[3] = 2 * c[4] - c[5] + k1 * (m * m / 20);
  return Segment::blend(c);
}

} // namespace

TEST_CASE("blend bounds hold between their samples on random blends", "[planner]") {
  // Segment::demand samples a blend at 33 points and adds 10 %: the axis
  // limits hold only if that is above every value between the samples.
  // Checked against 2,001 points along the length (Segment::at, the
  // player's evaluation) on corners of 1 to 175 degrees, with zero or chain
  // curvature at the ends, in the xy plane (the fast path) and tilted.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0, 1), sym(-1, 1);
  double closest = std::numeric_limits<double>::infinity();
  for (int n = 0; n < 2000; ++n) {
    const bool plane = n % 2 == 0;
    const double l = 0.01 + 2 * unit(rng), turn = (1 + 174 * unit(rng)) * kPi / 180, heading = 2 * kPi * unit(rng);
    Vec3 t0(std::cos(heading), std::sin(heading), 0), t1(std::cos(heading + turn), std::sin(heading + turn), 0);
    Vec3 k0 = Vec3::Zero(), k1 = Vec3::Zero();
    if (n % 3 != 0) {
      // Chains of short lines: end curvature normal to the tangent, up to
      // that of a circle through the corner.
      const double bend = 2 * std::sin(turn / 2) / l;
      k0 = Vec3(-t0.y(), t0.x(), 0) * (bend * unit(rng));
      k1 = Vec3(-t1.y(), t1.x(), 0) * (bend * unit(rng));
    }
    const Vec3 corner(100 * sym(rng), 100 * sym(rng), plane ? 5.0 : 0.0);
    Vec3 p0 = corner - t0 * l, p1 = corner + t1 * l;
    if (!plane) {
      // A tilt about a random axis: every axis sees the curve.
      const Eigen::Matrix3d r =
          Eigen::AngleAxisd(kPi * unit(rng), Vec3(sym(rng), sym(rng), sym(rng)).normalized()).toRotationMatrix();
      p0 = r * p0, p1 = r * p1, t0 = r * t0, t1 = r * t1, k0 = r * k0, k1 = r * k1;
    }
    const Segment b = plannerLikeBlend(p0, t0, k0, p1, t1, k1);
    const AxisDemand d = b.demand();
    Vec3 r1 = Vec3::Zero(), r2 = Vec3::Zero(), r3 = Vec3::Zero();
    for (int i = 0; i <= 2000; ++i) {
      const PathPoint pt = b.at(b.length * i / 2000);
      r1 = r1.cwiseMax(pt.r1.cwiseAbs());
      r2 = r2.cwiseMax(pt.r2.cwiseAbs());
      r3 = r3.cwiseMax(pt.r3.cwiseAbs());
    }
    INFO("blend " << n << ": turn " << turn * 180 / kPi << " deg, half-length " << l);
    for (int k = 0; k < 3; ++k) {
      CHECK(d.r1[k] >= r1[k] * (1 - 1e-12));
      CHECK(d.r2[k] >= r2[k] * (1 - 1e-12));
      CHECK(d.r3[k] >= r3[k] * (1 - 1e-12));
      if (r3[k] > 1e-9 * r3.maxCoeff())
        closest = std::min(closest, d.r3[k] / r3[k]);
    }
  }
  // The margin is not spent: the sampled bound with its 10 % stays above.
  CHECK(closest > 1.0);
}

TEST_CASE("a blend's arc-length table is its curve's length", "[planner]") {
  // Segment::blend evaluates all Gauss points at once; each entry must be
  // what QuinticCurve::length gives, bit for bit (the player inverts it).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> sym(-1, 1);
  for (int n = 0; n < 500; ++n) {
    std::array<Vec3, 6> c;
    for (Vec3 &p : c)
      p = Vec3(10 * sym(rng), 10 * sym(rng), n % 2 ? 3.0 : sym(rng));
    const Segment b = Segment::blend(c);
    const QuinticCurve q(c);
    double s = 0;
    for (int i = 0; i < Segment::kBlendTable; ++i) {
      s += q.length(double(i) / Segment::kBlendTable, double(i + 1) / Segment::kBlendTable);
      CHECK(b.arcTable[size_t(i) + 1] == s);
    }
    CHECK(b.length == s);
  }
}

TEST_CASE("braking starts before segments too short to stop on", "[planner]") {
  // A long fast line into a chain of 400 pieces 0.005 mm long (2 mm in all)
  // that ends the program: no piece is long enough to stop on, so the speed
  // must already be low where the chain begins.
  for (const std::string name : {"hsc-3axis", "conventional-3axis"}) {
    const Machine m = test::shippedMachine(name);
    PathInput p;
    p.moves.push_back(line(200, 0, 0, 12000));
    for (int i = 1; i <= 400; ++i)
      p.moves.push_back(line(200 + 0.005 * i, 0, 0, 12000));
    INFO(name);
    check(p, m);
    const Trajectory t = plan(p, m);
    REQUIRE(t.profiles.size() >= 2);
    // Entering the chain no faster than a stop over 2 mm allows: v^2 <= 2 a s.
    const double a = m.axes[0].acceleration;
    CHECK(t.profiles[1].v0 <= std::sqrt(2 * a * 2.0) * (1 + 1e-9));
  }
}

TEST_CASE("a chain of 20,000 pieces of 0.001 mm plays clean and ends at rest", "[planner]") {
  const Machine m = test::shippedMachine("hsc-3axis");
  PathInput p;
  p.start = Vec3(0, 0, 0);
  for (int i = 1; i <= 20000; ++i) {
    const double s = 0.001 * i;
    p.moves.push_back(line(s, 0.2 * std::sin(s * 0.5), 0, 6000));  // a gentle curve, 20 mm
  }
  const SimReport r = check(p, m);
  CHECK(r.duration > 0);
}

TEST_CASE("a segment that tilts the tool is capped by the joint that binds, and the player finds the joints "
          "within their limits",
          "[planner][five-axis]") {
  const Machine m = test::shippedMachine("table-table-5axis");
  std::string error;
  const std::unique_ptr<Kinematics> k = makeKinematics(m, error);
  REQUIRE(k);
  // 10 mm along x at 3000 mm/min while the tool, leaning 20 deg, swings its
  // lean from +x to +y: the table's C turns about 90 deg over the line.
  const double lean = 20 * 3.14159265358979323846 / 180;
  PathInput p;
  p.startAxis = Vec3(std::sin(lean), 0, std::cos(lean));
  p.start = Vec3(0, 0, 0);
  PathMove turn;
  turn.to = Vec3(10, 0, 0);
  turn.feed = 3000;
  turn.axis = Vec3(0, std::sin(lean), std::cos(lean));
  p.moves.push_back(turn);
  PlanOptions options;
  options.kinematics = k.get();
  options.workOffset = Vec3(250, 225, -250);
  const Trajectory t = plan(p, m, options);
  // A turning dwell first (C set for the first pose), then the line.
  const auto line = std::find_if(t.segments.begin(), t.segments.end(),
                                 [](const Segment &s) { return s.kind == SegmentKind::Line; });
  REQUIRE(line != t.segments.end());
  const SegmentInfo &info = t.info[size_t(line - t.segments.begin())];
  CHECK(line->tilted());
  REQUIRE(info.axis >= 0);
  CHECK(t.axisNames[size_t(info.axis)] == "c");
  CHECK((info.limitedBy == SpeedLimit::AxisVelocity || info.limitedBy == SpeedLimit::Acceleration ||
         info.limitedBy == SpeedLimit::Jerk));
  CHECK(info.limits.v < 50);  // below the 3000 mm/min the line asks for
  // Without the joints the same line would run at its feed.
  const Trajectory flat = plan(p, m);
  CHECK(flat.info.front().limits.v == Approx(50));
  // The player takes the joints at every sample: none beyond its limit, C
  // near its velocity limit somewhere.
  SimOptions sim;
  sim.workOffsetMm = options.workOffset;
  const SimReport r = simulate(t, m, sim);
  CHECK(r.violationCount == 0);
  CHECK(r.tiltedSamples > 0);
  const size_t c = 4;
  REQUIRE(m.axes[c].name == "c");
  CHECK(r.jointMaxVelocity[c] * 60 <= m.axes[c].velocity * 1.02);
  CHECK(r.jointMaxVelocity[c] * 60 >= 0.3 * m.axes[c].velocity);
}

TEST_CASE("the tool axis turns at one rate through a junction where it turns on both sides, and the tool does "
          "not stop there",
          "[planner][five-axis]") {
  const Machine m = test::shippedMachine("table-table-5axis");
  std::string error;
  const std::unique_ptr<Kinematics> k = makeKinematics(m, error);
  REQUIRE(k);
  // 200 moves of 0.5 to 1.5 mm along a gentle curve at 2000 mm/min, the
  // tool leaning 25 deg and swinging its lean round +z by 0.3 deg a mm (as
  // CAM output that samples a smooth orientation: the moves' own great
  // circles turn at one rate, their junctions between them); then 20 moves
  // with the lean held (the axis fixed) and 20 turning again.
  const double deg = 3.14159265358979323846 / 180;
  auto leaning = [&](double heading) {
    return Vec3(std::sin(25 * deg) * std::cos(heading), std::sin(25 * deg) * std::sin(heading), std::cos(25 * deg));
  };
  PathInput p;
  p.start = Vec3(0, 0, 0);
  p.startAxis = leaning(0);
  double x = 0, heading = 0;
  for (int i = 1; i <= 240; ++i) {
    const double step = 0.5 + (i % 3) * 0.5;
    x += step;
    if (i <= 200 || i > 220)
      heading += 0.3 * deg * step;
    PathMove move;
    move.to = Vec3(x, 5 * std::sin(x / 40), 0);
    move.feed = 2000;
    move.axis = leaning(heading);
    p.moves.push_back(move);
  }
  PlanOptions options;
  options.kinematics = k.get();
  options.workOffset = Vec3(100, 225, -250);
  const Trajectory t = plan(p, m, options);
  // Junctions between segments that both turn the axis: the same axis and
  // the same rate per mm on both sides, the speed there not a stop (but
  // where the tool slows for the stop where the fixed stretch ends).
  size_t smoothed = 0, fixedKept = 0, fast = 0;
  for (size_t i = 1; i < t.segments.size(); ++i) {
    const Segment &a = t.segments[i - 1], &b = t.segments[i];
    if (a.kind == SegmentKind::Dwell || b.kind == SegmentKind::Dwell)
      continue;
    INFO("junction " << i);
    CHECK((a.axisAt(a.length) - b.axisAt(0)).norm() < 1e-12);
    if (a.axis0 == a.axis1) {  // the fixed stretch keeps its axis throughout
      CHECK_FALSE(a.axisCubic());
      CHECK((a.axisAt(0.5 * a.length) - a.axis0).norm() < 1e-12);
      ++fixedKept;
      continue;
    }
    if (b.axis0 == b.axis1)
      continue;
    CHECK((a.axisRateAt(a.length) - b.axisRateAt(0)).norm() < 1e-9);
    fast += t.profiles[i].v0 > 0.5 * 2000.0 / 60;
    ++smoothed;
  }
  // Every segment's axis within the machine's orientation tolerance of its
  // even turn on the great circle (deg), here and where the moves' rates
  // alternate between 0.3 and 0.37 deg/mm on moves of 4 and 0.5 mm, where
  // the tolerance holds the shared rates back (near the long side's).
  auto worstOff = [&](const Trajectory &plan) {
    double worst = 0;
    for (const Segment &s : plan.segments)
      if (s.axisCubic())
        for (int piece = 1; piece < 40; ++piece) {
          const double f = piece / 40.0;
          const double cosine = s.axisAt(f * s.length).dot(axisBetween(s.axis0, s.axis1, f));
          worst = std::max(worst, std::acos(std::clamp(cosine, -1.0, 1.0)) / deg);
        }
    return worst;
  };
  CHECK(worstOff(t) <= m.orientationTolerance * (1 + 1e-6));
  CHECK(worstOff(t) > 0);
  PathInput alternating;
  alternating.start = Vec3(0, 0, 0);
  alternating.startAxis = leaning(0);
  double turned = 0, along = 0;
  for (int i = 1; i <= 20; ++i) {
    const double step = i % 2 ? 4 : 0.5;
    along += step;
    turned += (i % 2 ? 0.3 : 0.37) * step * deg;
    PathMove move;
    move.to = Vec3(along, 0, 0);
    move.feed = 2000;
    move.axis = leaning(turned);
    alternating.moves.push_back(move);
  }
  const double held = worstOff(plan(alternating, m, options));
  INFO("alternating rates: " << held << " deg off the even turns");
  CHECK(held <= m.orientationTolerance * (1 + 1e-6));
  CHECK(held > 0.25 * m.orientationTolerance);
  CHECK(smoothed > 300);
  CHECK(fast > 0.95 * double(smoothed));
  CHECK(fixedKept >= 20);
  // The player finds every joint within its limits; most of the time at
  // the programmed feed (without the smoothing the tool nearly stops at
  // every junction: more than twice as long).
  SimOptions sim;
  sim.workOffsetMm = options.workOffset;
  const SimReport r = simulate(t, m, sim);
  CHECK(r.violationCount == 0);
  double length = 0;
  for (const Segment &s : t.segments)
    length += s.length;
  INFO("motion " << r.duration << " s over " << length << " mm");
  CHECK(r.duration < 1.3 * length / (2000.0 / 60) + 2);
  // A junction whose two sides turn at rates too far apart to share one
  // within the tolerance keeps its kink; with the tolerance 0 none is
  // smoothed.
  PathInput jump;
  jump.start = Vec3(0, 0, 0);
  jump.startAxis = leaning(0);
  for (int i = 1; i <= 2; ++i) {
    PathMove move;
    move.to = Vec3(10 * i, 0, 0);
    move.feed = 2000;
    move.axis = leaning(i == 1 ? 1 * deg : 11 * deg);  // 0.1 deg/mm, then 1 deg/mm
    jump.moves.push_back(move);
  }
  for (const Segment &s : plan(jump, m, options).segments)
    CHECK_FALSE(s.axisCubic());
  PlanOptions off = options;
  off.axisToleranceDeg = 0;
  for (const Segment &s : plan(p, m, off).segments)
    CHECK_FALSE(s.axisCubic());
}

TEST_CASE("a segment's axis rates and curvatures at its ends are its axis's derivatives", "[planner][five-axis]") {
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0, 1);
  auto unit = [&] { return Vec3(n(rng), n(rng), n(rng)).normalized(); };
  for (int i = 0; i < 500; ++i) {
    Segment s = Segment::line(Vec3(0, 0, 0), Vec3(1 + 3 * std::abs(n(rng)), 0, 0));
    s.axis0 = unit();
    s.axis1 = (s.axis0 + 0.05 * unit()).normalized();
    if (i % 2) {  // a cubic: rates across the axes
      const Vec3 r0 = 0.05 * unit(), r1 = 0.05 * unit();
      s.axisRate0 = r0 - s.axis0 * s.axis0.dot(r0);
      s.axisRate1 = r1 - s.axis1 * s.axis1.dot(r1);
    }
    const Segment::AxisEnds e = s.axisEnds();
    // One-sided differences of the axis itself (second order).
    const double h = 1e-4 * s.length, L = s.length;
    auto at = [&](double x) { return s.axisAt(x); };
    const Vec3 d0 = (-3 * at(0) + 4 * at(h) - at(2 * h)) / (2 * h);
    const Vec3 d1 = (3 * at(L) - 4 * at(L - h) + at(L - 2 * h)) / (2 * h);
    const Vec3 c0 = (2 * at(0) - 5 * at(h) + 4 * at(2 * h) - at(3 * h)) / (h * h);
    const Vec3 c1 = (2 * at(L) - 5 * at(L - h) + 4 * at(L - 2 * h) - at(L - 3 * h)) / (h * h);
    INFO("segment " << i << (s.axisCubic() ? " (cubic)" : " (great circle)"));
    CHECK((e.rate0 - d0).norm() < 1e-6);
    CHECK((e.rate1 - d1).norm() < 1e-6);
    CHECK((e.curve0 - c0).norm() < 1e-3 * (1 + e.curve0.norm()));
    CHECK((e.curve1 - c1).norm() < 1e-3 * (1 + e.curve1.norm()));
    CHECK((s.axisRateAt(0) - e.rate0).norm() < 1e-12);
    CHECK((s.axisRateAt(L) - e.rate1).norm() < 1e-12);
  }
}

TEST_CASE("GreatCircle: the tool axis between two poses, at an even rate on their great circle",
          "[planner][five-axis]") {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  auto unit = [&] { return Vec3(n(rng), n(rng), n(rng)).normalized(); };
  for (int i = 0; i < 1000; ++i) {
    const Vec3 u = unit(), w = unit();
    const GreatCircle circle(u, w);
    // The ends exactly; outside [0, 1] clamped.
    CHECK(circle.at(0) == u);
    CHECK(circle.at(1) == w);
    CHECK(circle.at(-0.5) == u);
    CHECK(circle.at(2) == w);
    const double whole = std::acos(std::clamp(u.dot(w), -1.0, 1.0));
    for (double t : {0.1, 0.25, 0.5, 0.9}) {
      const Vec3 p = circle.at(t);
      INFO("u " << u.transpose() << ", w " << w.transpose() << ", t " << t);
      CHECK(std::abs(p.norm() - 1) < 1e-12);
      // In the plane of u and w, a fraction t of the angle from u and the
      // rest from w.
      CHECK(std::abs(p.dot(u.cross(w))) < 1e-9);
      CHECK(std::abs(std::acos(std::clamp(p.dot(u), -1.0, 1.0)) - t * whole) < 1e-7);
      CHECK(std::abs(std::acos(std::clamp(p.dot(w), -1.0, 1.0)) - (1 - t) * whole) < 1e-7);
      CHECK(axisBetween(u, w, t) == p);
    }
  }
  // Equal ends: no turn.
  const Vec3 z = Vec3::UnitZ();
  CHECK(GreatCircle(z, z).at(0.5) == z);
  // Opposite ends: a half turn through a direction across both.
  const GreatCircle half(z, -z);
  const Vec3 middle = half.at(0.5);
  CHECK(std::abs(middle.dot(z)) < 1e-12);
  CHECK(std::abs(middle.norm() - 1) < 1e-12);
  CHECK(std::abs(half.at(0.25).dot(z) - std::cos(std::numbers::pi / 4)) < 1e-12);
}

TEST_CASE("GreatCircle: its tangent is at()'s derivative; nearestCosine how near the arc comes to a direction",
          "[planner][five-axis]") {
  std::mt19937 rng(6);
  std::normal_distribution<double> n(0, 1);
  auto unit = [&] { return Vec3(n(rng), n(rng), n(rng)).normalized(); };
  for (int i = 0; i < 1000; ++i) {
    const Vec3 u = unit(), w = unit(), v = unit();
    const GreatCircle circle(u, w);
    INFO("u " << u.transpose() << ", w " << w.transpose() << ", v " << v.transpose());
    CHECK(std::abs(circle.angle() - std::acos(std::clamp(u.dot(w), -1.0, 1.0))) < 1e-7);
    for (double t : {0.0, 0.3, 0.7, 1.0}) {
      // Central differences inside, one-sided at the ends.
      constexpr double h = 1e-6;
      const double t0 = std::max(0.0, t - h), t1 = std::min(1.0, t + h);
      const Vec3 seen = (circle.at(t1) - circle.at(t0)) / (t1 - t0);
      CHECK((circle.tangent(t) - seen).norm() < 1e-5 * (1 + circle.angle()));
      CHECK(std::abs(circle.tangent(t).dot(circle.at(t))) < 1e-9);
    }
    // The largest |v . at(t)| by sampling the arc finely: never above
    // nearestCosine, and within the sampling's step of it.
    double sampled = 0;
    for (int k = 0; k <= 4000; ++k)
      sampled = std::max(sampled, std::abs(v.dot(circle.at(k / 4000.0))));
    const double nearest = circle.nearestCosine(v);
    CHECK(sampled <= nearest + 1e-12);
    CHECK(nearest - sampled < 1e-6);
  }
  // An arc passing over the direction, and one short of it.
  const GreatCircle over(Vec3(1, 0, 1).normalized(), Vec3(-1, 0, 1).normalized());
  CHECK(over.nearestCosine(Vec3::UnitZ()) == Approx(1.0));
  const GreatCircle shortOf(Vec3(1, 0, 0), Vec3(1, 0, 1).normalized());
  CHECK(shortOf.nearestCosine(Vec3::UnitZ()) == Approx(std::sqrt(0.5)));
  CHECK(shortOf.nearestCosine(-Vec3::UnitZ()) == Approx(std::sqrt(0.5)));
}
