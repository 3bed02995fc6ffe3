// The reference player: trajectories built by hand (segments and profiles
// whose phases are computed here) are sampled and checked. A valid one gives
// no violation and its exact end; each kind of fault gives its kind of
// violation on the right axis; the time and feed figures match the closed
// forms.
#include "runtime/Planner.h"
#include "runtime/Player.h"
#include "support/Format.h"
#include "tests/unit/runtime/ShippedMachine.h"

#include <catch2/catch.hpp>

#include <cctype>
#include <cmath>
#include <numbers>

using namespace stepnc;
using namespace stepnc::runtime;

namespace {

/// Every axis: 500 mm/s, 2000 mm/s^2, 20000 mm/s^3.
Machine testMachine() {
  Machine m;
  m.name = "test machine";
  m.cycleTime = 0.001;
  m.pathTolerance = 0.01;
  for (const char *name : {"x", "y", "z"})
    m.axes.push_back({name, -1000, 1000, 30000, 2000, 20000});
  return m;
}

/// A speed change with jerk +-jerk for t1, constant acceleration for t2:
/// jerk * t1 * (t1 + t2) of speed over (2 t1 + t2).
struct Ramp {
  double jerk = 8000;
  double t1 = 0.125;
  double t2 = 0.125;

  double dv() const { return jerk * t1 * (t1 + t2); }
  double time() const { return 2 * t1 + t2; }
  /// Distance of the ramp between speeds v and v + dv (either way).
  double distance(double v) const { return (2 * v + dv()) / 2 * time(); }
};

// The default ramp's numbers are exact in binary: 250 mm/s in 0.375 s over
// 46.875 mm, acceleration 1000 mm/s^2.
constexpr double kV = 250;

/// Rest to rest: rise, cruise, fall.
Profile restToRest(const Ramp &r, double cruise) {
  Profile p;
  p.v0 = 0;
  p.phases = {{{r.t1, r.jerk}, {r.t2, 0}, {r.t1, -r.jerk}, {cruise, 0}, {r.t1, -r.jerk}, {r.t2, 0}, {r.t1, r.jerk}}};
  return p;
}
double restToRestLength(const Ramp &r, double cruise) { return 2 * r.distance(0) + r.dv() * cruise; }

/// From rest up to dv, then cruise (ends at speed).
Profile rise(const Ramp &r, double cruise) {
  Profile p;
  p.phases = {{{r.t1, r.jerk}, {r.t2, 0}, {r.t1, -r.jerk}, {cruise, 0}, {}, {}, {}}};
  return p;
}
/// Cruise at dv, then down to rest.
Profile fall(const Ramp &r, double cruise) {
  Profile p;
  p.v0 = r.dv();
  p.phases = {{{}, {}, {}, {cruise, 0}, {r.t1, -r.jerk}, {r.t2, 0}, {r.t1, r.jerk}}};
  return p;
}

SegmentInfo feedInfo(double feed, uint32_t move, StopReason stop = StopReason::None) {
  SegmentInfo info;
  info.limits = {feed, 1000, 8000};
  info.feed = feed;
  info.move = info.nextMove = move;
  info.stop = stop;
  return info;
}

Trajectory empty(const Vec3 &start) {
  Trajectory t;
  t.machine = "test machine";
  t.tolerance = 0.01;
  t.start = start;
  return t;
}

void add(Trajectory &t, const Segment &seg, const Profile &profile, const SegmentInfo &info) {
  t.segments.push_back(seg);
  t.profiles.push_back(profile);
  t.info.push_back(info);
}

/// One feed line along `direction` from the origin, rest to rest, at 250 mm/s.
Trajectory oneLine(const Vec3 &direction, double cruise = 0.5, double feed = kV, const Ramp &ramp = Ramp{}) {
  Trajectory t = empty(Vec3::Zero());
  const double length = restToRestLength(ramp, cruise);
  add(t, Segment::line(Vec3::Zero(), direction.normalized() * length), restToRest(ramp, cruise),
      feedInfo(feed, 0, StopReason::Start));
  return t;
}

size_t count(const SimReport &r, ViolationKind kind, int axis = -2) {
  size_t n = 0;
  for (const Violation &v : r.violations)
    if (v.kind == kind && (axis == -2 || v.axis == axis))
      ++n;
  return n;
}

} // namespace

