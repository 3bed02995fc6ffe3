#include "runtime/Planner.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace stepnc::runtime {

namespace {

using Mat3 = Eigen::Matrix3d;

constexpr double kInf = std::numeric_limits<double>::infinity();

// How an axis's budget is shared on a curved segment (REFERENCES: v <=
// sqrt(a rho), (j rho^2)^(1/3)). At the speed cap the curvature may take
// kCurveAccel of an axis's acceleration and kCurveJerk of its jerk; the
// coupling term 3 v a r2 at most kCouplingJerk. What is left is the path's
// own acceleration and jerk, so that speed can still change on the segment.
constexpr double kCurveAccel = 0.8;
constexpr double kCurveJerk = 0.6;
constexpr double kCouplingJerk = 0.2;
/// Joint units per mm (and per mm^2): a jump of a joint's rate at a junction
/// below this is the finite differences' noise, not a kink.
constexpr double kJointKink = 1e-6;
/// mm or deg: joints that must move further than this with the tip still
/// turn first (a dwell); less is the inverse kinematics' rounding.
constexpr double kJointTurn = 1e-6;

/// Turning more than this (radians) is a reversal: the tool stops.
constexpr double kReversal = 179.0 * std::numbers::pi / 180.0;
/// What is left of a piece between its blends makes a segment when longer than this (mm).
constexpr double kKeptMiddle = 1e-9;
/// Blends shorter than this (mm on each side) are not made; the tool stops.
constexpr double kTinyBlend = 1e-6;
/// Share of the tolerance blends use; sampled deviations may miss a little.
constexpr double kToleranceShare = 0.9;
/// Segments whose caps differ by more than this factor are not one run.
constexpr double kRunCapSpread = 0.8;

/// A programmed move with any length, as the planner keeps it: its line or
/// arc without the fields a Segment has for blends (control points, arc-length
/// table) and without its ends, which are the programmed points
/// (`segment()` makes the same Segment again), so that the planner's working
/// copy of a long program stays small.
struct Piece {
  double length = 0;  ///< mm
  double centerX = 0, centerY = 0, radius = 0, startAngle = 0, sweep = 0;  ///< arcs, as in Segment
  double feed = 0;  ///< mm/s; 0 for rapids
  double cutStart = 0, cutEnd = 0;  ///< mm taken by blends at either end
  /// Whether something is left between the blends: a segment of its own
  /// (the test step 3 writes segments by).
  bool keepsMiddle() const { return (length - cutEnd) - cutStart > kKeptMiddle; }
  /// A line wholly taken by the blends at its ends, inside a chain of short
  /// lines: the curvature the two blends share at its middle (see
  /// smoothChains), when hasMidCurvature.
  Vec3 midCurvature = Vec3::Zero();
  uint32_t move = 0;
  SegmentKind kind = SegmentKind::Line;
  bool ccw = true;
  bool stopBefore = false;
  bool hasMidCurvature = false;
  /// How it meets the piece before it (join): through a blend, or at rest
  /// for `stopReason`; neither when tangent and curvature already agree.
  bool blendBefore = false;
  StopReason stopReason = StopReason::None;
  /// The blend before it as join made it (ends of zero curvature on lines):
  /// at most this far from the two pieces at blendDeviation's samples
  /// (mm), for smoothChains' bound.
  double joinDeviation = 0;

  Piece(const Segment &s, uint32_t moveIndex)
      : length(s.length), centerX(s.center.x()), centerY(s.center.y()), radius(s.radius), startAngle(s.startAngle),
        sweep(s.sweep), move(moveIndex), kind(s.kind), ccw(s.ccw) {}

  /// Where the move starts: where the one before it ends (moves of no
  /// length, which make no piece, included).
  const Vec3 &from(const PathInput &input) const { return move == 0 ? input.start : input.moves[move - 1].to; }
  const Vec3 &to(const PathInput &input) const { return input.moves[move].to; }

  /// The move's segment, as Segment::line or Segment::arcTurns made it,
  /// written into s (whose blend fields stay as they are: the steps below
  /// reuse two segments instead of making and copying one per piece).
  void segment(const PathInput &input, Segment &s) const {
    s.kind = kind;
    s.start = from(input);
    s.end = to(input);
    s.length = length;
    s.center = Vec3(centerX, centerY, 0);
    s.radius = radius;
    s.startAngle = startAngle;
    s.sweep = sweep;
    s.ccw = ccw;
    s.axis0 = move == 0 ? input.startAxis : input.moves[move - 1].axis;
    s.axis1 = input.moves[move].axis;
  }
};

/// A dwell between pieces: the tool stops before piece `beforePiece` (or at
/// the end, after the last) and waits at programmed move `move`'s point.
struct PieceDwell {
  size_t beforePiece = 0;
  uint32_t move = 0;
  double timeS = 0;
};

/// The points at which blendDeviation samples a blend: u = i / 24 for
/// i = 1..23, and the last again (an even count, for the compiler's pairs).
constexpr int kDeviationSamples = 24;
struct DeviationPoints {
  std::array<double, kDeviationSamples> x, y, z;

  /// The blend's points, as QuinticCurve::point gives them (the same
  /// operations on each coordinate), a coordinate at a time so that the
  /// compiler evaluates two points at once.
  [[gnu::always_inline]] explicit DeviationPoints(const std::array<Vec3, 6> &ctrl) {
    static constexpr std::array<double, kDeviationSamples> u = [] {
      std::array<double, kDeviationSamples> out{};
      for (int i = 0; i < kDeviationSamples; ++i)
        out[i] = double(std::min(i + 1, kDeviationSamples - 1)) / kDeviationSamples;
      return out;
    }();
    const QuinticCurve curve(ctrl);
    std::array<double, kDeviationSamples> *coordinates[3] = {&x, &y, &z};
    // A curve that keeps its z (every coefficient but the first has z = 0)
    // gives c[0].z() at every u (up to the sign of a zero, which no squared
    // distance below sees).
    const bool inPlane = curve.c[1].z() == 0 && curve.c[2].z() == 0 && curve.c[3].z() == 0 &&
                         curve.c[4].z() == 0 && curve.c[5].z() == 0;
    if (inPlane)
      z.fill(curve.c[0].z());
    for (int k = 0; k < (inPlane ? 2 : 3); ++k) {
      const double c0 = curve.c[0][k], c1 = curve.c[1][k], c2 = curve.c[2][k], c3 = curve.c[3][k],
                   c4 = curve.c[4][k], c5 = curve.c[5][k];
      std::array<double, kDeviationSamples> &out = *coordinates[k];
      for (int i = 0; i < kDeviationSamples; ++i)
        out[i] = ((((c5 * u[i] + c4) * u[i] + c3) * u[i] + c2) * u[i] + c1) * u[i] + c0;
    }
  }
};

/// The part [s0, s1] of a line or arc, for the squared distances of many
/// points from it. Squared, so that only the largest of them needs a square
/// root (which is monotone and correctly rounded: the same bits as taking the
/// root of each). Distances to plane arcs are exact and need no trigonometry
/// per point: the nearest point of the circle is in p's direction from the
/// axis, and whether that direction lies within the part's angles follows
/// from two cross products with the directions of its ends. Distances to
/// helices are an upper bound (a point of the helix at the point's angle).
class PartDistance {
public:
  using Squares = std::array<double, kDeviationSamples>;

  /// `first` and `last` are seg.at(s0).p and seg.at(s1).p, which the
  /// callers have at hand (the blend's ends, the pieces' ends).
  PartDistance(const Segment &seg, double s0, double s1, const Vec3 &first, const Vec3 &last)
      : first_(first), last_(last) {
    if (seg.kind == SegmentKind::Line) {
      dir_ = seg.length > 0 ? Vec3((seg.end - seg.start) / seg.length) : Vec3::Zero();
      span_ = s1 - s0;
      return;
    }
    kind_ = Kind::Helix;
    const double rise = seg.sweep > 0 ? (seg.end.z() - seg.start.z()) / seg.sweep : 0;
    const double k = std::sqrt(seg.radius * seg.radius + rise * rise);
    sigma_ = seg.ccw ? 1 : -1;
    t0_ = s0 / k;
    t1_ = s1 / k;
    centre_ = seg.center;
    radius_ = seg.radius;
    startAngle_ = seg.startAngle;
    z0_ = seg.start.z();
    rise_ = rise;
    if (rise == 0) {
      kind_ = Kind::PlaneArc;
      // The ends' directions from the axis: from the end points, which are
      // on the circle (to rounding), without a sine and cosine each; from
      // the angles where a point is too near the axis to give one.
      auto direction = [&](const Vec3 &p, double angle) {
        const Eigen::Vector2d w(p.x() - centre_.x(), p.y() - centre_.y());
        const double r = w.norm();
        return r > radius_ / 2 ? Eigen::Vector2d(w / r) : Eigen::Vector2d(std::cos(angle), std::sin(angle));
      };
      e0_ = direction(first, startAngle_ + sigma_ * t0_);
      e1_ = direction(last, startAngle_ + sigma_ * t1_);
      whole_ = t1_ - t0_ >= 2 * std::numbers::pi;
      wide_ = t1_ - t0_ > std::numbers::pi;
    }
  }

