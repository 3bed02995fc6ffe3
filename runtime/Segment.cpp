#include "runtime/Segment.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>


namespace stepnc::runtime {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Five-point Gauss–Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 5> kGaussX{0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640,
                                        0.9061798459386640};
constexpr std::array<double, 5> kGaussW{0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                                        0.2369268850561891, 0.2369268850561891};

} // namespace

double QuinticCurve::length(double u0, double u1) const {
  const double h = (u1 - u0) / 2, m = (u0 + u1) / 2;
  double sum = 0;
  for (size_t i = 0; i < kGaussX.size(); ++i)
    sum += kGaussW[i] * speed(m + h * kGaussX[i]);
  return sum * h;
}

namespace {

/// Derivatives with respect to arc length from those with respect to u.
PathPoint fromParameter(const Vec3 &p, const Vec3 &d1, const Vec3 &d2, const Vec3 &d3) {
  PathPoint out;
  out.p = p;
  const double q = d1.norm();
  if (q <= 0)
    return out;
  const double q2 = q * q, q4 = q2 * q2;
  const double d12 = d1.dot(d2);
  const double qu = d12 / q;
  out.r1 = d1 / q;
  out.r2 = d2 / q2 - d1 * (d12 / q4);
  const Vec3 first = d3 / q2 - d2 * (2 * qu / (q2 * q));
  const Vec3 second = d2 * (d12 / q4) + d1 * ((d2.squaredNorm() + d1.dot(d3)) / q4) - d1 * (4 * d12 * qu / (q4 * q));
  out.r3 = (first - second) / q;
  return out;
}

} // namespace