TEST_CASE("a valid hand-made trajectory plays clean to its exact end", "[player]") {
  const Machine m = testMachine();
  const Trajectory t = oneLine(Vec3(1, 0, 0));
  REQUIRE(t.segments[0].length == 218.75);
  size_t seen = 0;
  double lastT = -1;
  bool monotone = true;
  const SimReport r = simulate(t, m, {}, [&](const Sample &s) {
    ++seen;
    monotone = monotone && s.t > lastT;
    lastT = s.t;
  });
  INFO(formatReport(r, t, m));
  CHECK(r.violationCount == 0);
  CHECK(r.violations.empty());
  CHECK(r.endPosition == t.segments[0].end);  // exactly
  CHECK(seen == r.samples);
  CHECK(monotone);
  CHECK(lastT == r.duration);
  CHECK(r.maxVelocity.x() == Approx(kV).epsilon(1e-12));
  CHECK(r.maxVelocity.y() == 0);
  CHECK(r.maxAcceleration.x() == Approx(1000).epsilon(1e-9));
  CHECK(r.maxJerk.x() == Approx(8000).epsilon(1e-12));
  CHECK(r.maxDeviation == 0);
  CHECK_FALSE(r.deviationChecked);
  // The only segment starts and ends with a stop: its cruise is what counts.
  CHECK(r.minFeedRatio == Approx(1).epsilon(1e-12));
  CHECK(r.slowest.empty());
}

TEST_CASE("time, distance and feed figures follow the profiles", "[player]") {
  const Machine m = testMachine();
  // A rapid down z at 400 mm/s (rest to rest), then a stop and a feed move
  // along x at 250 mm/s.
  Trajectory t = empty(Vec3(0, 0, 50));
  Ramp fast;
  fast.t1 = 0.125;
  fast.t2 = 0.275;  // 8000 * 0.125 * 0.4 = 400 mm/s
  const double rapidLength = restToRestLength(fast, 0.25);
  SegmentInfo rapid;
  rapid.limits = {400, 1000, 8000};
  rapid.stop = StopReason::Start;
  add(t, Segment::line(Vec3(0, 0, 50), Vec3(0, 0, 50 - rapidLength)), restToRest(fast, 0.25), rapid);
  const double feedLength = restToRestLength(Ramp{}, 0.5);
  add(t, Segment::line(Vec3(0, 0, 50 - rapidLength), Vec3(feedLength, 0, 50 - rapidLength)),
      restToRest(Ramp{}, 0.5), feedInfo(kV, 1, StopReason::Program));

  const double rapidTime = 2 * fast.time() + 0.25, feedTime = 2 * Ramp{}.time() + 0.5;
  const SimReport r = simulate(t, m);
  INFO(formatReport(r, t, m));
  CHECK(r.violationCount == 0);
  CHECK(r.duration == Approx(rapidTime + feedTime).epsilon(1e-12));
  CHECK(r.rapidTime == Approx(rapidTime).epsilon(1e-12));
  CHECK(r.feedTime == Approx(1.25).epsilon(1e-12));
  CHECK(r.rapidDistance == Approx(rapidLength).epsilon(1e-12));
  CHECK(r.feedDistance == Approx(218.75).epsilon(1e-12));
  CHECK(r.meanFeed == Approx(218.75 / 1.25).epsilon(1e-12));
  CHECK(r.meanProgrammedFeed == Approx(kV).epsilon(1e-12));
  CHECK(r.maxVelocity.z() == Approx(400).epsilon(1e-9));
  CHECK(r.maxVelocity.x() == Approx(kV).epsilon(1e-9));

  // Below 95 % of the feed only while speeding up and slowing down: on each
  // ramp the speed is within 12.5 mm/s of 250 only in the last (first) jerk
  // phase, for sqrt(2 * 12.5 / 8000) s.
  const double slowPerRamp = Ramp{}.time() - std::sqrt(2 * 12.5 / 8000);
  CHECK(r.slowTime[static_cast<size_t>(SlowReason::Ramp)] == Approx(2 * slowPerRamp).margin(0.002));
  CHECK(r.slowTime[static_cast<size_t>(SlowReason::Cap)] == 0);
  CHECK(r.slowTime[static_cast<size_t>(SlowReason::Short)] == 0);

  const std::string text = formatReport(r, t, m);
  CHECK_THAT(text, Catch::Contains("machine: test machine (cycle 1.000 ms"));
  CHECK_THAT(text, Catch::Contains("cycle time: " + formatFixed(rapidTime + feedTime, 3) + " s (feed moves"));
  CHECK_THAT(text, Catch::Contains("feed moves 1.250 s over 218.8 mm"));
  CHECK_THAT(text, Catch::Contains("mean 10500.0 mm/min of 15000.0 mm/min programmed (70.0 %)"));
  CHECK_THAT(text, Catch::Contains("violations: none"));
  // No exponent notation anywhere: a digit is never followed by an 'e'.
  for (size_t i = 1; i + 1 < text.size(); ++i)
    if (text[i] == 'e' && std::isdigit(static_cast<unsigned char>(text[i - 1])) &&
        (std::isdigit(static_cast<unsigned char>(text[i + 1])) || text[i + 1] == '-' || text[i + 1] == '+'))
      FAIL("exponent in the report at " << i);
}