  /// The squared distance of each point.
  [[gnu::always_inline]] void squares(const DeviationPoints &pts, Squares &out) const {
    constexpr size_t n = kDeviationSamples;
    switch (kind_) {
    case Kind::Line:
      for (size_t i = 0; i < n; ++i) {
        const double px = pts.x[i], py = pts.y[i], pz = pts.z[i];
        const double along = (px - first_.x()) * dir_.x() + (py - first_.y()) * dir_.y() + (pz - first_.z()) * dir_.z();
        const double s = std::clamp(along, 0.0, span_);
        const double ex = first_.x() + dir_.x() * s - px, ey = first_.y() + dir_.y() * s - py,
                     ez = first_.z() + dir_.z() * s - pz;
        out[i] = ex * ex + ey * ey + ez * ez;
      }
      return;
    case Kind::PlaneArc: {
      // Every point's distance from the axis first, in a loop of its own,
      // then the choice without branches, in a loop for each kind of part,
      // so that the compiler takes several points at a time (square roots
      // included: the runtime is built without errno for them): the same
      // values as taking the root only where the nearest point lies on the
      // part.
      Squares fromAxis;
      for (size_t i = 0; i < n; ++i) {
        const double wx = pts.x[i] - centre_.x(), wy = pts.y[i] - centre_.y();
        fromAxis[i] = std::sqrt(wx * wx + wy * wy);
      }
      // Turning the part's way, the angle from its start to a point's
      // direction w from the axis is at most pi where fromStart >= 0, and
      // from w to its end where toEnd >= 0; the part holds the angles
      // within both (up to a half turn) or within either (more). `onPart`
      // gives the distance to the circle where the part holds the point's
      // angle and infinity elsewhere, from those it would give for either
      // condition alone (selections the compiler makes without branches).
      auto choose = [&](auto onPart) {
        for (size_t i = 0; i < n; ++i) {
          const double px = pts.x[i], py = pts.y[i], pz = pts.z[i];
          const double fx = first_.x() - px, fy = first_.y() - py, fz = first_.z() - pz;
          const double lx = last_.x() - px, ly = last_.y() - py, lz = last_.z() - pz;
          const double best = std::min(fx * fx + fy * fy + fz * fz, lx * lx + ly * ly + lz * lz);
          const double wx = px - centre_.x(), wy = py - centre_.y();
          const double fromStart = sigma_ * (e0_.x() * wy - e0_.y() * wx);
          const double toEnd = sigma_ * (wx * e1_.y() - wy * e1_.x());
          const double radial = fromAxis[i] - radius_, dz = pz - z0_;
          const double toCircle = radial * radial + dz * dz;
          const double afterStart = fromStart >= 0 ? toCircle : kInf, beforeEnd = toEnd >= 0 ? toCircle : kInf;
          out[i] = std::min(best, onPart(afterStart, beforeEnd, toCircle));
        }
      };
      if (whole_)
        choose([](double, double, double toCircle) { return toCircle; });
      else if (wide_)
        choose([](double afterStart, double beforeEnd, double) { return std::min(afterStart, beforeEnd); });
      else
        choose([](double afterStart, double beforeEnd, double) { return std::max(afterStart, beforeEnd); });
      return;
    }
    case Kind::Helix:
      for (size_t i = 0; i < n; ++i) {
        const Vec3 p(pts.x[i], pts.y[i], pts.z[i]);
        double best = std::min((first_ - p).squaredNorm(), (last_ - p).squaredNorm());
        constexpr double kTurn = 2 * std::numbers::pi;
        // The angle of p about the axis, from the part's start, taken into [0, 2 pi).
        double theta = sigma_ * (std::atan2(p.y() - centre_.y(), p.x() - centre_.x()) - startAngle_) - t0_;
        theta -= kTurn * std::floor(theta / kTurn);
        for (double t = t0_ + theta; t <= t1_; t += kTurn) {
          const double phi = startAngle_ + sigma_ * t;
          const Vec3 q(centre_.x() + radius_ * std::cos(phi), centre_.y() + radius_ * std::sin(phi), z0_ + rise_ * t);
          best = std::min(best, (q - p).squaredNorm());
        }
        out[i] = best;
      }
      return;
    }
  }

private:
  enum class Kind : uint8_t { Line, PlaneArc, Helix };
  Vec3 first_, last_, dir_ = Vec3::Zero(), centre_ = Vec3::Zero();
  Eigen::Vector2d e0_ = Eigen::Vector2d::Zero(), e1_ = Eigen::Vector2d::Zero();  ///< plane arcs: directions of the ends
  Kind kind_ = Kind::Line;
  bool whole_ = false, wide_ = false;  ///< plane arcs: a whole turn or more; more than half a turn
  double span_ = 0, sigma_ = 1, t0_ = 0, t1_ = 0, radius_ = 0, startAngle_ = 0, z0_ = 0, rise_ = 0;
};

/// A quintic joining a's point at s = a.length - la to b's at lb, matching
/// tangent and curvature at both ends (quintic Hermite, end derivatives
/// scaled by the chord).
std::array<Vec3, 6> blendPoints(const PathPoint &p0, const PathPoint &p1) {
  const double m = (p1.p - p0.p).norm();
  std::array<Vec3, 6> c;
  c[0] = p0.p;
  c[5] = p1.p;
  c[1] = c[0] + p0.r1 * (m / 5);
  c[2] = 2 * c[1] - c[0] + p0.r2 * (m * m / 20);
  c[4] = c[5] - p1.r1 * (m / 5);
  c[3] = 2 * c[4] - c[5] + p1.r2 * (m * m / 20);
  return c;
}

std::array<Vec3, 6> blendPoints(const Segment &a, double la, const Segment &b, double lb) {
  return blendPoints(a.at(a.length - la), b.at(lb));
}

/// How far a blend strays from the two pieces it replaces (sampled along
/// its parameter: no arc-length inversion needed to find the worst point):
/// the blend from a's point at a.length - la to b's at lb, which are ctrl's
/// ends, and b's start `bStart` (b.at(0).p).
[[gnu::always_inline]] inline double blendDeviationOf(const std::array<Vec3, 6> &ctrl, const Segment &a, double la,
                                                      const Segment &b, double lb, const Vec3 &bStart) {
  const DeviationPoints pts(ctrl);
  PartDistance::Squares toA, toB;
  PartDistance(a, a.length - la, a.length, ctrl[0], a.end).squares(pts, toA);
  PartDistance(b, 0, lb, bStart, ctrl[5]).squares(pts, toB);
  // The largest in eight lanes that the compiler keeps in registers, then
  // of those: the same as one running maximum from 0 (a NaN never raises
  // either), in an order that it can take several at a time.
  constexpr size_t kLanes = 8;
  static_assert(kDeviationSamples % kLanes == 0);
  std::array<double, kLanes> lanes{};
  for (size_t i = 0; i < kDeviationSamples; i += kLanes)
    for (size_t l = 0; l < kLanes; ++l) {
      const double nearest = std::min(toA[i + l], toB[i + l]);
      lanes[l] = nearest > lanes[l] ? nearest : lanes[l];
    }
  double worst = 0;
  for (const double lane : lanes)
    worst = std::max(worst, lane);
  return std::sqrt(worst);
}

// In three versions on x86-64 (GCC's function multiversioning picks one
// when the program starts), as Segment.cpp's blend kernels: the compiler
// takes eight sample points at a time in the one for processors with
// AVX-512, four in the one with AVX, two in the other, with the same
// operations on each (the same bits).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__ELF__)
__attribute__((target("default"))) double blendDeviation(const std::array<Vec3, 6> &ctrl, const Segment &a, double la,
                                                         const Segment &b, double lb, const Vec3 &bStart) {
  return blendDeviationOf(ctrl, a, la, b, lb, bStart);
}
__attribute__((target("avx"))) double blendDeviation(const std::array<Vec3, 6> &ctrl, const Segment &a, double la,
                                                     const Segment &b, double lb, const Vec3 &bStart) {
  return blendDeviationOf(ctrl, a, la, b, lb, bStart);
}
__attribute__((target("avx512f,prefer-vector-width=512"))) double
blendDeviation(const std::array<Vec3, 6> &ctrl, const Segment &a, double la, const Segment &b, double lb,
               const Vec3 &bStart) {
  return blendDeviationOf(ctrl, a, la, b, lb, bStart);
}
#else
double blendDeviation(const std::array<Vec3, 6> &ctrl, const Segment &a, double la, const Segment &b, double lb,
                      const Vec3 &bStart) {
  return blendDeviationOf(ctrl, a, la, b, lb, bStart);
}
#endif

/// Decides how pieces a and b (whose segments are sa and sb) meet: smoothly,
/// through a blend (b.blendBefore, with a.cutEnd and b.cutStart), or at rest
/// (b.stopReason).
void join(Piece &a, const Segment &sa, Piece &b, const Segment &sb, double tolerance) {
  if (b.stopBefore) {
    b.stopReason = StopReason::Program;
    return;
  }
  const PathPoint ea = sa.at(sa.length), bs = sb.at(0);
  const double cosTurn = std::clamp(ea.r1.dot(bs.r1), -1.0, 1.0);
  // The turn's angle decides only whether it is below 1e-9 or above
  // kReversal, and the arc cosine is needed for neither elsewhere: below
  // 1e-9 is cosTurn = 1 (the next double down already gives 1.5e-8), and
  // kReversal's cosine is -0.99985, so that nearer 1 it cannot be exceeded.
  const bool aligned = cosTurn == 1.0;
  const bool reversal = cosTurn < -0.99 && std::acos(cosTurn) > kReversal;
  const double scale = 1 / std::max(1e-3, std::max(ea.r2.norm(), bs.r2.norm()));  // a length of the curves
  if (aligned && (ea.r2 - bs.r2).norm() * scale < 1e-9)
    return;  // tangent and curvature already agree
  if (reversal) {
    b.stopReason = StopReason::Reversal;
    return;
  }
  // Cut back as far as the tolerance allows, at most half of each piece
  // (the other half belongs to the blend at its other end).
  const double target = tolerance * kToleranceShare;
  double l = std::min(sa.length / 2, sb.length / 2);
  auto blendHere = [&](double deviation) {
    b.blendBefore = true;
    b.joinDeviation = deviation;
    a.cutEnd = l;
    b.cutStart = l;
  };
  const bool linear = sa.kind == SegmentKind::Line && sb.kind == SegmentKind::Line;
  if (linear) {
    // Between two lines the blend is symmetric about the corner's bisector
    // and the same shape at every size: its deviation is its middle's
    // distance from the lines, proportional to l. (Its largest at
    // blendDeviation's samples, too: the middle is one of them, and no other
    // point is farther from the lines, which a scan of turns from 0 to 179
    // degrees in steps of 1e-4 degree, at 2000 points each, confirmed.)
    // With the corner at E and the lines' directions t0 and t1, blendPoints
    // gives P0 = E - l t0, P5 = E + l t1, the chord m = l |t0 + t1|,
    // P1 = P0 + t0 m/5, P2 = P0 + 2 t0 m/5 and mirrored P4, P3; the middle,
    // sum C(5,i) P_i / 32, is E + (l/2 - 5m/32)(t1 - t0), whose distance
    // from the line through E along t0 is |l/2 - 5m/32| |t1 - t0 cos(turn)|.
    const Vec3 &t0 = ea.r1, &t1 = bs.r1;
    const double m = l * (t0 + t1).norm();
    const double dev = std::abs(l / 2 - 5 * m / 32) * (t1 - t0 * cosTurn).norm();
    if (dev > target)
      l *= target / dev;
    if (l >= kTinyBlend) {
      blendHere(std::min(dev, target));
      return;
    }
  }
  double lastL = 0, lastDev = 0;
  for (int it = 0; it < 40 && l >= kTinyBlend; ++it) {
    const std::array<Vec3, 6> ctrl = blendPoints(sa, l, sb, l);
    const double dev = blendDeviation(ctrl, sa, l, sb, l, bs.p);
    if (dev <= target) {
      blendHere(dev);
      return;
    }
    // The deviation grows like l^p near the junction, p between 1 (a
    // corner) and 3 (a curvature step): estimated from the last two tries,
    // 2 until there are two.
    double p = 2;
    if (lastL > 0 && lastDev > 0 && dev > 0 && lastL != l)
      p = std::clamp(std::log(dev / lastDev) / std::log(l / lastL), 1.0, 4.0);
    lastL = l;
    lastDev = dev;
    l *= std::clamp(std::pow(0.97 * target / dev, 1 / p), 0.02, 0.95);
  }
  b.stopReason = StopReason::Tiny;
}

/// Asks the kernel to back a freshly reserved output array with huge pages
/// where it can (Linux's transparent huge pages, on request): the planner
/// writes it once from front to back, and with 4 KiB pages a long plan
/// spends about a sixth of its time in page faults for its output (a page
/// fault per 12 segments). Only a hint: where it is not taken, nothing
/// changes but the time.
template <class T>
void preferHugePages(const std::vector<T> &v) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t(1) << 21;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(v.data()) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(v.data() + v.capacity()) & ~(kHuge - 1);
  if (end > begin)
    madvise(reinterpret_cast<void *>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)v;
#endif
}