namespace {

/// Whether the curve keeps its z (every power coefficient but the first has
/// z = 0): its derivatives then have z = 0 exactly, and the work on z can be
/// left out without changing a bit of the results.
bool inPlaneZ(const QuinticCurve &q) {
  return q.c[1].z() == 0 && q.c[2].z() == 0 && q.c[3].z() == 0 && q.c[4].z() == 0 && q.c[5].z() == 0;
}

/// The arc-length table of a blend: five-point Gauss-Legendre on each of the
/// kBlendTable intervals, as QuinticCurve::length computes it (same points,
/// same operations in the same order, so the same bits), all 40 speeds in
/// one loop that the compiler evaluates two or (in the AVX clone) four at a
/// time. D = 2 leaves out z when it is zero.
template <int D>
[[gnu::always_inline]] inline void blendArcTable(const QuinticCurve &q,
                                                 std::array<double, Segment::kBlendTable + 1> &table) {
  constexpr size_t kIntervals = Segment::kBlendTable, kNodes = kGaussX.size(), kPoints = kNodes * kIntervals;
  // u of node i in interval j at i * kIntervals + j, computed as
  // QuinticCurve::length computes it.
  static const std::array<double, kPoints> u = [] {
    std::array<double, kPoints> out{};
    for (size_t i = 0; i < kNodes; ++i)
      for (size_t j = 0; j < kIntervals; ++j) {
        const double u0 = double(j) / kIntervals, u1 = double(j + 1) / kIntervals;
        out[i * kIntervals + j] = (u0 + u1) / 2 + (u1 - u0) / 2 * kGaussX[i];
      }
    return out;
  }();
  double a[D][5];
  for (int k = 0; k < D; ++k) {
    a[k][0] = q.c[1][k], a[k][1] = 2 * q.c[2][k], a[k][2] = 3 * q.c[3][k], a[k][3] = 4 * q.c[4][k];
    a[k][4] = 5 * q.c[5][k];
  }
  std::array<double, kPoints> speed;
  for (size_t p = 0; p < kPoints; ++p) {
    const double t = u[p];
    double squared = 0;
    for (int k = 0; k < D; ++k) {
      const double d1 = (((a[k][4] * t + a[k][3]) * t + a[k][2]) * t + a[k][1]) * t + a[k][0];
      squared = k == 0 ? d1 * d1 : squared + d1 * d1;
    }
    speed[p] = std::sqrt(squared);  // as many at a time as the version's vectors hold (no errno: CMakeLists.txt)
  }
  table[0] = 0;
  for (size_t j = 0; j < kIntervals; ++j) {
    double sum = 0;
    for (size_t i = 0; i < kNodes; ++i)
      sum += kGaussW[i] * speed[i * kIntervals + j];
    table[j + 1] = table[j] + sum * (0.5 / kIntervals);
  }
}

/// Two, four or eight doubles in the compiler's generic vectors: one SSE2,
/// AVX or AVX-512 register. The kernels below take eight at a time in their
/// versions for processors with AVX-512, four with AVX and two elsewhere,
/// with the same IEEE operations on each element (no fused multiply-add:
/// AVX-512 has it, and the build turns contraction off on x86-64 for that),
/// so that all give the same bits.
using Pair = double __attribute__((vector_size(16)));
using Quad = double __attribute__((vector_size(32)));
using Oct = double __attribute__((vector_size(64)));
/// Their bits, as integers.
using PairBits = int64_t __attribute__((vector_size(16)));
using QuadBits = int64_t __attribute__((vector_size(32)));
using OctBits = int64_t __attribute__((vector_size(64)));

/// m = max(m, x) element by element, as std::max gives it.
template <class V>
[[gnu::always_inline]] inline void raise(V &m, const V &x) {
  m = m < x ? x : m;
}

/// m = max(m, |x|) element by element, as std::max and std::abs give them
/// (|x| by clearing the sign bit).
template <class V>
[[gnu::always_inline]] inline void raiseToAbs(V &m, const V &x) {
  using Bits = std::conditional_t<sizeof(V) == sizeof(Pair), PairBits,
                                  std::conditional_t<sizeof(V) == sizeof(Quad), QuadBits, OctBits>>;
  constexpr int64_t kMagnitude = std::numeric_limits<int64_t>::max();
  const V a = V(Bits(x) & kMagnitude);
  m = m < a ? a : m;
}

/// The blend's largest |r1|, |r2|, |r3| per axis over the samples u = i / 32,
/// i = 0..32, as many samples at a time as V holds (the last group takes
/// u = 1 again). D = 2 leaves out z when it is zero.
///
/// fromParameter's formulas, rearranged so that a sample needs one division
/// and no square root: with q = |d1|, b = d12 / q^2 and
/// g = (d22 + d13) / q^2 - 4 b^2,
///   r1 = d1 / q,  r2 = (d2 - b d1) / q^2,  r3 = (d3 - 3 b d2 - g d1) / q^3,
/// so r1^2 and r3^2 need only 1 / q^2; their largest values' square roots
/// are taken once at the end (the root is monotone, so that is the largest
/// root). The results agree with fromParameter's to rounding; where q = 0
/// fromParameter gives zeros, and so do these with 1/q^2 := 0.
template <int D, class V>
[[gnu::always_inline]] inline void sampleBlendDemand(const QuinticCurve &q, AxisDemand &d) {
  static constexpr int kSamples = 32, kLanes = sizeof(V) / sizeof(double), kGroups = kSamples / kLanes + 1;
  static constexpr std::array<double, kLanes * kGroups> ts = [] {
    std::array<double, kLanes * kGroups> out{};
    for (int i = 0; i < kLanes * kGroups; ++i)
      out[i] = double(std::min(i, kSamples)) / kSamples;
    return out;
  }();
  // Derivatives' coefficients in u.
  double a1[D][5], a2[D][4], a3[D][3];
  for (int k = 0; k < D; ++k) {
    a1[k][0] = q.c[1][k], a1[k][1] = 2 * q.c[2][k], a1[k][2] = 3 * q.c[3][k], a1[k][3] = 4 * q.c[4][k];
    a1[k][4] = 5 * q.c[5][k];
    a2[k][0] = 2 * q.c[2][k], a2[k][1] = 6 * q.c[3][k], a2[k][2] = 12 * q.c[4][k], a2[k][3] = 20 * q.c[5][k];
    a3[k][0] = 6 * q.c[3][k], a3[k][1] = 24 * q.c[4][k], a3[k][2] = 60 * q.c[5][k];
  }
  const V zero{};
  V m1[D], m2[D], m3[D];  // the largest r1^2, |r2| and r3^2
  for (int k = 0; k < D; ++k)
    m1[k] = m2[k] = m3[k] = zero;
  for (int i = 0; i < kGroups; ++i) {
    V t;
    std::memcpy(&t, &ts[kLanes * i], sizeof t);
    V d1[D], d2[D], d3[D];
    V q2 = zero, d12 = zero, d22 = zero, d13 = zero;
    for (int k = 0; k < D; ++k) {
      d1[k] = (((a1[k][4] * t + a1[k][3]) * t + a1[k][2]) * t + a1[k][1]) * t + a1[k][0];
      d2[k] = ((a2[k][3] * t + a2[k][2]) * t + a2[k][1]) * t + a2[k][0];
      d3[k] = (a3[k][2] * t + a3[k][1]) * t + a3[k][0];
      q2 += d1[k] * d1[k];
      d12 += d1[k] * d2[k];
      d22 += d2[k] * d2[k];
      d13 += d1[k] * d3[k];
    }
    const V iq2 = q2 > 0 ? 1 / q2 : zero;
    const V b = d12 * iq2, g = (d22 + d13) * iq2 - 4 * b * b, iq6 = iq2 * iq2 * iq2;
    for (int k = 0; k < D; ++k) {
      raise(m1[k], d1[k] * d1[k] * iq2);
      raiseToAbs(m2[k], (d2[k] - b * d1[k]) * iq2);
      const V r3q3 = d3[k] - 3 * b * d2[k] - g * d1[k];
      raise(m3[k], r3q3 * r3q3 * iq6);
    }
  }
  // All lanes hold values >= +0 and no NaN (a NaN never raises m): their
  // largest, whatever the order.
  for (int k = 0; k < D; ++k) {
    d.r1[k] = d.r2[k] = d.r3[k] = 0;
    for (int l = 0; l < kLanes; ++l) {
      d.r1[k] = std::max(d.r1[k], m1[k][l]);
      d.r2[k] = std::max(d.r2[k], m2[k][l]);
      d.r3[k] = std::max(d.r3[k], m3[k][l]);
    }
    d.r1[k] = std::sqrt(d.r1[k]);
    d.r3[k] = std::sqrt(d.r3[k]);
  }
}

// The blend kernels in three versions on x86-64 (GCC's function
// multiversioning picks one when the program starts): for processors with
// AVX-512 (preferring its full width where the compiler vectorizes loops),
// with AVX, and for the rest. Clang (the fuzz build) takes the one version:
// it has no "prefer-vector-width" target attribute.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__ELF__)
#define STEPNC_MULTIVERSIONED 1
#endif

#if STEPNC_MULTIVERSIONED
__attribute__((target("default")))
#endif
void blendArcTable(const QuinticCurve &q, std::array<double, Segment::kBlendTable + 1> &table) {
  if (inPlaneZ(q))
    blendArcTable<2>(q, table);
  else
    blendArcTable<3>(q, table);
}

#if STEPNC_MULTIVERSIONED
__attribute__((target("default")))
#endif
void sampleBlendDemand(const QuinticCurve &q, AxisDemand &d) {
  if (inPlaneZ(q))
    sampleBlendDemand<2, Pair>(q, d);
  else
    sampleBlendDemand<3, Pair>(q, d);
}

#if STEPNC_MULTIVERSIONED
__attribute__((target("avx"))) void blendArcTable(const QuinticCurve &q,
                                                  std::array<double, Segment::kBlendTable + 1> &table) {
  if (inPlaneZ(q))
    blendArcTable<2>(q, table);
  else
    blendArcTable<3>(q, table);
}

__attribute__((target("avx"))) void sampleBlendDemand(const QuinticCurve &q, AxisDemand &d) {
  if (inPlaneZ(q))
    sampleBlendDemand<2, Quad>(q, d);
  else
    sampleBlendDemand<3, Quad>(q, d);
}

__attribute__((target("avx512f,prefer-vector-width=512"))) void
blendArcTable(const QuinticCurve &q, std::array<double, Segment::kBlendTable + 1> &table) {
  if (inPlaneZ(q))
    blendArcTable<2>(q, table);
  else
    blendArcTable<3>(q, table);
}

__attribute__((target("avx512f,prefer-vector-width=512"))) void sampleBlendDemand(const QuinticCurve &q,
                                                                                  AxisDemand &d) {
  if (inPlaneZ(q))
    sampleBlendDemand<2, Oct>(q, d);
  else
    sampleBlendDemand<3, Oct>(q, d);
}
#endif

} // namespace