TEST_CASE("the sample count: every period before the end, plus the end", "[player]") {
  const Machine m = testMachine();
  const Trajectory t = oneLine(Vec3(1, 0, 0));  // 1.25 s
  SimOptions o;
  // A whole number of periods: the last period is the end, floor(D/T) + 1.
  o.period = 0.0625;
  CHECK(simulate(t, m, o).samples == 21);
  // Otherwise floor(D/T) + 2: the periods from 0 and the end itself.
  o.period = 0.003;
  CHECK(simulate(t, m, o).samples == 418);
  // The machine's 1 ms: 1.25 s is 1250 periods to within rounding.
  CHECK(simulate(t, m).samples == 1251);
  // An empty trajectory is one sample at its start, at rest.
  const Trajectory none = empty(Vec3(1, 2, 3));
  const SimReport r = simulate(none, m);
  CHECK(r.samples == 1);
  CHECK(r.duration == 0);
  CHECK(r.violationCount == 0);
  CHECK(r.endPosition == Vec3(1, 2, 3));
}

TEST_CASE("a dwell is played at rest at its point for its time", "[player][dwell]") {
  const Machine m = testMachine();
  // A line along x rest to rest (1.25 s), 0.75 s at its end, and a line
  // back along y (1.25 s).
  Trajectory t = oneLine(Vec3(1, 0, 0));
  const Vec3 corner = t.segments[0].end;
  SegmentInfo wait;
  wait.move = wait.nextMove = 1;
  wait.stop = StopReason::Dwell;
  add(t, Segment::dwell(corner), dwellProfile(0.75), wait);
  const double length = restToRestLength(Ramp{}, 0.5);
  add(t, Segment::line(corner, corner + Vec3(0, length, 0)), restToRest(Ramp{}, 0.5),
      feedInfo(kV, 2, StopReason::Dwell));
  PathInput programmed;
  programmed.moves.push_back({PathMove::Kind::Line, corner});
  PathMove d{PathMove::Kind::Dwell, corner};
  d.dwellS = 0.75;
  programmed.moves.push_back(d);
  programmed.moves.push_back({PathMove::Kind::Line, corner + Vec3(0, length, 0)});
  SimOptions o;
  o.programmed = &programmed;

  size_t waiting = 0, atCorner = 0;
  const SimReport r = simulate(t, m, o, [&](const Sample &s) {
    if (s.segment == 1) {
      ++waiting;
      CHECK(s.p == corner);
      CHECK(s.speed == 0);
      CHECK(s.v == Vec3::Zero());
      CHECK(s.a == Vec3::Zero());
      CHECK(s.j == Vec3::Zero());
    }
    atCorner += s.p == corner;
  });
  const std::string text = formatReport(r, t, m);
  INFO(text);
  CHECK(r.violationCount == 0);
  CHECK(r.maxDeviation < 1e-12);
  CHECK(r.duration == 1.25 + 0.75 + 1.25);
  CHECK(r.dwellTime == 0.75);
  CHECK(r.feedTime == 2.5);
  CHECK(r.rapidTime == 0);
  CHECK(r.feedDistance == 2 * 218.75);
  CHECK(r.samples == 3251);
  // The samples at t = 1.250 s (where the first line ends and the dwell
  // starts) to 1.999 s are the dwell's; at 2.000 s the next line starts
  // from the corner.
  CHECK(waiting == 750);
  CHECK(atCorner == 751);
  CHECK(r.endPosition == t.segments[2].end);
  // Both lines start and end at rest: their cruise is what counts.
  CHECK(r.minFeedRatio == Approx(1).epsilon(1e-12));
  CHECK_THAT(text, Catch::Contains("cycle time: 3.250 s (feed moves 2.500 s over 437.5 mm, rapids 0.000 s over 0.0 "
                                   "mm, dwells 0.750 s)\n"));
}