/// The machine's axis limits as the speed caps use them, taken from the
/// Machine once per plan: its axes are a list of named entries, and the
/// caps are asked for every segment.
class SpeedBudget {
public:
  explicit SpeedBudget(const Machine &machine) : count_(std::min<size_t>(3, machine.axes.size())) {
    if (machine.maxFeed)
      maxFeed_ = *machine.maxFeed / 60;
    for (size_t k = 0; k < count_; ++k) {
      const Axis &ax = machine.axes[k];
      axes_[k] = {ax.velocity / 60, ax.acceleration, ax.jerk, kCurveAccel * ax.acceleration, kCurveJerk * ax.jerk,
                  kCouplingJerk * ax.jerk};
    }
    // The rotary joints after x, y, z, in their order (AxisDemand::rotary1).
    for (size_t k = 3; k < machine.axes.size() && rotaryCount_ < rotary_.size(); ++k) {
      const Axis &ax = machine.axes[k];
      rotaryIndex_[rotaryCount_] = static_cast<int8_t>(k);
      rotary_[rotaryCount_++] = {ax.velocity / 60, ax.acceleration, ax.jerk, kCurveAccel * ax.acceleration,
                                 kCurveJerk * ax.jerk, kCouplingJerk * ax.jerk};
    }
  }

  /// The speed cap and the path acceleration and jerk for a segment whose
  /// demand() is d (the same operations as on the Machine's values).
  void limitsFor(const AxisDemand &d, double feed, SegmentInfo &info) const {
    double v = kInf;
    SpeedLimit by = SpeedLimit::Feed;
    int8_t limiting = -1;
    auto cap = [&](double value, SpeedLimit why, int8_t axis = -1) {
      if (value < v) {
        v = value;
        by = why;
        limiting = axis;
      }
    };
    if (feed > 0) {
      cap(feed, SpeedLimit::Feed);
      cap(maxFeed_, SpeedLimit::MachineFeed);
    }
    // Each joint's demand with its budget: x, y, z, then the rotary joints.
    auto each = [&](auto &&visit) {
      for (size_t k = 0; k < count_; ++k)
        visit(axes_[k], d.r1[Eigen::Index(k)], d.r2[Eigen::Index(k)], d.r3[Eigen::Index(k)], static_cast<int8_t>(k));
      for (size_t k = 0; k < rotaryCount_; ++k)
        visit(rotary_[k], d.rotary1[k], d.rotary2[k], d.rotary3[k], rotaryIndex_[k]);
    };
    each([&](const AxisBudget &ax, double r1, double r2, double r3, int8_t axis) {
      if (r1 > 0)
        cap(ax.velocity / r1, SpeedLimit::AxisVelocity, axis);
      if (r2 > 0)
        cap(std::sqrt(ax.curveAccel / r2), SpeedLimit::Acceleration, axis);
      if (r3 > 0) {
        // The cube root only where it may be the lower: above (1 + 1e-12) v^3
        // its root exceeds v by far more than cbrt's and the cube's rounding.
        const double jerkRoom = ax.curveJerk / r3;
        if (!(jerkRoom > v * v * v * (1 + 1e-12)))
          cap(std::cbrt(jerkRoom), SpeedLimit::Jerk, axis);
      }
    });
    double a = kInf, jerk = kInf;
    each([&](const AxisBudget &ax, double r1, double r2, double, int8_t) {
      if (r1 <= 0)
        return;
      double ak = (ax.acceleration - v * v * r2) / r1;
      if (r2 > 0 && v > 0)
        ak = std::min(ak, ax.couplingJerk / (3 * v * r2));
      a = std::min(a, ak);
    });
    each([&](const AxisBudget &ax, double r1, double r2, double r3, int8_t) {
      if (r1 > 0)
        jerk = std::min(jerk, (ax.jerk - v * v * v * r3 - 3 * v * a * r2) / r1);
    });
    info.limits = {v, a, jerk};
    info.limitedBy = by;
    info.axis = limiting;
  }

private:
  struct AxisBudget {
    double velocity = 0;      ///< mm/s
    double acceleration = 0;  ///< mm/s^2
    double jerk = 0;          ///< mm/s^3
    double curveAccel = 0;    ///< what curvature may take of the acceleration (kCurveAccel)
    double curveJerk = 0;     ///< and of the jerk (kCurveJerk)
    double couplingJerk = 0;  ///< the coupling term's share of the jerk (kCouplingJerk)
  };
  size_t count_;
  std::array<AxisBudget, 3> axes_{};
  /// The rotary joints (deg, deg/s, ...) and their index in Machine::axes.
  size_t rotaryCount_ = 0;
  std::array<AxisBudget, 3> rotary_{};
  std::array<int8_t, 3> rotaryIndex_{};
  double maxFeed_ = kInf;  ///< mm/s, the controller's max_feed
};

