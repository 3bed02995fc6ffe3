#include "runtime/Profile.h"

#include <algorithm>
#include <cmath>

namespace stepnc::runtime {

double Profile::duration() const {
  double t = 0;
  for (const Phase &ph : phases)
    t += ph.duration;
  return t;
}

PathState Profile::at(double t) const {
  PathState st{0, v0, a0, 0};
  if (t <= 0) {
    st.j = phases[0].jerk;
    return st;
  }
  for (const Phase &ph : phases) {
    if (ph.duration <= 0)
      continue;
    const double d = std::min(t, ph.duration);
    st.s += st.v * d + st.a * d * d / 2 + ph.jerk * d * d * d / 6;
    st.v += st.a * d + ph.jerk * d * d / 2;
    st.a += ph.jerk * d;
    st.j = ph.jerk;
    t -= d;
    if (t <= 0)
      return st;
  }
  st.j = 0;
  return st;
}

double Profile::v1() const {
  double v = v0, a = a0;
  for (const Phase &ph : phases) {
    v += a * ph.duration + ph.jerk * ph.duration * ph.duration / 2;
    a += ph.jerk * ph.duration;
  }
  return v;
}

double Profile::peak() const {
  // Speed is extreme at the phase boundaries or where the acceleration
  // passes zero inside a phase (slices of a run may start mid-phase).
  double v = v0, a = a0, best = v0;
  for (const Phase &ph : phases) {
    if (ph.jerk != 0) {
      const double t = -a / ph.jerk;
      if (t > 0 && t < ph.duration)
        best = std::max(best, v + a * t + ph.jerk * t * t / 2);
    }
    v += a * ph.duration + ph.jerk * ph.duration * ph.duration / 2;
    a += ph.jerk * ph.duration;
    best = std::max(best, v);
  }
  return best;
}

double Profile::a1() const {
  double a = a0;
  for (const Phase &ph : phases)
    a += ph.jerk * ph.duration;
  return a;
}

double Profile::timeAt(double target) const {
  double t = 0, s = 0, v = v0, a = a0;
  for (const Phase &ph : phases) {
    const double d = ph.duration, j = ph.jerk;
    if (d <= 0)
      continue;
    const double sEnd = s + v * d + a * d * d / 2 + j * d * d * d / 6;
    if (target <= sEnd) {
      // s is non-decreasing here: Newton inside a shrinking bracket, until
      // the bracket or Newton's step is below 1e-15 of the time (Newton
      // converges from one side, where the bracket would shrink from that
      // side alone: by bisection, in many more steps).
      const double resolution = 1e-15 * (t + d);
      double lo = 0, hi = d, x = v > 0 ? std::min(d, (target - s) / v) : d / 2;
      for (int it = 0; it < 100 && hi - lo > resolution; ++it) {
        const double f = s + v * x + a * x * x / 2 + j * x * x * x / 6 - target;
        if (f < 0)
          lo = x;
        else
          hi = x;
        const double df = v + a * x + j * x * x / 2;
        if (f == 0)
          break;
        const double next = df > 0 ? x - f / df : (lo + hi) / 2;
        if (!(next > lo && next < hi)) {
          x = (lo + hi) / 2;
          continue;
        }
        const bool converged = std::abs(next - x) <= resolution;
        x = next;
        if (converged)
          break;
      }
      return t + x;
    }
    s = sEnd;
    v += a * d + j * d * d / 2;
    a += j * d;
    t += d;
  }
  return t;
}

Profile Profile::slice(double t0, double t1) const {
  const PathState start = at(t0);
  Profile out;
  out.v0 = start.v;
  out.a0 = start.a;
  double begin = 0;
  size_t k = 0;
  for (const Phase &ph : phases) {
    const double end = begin + ph.duration;
    const double from = std::max(begin, t0), to = std::min(end, t1);
    if (to > from && k < out.phases.size())
      out.phases[k++] = {to - from, ph.jerk};
    begin = end;
  }
  return out;
}

double rampTime(double dv, double a, double j) {
  if (dv <= 0)
    return 0;
  return dv >= a * a / j ? dv / a + a / j : 2 * std::sqrt(dv / j);
}

double rampDistance(double v0, double v1, double a, double j) {
  return (v0 + v1) / 2 * rampTime(std::abs(v1 - v0), a, j);
}

double reachableSpeed(double v0, double length, double a, double j) {
  if (length <= 0)
    return v0;
  const double dvFull = a * a / j;  // the change at which acceleration first reaches a
  if (rampDistance(v0, v0 + dvFull, a, j) >= length) {
    // (2 v0 + dv) sqrt(dv / j) = L: with x = sqrt(dv), x^3 + p x - q = 0,
    // p = 2 v0 >= 0, q = L sqrt(j): one real root. Cardano's x = A + B with
    // A = cbrt(q/2 + sqrt(q^2/4 + p^3/27)) and B = -p / (3 A) loses digits
    // to cancellation where p is large; written as
    // (A^3 + B^3) / (A^2 - A B + B^2) = q / (A^2 + p/3 + (p / (3 A))^2)
    // every term is positive. (One cube root, where the hyperbolic form
    // needs an inverse hyperbolic sine and a hyperbolic sine.)
    const double p = 2 * v0, q = length * std::sqrt(j);
    double x;
    if (p <= 0) {
      x = std::cbrt(q);
    } else {
      const double big = std::cbrt(q / 2 + std::sqrt(q * q / 4 + p * p * p / 27)), small = p / (3 * big);
      if (std::isfinite(big))
        x = q / (big * big + p / 3 + small * small);
      else  // p^3 or q^2 beyond a double: the hyperbolic form
        x = 2 * std::sqrt(p / 3) * std::sinh(std::asinh(1.5 * q / p * std::sqrt(3 / p)) / 3);
    }
    x -= (x * x * x + p * x - q) / (3 * x * x + p);  // one Newton step polishes rounding
    return v0 + std::max(0.0, x * x);
  }
  // (2 v0 + dv)(dv / a + a / j) = 2 L: dv^2 / a + b dv + c = 0.
  const double b = 2 * v0 / a + a / j, c = 2 * v0 * a / j - 2 * length;
  const double dv = -2 * c / (b + std::sqrt(b * b - 4 * c / a));
  return v0 + std::max(0.0, dv);
}

namespace {

/// Phases of a speed change from v0 to v1 with zero end accelerations,
/// written to phases[first..first+2].
void rampPhases(std::array<Phase, 7> &phases, int first, double v0, double v1, double a, double j) {
  const double dv = std::abs(v1 - v0);
  const double sign = v1 >= v0 ? 1 : -1;
  if (dv <= 0)
    return;
  double t1, t2;
  if (dv >= a * a / j) {
    t1 = a / j;
    t2 = dv / a - a / j;
  } else {
    t1 = std::sqrt(dv / j);
    t2 = 0;
  }
  phases[first] = {t1, sign * j};
  phases[first + 1] = {t2, 0};
  phases[first + 2] = {t1, -sign * j};
}

} // namespace

Profile planProfile(double v0, double v1, double length, const PathLimits &limits) {
  const double a = limits.a, j = limits.j;
  Profile prof;
  prof.v0 = v0;
  if (length <= 0)
    return prof;
  const double low = std::max(v0, v1);
  auto distance = [&](double vp) { return rampDistance(v0, vp, a, j) + rampDistance(vp, v1, a, j); };
  double vp = std::max(low, limits.v);
  if (distance(vp) > length) {
    // Highest peak whose rise and fall fit: distance(vp) grows with vp.
    // Newton inside a shrinking bracket; `lo` always fits, so the cruise
    // below makes up any remainder and the length is exact. The distance
    // and its slope d/dx both come from each ramp's time T(|x - v|),
    // computed once per side: rampDistance's (v + x)/2 T, and
    // T/2 + (v + x)/2 dT/dx where x > v (0 elsewhere).
    //
    // Newton converges from one side wherever the distance is convex or
    // concave near the peak, so only that side of the bracket moves; it
    // stops once its step falls below kConverged of the speed, from a point
    // that fits. Converged from above, it steps kConverged / 4 below the
    // root to find one. The peak is then within kConverged of the exact
    // one, finer than the bracket's 1e-12 (which bisection still ensures
    // where Newton fails), in far fewer steps than shrinking the bracket.
    const double dvFull = a * a / j;
    // One side's T as rampTime gives it, and its distance's slope; below a
    // full ramp T = 2 sqrt(dv / j) and dT/dx = 1 / (j sqrt(dv / j)): one
    // square root for both.
    auto ramp = [&](double v, double x, double &time, double &slope) {
      const double dv = std::abs(x - v);
      time = slope = 0;
      if (dv <= 0)
        return;
      double dT;
      if (dv >= dvFull) {
        time = dv / a + a / j;
        dT = 1 / a;
      } else {
        const double root = std::sqrt(dv / j);
        time = 2 * root;
        dT = 1 / (j * root);
      }
      if (x > v)
        slope = time / 2 + (v + x) / 2 * dT;
    };
    constexpr double kConverged = 4e-14;
    double lo = low, hi = std::min(vp, reachableSpeed(std::min(v0, v1), length, a, j));
    double x = hi;
    for (int it = 0; it < 60 && hi - lo > 1e-12 * hi; ++it) {
      double rise, riseSlope, fall, fallSlope;
      ramp(v0, x, rise, riseSlope);
      ramp(v1, x, fall, fallSlope);
      const double f = ((v0 + x) / 2 * rise + (x + v1) / 2 * fall) - length;
      if (f <= 0)
        lo = x;
      else
        hi = x;
      const double df = riseSlope + fallSlope;
      double step = f / df;  // not finite where df is 0: bisection below
      if (std::abs(step) <= kConverged * x) {
        if (f <= 0)
          break;
        step += kConverged / 4 * x;
      }
      double next = x - step;
      if (!(next > lo && next < hi))
        next = (lo + hi) / 2;
      x = next;
    }
    vp = lo;
  }
  rampPhases(prof.phases, 0, v0, vp, a, j);
  rampPhases(prof.phases, 4, vp, v1, a, j);
  const double cruise = length - distance(vp);
  if (vp > 0 && cruise > 1e-12 * vp)  // below that, rounding of the ramps' distances
    prof.phases[3] = {cruise / vp, 0};
  return prof;
}

Profile dwellProfile(double timeS) {
  Profile p;
  p.phases[3] = {timeS, 0};
  return p;
}

} // namespace stepnc::runtime