TEST_CASE("jerk above an axis's limit is reported on that axis", "[player]") {
  const Machine m = testMachine();
  Ramp hard;
  hard.jerk = 32000;  // the machine allows 20000 mm/s^3
  hard.t1 = 0.03125;
  hard.t2 = 0.21875;  // 32000 * 0.03125 * 0.25 = 250 mm/s
  const Trajectory t = oneLine(Vec3(0, 1, 0), 0.5, kV, hard);
  SimOptions o;
  o.maxViolations = 5;
  const SimReport r = simulate(t, m, o);
  INFO(formatReport(r, t, m));
  REQUIRE(r.violationCount > 5);
  CHECK(r.violations.size() == 5);
  CHECK(count(r, ViolationKind::Jerk, 1) == 5);
  CHECK(r.maxJerk.y() == Approx(32000));
  CHECK(r.maxJerk.x() == 0);
  CHECK(r.maxJerk.z() == 0);
  // Nothing but jerk on y, and the list is in time order.
  SimOptions all;
  all.maxViolations = 100000;
  const SimReport full = simulate(t, m, all);
  CHECK(full.violations.size() == full.violationCount);
  CHECK(count(full, ViolationKind::Jerk, 1) == full.violationCount);
  for (size_t i = 1; i < full.violations.size(); ++i)
    CHECK(full.violations[i - 1].t <= full.violations[i].t);
  // At t = 0 there is no neighbour: the analytic jerk alone reports it.
  CHECK(full.violations.front().t == 0);
  CHECK(full.violations.front().value == Approx(32000));
  CHECK(full.violations.front().limit == 20000);
  CHECK_THAT(formatReport(r, t, m), Catch::Contains("axis y: jerk 32000.0 mm/s^3 > 20000.0 mm/s^3"));
}

TEST_CASE("a corner taken at speed is a jump in velocity", "[player]") {
  const Machine m = testMachine();
  // Along x up to 250 mm/s, then straight on along y at that speed: no blend.
  Trajectory t = empty(Vec3::Zero());
  const Ramp ramp;
  const double l0 = ramp.distance(0) + kV * 0.25, l1 = kV * 0.25 + ramp.distance(0);
  add(t, Segment::line(Vec3::Zero(), Vec3(l0, 0, 0)), rise(ramp, 0.25), feedInfo(kV, 0, StopReason::Start));
  add(t, Segment::line(Vec3(l0, 0, 0), Vec3(l0, l1, 0)), fall(ramp, 0.25), feedInfo(kV, 1));
  const double corner = ramp.time() + 0.25;
  const SimReport r = simulate(t, m);
  INFO(formatReport(r, t, m));
  // Each axis changes by 250 mm/s within one period: 250000 mm/s^2.
  REQUIRE(count(r, ViolationKind::Acceleration, 0) == 1);
  REQUIRE(count(r, ViolationKind::Acceleration, 1) == 1);
  CHECK(r.violationCount == 2);
  for (const Violation &v : r.violations) {
    CHECK(v.t == Approx(corner).margin(0.0011));
    CHECK(v.segment == 1);
    CHECK(v.value == Approx(kV / 0.001).epsilon(0.01));
    CHECK(v.limit == 2000);
  }
  CHECK(r.endPosition == Vec3(l0, l1, 0));
}

TEST_CASE("a step in curvature at speed is a jump in acceleration", "[player]") {
  const Machine m = testMachine();
  // Along x at 250 mm/s straight into a quarter circle of radius 100 (same
  // tangent): y acceleration steps from 0 to v^2 / R = 625 mm/s^2.
  Trajectory t = empty(Vec3::Zero());
  const Ramp ramp;
  const double l0 = ramp.distance(0) + kV * 0.25;
  const Vec3 corner(l0, 0, 0);
  const Segment arc = Segment::arc(corner, Vec3(l0 + 100, 100, 0), Vec3(l0, 100, 0), true, std::numbers::pi / 2);
  REQUIRE(arc.length == Approx(50 * std::numbers::pi));
  const double cruise = (arc.length - ramp.distance(0)) / kV;
  add(t, Segment::line(Vec3::Zero(), corner), rise(ramp, 0.25), feedInfo(kV, 0, StopReason::Start));
  add(t, arc, fall(ramp, cruise), feedInfo(kV, 1));
  Vec3 onArc = Vec3::Zero();  // the acceleration at the first sample on the arc
  const SimReport r = simulate(t, m, {}, [&](const Sample &s) {
    if (s.segment == 1 && onArc == Vec3::Zero())
      onArc = s.a;
  });
  INFO(formatReport(r, t, m));
  CHECK(onArc.y() == Approx(625).epsilon(1e-3));
  CHECK(onArc.x() == Approx(0).margin(1));
  CHECK(count(r, ViolationKind::Acceleration) == 0);
  CHECK(count(r, ViolationKind::Velocity) == 0);
  REQUIRE(r.violationCount == 1);
  const Violation &v = r.violations[0];
  CHECK(v.kind == ViolationKind::Jerk);
  CHECK(v.axis == 1);
  CHECK(v.value == Approx(625 / 0.001).epsilon(0.01));
  CHECK(v.t == Approx(ramp.time() + 0.25).margin(0.0011));
  CHECK((r.endPosition - arc.end).norm() < 1e-9);
}