/// The joints' first and second derivatives with respect to the tip's path
/// at a segment's two ends (joint units per mm, per mm^2).
struct JointEnds {
  Joints d1Start, d1End, d2Start, d2End;
  /// Where the chain has its rates at both ends (Kinematics::rates): d1Start
  /// and d1End are exact, and curveStart, curveEnd are the parts of the
  /// joints' second derivatives there that the path's and the tool axis's
  /// own second derivatives make (rates applied to p'' and k''). Across a
  /// junction the rest of the second derivatives is continuous where the
  /// first derivatives are, so the jump is the difference of these.
  bool exact = false;
  Joints curveStart, curveEnd;
};

/// JointEnds' exact parts from the rates at the two ends.
/// The segment's path and tool axis at its two ends, each found once.
struct SegmentEnds {
  PathPoint start, end;
  Segment::AxisEnds axis;
  SegmentEnds(const Segment &seg, const GreatCircle &circle)
      : start(seg.atStart()), end(seg.atEnd()), axis(seg.axisEnds(&circle)) {}
};

void exactEnds(const SegmentEnds &at, const JointRates &start, const JointRates &end, JointEnds &ends) {
  ends.d1Start = start.of(at.start.r1, at.axis.rate0);
  ends.d1End = end.of(at.end.r1, at.axis.rate1);
  ends.curveStart = start.of(at.start.r2, at.axis.curve0);
  ends.curveEnd = end.of(at.end.r2, at.axis.curve1);
  ends.exact = true;
}

/// The pose the joints were last solved at by jointDemand (a segment's end),
/// so that the next segment starting there need not solve it again.
struct SolvedPose {
  Vec3 tip = Vec3::Zero();  ///< in machine coordinates at zero (the work offset added)
  Vec3 axis = Vec3::Zero();
  Mat3 turn = Mat3::Identity();  ///< Kinematics::tipTurn there (serial chains)
  std::optional<JointRates> rates;  ///< Kinematics::rates there, when jointDemand took them
  bool valid = false;  ///< the planner's joints are that pose's, not singular there
  bool at(const Vec3 &t, const Vec3 &a) const { return valid && tip == t && axis == a; }
};

/// What jointDemand samples the joints with, for one plan.
struct JointSampler {
  const Kinematics &kin;
  Vec3 offset;  ///< the work offset: where the workpiece's origin is on the machine
  /// A serial chain (Kinematics::tipTurn gives the linear joints' turn),
  /// known once for the plan.
  bool serial;
  /// Kinematics::singularDirection, known once for the plan.
  std::optional<Vec3> singular;
  SolvedPose solved;
};

/// Orientation smoothing: where the tool turns on both sides of a junction
/// it passes without stopping, the axis turns through the junction at one
/// rate instead of each side's own (whose jump would make the joints' rates
/// jump, and the tool stop): the three-point rule on the two sides' rates
/// (each weighted by the other side's length, exact where the orientation
/// is a quadratic of the arc length), across the axis there. Each side then
/// follows a cubic (Segment::axisRate0, axisRate1) with that rate at the
/// junction and its great circle's (or the shared one) at its other end. A
/// side whose axis does not turn keeps it (a flank's fixed tilt stays
/// fixed: the tool stops where the turning starts).
///
/// The cubic leaves the great circle by at most 4/27 of the change of each
/// end's rate (per unit of the fraction: the Hermite basis's peak), so the
/// shared rate is kept within (27/8) tolerance / length of each side's own
/// rate: each segment then stays within `tolerance` (rad) of its even turn.
/// Where no rate is that close to both, the junction is not smoothed.
void smoothJunction(Segment &a, const GreatCircle &ca, Segment &b, const GreatCircle &cb, double tolerance) {
  if (!(tolerance > 0) || a.kind == SegmentKind::Dwell || b.kind == SegmentKind::Dwell || !(a.length > 0) ||
      !(b.length > 0))
    return;
  if (!a.tilted() || !b.tilted() || a.axis1 != b.axis0)
    return;
  if (!(ca.angle() > 1e-9) || !(cb.angle() > 1e-9))
    return;
  const Vec3 rateA = ca.tangent(1) / a.length, rateB = cb.tangent(0) / b.length;  // per mm
  // The shared rate on the line from rateA to rateB, at the three-point
  // rule's place, moved into the reach of both sides' tolerance.
  const double reachA = 27.0 / 8 * tolerance / a.length, reachB = 27.0 / 8 * tolerance / b.length;
  const double apart = (rateB - rateA).norm();
  if (apart > reachA + reachB)
    return;
  double along = a.length / (a.length + b.length);
  if (apart > 0)
    along = std::clamp(along, std::max(0.0, 1 - reachB / apart), std::min(1.0, reachA / apart));
  Vec3 shared = rateA + along * (rateB - rateA);
  shared -= a.axis1 * a.axis1.dot(shared);
  if (!a.axisCubic())
    a.axisRate0 = ca.tangent(0);
  a.axisRate1 = shared * a.length;
  b.axisRate0 = shared * b.length;
  b.axisRate1 = cb.tangent(1);
}

/// Bounds of |q'|, |q''|, |q'''| over [0, length] of the cubic with values
/// q0, q1 and derivatives m0, m1 at its ends (Hermite).
struct Cubic {
  double r1 = 0, r2 = 0, r3 = 0;
};
Cubic hermite(double q0, double q1, double m0, double m1, double length) {
  const double perLength = 1 / length;
  const double slope = (q1 - q0) * perLength;
  const double start2 = (6 * slope - 4 * m0 - 2 * m1) * perLength;  // q'' at 0
  const double end2 = (2 * m0 + 4 * m1 - 6 * slope) * perLength;    // q'' at length
  const double third = (end2 - start2) * perLength;                 // q''', constant
  Cubic c;
  c.r1 = std::max(std::abs(m0), std::abs(m1));
  // q' is a parabola: its extremum where q'' = start2 + third s vanishes
  // inside.
  if (third != 0) {
    const double s = -start2 / third;
    if (s > 0 && s < length)
      c.r1 = std::max(c.r1, std::abs(m0 + start2 * s + 0.5 * third * s * s));
  }
  c.r2 = std::max(std::abs(start2), std::abs(end2));
  c.r3 = std::abs(third);
  return c;
}

/// jointDemand on a short segment that turns the tool little for how far it
/// stays from the chain's singular direction, where the chain has its
/// joints' rates in closed form (Kinematics::rates): the joints at the two
/// ends and their rates there fix a cubic per joint (Hermite), whose
/// derivatives bound the joints' as the differences of three pieces did, at
/// one inverse kinematics per segment (the start's kept from the segment
/// before). The linear joints as jointDemand splits them: the path's own
/// derivatives turned, and the rest, rho = x - M0 p, by its cubic. nullopt
/// where the rates are not to be had (jointDemand samples instead).
std::optional<bool> jointDemandByRates(const Segment &seg, const GreatCircle &circle, JointSampler &sampler,
                                       Joints &near, AxisDemand &d, JointEnds &ends, bool startSolved, double margin) {
  const Kinematics &kin = sampler.kin;
  SolvedPose &solved = sampler.solved;
  const Vec3 tip0 = seg.start + sampler.offset, tip1 = seg.end + sampler.offset;
  const bool continued = solved.at(tip0, seg.axis0);
  Joints q0 = near;
  bool singularStart = false;
  if (!startSolved && !continued) {
    const InverseResult r = kin.inverse({tip0, seg.axis0}, &near);
    if (!r.joints)
      return std::nullopt;
    q0 = *r.joints;
    singularStart = r.singular;
  }
  // The start's rates: the last segment's end's, else solved for.
  std::optional<JointRates> own;
  if (!(continued && solved.rates))
    own = kin.rates(q0, 0);
  const std::optional<JointRates> &g0 = own ? own : solved.rates;
  if (!g0 || singularStart)
    return std::nullopt;
  std::optional<JointRates> g1;
  const InverseResult end = kin.inverseWithRates({tip1, seg.axis1}, &q0, 0, g1);
  if (!end.joints) {
    solved.valid = false;
    return false;
  }
  const Joints &q1 = *end.joints;
  if (!g1)
    return std::nullopt;
  const SegmentEnds at(seg, circle);
  exactEnds(at, *g0, *g1, ends);
  const Vec3 &along0 = at.start.r1, &along1 = at.end.r1;
  const Joints &rate0 = ends.d1Start, &rate1 = ends.d1End;
  const Mat3 &m0 = g0->tipTurn, &m1 = g1->tipTurn;
  // The rest: rho = x - M0 p, and the rotary joints as they are.
  Joints rho0 = q0, rho1 = q1, m0rho = rate0, m1rho = rate1;
  rho0.head<3>() -= m0 * tip0;
  rho1.head<3>() -= m0 * tip1;
  m0rho.head<3>() -= m0 * along0;
  m1rho.head<3>() -= m0 * along1;
  const Mat3 bound = m0.cwiseAbs() + (m1 - m0).cwiseAbs();
  const Vec3 path1 = bound * d.r1, path2 = bound * d.r2, path3 = bound * d.r3;
  AxisDemand out;
  size_t rotary = 0;
  // The junctions take the second derivatives' bounds (as jointDemand's).
  ends.d2Start.resize(q1.size());
  for (Eigen::Index k = 0; k < q1.size(); ++k) {
    const Cubic c = hermite(rho0[k], rho1[k], m0rho[k], m1rho[k], seg.length);
    if (k < 3) {
      out.r1[k] = margin * (path1[k] + c.r1);
      out.r2[k] = margin * (path2[k] + c.r2);
      out.r3[k] = margin * (path3[k] + c.r3);
      ends.d2Start[k] = out.r2[k];
    } else if (rotary < out.rotary1.size()) {
      out.rotary1[rotary] = margin * c.r1;
      out.rotary2[rotary] = margin * c.r2;
      out.rotary3[rotary] = margin * c.r3;
      ends.d2Start[k] = out.rotary2[rotary];
      ++rotary;
    } else {
      ends.d2Start[k] = 0;
    }
  }
  ends.d2End = ends.d2Start;
  d = out;
  near = q1;
  solved.tip = tip1;
  solved.axis = seg.axis1;
  solved.turn = m1;
  solved.rates = std::move(g1);
  solved.valid = true;
  return true;
}

