// The geometry of motion segments: straight lines, circular arcs and helices
// about an axis parallel to z, quintic blends that join two pieces with
// continuous tangent and curvature, and dwells, where the tool waits at one
// point (no length; the wait is its profile's duration). A segment is parametrised by arc length s
// in [0, length]; `at` gives the point and its first three derivatives with
// respect to s (unit tangent, curvature vector, and its rate of change), from
// which the player turns a path speed profile into axis velocities,
// accelerations and jerks:
//   v = s' r1,  a = s'' r1 + s'^2 r2,  j = s''' r1 + 3 s' s'' r2 + s'^3 r3.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

namespace stepnc::runtime {

using Vec3 = Eigen::Vector3d;

/// Dwell: the tool at rest at `start` (= `end`, length 0) for as long as the
/// segment's profile lasts (dwellProfile, Profile.h).
enum class SegmentKind : uint8_t { Line, Arc, Blend, Dwell };

/// A point of a path and its derivatives with respect to arc length.
struct PathPoint {
  Vec3 p = Vec3::Zero();   ///< mm
  Vec3 r1 = Vec3::Zero();  ///< unit tangent
  Vec3 r2 = Vec3::Zero();  ///< curvature vector, 1/mm
  Vec3 r3 = Vec3::Zero();  ///< d r2 / ds, 1/mm^2
};

/// Per-axis bounds of |r1|, |r2|, |r3| over a segment: what its speed and
/// acceleration demand of each axis.
struct AxisDemand {
  Vec3 r1 = Vec3::Zero();
  Vec3 r2 = Vec3::Zero();
  Vec3 r3 = Vec3::Zero();
  /// On a segment that tilts the tool (5-axis), r1..r3 are the machine's
  /// linear joints' and these its rotary joints', in Machine::axes order
  /// after x, y, z: deg per mm of the tip's path, and its derivatives.
  std::array<double, 3> rotary1{}, rotary2{}, rotary3{};
};

/// The great circle from unit vector u to unit vector w, turned along at an
/// even rate: the tool axis between two poses (the toolpath IR's rule).
/// Built once for the many points of one segment; opposite vectors turn
/// through the axis of x, y, z least along u.
class GreatCircle {
public:
  GreatCircle(const Vec3 &u, const Vec3 &w);
  /// The point a fraction t (0..1) of the way: u at 0 and w at 1 exactly.
  Vec3 at(double t) const {
    if (t <= 0 || angle_ == 0)
      return u_;
    if (t >= 1)
      return w_;
    const double a = t * angle_;
    return (u_ * std::cos(a) + across_ * std::sin(a)).normalized();
  }
  /// The direction's rate at t (0..1) per unit of t: at(t)'s derivative,
  /// perpendicular to it, of length angle().
  Vec3 tangent(double t) const {
    if (t <= 0)
      return angle_ * across_;
    if (t >= 1)
      return angle_ * (across_ * cos_ - u_ * sin_);
    const double a = t * angle_;
    return angle_ * (across_ * std::cos(a) - u_ * std::sin(a));
  }
  /// The angle turned from u to w (rad).
  double angle() const { return angle_; }
  /// The largest |v . at(t)| over t in 0..1 for a unit vector v: how near
  /// the arc comes to v or -v (its cosine).
  double nearestCosine(const Vec3 &v) const;

private:
  Vec3 u_, w_;
  Vec3 across_ = Vec3::Zero();  ///< unit, in the plane of u and w, across u towards w
  double angle_ = 0;            ///< rad from u to w; 0 when they are equal
  double cos_ = 1, sin_ = 0;    ///< of angle_
};

/// A unit vector read back from a file: as written when it is unit to
/// rounding (so that it reads back bit for bit), else scaled to unit length.
inline Vec3 unitAsWritten(const Vec3 &v) {
  return std::abs(v.squaredNorm() - 1) <= 8 * std::numeric_limits<double>::epsilon() ? v : Vec3(v.normalized());
}

/// The tool axis a fraction t (0..1) of the way from unit vector u to w.
inline Vec3 axisBetween(const Vec3 &u, const Vec3 &w, double t) { return GreatCircle(u, w).at(t); }

/// A quintic Bezier curve (the blends) in power form: B(u) = sum c[k] u^k.
struct QuinticCurve {
  std::array<Vec3, 6> c;