TEST_CASE("speed above the programmed feed is a feed violation", "[player]") {
  const Machine m = testMachine();
  const Trajectory t = oneLine(Vec3(1, 1, 0), 0.5, 200);  // runs at 250 mm/s
  const SimReport r = simulate(t, m);
  INFO(formatReport(r, t, m));
  REQUIRE(r.violationCount > 0);
  CHECK(count(r, ViolationKind::Feed) == r.violations.size());
  CHECK(r.violations[0].axis == -1);
  CHECK(r.violations[0].value > 200);
  CHECK(r.violations[0].limit == 200);
  CHECK_THAT(formatReport(r, t, m), Catch::Contains("above the programmed feed 12000.0 mm/min"));
  // At exactly the feed nothing is reported.
  CHECK(simulate(oneLine(Vec3(1, 1, 0), 0.5, kV), m).violationCount == 0);
}

TEST_CASE("deviation from the programmed path", "[player]") {
  const Machine m = testMachine();
  const Trajectory t = oneLine(Vec3(1, 0, 0));
  PathInput same;
  same.moves.push_back({PathMove::Kind::Line, Vec3(218.75, 0, 0)});
  SimOptions o;
  o.programmed = &same;
  SimReport r = simulate(t, m, o);
  CHECK(r.violationCount == 0);
  CHECK(r.deviationChecked);
  CHECK(r.tolerance == 0.01);  // the trajectory's
  CHECK(r.maxDeviation < 1e-12);

  // The same line 0.05 mm off in y.
  PathInput off;
  off.start = Vec3(0, 0.05, 0);
  off.moves.push_back({PathMove::Kind::Line, Vec3(218.75, 0.05, 0)});
  o.programmed = &off;
  r = simulate(t, m, o);
  INFO(formatReport(r, t, m));
  CHECK(r.maxDeviation == Approx(0.05).epsilon(1e-9));
  CHECK(r.violationCount == r.samples + 1);  // every sample, and the end point
  CHECK(count(r, ViolationKind::Deviation) == r.violations.size());  // the end point comes last
  CHECK(r.violations[0].kind == ViolationKind::Deviation);
  CHECK(r.violations[0].value == Approx(0.05).epsilon(1e-9));
  CHECK_THAT(formatReport(r, t, m), Catch::Contains("contour deviation: max 0.0500 mm (tolerance 0.0100 mm)"));
  // A wider tolerance passes the path, not the end point.
  o.tolerance = 0.06;
  r = simulate(t, m, o);
  CHECK(r.violationCount == 1);
  REQUIRE(r.violations.size() == 1);
  CHECK(r.violations[0].kind == ViolationKind::EndState);
  CHECK(r.violations[0].value == Approx(0.05));
}