/// The demand a segment that tilts the tool makes of the machine's joints:
/// their first three derivatives with respect to the tip's path, from the
/// joints at points along it (each solution the nearest the one before,
/// starting from `near`, which is left at the segment's end). False (d
/// unchanged) where a point is out of reach: the backends and the verifier
/// refuse such a path before it is planned. `startSolved`: `near` is
/// already the joints at the segment's start (turnFirst found them).
///
/// On a serial chain (Kinematics::tipTurn) the linear joints are the tip
/// turned, x(s) = M(s) p(s) + c(s), M and c functions of the tool's
/// direction alone: their derivatives are M0 p^(n) (the path's own, whose
/// bounds d already holds, exact at every curvature peak however short the
/// segment) plus those of the rest, rho(s) = x(s) - M0 p(s), which changes
/// only as the direction turns (slowly and smoothly along the segment's
/// great circle): so a few points suffice, every 0.5 deg of turn and every
/// 1 mm of path, at least 3 pieces (the third differences). Bounds per axis:
/// margin x (|M0| d + |M1 - M0| d + differences of rho); the rotary joints
/// by their differences, with the margin. The margin on the path's part is
/// for the junctions: there the rotary axes' rates jump (each segment's
/// great circle its own), which the junction caps bound but which adds to
/// the jerk the segments' own limits use up (without it the player finds x
/// and y jerk up to 23 % over just after junctions on the 5-axis benchmark
/// path). Elsewhere (parallel kinematics) every joint by its differences, at
/// least 8 pieces (fewer let the player find jerk 3 % over a limit on the
/// shipped head-head machine); the path's own curvature as a floor.
///
/// The joints at the start are not solved again where the last segment
/// ended (`sampler.solved`); on a path of short segments (jointDemandByRates)
/// each costs one inverse kinematics (BM_PlanFiveAxis, docs/performance.md).
bool jointDemand(const Segment &seg, const GreatCircle &circle, JointSampler &sampler, Joints &near, AxisDemand &d,
                 JointEnds &ends, bool startSolved) {
  constexpr double kMargin = 1.25;  // what the pieces' differences may miss of a peak
  const Kinematics &kin = sampler.kin;
  const Vec3 &offset = sampler.offset;
  const bool serial = sampler.serial;
  SolvedPose &solved = sampler.solved;
  // How far the axis turns: its great circle's angle (`circle` is the one
  // from axis0 to axis1), or a cubic's rates at the ends where they are
  // more.
  const double turn = std::max({circle.angle(), seg.axisRate0.norm(), seg.axisRate1.norm()});
  const double turned = turn * 180 / std::numbers::pi;
  const int n = std::clamp(static_cast<int>(std::ceil(std::max(turned / 0.5, seg.length / 1.0))), serial ? 3 : 8, 64);
  const double h = seg.length / n;
  if (!(h > 0))
    return false;
  // Where three pieces would do, a cubic from the ends' rates does as well
  // when the rates change little along the segment: the rotary joints' grow
  // as 1 / sin of the angle to the singular direction, so the turn must be
  // small beside that sine (a tenth: the rates change by about a tenth).
  // (A cubic's axis leaves the great circle by less than a sixth of how far
  // its rates at the ends are from the circle's: taken off the sine.)
  if (serial && n == 3 && sampler.singular) {
    const double cosine = circle.nearestCosine(*sampler.singular);
    double sine = std::sqrt(std::max(0.0, 1 - cosine * cosine));
    if (seg.axisCubic())
      sine -= 0.25 * ((seg.axisRate0 - circle.tangent(0)).norm() + (seg.axisRate1 - circle.tangent(1)).norm());
    if (turn <= 0.1 * sine)
      if (const std::optional<bool> done =
              jointDemandByRates(seg, circle, sampler, near, d, ends, startSolved, kMargin))
        return *done;
  }
  std::array<Joints, 65> q;
  std::array<Vec3, 65> tip;
  Joints at = near;
  q[0] = near;
  tip[0] = seg.pointAt(0) + offset;
  const bool continued = solved.at(tip[0], seg.axis0);
  startSolved |= continued;
  bool singularEnd = false;
  for (int i = startSolved ? 1 : 0; i <= n; ++i) {
    const double s = seg.length * i / n;
    tip[size_t(i)] = seg.pointAt(s) + offset;
    const InverseResult r = kin.inverse({tip[size_t(i)], seg.axisAt(s)}, &at);
    if (!r.joints) {
      solved.valid = false;
      return false;
    }
    at = *r.joints;
    q[size_t(i)] = at;
    singularEnd = r.singular;
  }
  near = at;
  const Joints q0 = q[0];
  // On a serial chain the linear joints' differences are taken of rho.
  Mat3 m0 = Mat3::Identity(), m1 = Mat3::Identity();
  if (serial) {
    m0 = continued ? solved.turn : *kin.tipTurn(q[0]);
    m1 = *kin.tipTurn(q[size_t(n)]);
    for (int i = 0; i <= n; ++i)
      q[size_t(i)].head<3>() -= m0 * tip[size_t(i)];
  }
  // The ends' rates exactly where the chain has them there.
  std::optional<JointRates> startRates = continued && solved.rates ? solved.rates : std::nullopt;
  if (serial && !startRates)
    startRates = kin.rates(q0, 0);
  std::optional<JointRates> endRates = serial && !singularEnd ? kin.rates(near, 0) : std::nullopt;
  solved = {tip[size_t(n)], seg.axis1, m1, endRates, !singularEnd};
  const Mat3 spread = (m1 - m0).cwiseAbs();
  ends.exact = false;
  if (startRates && endRates) {
    exactEnds(SegmentEnds(seg, circle), *startRates, *endRates, ends);
  } else {
    ends.d1Start = (q[1] - q[0]) / h;
    ends.d1End = (q[size_t(n)] - q[size_t(n - 1)]) / h;
    if (serial) {
      ends.d1Start.head<3>() += m0 * seg.at(0).r1;
      ends.d1End.head<3>() += m0 * seg.at(seg.length).r1;
    }
  }
  // The path's own bounds as the linear joints see them.
  const Mat3 bound = m0.cwiseAbs() + spread;
  const Vec3 path1 = bound * d.r1, path2 = bound * d.r2, path3 = bound * d.r3;
  AxisDemand out;
  size_t rotary = 0;
  for (Eigen::Index k = 0; k < near.size(); ++k) {
    double r1 = 0, r2 = 0, r3 = 0;
    for (int i = 0; i < n; ++i)
      r1 = std::max(r1, std::abs(q[size_t(i + 1)][k] - q[size_t(i)][k]) / h);
    for (int i = 1; i < n; ++i)
      r2 = std::max(r2, std::abs(q[size_t(i + 1)][k] - 2 * q[size_t(i)][k] + q[size_t(i - 1)][k]) / (h * h));
    for (int i = 1; i + 1 < n; ++i)
      r3 = std::max(r3, std::abs(q[size_t(i + 2)][k] - 3 * q[size_t(i + 1)][k] + 3 * q[size_t(i)][k] -
                                 q[size_t(i - 1)][k]) /
                            (h * h * h));
    if (k < 3 && serial) {
      out.r1[k] = kMargin * (path1[k] + r1);
      out.r2[k] = kMargin * (path2[k] + r2);
      out.r3[k] = kMargin * (path3[k] + r3);
    } else if (k < 3) {
      // The joints' curvature cannot be less than the path's own (the tip's
      // path is what the linear joints carry, turned).
      out.r1[k] = kMargin * r1;
      out.r2[k] = std::max(kMargin * r2, d.r2[k]);
      out.r3[k] = std::max(kMargin * r3, d.r3[k]);
    } else if (rotary < out.rotary1.size()) {
      out.rotary1[rotary] = kMargin * r1;
      out.rotary2[rotary] = kMargin * r2;
      out.rotary3[rotary] = kMargin * r3;
      ++rotary;
    }
  }
  d = out;
  ends.d2Start = ends.d2End = Joints::Zero(near.size());
  for (Eigen::Index k = 0; k < near.size(); ++k)
    ends.d2Start[k] = ends.d2End[k] = k < 3 ? d.r2[k] : d.rotary2[size_t(std::min<Eigen::Index>(k - 3, 2))];
  return true;
}