Segment Segment::line(const Vec3 &from, const Vec3 &to) {
  Segment s;
  s.kind = SegmentKind::Line;
  s.start = from;
  s.end = to;
  s.length = (to - from).norm();
  return s;
}

namespace {

/// An arc's sweep and the length it gives (the rise per radian from its ends).
void setSweep(Segment &s, double sweep) {
  s.sweep = sweep;
  const double rise = sweep > 0 ? (s.end.z() - s.start.z()) / sweep : 0;
  s.length = sweep * std::sqrt(s.radius * s.radius + rise * rise);
}

} // namespace

Segment Segment::arc(const Vec3 &from, const Vec3 &to, const Vec3 &center, bool ccw, double sweep) {
  Segment s;
  s.kind = SegmentKind::Arc;
  s.start = from;
  s.end = to;
  s.ccw = ccw;
  Eigen::Vector2d f = from.head<2>(), t = to.head<2>(), c = center.head<2>();
  const Eigen::Vector2d chord = t - f;
  if (chord.norm() > 1e-9) {
    // The nearest point to the given centre that is equally far from both
    // ends: printed centres are rounded, the arc must still end at `to`.
    // Only a rounding's worth: a nearly closed arc whose ends differ in
    // radius would otherwise collapse onto its short chord.
    const Eigen::Vector2d mid = (f + t) / 2;
    const Eigen::Vector2d n = Eigen::Vector2d(-chord.y(), chord.x()).normalized();
    const Eigen::Vector2d moved = mid + n * n.dot(c - mid);
    if ((moved - c).norm() <= 1e-3)
      c = moved;
  }
  s.center = Vec3(c.x(), c.y(), 0);
  s.radius = (f - c).norm();
  s.startAngle = std::atan2(f.y() - c.y(), f.x() - c.x());
  setSweep(s, sweep);
  return s;
}