TEST_CASE("deviation from programmed arcs and helices", "[player]") {
  const Machine m = testMachine();
  const Ramp ramp;
  auto along = [&](const Segment &seg) {
    Trajectory t = empty(seg.start);
    const double cruise = (seg.length - 2 * ramp.distance(0)) / kV;
    REQUIRE(cruise > 0);
    add(t, seg, restToRest(ramp, cruise), feedInfo(kV, 0, StopReason::Start));
    return t;
  };
  // A quarter circle of radius 100 about the origin, ccw.
  const Trajectory t = along(Segment::arc(Vec3(100, 0, 0), Vec3(0, 100, 0), Vec3::Zero(), true, std::numbers::pi / 2));
  PathInput wider;  // radius 100.02: every sample is exactly 0.02 mm off
  wider.start = Vec3(100.02, 0, 0);
  wider.moves.push_back({PathMove::Kind::Arc, Vec3(0, 100.02, 0), Vec3::Zero(), true});
  SimOptions o;
  o.programmed = &wider;
  o.tolerance = 0.03;
  SimReport r = simulate(t, m, o);
  INFO(formatReport(r, t, m));
  CHECK(r.maxDeviation == Approx(0.02).epsilon(1e-9));
  CHECK(count(r, ViolationKind::Deviation) == 0);
  // Clockwise the same end points are three quarters the other way round.
  wider.moves[0].ccw = false;
  r = simulate(t, m, o);
  CHECK(r.maxDeviation > 50);
  CHECK(count(r, ViolationKind::Deviation) > 0);

  // Two whole turns and a quarter, 10 mm down: the same helix, programmed.
  const double sweep = 2 * 2 * std::numbers::pi + std::numbers::pi / 2;
  const Trajectory h = along(Segment::arc(Vec3(100, 0, 0), Vec3(0, 100, -10), Vec3::Zero(), true, sweep));
  PathInput helix;
  helix.start = Vec3(100, 0, 0);
  helix.moves.push_back({PathMove::Kind::Arc, Vec3(0, 100, -10), Vec3::Zero(), true, 2});
  o.programmed = &helix;
  o.tolerance = 0;
  r = simulate(h, m, o);
  CHECK(r.maxDeviation < 1e-9);
  CHECK(r.violationCount == 0);
  // One turn fewer is a different helix: up to a third of the pitch away.
  helix.moves[0].turns = 1;
  r = simulate(h, m, o);
  CHECK(r.maxDeviation > 1);
  // A whole circle: the end over the start.
  const Trajectory c = along(Segment::arc(Vec3(100, 0, 0), Vec3(100, 0, 0), Vec3::Zero(), true, 2 * std::numbers::pi));
  PathInput circle;
  circle.start = Vec3(100, 0, 0);
  circle.moves.push_back({PathMove::Kind::Arc, Vec3(100, 0, 0), Vec3::Zero(), true});
  o.programmed = &circle;
  r = simulate(c, m, o);
  CHECK(r.maxDeviation < 1e-9);
  CHECK(r.violationCount == 0);
}

TEST_CASE("a trajectory that stops short of its end", "[player]") {
  const Machine m = testMachine();
  // Up to speed and no slowing down: the last sample is still moving.
  Trajectory t = empty(Vec3::Zero());
  const Ramp ramp;
  const double l0 = ramp.distance(0) + kV * 0.25;
  add(t, Segment::line(Vec3::Zero(), Vec3(l0, 0, 0)), rise(ramp, 0.25), feedInfo(kV, 0, StopReason::Start));
  SimReport r = simulate(t, m);
  INFO(formatReport(r, t, m));
  REQUIRE(r.violationCount == 1);
  CHECK(r.violations[0].kind == ViolationKind::EndState);
  CHECK(r.violations[0].axis == 0);
  CHECK(r.violations[0].value == Approx(kV));
  CHECK_THAT(formatReport(r, t, m), Catch::Contains("axis x: not at rest at the end (15000.0 mm/min)"));
  // A profile that covers less than its segment ends short of the end point.
  Trajectory shortOne = oneLine(Vec3(1, 0, 0));
  shortOne.segments[0] = Segment::line(Vec3::Zero(), Vec3(219, 0, 0));
  r = simulate(shortOne, m);
  REQUIRE(r.violationCount == 1);
  CHECK(r.violations[0].kind == ViolationKind::EndState);
  CHECK(r.violations[0].axis == -1);
  CHECK(r.violations[0].value == Approx(0.25));
}