/// The curvature vector of the circle through the vertex between lines a and
/// b and the vertices before and after it; zero when either is not a line.
Vec3 vertexCurvature(const PathInput &input, const Piece &a, const Piece &b) {
  if (a.kind != SegmentKind::Line || b.kind != SegmentKind::Line)
    return Vec3::Zero();
  const Vec3 &a0 = a.from(input), &a1 = a.to(input), &b0 = b.from(input), &b1 = b.to(input);
  const Vec3 ta = (a1 - a0) / a.length, tb = (b1 - b0) / b.length;
  const Vec3 turn = tb - ta;
  const double chord = (a1 - a0 + b1 - b0).norm();
  const double sinTurn = ta.cross(tb).norm();
  if (turn.norm() <= 0 || chord <= 0)
    return Vec3::Zero();
  return turn.normalized() * (2 * sinTurn / chord);
}

/// The end of a blend at arc length s of piece p (its segment): the piece's
/// own point, with the shared curvature at a smoothed middle.
PathPoint blendEnd(const Piece &p, const Segment &seg, double s) {
  PathPoint pt = seg.at(s);
  if (p.hasMidCurvature)
    pt.r2 = p.midCurvature;
  return pt;
}

/// The control points of the blend before piece b (b.blendBefore), from its
/// pieces' cuts and curvatures as join and smoothChains leave them.
std::array<Vec3, 6> blendBetween(const Piece &a, const Segment &sa, const Piece &b, const Segment &sb) {
  return blendPoints(blendEnd(a, sa, sa.length - a.cutEnd), blendEnd(b, sb, b.cutStart));
}

/// Dense polylines (CAM output, a curve as many short lines) would become
/// a chain of blends whose curvature falls to zero at every line's middle,
/// the lines' own curvature, and rises again: the jerk that takes holds the
/// speed far below the feed. Where a line is wholly taken by its two blends,
/// nothing needs zero curvature there: both blends are made again sharing
/// the curvature of the curve the vertices describe (the mean of the circles
/// through the neighbouring vertices). A remade blend that leaves the
/// tolerance is given back its zero-curvature ends, and so is its neighbour
/// across each such middle, until every blend is within tolerance and every
/// middle's two blends agree. (The blends themselves are made from the
/// pieces when the segments are written: blendBetween.)
void smoothChains(const PathInput &input, std::vector<Piece> &pieces, double tolerance) {
  const size_t n = pieces.size();
  auto consumed = [&](size_t i) {
    const Piece &p = pieces[i];
    return p.kind == SegmentKind::Line && i > 0 && i + 1 < n && p.blendBefore && pieces[i + 1].blendBefore &&
           !p.keepsMiddle();  // what is left is dropped (plan, step 3)
  };
  for (size_t i = 0; i < n; ++i) {
    if (!consumed(i))
      continue;
    const Vec3 t = (pieces[i].to(input) - pieces[i].from(input)) / pieces[i].length;
    Vec3 k = (vertexCurvature(input, pieces[i - 1], pieces[i]) + vertexCurvature(input, pieces[i], pieces[i + 1])) / 2;
    k -= t * k.dot(t);  // normal to the line, as curvature is
    pieces[i].midCurvature = k;
    pieces[i].hasMidCurvature = true;
  }
  const double target = tolerance * kToleranceShare;
  std::vector<char> pending(n, 0);
  for (size_t j = 1; j < n; ++j)
    pending[j] = pieces[j].blendBefore && (pieces[j - 1].hasMidCurvature || pieces[j].hasMidCurvature);
  Segment sa, sb;
  for (bool again = true; again;) {
    again = false;
    for (size_t j = 1; j < n; ++j) {
      if (!pending[j])
        continue;
      pending[j] = 0;
      Piece &a = pieces[j - 1], &b = pieces[j];
      if (!a.hasMidCurvature && !b.hasMidCurvature)
        continue;  // zero-curvature ends again: the blend join() made and checked
      // The remade blend differs from join's only in the curvature at a
      // smoothed middle: blendPoints moves its control point P2 by
      // (k' - k) m^2 / 20 and P3 likewise, m the chord, which is at most the
      // path length between the blend's ends. Every point of the curve then
      // moves by at most b2(u) |dP2| + b3(u) |dP3|, with the Bernstein
      // weights b2 and b3 at most 0.3456 each and 0.625 together; a blend
      // whose join deviation plus that stays within the target needs no
      // samples (with a margin far above rounding: the samples would pass).
      const double reach = a.cutEnd + b.cutStart, spread = reach * reach / 20;
      const double moveP2 = a.hasMidCurvature ? a.midCurvature.norm() * spread : 0;
      const double moveP3 = b.hasMidCurvature ? b.midCurvature.norm() * spread : 0;
      const double moved = std::min(0.3456 * (moveP2 + moveP3), 0.625 * std::max(moveP2, moveP3));
      if (b.joinDeviation + moved <= target * (1 - 1e-6))
        continue;
      a.segment(input, sa);
      b.segment(input, sb);
      if (blendDeviation(blendBetween(a, sa, b, sb), sa, a.cutEnd, sb, b.cutStart, sb.at(0).p) <= target)
        continue;
      // Back to zero curvature at both ends; the blends across those
      // middles are made again to match.
      for (size_t side : {j - 1, j}) {
        if (!pieces[side].hasMidCurvature)
          continue;
        pieces[side].hasMidCurvature = false;
        pending[side] = 1;          // the blend at the piece's start
        if (side + 1 < n)
          pending[side + 1] = 1;    // and at its end
        again = true;
      }
    }
  }
}

} // namespace