Segment Segment::arcTurns(const Vec3 &from, const Vec3 &to, const Vec3 &center, bool ccw, int64_t turns) {
  Segment s = arc(from, to, center, ccw, 0);
  const double endAngle = std::atan2(to.y() - s.center.y(), to.x() - s.center.x());
  double d = ccw ? endAngle - s.startAngle : s.startAngle - endAngle;
  d = std::fmod(d, 2 * kPi);
  if (d < 0)
    d += 2 * kPi;
  if ((to.head<2>() - from.head<2>()).norm() <= 1e-9)
    d = 2 * kPi;  // over the start: the last arc is a whole turn
  // The centre, radius and start angle do not depend on the sweep.
  setSweep(s, d + 2 * kPi * double(std::max<int64_t>(turns, 0)));
  return s;
}

GreatCircle::GreatCircle(const Vec3 &u, const Vec3 &w) : u_(u), w_(w) {
  if (u == w)
    return;
  const Vec3 off = w - u * u.dot(w);  // w's part across u
  angle_ = std::atan2(off.norm(), u.dot(w));
  if (off.norm() > 1e-12) {
    across_ = off.normalized();
  } else if (u.dot(w) < 0) {
    // Opposite: any great circle joins them; the one through the
    // coordinate axis least along u.
    Eigen::Index least = 0;
    u.cwiseAbs().minCoeff(&least);
    across_ = (Vec3::Unit(least) - u * u[least]).normalized();
  } else {
    angle_ = 0;  // equal to rounding
  }
  // w in the plane's terms (cos, sin of the angle), as at(1) is w.
  if (angle_ > 0) {
    cos_ = w.dot(u);
    sin_ = w.dot(across_);
  }
}