  explicit QuinticCurve(const std::array<Vec3, 6> &p) {
    c[0] = p[0];
    c[1] = 5 * (p[1] - p[0]);
    c[2] = 10 * (p[2] - 2 * p[1] + p[0]);
    c[3] = 10 * (p[3] - 3 * p[2] + 3 * p[1] - p[0]);
    c[4] = 5 * (p[4] - 4 * p[3] + 6 * p[2] - 4 * p[1] + p[0]);
    c[5] = p[5] - 5 * p[4] + 10 * p[3] - 10 * p[2] + 5 * p[1] - p[0];
  }
  Vec3 point(double u) const { return ((((c[5] * u + c[4]) * u + c[3]) * u + c[2]) * u + c[1]) * u + c[0]; }
  Vec3 d1(double u) const { return (((5 * c[5] * u + 4 * c[4]) * u + 3 * c[3]) * u + 2 * c[2]) * u + c[1]; }
  Vec3 d2(double u) const { return ((20 * c[5] * u + 12 * c[4]) * u + 6 * c[3]) * u + 2 * c[2]; }
  Vec3 d3(double u) const { return (60 * c[5] * u + 24 * c[4]) * u + 6 * c[3]; }
  double speed(double u) const { return d1(u).norm(); }
  /// Arc length from u0 to u1 (five-point Gauss–Legendre).
  double length(double u0, double u1) const;
};

struct Segment {
  SegmentKind kind = SegmentKind::Line;
  Vec3 start = Vec3::Zero();
  Vec3 end = Vec3::Zero();
  double length = 0;  ///< mm, along the path

  // Arc (helix): the axis is parallel to z through `center` (its z unused);
  // the arc turns `sweep` radians (> 0, whole turns included) from
  // `startAngle`, counter-clockwise seen from +z when `ccw`, while z goes
  // from start.z() to end.z() in proportion.
  Vec3 center = Vec3::Zero();
  double radius = 0;
  double startAngle = 0;
  double sweep = 0;
  bool ccw = true;

  // The tool axis (a unit vector from the tip towards the spindle) at the
  // start and at the end, turning evenly along the segment (axisBetween by
  // the fraction of its length); +z on a 3-axis path.
  Vec3 axis0 = Vec3::UnitZ();
  Vec3 axis1 = Vec3::UnitZ();
  // Where the planner smooths the orientation across a junction (the tool
  // turning on at the rate it had): the axis's derivative per unit of the
  // fraction at the start and at the end, the axis then the cubic
  // (Hermite) between axis0 and axis1 with these derivatives, scaled to
  // unit length. Both zero (the default): evenly on the great circle.
  Vec3 axisRate0 = Vec3::Zero();
  Vec3 axisRate1 = Vec3::Zero();
  bool tilted() const { return axis0 != Vec3::UnitZ() || axis1 != Vec3::UnitZ(); }
  /// Whether the axis follows the cubic (axisRate0, axisRate1).
  bool axisCubic() const { return !axisRate0.isZero(0) || !axisRate1.isZero(0); }
  /// The tool axis at arc length s.
  Vec3 axisAt(double s) const {
    if (!(length > 0))
      return axis1;
    return axisCubic() ? cubicAxis(fraction(s)) : axisBetween(axis0, axis1, fraction(s));
  }
  /// The same with `circle` = GreatCircle(axis0, axis1) found once by the
  /// caller (several points of one segment).
  Vec3 axisAt(double s, const GreatCircle &circle) const {
    if (!(length > 0))
      return axis1;
    return axisCubic() ? cubicAxis(fraction(s)) : circle.at(fraction(s));
  }
  /// The tool axis's derivative with respect to arc length at s (per mm).
  Vec3 axisRateAt(double s) const;
  /// It and the second derivative (per mm^2) at the two ends, in closed
  /// form (the planner asks for them at every segment): `circle`, when
  /// given, is GreatCircle(axis0, axis1).
  struct AxisEnds {
    Vec3 rate0, rate1;    ///< per mm
    Vec3 curve0, curve1;  ///< per mm^2
  };
  AxisEnds axisEnds(const GreatCircle *circle = nullptr) const;
  /// Blends: the curve's parameter at arc length s.
  double blendParameter(const QuinticCurve &q, double s) const;
  /// How far along the segment arc length s is, 0..1 (axisAt's fraction).
  double fraction(double s) const { return std::clamp(s / length, 0.0, 1.0); }

