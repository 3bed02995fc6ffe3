// Jerk-limited profiles: the closed forms agree with the profiles built from
// them, profiles cover exactly their length, keep within their limits and
// end with zero acceleration.
#include "runtime/Profile.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

using namespace stepnc::runtime;

namespace {

/// Integrates a profile's phases by small steps (not its closed form) and
/// checks speed, acceleration and jerk against the limits on the way.
struct Walk {
  double s = 0, v = 0, a = 0, maxV = 0, maxA = 0, maxJ = 0;
};
Walk integrate(const Profile &p) {
  Walk w;
  w.v = p.v0;
  w.maxV = p.v0;
  for (const Phase &ph : p.phases) {
    const int steps = 2000;
    const double h = ph.duration / steps;
    for (int i = 0; i < steps; ++i) {
      w.s += w.v * h + w.a * h * h / 2 + ph.jerk * h * h * h / 6;
      w.v += w.a * h + ph.jerk * h * h / 2;
      w.a += ph.jerk * h;
      w.maxV = std::max(w.maxV, w.v);
      w.maxA = std::max(w.maxA, std::abs(w.a));
    }
    if (ph.duration > 0)
      w.maxJ = std::max(w.maxJ, std::abs(ph.jerk));
  }
  return w;
}

} // namespace

TEST_CASE("ramp time and distance follow the closed forms", "[profile]") {
  // dv below a^2/j: the acceleration never reaches a.
  CHECK(rampTime(100, 6000, 80000) == Approx(2 * std::sqrt(100.0 / 80000)));
  // dv above: dv/a + a/j.
  CHECK(rampTime(1000, 6000, 80000) == Approx(1000.0 / 6000 + 6000.0 / 80000));
  CHECK(rampDistance(0, 1000, 6000, 80000) == Approx(500 * (1000.0 / 6000 + 6000.0 / 80000)));
  CHECK(rampDistance(1000, 0, 6000, 80000) == Approx(rampDistance(0, 1000, 6000, 80000)));
  CHECK(rampTime(0, 6000, 80000) == 0);
}

TEST_CASE("reachable speed inverts the ramp distance in both regimes", "[profile]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> v0s(0, 500), lengths(1e-4, 300);
  for (int i = 0; i < 2000; ++i) {
    const double v0 = v0s(rng), length = lengths(rng);
    const double v1 = reachableSpeed(v0, length, 6000, 80000);
    REQUIRE(v1 >= v0);
    CHECK(rampDistance(v0, v1, 6000, 80000) == Approx(length).epsilon(1e-9));
  }
}

TEST_CASE("reachable speed keeps its digits where the start speed dwarfs the change", "[profile]") {
  // Short lengths from high speeds: the change is tiny beside v0 (the
  // cubic's p large beside q^(2/3)), where Cardano's form as usually
  // written cancels. Log-uniform over many decades; checked on the change
  // itself, not on v1, whose digits v0 would hide.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> decades(-9, 4);
  for (int i = 0; i < 20000; ++i) {
    const double v0 = i % 10 == 0 ? 0 : std::pow(10.0, decades(rng)), length = std::pow(10.0, decades(rng));
    const double a = std::pow(10.0, 2 + decades(rng) / 4), j = std::pow(10.0, 4 + decades(rng) / 4);
    const double v1 = reachableSpeed(v0, length, a, j);
    REQUIRE(v1 >= v0);
    const double dv = v1 - v0;
    // The ramp of dv covers the length: (v0 + dv/2) T(dv) = L, to 1e-12
    // and to what rounding v1 to a double (a few units of v1's last place
    // in dv) does to the distance, through its slope in dv.
    const double time = rampTime(dv, a, j);
    const double covered = (v0 + dv / 2) * time;
    const double slope = time / 2 + (v0 + dv / 2) * (dv >= a * a / j ? 1 / a : 1 / std::sqrt(j * dv));
    const double rounding = 4 * std::numeric_limits<double>::epsilon() * v1 * slope;
    CHECK(std::abs(covered - length) <= 1e-12 * length + rounding);
  }
}

namespace {

/// A profile the planner could ask for: a length of 1e-3 to 200 mm, a speed
/// limit of 1 to 500 mm/s, and end speeds the look-ahead could hand over
/// (reachable from each other).
struct ProfileCase {
  double length = 0, v0 = 0, v1 = 0;
  PathLimits limits;
};
ProfileCase randomProfileCase(std::mt19937 &rng, double a, double j) {
  std::uniform_real_distribution<double> lengths(1e-3, 200), unit(0, 1), limitsV(1, 500);
  ProfileCase c;
  c.length = lengths(rng);
  c.limits = {limitsV(rng), a, j};
  c.v0 = unit(rng) * c.limits.v;
  c.v1 = std::min(unit(rng) * c.limits.v, reachableSpeed(c.v0, c.length, a, j));
  c.v0 = std::min(c.v0, reachableSpeed(c.v1, c.length, a, j));
  return c;
}

} // namespace