double GreatCircle::nearestCosine(const Vec3 &v) const {
  // v . at(a) = v.u cos a + v.across sin a: (cu, ca) is the nearest point
  // of the circle's plane to v; it or its opposite lies on the arc when it
  // is at most angle_ round from u (the arc turns at most half a circle: on
  // the side of u towards w, and not past w). Elsewhere the ends are the
  // nearest.
  const double cu = v.dot(u_), ca = v.dot(across_);
  double best = std::max(std::abs(cu), std::abs(v.dot(w_)));
  if (angle_ > 0) {
    const double sign = ca < 0 ? -1 : 1;
    if (sign * (cu * sin_ - ca * cos_) >= 0)
      best = std::max(best, std::hypot(cu, ca));
  }
  return std::min(best, 1.0);
}

Vec3 Segment::axisRateAt(double s) const {
  if (!(length > 0))
    return Vec3::Zero();
  const double t = fraction(s);
  if (!axisCubic())
    return GreatCircle(axis0, axis1).tangent(t) / length;
  // d/dt of c / |c| is the part of c' across c, over |c|.
  const double t2 = t * t;
  const Vec3 c = cubicPoint(t);
  const Vec3 d = (6 * t2 - 6 * t) * axis0 + (3 * t2 - 4 * t + 1) * axisRate0 + (6 * t - 6 * t2) * axis1 +
                 (3 * t2 - 2 * t) * axisRate1;
  const double n = c.norm();
  const Vec3 u = c / n;
  return (d - u * u.dot(d)) / (n * length);
}

Segment::AxisEnds Segment::axisEnds(const GreatCircle *circle) const {
  AxisEnds e;
  if (!(length > 0)) {
    e.rate0 = e.rate1 = e.curve0 = e.curve1 = Vec3::Zero();
    return e;
  }
  const double perLength = 1 / length;
  if (!axisCubic()) {
    if (!circle) {
      const GreatCircle own(axis0, axis1);
      return axisEnds(&own);
    }
    const GreatCircle &c = *circle;
    e.rate0 = c.tangent(0) * perLength;
    e.rate1 = c.tangent(1) * perLength;
    const double rate = c.angle() * perLength;
    e.curve0 = -rate * rate * axis0;
    e.curve1 = -rate * rate * axis1;
    return e;
  }
  // u = c / |c|, n = |c|: u' = (c' - u n') / n and u'' = (c'' - 2 u' n' -
  // u n'') / n, with n' = u . c' and n'' = u' . c' + u . c'' (derivatives in
  // the fraction). At the ends n = 1 (the axes are unit).
  const Vec3 second0 = -6 * axis0 - 4 * axisRate0 + 6 * axis1 - 2 * axisRate1;
  const Vec3 second1 = 6 * axis0 + 2 * axisRate0 - 6 * axis1 + 4 * axisRate1;
  auto rateAt = [](const Vec3 &u, const Vec3 &d1) { return Vec3(d1 - u * u.dot(d1)); };
  const Vec3 u10 = rateAt(axis0, axisRate0), u11 = rateAt(axis1, axisRate1);
  const double n10 = axis0.dot(axisRate0), n11 = axis1.dot(axisRate1);
  e.rate0 = u10 * perLength;
  e.rate1 = u11 * perLength;
  e.curve0 = (second0 - 2 * u10 * n10 - axis0 * (u10.dot(axisRate0) + axis0.dot(second0))) * perLength * perLength;
  e.curve1 = (second1 - 2 * u11 * n11 - axis1 * (u11.dot(axisRate1) + axis1.dot(second1))) * perLength * perLength;
  return e;
}