TEST_CASE("slow places and why", "[player]") {
  const Machine m = testMachine();
  // Three feed lines on one straight path, programmed at 300 mm/s: the first
  // and last run up from and down to the stops; the middle one is capped at
  // 250 mm/s by acceleration (its limits say so).
  Trajectory t = empty(Vec3::Zero());
  const Ramp ramp;
  const double l0 = ramp.distance(0) + kV * 0.25;
  SegmentInfo capped = feedInfo(300, 1);
  capped.limits.v = kV;
  capped.limitedBy = SpeedLimit::Acceleration;
  SegmentInfo first = capped, last = capped;
  first.move = first.nextMove = 0;
  first.stop = StopReason::Start;
  last.move = last.nextMove = 2;
  add(t, Segment::line(Vec3::Zero(), Vec3(l0, 0, 0)), rise(ramp, 0.25), first);
  Profile cruise;
  cruise.v0 = kV;
  cruise.phases[3] = {0.5, 0};
  add(t, Segment::line(Vec3(l0, 0, 0), Vec3(l0 + 125, 0, 0)), cruise, capped);
  add(t, Segment::line(Vec3(l0 + 125, 0, 0), Vec3(2 * l0 + 125, 0, 0)), fall(ramp, 0.25), last);
  const SimReport r = simulate(t, m);
  INFO(formatReport(r, t, m));
  CHECK(r.violationCount == 0);
  // 250 of 300 mm/s is below 95 % everywhere: all of it is the cap, since
  // the cap itself is below.
  CHECK(r.slowTime[static_cast<size_t>(SlowReason::Cap)] == Approx(r.duration).margin(0.0011));
  CHECK(r.slowCapTime[static_cast<size_t>(SpeedLimit::Acceleration)] ==
        Approx(r.slowTime[static_cast<size_t>(SlowReason::Cap)]));
  CHECK(r.minFeedRatio == Approx(kV / 300));
  REQUIRE(r.slowest.size() == 3);
  // All three at the same lowest counted speed: in path order.
  CHECK(r.slowest[0].segment == 0);
  CHECK(r.slowest[1].segment == 1);
  CHECK(r.slowest[2].segment == 2);
  CHECK(r.slowest[1].move == 1);
  CHECK(r.slowest[1].speed == Approx(kV));
  CHECK(r.slowest[1].feed == 300);
  CHECK(r.slowest[1].reason == SlowReason::Cap);
  CHECK(r.slowest[1].limitedBy == SpeedLimit::Acceleration);
  SimOptions few;
  few.maxSlowSpots = 1;
  CHECK(simulate(t, m, few).slowest.size() == 1);
  const std::string text = formatReport(r, t, m, [](uint32_t move) { return "@step" + std::to_string(move); });
  CHECK_THAT(text, Catch::Contains("slowest places:\n  @step0 (segment 0): 15000.0 mm/min of 18000.0 mm/min (83.3 %), capped by"));
  CHECK_THAT(text, Catch::Contains("below 95 % of the programmed feed: 1.750 s"));
}

TEST_CASE("a planned rectangle plays without violations", "[player]") {
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  std::unique_ptr<SourceFile> file;
  const std::optional<Machine> m = loadMachine("hsc-3axis", file, diags);
  REQUIRE(m);
  PathInput in;
  in.start = Vec3(10, 10, -5);
  for (const Vec3 &to : {Vec3(110, 10, -5), Vec3(110, 60, -5), Vec3(10, 60, -5), Vec3(10, 10, -5)}) {
    PathMove move;
    move.to = to;
    move.feed = 1800;
    in.moves.push_back(move);
  }
  const Trajectory t = plan(in, *m);
  SimOptions o;
  o.programmed = &in;
  const SimReport r = simulate(t, *m, o);
  const std::string text = formatReport(r, t, *m);
  INFO(text);
  CHECK(r.violationCount == 0);
  CHECK((r.endPosition - Vec3(10, 10, -5)).norm() < 1e-9);
  CHECK(r.feedDistance == Approx(300).margin(0.1));  // blends cut the corners a little
  CHECK(r.meanFeed < 30);
  CHECK(r.maxDeviation <= t.tolerance);
  CHECK_THAT(text, Catch::Contains("violations: none"));
}