  // Blend: a quintic Bezier curve; ctrl[0] = start, ctrl[5] = end.
  std::array<Vec3, 6> ctrl{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  /// Blends: arc length at u = i / kBlendTable, for the s -> u inversion.
  static constexpr int kBlendTable = 8;
  std::array<double, kBlendTable + 1> arcTable{};

  static Segment line(const Vec3 &from, const Vec3 &to);
  /// An arc from `from` about the axis through `center` to `to`, turning
  /// `sweep` radians. The centre is moved onto the bisector of from and to
  /// (when they differ in the plane) so that the arc passes through both.
  static Segment arc(const Vec3 &from, const Vec3 &to, const Vec3 &center, bool ccw, double sweep);
  /// The same, with the sweep made of `turns` whole turns and the angle from
  /// `from` to `to` (a whole turn when they are over each other), measured
  /// about the moved centre.
  static Segment arcTurns(const Vec3 &from, const Vec3 &to, const Vec3 &center, bool ccw, int64_t turns);
  static Segment blend(const std::array<Vec3, 6> &ctrl);
  /// The same, with its demand() written to `demand` (the same bits), both
  /// from one evaluation of the curve's power form.
  static Segment blend(const std::array<Vec3, 6> &ctrl, AxisDemand &demand);
  /// A dwell at `at`: no length; every point is `at`, every derivative 0.
  static Segment dwell(const Vec3 &at);
  /// The part of this segment from arc length s0 to s1 (a line, arc or blend
  /// of the same curve; blends and dwells only whole).
  Segment part(double s0, double s1) const;

  /// The point at arc length s (clamped to [0, length]); `at(length).p` is
  /// exactly `end`. Lines here, where the compiler can inline them (the
  /// planner asks for many line points), the others in curveAt.
  PathPoint at(double s) const {
    if (kind != SegmentKind::Line)
      return curveAt(s);
    s = std::clamp(s, 0.0, length);
    PathPoint out;
    if (length > 0)
      out.r1 = (end - start) / length;
    out.p = s >= length ? end : Vec3(start + out.r1 * s);
    return out;
  }
  /// at(0) and at(length): a blend's from its curve's ends, without
  /// inverting its arc length.
  PathPoint atStart() const;
  PathPoint atEnd() const;
  /// at() for arcs, blends and dwells.
  PathPoint curveAt(double s) const;
  /// at(s).p for arcs, blends and dwells.
  Vec3 curvePointAt(double s) const;
  /// at(s).p alone, without the derivatives (the same bits).
  Vec3 pointAt(double s) const { return kind == SegmentKind::Line ? at(s).p : curvePointAt(s); }
  /// Upper bounds of the derivatives per axis over the whole segment.
  AxisDemand demand() const;

private:
  /// The cubic between axis0 and axis1 at fraction t, before and after
  /// scaling to unit length.
  Vec3 cubicPoint(double t) const {
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * axis0 + (t3 - 2 * t2 + t) * axisRate0 + (3 * t2 - 2 * t3) * axis1 +
           (t3 - t2) * axisRate1;
  }
  Vec3 cubicAxis(double t) const {
    if (t <= 0)
      return axis0;
    if (t >= 1)
      return axis1;
    return cubicPoint(t).normalized();
  }
};

} // namespace stepnc::runtime