Segment Segment::part(double s0, double s1) const {
  s0 = std::clamp(s0, 0.0, length);
  s1 = std::clamp(s1, s0, length);
  if (s0 <= 0 && s1 >= length)
    return *this;
  // The part's axes at its ends; a cubic's rates there, per unit of the
  // part's fraction (the part then follows a cubic of its own, within the
  // cubic's change of curvature of the whole's).
  auto axesOf = [&](Segment &out) {
    if (axisCubic()) {
      out.axis0 = axisAt(s0);
      out.axis1 = axisAt(s1);
      out.axisRate0 = axisRateAt(s0) * (s1 - s0);
      out.axisRate1 = axisRateAt(s1) * (s1 - s0);
    } else {
      const GreatCircle circle(axis0, axis1);
      out.axis0 = axisAt(s0, circle);
      out.axis1 = axisAt(s1, circle);
    }
  };
  if (kind == SegmentKind::Line) {
    Segment out = line(at(s0).p, at(s1).p);
    axesOf(out);
    return out;
  }
  Segment out = *this;
  axesOf(out);
  if (kind == SegmentKind::Arc) {
    const double rise = sweep > 0 ? (end.z() - start.z()) / sweep : 0;
    const double k = std::sqrt(radius * radius + rise * rise);
    out.start = at(s0).p;
    out.end = at(s1).p;
    out.startAngle = startAngle + (ccw ? 1 : -1) * s0 / k;
    out.sweep = (s1 - s0) / k;
    out.length = s1 - s0;
  }
  return out;
}

namespace {

/// A blend's bounds from its 33 samples, with the margin for what lies
/// between them.
AxisDemand blendDemand(const QuinticCurve &q) {
  // Sampled densely in u; a quintic's derivatives vary smoothly, and the
  // margin covers what lies between samples.
  AxisDemand d;
  sampleBlendDemand(q, d);
  constexpr double kMargin = 1.1;
  d.r1 = (d.r1 * kMargin).cwiseMin(Vec3::Ones());
  d.r2 *= kMargin;
  d.r3 *= kMargin;
  return d;
}

} // namespace

Segment Segment::blend(const std::array<Vec3, 6> &ctrl) {
  Segment s;
  s.kind = SegmentKind::Blend;
  s.ctrl = ctrl;
  s.start = ctrl[0];
  s.end = ctrl[5];
  blendArcTable(QuinticCurve(ctrl), s.arcTable);
  s.length = s.arcTable[kBlendTable];
  return s;
}

Segment Segment::blend(const std::array<Vec3, 6> &ctrl, AxisDemand &demand) {
  Segment s;
  s.kind = SegmentKind::Blend;
  s.ctrl = ctrl;
  s.start = ctrl[0];
  s.end = ctrl[5];
  const QuinticCurve q(ctrl);
  blendArcTable(q, s.arcTable);
  s.length = s.arcTable[kBlendTable];
  demand = blendDemand(q);
  return s;
}

Segment Segment::dwell(const Vec3 &at) {
  Segment s;
  s.kind = SegmentKind::Dwell;
  s.start = at;
  s.end = at;
  return s;
}