TEST_CASE("travel on an xyz machine is what the kinematics' path gives", "[player][travel]") {
  // The xyz machine's own check (the position is the axes') against the
  // general one: a table-table machine with the same x, y, z and its rotary
  // axes at 0 maps each position through its kinematics to the same x, y, z.
  const Machine five = test::shippedMachine("table-table-5axis");
  REQUIRE(five.axes.size() == 5);
  Machine xyz = five;
  xyz.kinematics = {};
  xyz.kinematics.chain = Chain::Xyz;
  xyz.axes.resize(3);
  // A path that goes out of x's and z's travel and back (x travels 0..500,
  // z -400..0, with the origin at the offsets below), twice, and spans
  // more x than the travel.
  PathInput in;
  in.start = Vec3(0, 0, 0);
  for (const Vec3 &to :
       {Vec3(-20, 0, 0), Vec3(300, 10, -20), Vec3(-30, 20, 30), Vec3(520, 30, -50), Vec3(100, 40, 10)}) {
    PathMove move;
    move.to = to;
    move.feed = 6000;
    in.moves.push_back(move);
  }
  const Trajectory t = plan(in, xyz);
  const std::optional<Vec3> offsets[] = {std::nullopt, Vec3(10, 100, -20), Vec3(200, 100, -200), Vec3(-5, 0, 0)};
  for (const std::optional<Vec3> &offset : offsets) {
    INFO("offset " << (offset ? formatTuple({offset->x(), offset->y(), offset->z()}, 1) : "none"));
    SimOptions o;
    o.workOffsetMm = offset;
    o.maxViolations = 1000;
    const SimReport a = simulate(t, xyz, o), b = simulate(t, five, o);
    INFO(formatReport(a, t, xyz));
    CHECK(a.travelNotChecked.empty());
    CHECK(b.travelNotChecked.empty());
    REQUIRE(a.axisMin.size() == 3);
    for (size_t k = 0; k < 3; ++k) {
      CHECK(a.axisMin[k] == Approx(b.axisMin[k]).margin(1e-9));
      CHECK(a.axisMax[k] == Approx(b.axisMax[k]).margin(1e-9));
    }
    std::vector<Violation> travel;
    for (const Violation &v : b.violations)
      if (v.kind == ViolationKind::Travel || v.kind == ViolationKind::Extent)
        travel.push_back(v);
    REQUIRE(a.violations.size() == travel.size());
    CHECK(a.violationCount == travel.size());
    for (size_t i = 0; i < travel.size(); ++i) {
      CHECK(a.violations[i].kind == travel[i].kind);
      CHECK(a.violations[i].axis == travel[i].axis);
      CHECK(a.violations[i].t == travel[i].t);
      CHECK(a.violations[i].value == Approx(travel[i].value).margin(1e-9));
      CHECK(a.violations[i].limit == travel[i].limit);
    }
  }
}

// Each limit the player checks, at 1 % either side of it: a trajectory that
// asks 1.01 times the limit is a violation of that kind, one that asks 0.99
// times it is clean.
TEST_CASE("the player's limits hold at 1 % either side", "[player]") {
  const Machine m = testMachine();  // 500 mm/s, 2000 mm/s^2, 20000 mm/s^3 per axis
  auto play = [&](const Trajectory &t, const SimOptions &o = {}) {
    const SimReport r = simulate(t, m, o);
    INFO(formatReport(r, t, m));
    return r;
  };
  for (const double f : {1.01, 0.99}) {
    INFO("the limit times " << f);
    const size_t expected = f > 1 ? 1 : 0;
    {
      // Jerk: the ramp's jerk at f x 20000, up to 250 mm/s.
      Ramp r;
      r.jerk = 20000 * f;
      r.t1 = 0.05;
      r.t2 = 250 / (r.jerk * r.t1) - r.t1;
      const SimReport rep = play(oneLine(Vec3(0, 1, 0), 0.5, kV, r));
      CHECK(std::min<size_t>(count(rep, ViolationKind::Jerk, 1), 1) == expected);
      CHECK(rep.violations.size() == count(rep, ViolationKind::Jerk, 1));
    }
    {
      // Acceleration: the ramp's plateau at f x 2000, up to 450 mm/s.
      Ramp r;
      r.jerk = 16000;
      r.t1 = 2000 * f / r.jerk;
      r.t2 = 450 / (r.jerk * r.t1) - r.t1;
      const SimReport rep = play(oneLine(Vec3(1, 0, 0), 0.5, 450, r));
      CHECK(std::min<size_t>(count(rep, ViolationKind::Acceleration, 0), 1) == expected);
      CHECK(rep.violations.size() == count(rep, ViolationKind::Acceleration, 0));
    }
    {
      // Velocity: cruising at f x 500 mm/s, programmed so.
      Ramp r;
      r.jerk = 16000;
      r.t1 = 0.1;
      r.t2 = 500 * f / (r.jerk * r.t1) - r.t1;
      const SimReport rep = play(oneLine(Vec3(0, 0, 1), 0.5, 500 * f, r));
      CHECK(std::min<size_t>(count(rep, ViolationKind::Velocity, 2), 1) == expected);
      CHECK(rep.violations.size() == count(rep, ViolationKind::Velocity, 2));
    }
    {
      // Deviation: the programmed line f x 0.01 mm beside the played one.
      const Trajectory t = oneLine(Vec3(1, 0, 0));
      PathInput off;
      off.start = Vec3(0, 0.01 * f, 0);
      off.moves.push_back({PathMove::Kind::Line, Vec3(218.75, 0.01 * f, 0)});
      SimOptions o;
      o.programmed = &off;
      const SimReport rep = play(t, o);
      CHECK(std::min<size_t>(count(rep, ViolationKind::Deviation), 1) == expected);
    }
  }
}