TEST_CASE("profiles cover their length, keep their limits and end at rest acceleration", "[profile]") {
  std::mt19937 rng(11);
  const double a = 6000, j = 80000;
  for (int i = 0; i < 300; ++i) {
    const auto [length, v0, v1, limits] = randomProfileCase(rng, a, j);
    const Profile p = planProfile(v0, v1, length, limits);
    const Walk w = integrate(p);
    INFO("v0 " << v0 << " v1 " << v1 << " length " << length << " vmax " << limits.v);
    CHECK(w.s == Approx(length).epsilon(1e-6));
    CHECK(p.at(p.duration()).s == Approx(length).epsilon(1e-9));
    CHECK(p.v1() == Approx(v1).margin(1e-6));
    CHECK(std::abs(p.at(p.duration()).a) < 1e-6);
    CHECK(w.maxV <= limits.v * (1 + 1e-9) + 1e-9);
    CHECK(w.maxA <= a * (1 + 1e-9));
    CHECK(w.maxJ <= j * (1 + 1e-12));
  }
}

TEST_CASE("a long profile cruises at its speed limit", "[profile]") {
  const Profile p = planProfile(0, 0, 300, {50, 6000, 80000});
  CHECK(p.peak() == Approx(50));
  // Rise and fall each take 2 sqrt(50 / 80000) s over 50 * sqrt(50 / 80000) mm.
  const double ramp = 2 * std::sqrt(50.0 / 80000);
  CHECK(p.duration() == Approx(2 * ramp + (300 - 50 * ramp) / 50).epsilon(1e-12));
}

TEST_CASE("a profile too short to cruise peaks at the highest speed that fits", "[profile]") {
  // Its rise and fall fit in the length, and at a peak higher by 1e-12 they
  // would not: the root finder is at least as fine as its bracket.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> lengths(1e-4, 20), speeds(0, 300);
  const double a = 6000, j = 80000;
  auto distance = [&](double v0, double vp, double v1) { return rampDistance(v0, vp, a, j) + rampDistance(vp, v1, a, j); };
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    const double length = lengths(rng);
    double v0 = speeds(rng);
    double v1 = std::min(speeds(rng), reachableSpeed(v0, length, a, j));
    v0 = std::min(v0, reachableSpeed(v1, length, a, j));
    const PathLimits limits{1e4, a, j};
    const double peak = planProfile(v0, v1, length, limits).peak();
    // Peaks at an end speed are where the ends are only just reachable
    // from each other (reachableSpeed's own rounding decides).
    if (peak <= std::max(v0, v1) * (1 + 1e-9) || peak >= limits.v)
      continue;
    INFO("v0 " << v0 << " v1 " << v1 << " length " << length << " peak " << peak);
    CHECK(distance(v0, peak, v1) <= length * (1 + 1e-13));
    CHECK(distance(v0, peak * (1 + 1e-12), v1) > length);
    ++checked;
  }
  CHECK(checked > 1000);
}

TEST_CASE("timeAt finds the time a distance is covered, in profiles and their slices", "[profile]") {
  // The planner cuts a run's profile where its segments end: timeAt must
  // give the time at which the profile has covered each distance, to a
  // rounding of the clock, wherever the root lies (ramps, cruises,
  // slices that start with an acceleration).
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(0, 1);
  const double a = 6000, j = 80000;
  int checked = 0;
  for (int i = 0; i < 300; ++i) {
    const auto [length, v0, v1, limits] = randomProfileCase(rng, a, j);
    const Profile whole = planProfile(v0, v1, length, limits);
    // A slice from a random time: it starts with the whole's acceleration.
    const double t0 = unit(rng) * whole.duration() / 2;
    for (const Profile &p : {whole, whole.slice(t0, whole.duration())}) {
      const double total = p.at(p.duration()).s;
      double last = 0;
      for (int k = 0; k <= 40; ++k) {
        const double s = total * k / 40;
        const double t = p.timeAt(s);
        INFO("profile " << i << " s " << s << " of " << total << " t " << t << " of " << p.duration());
        REQUIRE(t >= last);
        REQUIRE(t <= p.duration());
        // The distance at t: s within the distance the speed there covers
        // in a few units of the clock's last place.
        const PathState st = p.at(t);
        const double clockRounding = 8 * std::numeric_limits<double>::epsilon() * p.duration();
        CHECK(std::abs(st.s - s) <= 1e-12 * total + (st.v + std::abs(st.a) * p.duration()) * clockRounding + 1e-15);
        last = t;
        ++checked;
      }
    }
  }
  CHECK(checked == 300 * 2 * 41);
}