double Segment::blendParameter(const QuinticCurve &q, double s) const {
  // The table interval holding s, then Newton on the arc length within it.
  int i = int(std::upper_bound(arcTable.begin(), arcTable.end(), s) - arcTable.begin()) - 1;
  i = std::clamp(i, 0, kBlendTable - 1);
  const double u0 = double(i) / kBlendTable, u1 = double(i + 1) / kBlendTable;
  const double span = arcTable[i + 1] - arcTable[i];
  double u = span > 0 ? u0 + (u1 - u0) * (s - arcTable[i]) / span : u0;
  for (int it = 0; it < 4; ++it) {
    const double g = arcTable[i] + q.length(u0, u) - s;
    const double sp = q.speed(u);
    if (sp <= 0)
      break;
    u = std::clamp(u - g / sp, u0, u1);
    if (std::abs(g) < 1e-13)
      break;
  }
  return u;
}

Vec3 Segment::curvePointAt(double s) const {
  if (kind != SegmentKind::Blend)
    return curveAt(s).p;
  s = std::clamp(s, 0.0, length);
  if (s >= length)
    return end;
  const QuinticCurve q(ctrl);
  if (s <= 0)
    return q.point(0);  // what the inversion gives there, without it
  return q.point(blendParameter(q, s));
}

PathPoint Segment::atStart() const {
  if (kind != SegmentKind::Blend)
    return at(0);
  const QuinticCurve q(ctrl);
  return fromParameter(start, q.d1(0), q.d2(0), q.d3(0));
}

PathPoint Segment::atEnd() const {
  if (kind != SegmentKind::Blend)
    return at(length);
  const QuinticCurve q(ctrl);
  return fromParameter(end, q.d1(1), q.d2(1), q.d3(1));
}

PathPoint Segment::curveAt(double s) const {
  s = std::clamp(s, 0.0, length);
  switch (kind) {
  case SegmentKind::Line:
    return at(s);
  case SegmentKind::Arc: {
    const double rise = sweep > 0 ? (end.z() - start.z()) / sweep : 0;  // mm per radian
    const double k = std::sqrt(radius * radius + rise * rise);         // mm per radian along the path
    const double theta = k > 0 ? s / k : 0;
    const double sigma = ccw ? 1 : -1;
    const double phi = startAngle + sigma * theta;
    const double c = std::cos(phi), sn = std::sin(phi);
    PathPoint out;
    out.p = s >= length ? end : Vec3(center.x() + radius * c, center.y() + radius * sn, start.z() + rise * theta);
    if (k > 0) {
      out.r1 = Vec3(-radius * sn * sigma / k, radius * c * sigma / k, rise / k);
      out.r2 = Vec3(-radius * c / (k * k), -radius * sn / (k * k), 0);
      out.r3 = Vec3(radius * sn * sigma / (k * k * k), -radius * c * sigma / (k * k * k), 0);
    }
    return out;
  }
  case SegmentKind::Blend: {
    const QuinticCurve q(ctrl);
    const double u = blendParameter(q, s);
    PathPoint out = fromParameter(q.point(u), q.d1(u), q.d2(u), q.d3(u));
    if (s >= length)
      out.p = end;
    return out;
  }
  case SegmentKind::Dwell: {
    PathPoint out;
    out.p = start;  // at rest: no tangent, no curvature
    return out;
  }
  }
  return {};
}

AxisDemand Segment::demand() const {
  AxisDemand d;
  switch (kind) {
  case SegmentKind::Line:
    if (length > 0)
      d.r1 = ((end - start) / length).cwiseAbs();
    break;
  case SegmentKind::Arc: {
    const double rise = sweep > 0 ? (end.z() - start.z()) / sweep : 0;
    const double k = std::sqrt(radius * radius + rise * rise);
    if (k > 0) {
      d.r1 = Vec3(radius / k, radius / k, std::abs(rise) / k);
      d.r2 = Vec3(radius / (k * k), radius / (k * k), 0);
      d.r3 = Vec3(radius / (k * k * k), radius / (k * k * k), 0);
    }
    break;
  }
  case SegmentKind::Blend:
    d = blendDemand(QuinticCurve(ctrl));
    break;
  case SegmentKind::Dwell:
    break;  // nothing moves
  }
  return d;
}

} // namespace stepnc::runtime