Trajectory plan(const PathInput &input, const Machine &machine, const PlanOptions &options) {
  const double tolerance = options.tolerance > 0 ? options.tolerance : machine.pathTolerance;
  Trajectory out;
  out.machine = machine.name;
  out.tolerance = tolerance;
  out.cycleTime = machine.cycleTime;
  out.start = input.start;
  for (const Axis &a : machine.axes)
    out.axisNames.push_back(a.name);

  // 1. One piece per move with any length; dwells stop the tool between
  // pieces.
  std::vector<Piece> pieces;
  pieces.reserve(input.moves.size());
  std::vector<PieceDwell> dwells;
  Vec3 at = input.start;
  bool pendingStop = false;
  for (size_t i = 0; i < input.moves.size(); ++i) {
    const PathMove &m = input.moves[i];
    pendingStop = pendingStop || m.stopBefore;
    if (m.kind == PathMove::Kind::Dwell) {
      at = m.to;  // where the move before ends (PathMove): the next piece starts here
      if (m.dwellS > 0) {
        dwells.push_back({pieces.size(), uint32_t(i), m.dwellS});
        pendingStop = true;
      }
      continue;
    }
    const Segment seg = m.kind == PathMove::Kind::Line ? Segment::line(at, m.to)
                                                       : Segment::arcTurns(at, m.to, m.center, m.ccw, m.turns);
    at = m.to;
    if (!(seg.length > 1e-9))
      continue;
    Piece &p = pieces.emplace_back(seg, uint32_t(i));
    p.feed = m.feed > 0 ? m.feed / 60 : 0;
    p.stopBefore = pendingStop;
    pendingStop = false;
  }

  // 2. Junctions: blends or stops.
  {
    Segment segments[2];  // piece i's in segments[i % 2]
    for (size_t i = 0; i < pieces.size(); ++i) {
      pieces[i].segment(input, segments[i % 2]);
      if (i > 0)
        join(pieces[i - 1], segments[(i - 1) % 2], pieces[i], segments[i % 2], tolerance);
    }
  }
  smoothChains(input, pieces, tolerance);

  // 3. Segments with their caps.
  size_t count = dwells.size();
  for (const Piece &p : pieces)
    count += size_t(p.blendBefore) + size_t(p.keepsMiddle());
  // 5-axis: room for the dwells that turn the joints before a segment
  // (turnFirst: after rapids, stops and upright runs, and at singular
  // poses), so that one of them does not copy every segment to a new block.
  if (options.kinematics)
    count += count / 16 + 16;
  out.segments.reserve(count);
  out.info.reserve(count);
  preferHugePages(out.segments);
  preferHugePages(out.info);
  // The segments' lengths again, packed: the steps below read them for every
  // segment, and a Segment is 336 bytes.
  std::vector<double> lengths;
  lengths.reserve(count);
  // d is the last segment's demand().
  const SpeedBudget budget(machine);
  // 5-axis: where the joints are, for the next segment that tilts the tool;
  // the joints' derivatives at the end of the segment before; and the speed
  // each junction may be passed at (joints' rates that jump there).
  Joints joints;
  std::optional<JointSampler> sampler;  // and where they were solved, when jointDemand did
  std::optional<JointEnds> lastEnds;
  bool lastTilted = false;
  std::vector<double> junctionCap;
  // A parallel-kinematic machine's sliders are not the tip's coordinates:
  // every segment's joints come from its inverse kinematics (upright ones
  // too: a straight line of the tip is a curve of the sliders), starting
  // from the joints at the path's start.
  const bool everySegmentByJoints = options.kinematics && !options.kinematics->linearJointsAreCartesian();
  if (options.kinematics) {
    joints = Joints::Zero(static_cast<Eigen::Index>(options.kinematics->jointCount()));
    sampler.emplace(JointSampler{*options.kinematics, options.workOffset,
                                 options.kinematics->tipTurn(joints).has_value(),
                                 options.kinematics->singularDirection(), SolvedPose{}});
    junctionCap.reserve(count);
    out.joints.reserve(count * options.kinematics->jointCount());
  }
  if (everySegmentByJoints)
    if (const InverseResult start = options.kinematics->inverse({input.start + options.workOffset, input.startAxis});
        start.joints)
      joints = *start.joints;
  // Each dwell segment's wait, in the order of the segments; the joints
  // recorded at the last segment's end (Trajectory::joints).
  std::vector<double> dwellTimes;
  Joints recorded;
  // The joints at an upright segment's end, from the last recorded (the
  // rotary axes kept where they are free).
  auto record = [&](const Segment &seg) {
    const Joints near = recorded.size() ? recorded : joints;
    const InverseResult end = options.kinematics->inverse({seg.end + options.workOffset, seg.axis1}, &near);
    recorded = end.joints ? *end.joints : near;
  };
  // A segment that tilts the tool and starts where the tool lies along a
  // rotary axis (upright, after a step that does not tilt it, or where its
  // axis passes that way): the free axis is set from where the tool axis
  // goes (the other solutions would swing it as the tool leaves), and the
  // joints that must move to get there turn first, the tip at rest: a
  // dwell as long as the slowest of them takes, from rest to rest within
  // its limits (the tool stops there).
  // The segment is out.segments[index] (the last, or the one before the last
  // when the last waits for orientation smoothing); a turning dwell goes in
  // before it, and `index` moves on to it again.
  // True when `joints` is then the solution at the segment's start.
  auto turnFirst = [&](size_t &index, StopReason &stop, uint32_t move, bool fromMiddle) {
    const Segment &seg = out.segments[index];
    const Kinematics &kin = *options.kinematics;
    const Vec3 offset = options.workOffset;
    // At a rapid that turns the tool, the rotary axes start again from the
    // solution nearest the middle of their travel (0), as the G-code
    // targets turn them (docs/five-axis.md): the path after has the most
    // travel either way.
    // Starting where the last segment that tilted the tool ended, the
    // joints are already there.
    if (!fromMiddle && sampler->solved.at(seg.start + offset, seg.axis0))
      return true;
    sampler->solved.valid = false;
    Joints near = joints;
    if (fromMiddle)
      for (size_t k = 3; k < machine.axes.size() && Eigen::Index(k) < near.size(); ++k)
        if (machine.axes[k].rotary)
          near[Eigen::Index(k)] = 0;
    InverseResult start = kin.inverse({seg.start + offset, seg.axis0}, &near);
    if (!start.joints)
      return false;
    if (start.singular && seg.length > 0) {
      const double ahead = std::min(seg.length, 1e-3);
      const InverseResult next = kin.inverse({seg.at(ahead).p + offset, seg.axisAt(ahead)}, &joints);
      if (next.joints)
        start = kin.inverse({seg.start + offset, seg.axis0}, &*next.joints);
      if (!start.joints)
        return false;
    }
    // Joints that agree within what the inverse kinematics' rounding leaves
    // need no turn.
    double wait = 0;
    for (size_t k = 0; k < machine.axes.size() && Eigen::Index(k) < joints.size(); ++k) {
      const double travel = std::abs((*start.joints)[Eigen::Index(k)] - joints[Eigen::Index(k)]);
      const Axis &axis = machine.axes[k];
      if (travel > kJointTurn)
        wait = std::max(wait, planProfile(0, 0, travel, {axis.velocity / 60, axis.acceleration, axis.jerk}).duration());
    }
    joints = *start.joints;
    if (!(wait > 0))
      return true;
    Segment turn = Segment::dwell(seg.start);
    turn.axis0 = turn.axis1 = seg.axis0;
    out.segments.insert(out.segments.begin() + std::ptrdiff_t(index), std::move(turn));
    ++index;
    lengths.push_back(0);
    SegmentInfo &info = out.info.emplace_back();
    info.stop = StopReason::Dwell;
    info.move = info.nextMove = move;
    junctionCap.push_back(kInf);
    dwellTimes.push_back(wait);
    recorded = joints;  // turned: the new ones
    out.joints.insert(out.joints.end(), recorded.data(), recorded.data() + recorded.size());
    stop = StopReason::Dwell;
    return true;
  };
  // Plans out.segments[index]: the last segment, or the one before it when
  // the last waits (orientation smoothing).
  auto push = [&](size_t index, double feed, uint32_t move, uint32_t next, StopReason stop, const AxisDemand &given,
                  const GreatCircle *circle) {
    bool startSolved = false;
    if (options.kinematics && (out.segments[index].tilted() || everySegmentByJoints)) {
      const Segment &here = out.segments[index];
      const bool fromMiddle = feed == 0 && here.kind == SegmentKind::Line && here.axis0 != here.axis1;
      startSolved = turnFirst(index, stop, move, fromMiddle);
    }
    const Segment &seg = out.segments[index];
    lengths.push_back(seg.length);
    SegmentInfo &info = out.info.emplace_back();
    info.feed = feed;
    info.move = move;
    info.nextMove = next;
    info.stop = stop;
    AxisDemand d = given;
    if (!options.kinematics) {
      budget.limitsFor(d, feed, info);
      return;
    }
    // The joints' rates at the segment's ends: by the inverse kinematics on
    // a segment that tilts the tool, else the tip's own (the rotary axes
    // still; the tool upright keeps them at 0).
    std::optional<JointEnds> ends;
    const bool tilted = seg.tilted();
    const bool byJoints = tilted || everySegmentByJoints;
    if (byJoints) {
      JointEnds e;
      if (jointDemand(seg, circle ? *circle : GreatCircle(seg.axis0, seg.axis1), *sampler, joints, d, e, startSolved))
        ends = e;
    } else if (seg.kind != SegmentKind::Dwell && seg.length > 0) {
      JointEnds e;
      e.d1Start = e.d1End = e.d2Start = e.d2End = Joints::Zero(joints.size());
      const PathPoint a = seg.atStart(), b = seg.atEnd();
      e.d1Start.head<3>() = a.r1;
      e.d1End.head<3>() = b.r1;
      e.d2Start.head<3>() = d.r2;
      e.d2End.head<3>() = d.r2;
      ends = e;
    }
    // A junction next to a segment that tilts the tool, where the joints'
    // rates jump (the axis turning at another rate on either side): what a
    // jump of velocity or acceleration within one cycle would cost in jerk
    // bounds the speed there (in practice the tool stops for an orientation
    // that turns at a new rate; smoothing it is not done yet).
    double cap = kInf;
    if (stop == StopReason::None && ends && lastEnds && (tilted || lastTilted)) {
      const double cycle = machine.cycleTime > 0 ? machine.cycleTime : 0.001;
      for (Eigen::Index k = 0; k < joints.size() && size_t(k) < machine.axes.size(); ++k) {
        const double jk = machine.axes[size_t(k)].jerk;
        // The rates' jump; the second derivatives': where both sides have
        // their rates, what the path's and the axis's own second
        // derivatives change by (JointEnds::curveStart), else by their
        // bounds on the two sides (what finite differences give at an end
        // is not sharp).
        const double dv = std::abs(ends->d1Start[k] - lastEnds->d1End[k]);
        const double da = ends->exact && lastEnds->exact
                              ? std::abs(ends->curveStart[k] - lastEnds->curveEnd[k])
                              : std::abs(ends->d2Start[k]) + std::abs(lastEnds->d2End[k]);
        // Half of each to the velocity's jump and to the acceleration's,
        // and half again for the ends' rates, which the differences over a
        // piece of the segment see less sharp than they are.
        if (dv > kJointKink)
          cap = std::min(cap, 0.25 * jk * cycle * cycle / dv);
        if (da > kJointKink)
          cap = std::min(cap, std::sqrt(0.25 * jk * cycle / da));
      }
    }
    junctionCap.push_back(cap);
    lastEnds = ends;
    lastTilted = tilted;
    budget.limitsFor(d, feed, info);
    // Where the joints are at the segment's end: where jointDemand left them
    // on a tilted one; on an upright one, the inverse kinematics from the
    // last recorded (the rotary axes kept; only recorded, the caps of the
    // tilted segments keep chaining from the last tilted one).
    if (byJoints)
      recorded = joints;
    else
      record(seg);
    out.joints.insert(out.joints.end(), recorded.data(), recorded.data() + recorded.size());
  };
  // With the joints planned, each segment waits in out.segments until the
  // one after it is known, so that the orientation can be smoothed across
  // their junction (smoothJunction) before either is planned.
  // (Each with its axis's great circle, found once.)
  struct Pending {
    double feed = 0;
    uint32_t move = 0, next = 0;
    StopReason stop = StopReason::None;
    AxisDemand demand;
    GreatCircle circle;
  };
  std::optional<Pending> pending;
  const double axisTolerance =
      options.axisToleranceDeg.value_or(machine.orientationTolerance) * std::numbers::pi / 180;
  // The pending segment: out.segments' last, or the one before the last
  // (`behind`) while the one after it is being joined to it.
  auto flush = [&](size_t behind = 0) {
    if (pending) {
      push(out.segments.size() - 1 - behind, pending->feed, pending->move, pending->next, pending->stop,
           pending->demand, &pending->circle);
      pending.reset();
    }
  };
  auto emit = [&](double feed, uint32_t move, uint32_t next, StopReason stop, const AxisDemand &demand) {
    if (!options.kinematics) {
      push(out.segments.size() - 1, feed, move, next, stop, demand, nullptr);
      return;
    }
    const GreatCircle circle(out.segments.back().axis0, out.segments.back().axis1);
    if (pending) {
      // out.segments ends with the pending segment and this one. Not next
      // to a rapid: one that turns the tool starts its rotary axes afresh
      // (turnFirst).
      const size_t n = out.segments.size();
      if (stop == StopReason::None && pending->feed > 0 && feed > 0)
        smoothJunction(out.segments[n - 2], pending->circle, out.segments[n - 1], circle, axisTolerance);
      flush(1);
    }
    pending = Pending{feed, move, next, stop, demand, circle};
  };
  StopReason stop = StopReason::Start;
  // The dwells before piece `piece`: a segment each, at rest (their limits
  // zero: nothing moves), and the segment after them starts at rest.
  size_t nextDwell = 0;
  auto pushDwells = [&](size_t piece) {
    if (nextDwell < dwells.size() && dwells[nextDwell].beforePiece == piece)
      flush();
    for (; nextDwell < dwells.size() && dwells[nextDwell].beforePiece == piece; ++nextDwell) {
      const PieceDwell &d = dwells[nextDwell];
      out.segments.push_back(Segment::dwell(input.moves[d.move].to));
      lengths.push_back(0);
      SegmentInfo &info = out.info.emplace_back();
      info.move = d.move;
      info.nextMove = d.move;
      info.stop = StopReason::Dwell;
      stop = StopReason::Dwell;
      dwellTimes.push_back(d.timeS);
      if (options.kinematics) {
        junctionCap.push_back(kInf);
        record(out.segments.back());
        out.joints.insert(out.joints.end(), recorded.data(), recorded.data() + recorded.size());
      }
    }
  };
  {
    Segment segments[2];  // piece i's in segments[i % 2]
    Vec3 axisOut = input.startAxis;  // the tool axis where the last piece's blend starts
    for (size_t i = 0; i < pieces.size(); ++i) {
      const Piece &p = pieces[i];
      const Segment &before = segments[(i + 1) % 2], &here = segments[i % 2];
      p.segment(input, segments[i % 2]);
      // The piece's axis on its great circle, found once for both ends.
      const GreatCircle hereCircle(here.axis0, here.axis1);
      const Vec3 axisIn = here.axisAt(p.cutStart, hereCircle);  // where the blend before this piece ends
      if (i > 0 && p.stopReason != StopReason::None)
        stop = p.stopReason;
      pushDwells(i);
      if (i > 0) {
        if (p.blendBefore) {
          const Piece &prev = pieces[i - 1];
          double feed = 0;  // the slower of the two; a rapid takes the feed of the other
          if (prev.feed > 0 && p.feed > 0)
            feed = std::min(prev.feed, p.feed);
          else
            feed = std::max(prev.feed, p.feed);
          AxisDemand demand;
          out.segments.push_back(Segment::blend(blendBetween(prev, before, p, here), demand));
          out.segments.back().axis0 = axisOut;
          out.segments.back().axis1 = axisIn;
          emit(feed, prev.move, p.move, stop, demand);
          stop = StopReason::None;
        }
      }
      if (p.keepsMiddle()) {
        out.segments.push_back(here.part(p.cutStart, here.length - p.cutEnd));  // its axes turned with it
        emit(p.feed, p.move, p.move, stop, out.segments.back().demand());
        stop = StopReason::None;
      }
      axisOut = here.axisAt(here.length - p.cutEnd, hereCircle);
    }
    flush();
    pushDwells(pieces.size());  // after the last move
  }
  std::vector<Piece>().swap(pieces);  // not needed any more: its memory serves the steps below

  // 4. Runs: consecutive segments too short to reach their caps on their
  // own, none starting at rest, with caps within kRunCapSpread of each other,
  // share one profile planned over their total length with the least of
  // their limits (each member's bounds then hold) and cut at the members'
  // ends: speed changes spread over many short segments instead of each
  // starting and ending with zero acceleration.
  const size_t n = out.segments.size();
  struct Run {
    uint32_t first = 0, last = 0;  ///< segments (a trajectory's segment count fits, as its moves' do)
    bool fromRest = false;         ///< its first segment starts at rest
    double length = 0;
    PathLimits limits;
  };
  auto isShort = [&](size_t k) {
    const PathLimits &l = out.info[k].limits;
    return lengths[k] < rampDistance(0, l.v, l.a, l.j);
  };
  std::vector<Run> runs;
  runs.reserve(n);
  for (size_t k = 0; k < n;) {
    Run r;
    r.first = r.last = uint32_t(k);
    r.fromRest = out.info[k].stop != StopReason::None;
    r.length = lengths[k];
    r.limits = out.info[k].limits;
    double highest = r.limits.v;
    auto junctionFree = [&](size_t j) { return junctionCap.empty() || junctionCap[j] == kInf; };
    if (isShort(k)) {
      while (r.last + 1 < n && out.info[r.last + 1].stop == StopReason::None && isShort(r.last + 1) &&
             junctionFree(r.last + 1)) {
        const PathLimits &l = out.info[r.last + 1].limits;
        if (std::min(r.limits.v, l.v) < kRunCapSpread * std::max(highest, l.v))
          break;
        ++r.last;
        r.length += lengths[r.last];
        highest = std::max(highest, l.v);
        r.limits = {std::min(r.limits.v, l.v), std::min(r.limits.a, l.a), std::min(r.limits.j, l.j)};
      }
    }
    runs.push_back(r);
    k = r.last + 1;
  }

  // 5. Speeds where runs meet: caps, then backward and forward look-ahead.
  const size_t m = runs.size();
  std::vector<double> vj(m + 1, 0.0);
  for (size_t r = 1; r < m; ++r) {
    vj[r] = runs[r].fromRest ? 0 : std::min(runs[r - 1].limits.v, runs[r].limits.v);
    if (!junctionCap.empty())
      vj[r] = std::min(vj[r], junctionCap[runs[r].first]);
  }
  // A run's far end bounds its near end by the speed reachable from it over
  // the run (reachableSpeed), which binds only where the change between the
  // two does not fit in the run's length: where it fits (or the near end is
  // the slower), the bound keeps its value without the cubic's root.
  auto bound = [&](double &near, double far, const Run &run) {
    if (near > far && rampDistance(far, near, run.limits.a, run.limits.j) > run.length)
      near = std::min(near, reachableSpeed(far, run.length, run.limits.a, run.limits.j));
  };
  for (size_t r = m; r-- > 0;)
    bound(vj[r], vj[r + 1], runs[r]);
  for (size_t r = 0; r < m; ++r)
    bound(vj[r + 1], vj[r], runs[r]);

  // 6. Profiles: one per run, cut at its members' ends; a dwell's is its
  // wait at rest. (A dwell is a run of its own: it and the segment after it
  // start at rest.)
  out.profiles.reserve(n);
  preferHugePages(out.profiles);
  size_t dwellAt = 0;  // dwells come in the order of `dwells`
  for (size_t r = 0; r < m; ++r) {
    const Run &run = runs[r];
    if (lengths[run.first] == 0) {  // only dwells have no length (moves of none make no piece)
      out.profiles.push_back(dwellProfile(dwellTimes[dwellAt++]));
      continue;
    }
    const Profile whole = planProfile(vj[r], vj[r + 1], run.length, run.limits);
    if (run.first == run.last) {
      out.profiles.push_back(whole);
      continue;
    }
    double t0 = 0, along = 0;
    for (size_t k = run.first; k <= run.last; ++k) {
      along += lengths[k];
      const double t1 = k == run.last ? whole.duration() : whole.timeAt(along);
      out.profiles.push_back(whole.slice(t0, t1));
      out.info[k].limits = run.limits;
      t0 = t1;
    }
  }
  return out;
}

} // namespace stepnc::runtime
