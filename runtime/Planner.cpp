#include "runtime/Planner.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace stepnc::runtime {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// How an axis's budget is shared on a curved segment (REFERENCES: v <=
// sqrt(a rho), (j rho^2)^(1/3)). At the speed cap the curvature may take
// kCurveAccel of an axis's acceleration and kCurveJerk of its jerk; the
// coupling term 3 v a r2 at most kCouplingJerk. What is left is the path's
// own acceleration and jerk, so that speed can still change on the segment.
constexpr double kCurveAccel = 0.8;
constexpr double kCurveJerk = 0.6;
constexpr double kCouplingJerk = 0.2;

/// Turning more than this (radians) is a reversal: the tool stops.
constexpr double kReversal = 179.0 * 3.14159265358979323846 / 180.0;
/// Blends shorter than this (mm on each side) are not made; the tool stops.
constexpr double kTinyBlend = 1e-6;
/// Share of the tolerance blends use; sampled deviations may miss a little.
constexpr double kToleranceShare = 0.9;
/// Segments whose caps differ by more than this factor are not one run.
constexpr double kRunCapSpread = 0.8;

struct Piece {
  Segment seg;
  double feed = 0;  ///< mm/s; 0 for rapids
  uint32_t move = 0;
  bool stopBefore = false;
  double cutStart = 0, cutEnd = 0;  ///< mm taken by blends at either end
  /// A line wholly taken by the blends at its ends, inside a chain of short
  /// lines: the curvature the two blends share at its middle (see
  /// smoothChains).
  std::optional<Vec3> midCurvature;
};

/// The part [s0, s1] of a line or arc, ready for many distance queries.
/// Distances to helices are an upper bound (a point of the helix at the
/// query's angle).
class PartDistance {
public:
  PartDistance(const Segment &seg, double s0, double s1) {
    first_ = seg.at(s0).p;
    last_ = seg.at(s1).p;
    line_ = seg.kind == SegmentKind::Line;
    if (line_) {
      dir_ = seg.length > 0 ? Vec3((seg.end - seg.start) / seg.length) : Vec3::Zero();
      span_ = s1 - s0;
      return;
    }
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
  }

  double operator()(const Vec3 &p) const {
    if (line_) {
      const double s = std::clamp((p - first_).dot(dir_), 0.0, span_);
      return (first_ + dir_ * s - p).norm();
    }
    constexpr double kTurn = 2 * 3.14159265358979323846;
    double best = std::min((first_ - p).norm(), (last_ - p).norm());
    // The angle of p about the axis, from the part's start, taken into [0, 2 pi).
    double theta = sigma_ * (std::atan2(p.y() - centre_.y(), p.x() - centre_.x()) - startAngle_) - t0_;
    theta -= kTurn * std::floor(theta / kTurn);
    for (double t = t0_ + theta; t <= t1_; t += kTurn) {
      const double phi = startAngle_ + sigma_ * t;
      const Vec3 q(centre_.x() + radius_ * std::cos(phi), centre_.y() + radius_ * std::sin(phi), z0_ + rise_ * t);
      best = std::min(best, (q - p).norm());
    }
    return best;
  }

private:
  Vec3 first_, last_, dir_ = Vec3::Zero(), centre_ = Vec3::Zero();
  bool line_ = true;
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
/// its parameter: no arc-length inversion needed to find the worst point).
double blendDeviation(const std::array<Vec3, 6> &ctrl, const Segment &a, double la, const Segment &b, double lb) {
  constexpr int kSamples = 24;
  const QuinticCurve curve(ctrl);
  const PartDistance toA(a, a.length - la, a.length), toB(b, 0, lb);
  double worst = 0;
  for (int i = 1; i < kSamples; ++i) {
    const Vec3 p = curve.point(double(i) / kSamples);
    worst = std::max(worst, std::min(toA(p), toB(p)));
  }
  return worst;
}

struct Junction {
  bool stop = false;
  StopReason reason = StopReason::None;
  bool blended = false;
  Segment blend;
};

/// Decides how pieces a and b meet: smoothly, through a blend, or at rest.
Junction join(Piece &a, Piece &b, double tolerance) {
  Junction j;
  if (b.stopBefore) {
    j.stop = true;
    j.reason = StopReason::Program;
    return j;
  }
  const PathPoint ea = a.seg.at(a.seg.length), sb = b.seg.at(0);
  const double cosTurn = std::clamp(ea.r1.dot(sb.r1), -1.0, 1.0);
  const double turn = std::acos(cosTurn);
  const double scale = 1 / std::max(1e-3, std::max(ea.r2.norm(), sb.r2.norm()));  // a length of the curves
  if (turn < 1e-9 && (ea.r2 - sb.r2).norm() * scale < 1e-9)
    return j;  // tangent and curvature already agree
  if (turn > kReversal) {
    j.stop = true;
    j.reason = StopReason::Reversal;
    return j;
  }
  // Cut back as far as the tolerance allows, at most half of each piece
  // (the other half belongs to the blend at its other end).
  const double target = tolerance * kToleranceShare;
  double l = std::min(a.seg.length / 2, b.seg.length / 2);
  const bool linear = a.seg.kind == SegmentKind::Line && b.seg.kind == SegmentKind::Line;
  if (linear) {
    // Between two lines the blend is symmetric about the corner's bisector
    // and the same shape at every size: its deviation is its middle's
    // distance from the lines, proportional to l.
    const QuinticCurve curve(blendPoints(a.seg, l, b.seg, l));
    const Vec3 mid = curve.point(0.5), dir = a.seg.at(0).r1;
    const Vec3 off = mid - a.seg.end;
    const double dev = (off - dir * off.dot(dir)).norm();
    if (dev > target)
      l *= target / dev;
    if (l >= kTinyBlend) {
      j.blended = true;
      j.blend = Segment::blend(blendPoints(a.seg, l, b.seg, l));
      a.cutEnd = l;
      b.cutStart = l;
      return j;
    }
  }
  double lastL = 0, lastDev = 0;
  for (int it = 0; it < 40 && l >= kTinyBlend; ++it) {
    const std::array<Vec3, 6> ctrl = blendPoints(a.seg, l, b.seg, l);
    const double dev = blendDeviation(ctrl, a.seg, l, b.seg, l);
    if (dev <= target) {
      j.blended = true;
      j.blend = Segment::blend(ctrl);
      a.cutEnd = l;
      b.cutStart = l;
      return j;
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
  j.stop = true;
  j.reason = StopReason::Tiny;
  return j;
}

/// The speed cap and the path acceleration and jerk for one segment.
void limitsFor(const Segment &seg, double feed, const Machine &machine, SegmentInfo &info) {
  const AxisDemand d = seg.demand();
  double v = kInf;
  SpeedLimit by = SpeedLimit::Feed;
  auto cap = [&](double value, SpeedLimit why) {
    if (value < v) {
      v = value;
      by = why;
    }
  };
  if (feed > 0) {
    cap(feed, SpeedLimit::Feed);
    if (machine.maxFeed)
      cap(*machine.maxFeed / 60, SpeedLimit::MachineFeed);
  }
  const size_t n = std::min<size_t>(3, machine.axes.size());
  for (size_t k = 0; k < n; ++k) {
    const Axis &ax = machine.axes[k];
    if (d.r1[k] > 0)
      cap(ax.velocity / 60 / d.r1[k], SpeedLimit::AxisVelocity);
    if (d.r2[k] > 0)
      cap(std::sqrt(kCurveAccel * ax.acceleration / d.r2[k]), SpeedLimit::Acceleration);
    if (d.r3[k] > 0)
      cap(std::cbrt(kCurveJerk * ax.jerk / d.r3[k]), SpeedLimit::Jerk);
  }
  double a = kInf, jerk = kInf;
  for (size_t k = 0; k < n; ++k) {
    const Axis &ax = machine.axes[k];
    if (d.r1[k] <= 0)
      continue;
    double ak = (ax.acceleration - v * v * d.r2[k]) / d.r1[k];
    if (d.r2[k] > 0 && v > 0)
      ak = std::min(ak, kCouplingJerk * ax.jerk / (3 * v * d.r2[k]));
    a = std::min(a, ak);
  }
  for (size_t k = 0; k < n; ++k) {
    const Axis &ax = machine.axes[k];
    if (d.r1[k] > 0)
      jerk = std::min(jerk, (ax.jerk - v * v * v * d.r3[k] - 3 * v * a * d.r2[k]) / d.r1[k]);
  }
  info.limits = {v, a, jerk};
  info.limitedBy = by;
}

/// The curvature vector of the circle through the vertex between lines a and
/// b and the vertices before and after it; zero when either is not a line.
Vec3 vertexCurvature(const Piece &a, const Piece &b) {
  if (a.seg.kind != SegmentKind::Line || b.seg.kind != SegmentKind::Line)
    return Vec3::Zero();
  const Vec3 ta = (a.seg.end - a.seg.start) / a.seg.length, tb = (b.seg.end - b.seg.start) / b.seg.length;
  const Vec3 turn = tb - ta;
  const double chord = (a.seg.end - a.seg.start + b.seg.end - b.seg.start).norm();
  const double sinTurn = ta.cross(tb).norm();
  if (turn.norm() <= 0 || chord <= 0)
    return Vec3::Zero();
  return turn.normalized() * (2 * sinTurn / chord);
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
/// middle's two blends agree.
void smoothChains(std::vector<Piece> &pieces, std::vector<Junction> &joins, double tolerance) {
  const size_t n = pieces.size();
  auto consumed = [&](size_t i) {
    const Piece &p = pieces[i];
    return p.seg.kind == SegmentKind::Line && i > 0 && i + 1 < n && joins[i].blended && joins[i + 1].blended &&
           p.seg.length - p.cutStart - p.cutEnd <= 1e-9;  // what is left is dropped (plan, step 3)
  };
  for (size_t i = 0; i < n; ++i) {
    if (!consumed(i))
      continue;
    const Vec3 t = (pieces[i].seg.end - pieces[i].seg.start) / pieces[i].seg.length;
    Vec3 k = (vertexCurvature(pieces[i - 1], pieces[i]) + vertexCurvature(pieces[i], pieces[i + 1])) / 2;
    k -= t * k.dot(t);  // normal to the line, as curvature is
    pieces[i].midCurvature = k;
  }
  // The end of a blend: the piece's own point, with the shared curvature at
  // a smoothed middle.
  auto endPoint = [&](const Piece &p, double s) {
    PathPoint pt = p.seg.at(s);
    if (p.midCurvature)
      pt.r2 = *p.midCurvature;
    return pt;
  };
  const double target = tolerance * kToleranceShare;
  std::vector<char> pending(n, 0);
  for (size_t j = 1; j < n; ++j)
    pending[j] = joins[j].blended && (pieces[j - 1].midCurvature || pieces[j].midCurvature);
  for (bool again = true; again;) {
    again = false;
    for (size_t j = 1; j < n; ++j) {
      if (!pending[j])
        continue;
      pending[j] = 0;
      Piece &a = pieces[j - 1], &b = pieces[j];
      if (!a.midCurvature && !b.midCurvature) {
        // Zero-curvature ends again: the blend join() made and checked.
        joins[j].blend = Segment::blend(blendPoints(a.seg, a.cutEnd, b.seg, b.cutStart));
        continue;
      }
      const double la = a.cutEnd, lb = b.cutStart;
      const std::array<Vec3, 6> ctrl = blendPoints(endPoint(a, a.seg.length - la), endPoint(b, lb));
      if (blendDeviation(ctrl, a.seg, la, b.seg, lb) <= target) {
        joins[j].blend = Segment::blend(ctrl);
        continue;
      }
      // Back to zero curvature at both ends; the blends across those
      // middles are made again to match.
      for (size_t side : {j - 1, j}) {
        if (!pieces[side].midCurvature)
          continue;
        pieces[side].midCurvature.reset();
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

  // 1. One piece per move with any length.
  std::vector<Piece> pieces;
  pieces.reserve(input.moves.size());
  Vec3 at = input.start;
  bool pendingStop = false;
  for (size_t i = 0; i < input.moves.size(); ++i) {
    const PathMove &m = input.moves[i];
    pendingStop = pendingStop || m.stopBefore;
    Piece p;
    p.seg = m.kind == PathMove::Kind::Line ? Segment::line(at, m.to)
                                           : Segment::arcTurns(at, m.to, m.center, m.ccw, m.turns);
    if (!(p.seg.length > 1e-9)) {
      at = m.to;
      continue;
    }
    p.feed = m.feed > 0 ? m.feed / 60 : 0;
    p.move = uint32_t(i);
    p.stopBefore = pendingStop;
    pendingStop = false;
    pieces.push_back(std::move(p));
    at = m.to;
  }

  // 2. Junctions: blends or stops.
  std::vector<Junction> joins(pieces.size());
  for (size_t i = 1; i < pieces.size(); ++i)
    joins[i] = join(pieces[i - 1], pieces[i], tolerance);
  smoothChains(pieces, joins, tolerance);

  // 3. Segments with their caps.
  auto push = [&](Segment seg, double feed, uint32_t move, uint32_t next, StopReason stop) {
    SegmentInfo info;
    info.feed = feed;
    info.move = move;
    info.nextMove = next;
    info.stop = stop;
    limitsFor(seg, feed, machine, info);
    out.segments.push_back(std::move(seg));
    out.info.push_back(info);
  };
  out.segments.reserve(pieces.size() * 2);
  out.info.reserve(pieces.size() * 2);
  StopReason stop = StopReason::Start;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const Piece &p = pieces[i];
    if (i > 0) {
      const Junction &jn = joins[i];
      if (jn.stop)
        stop = jn.reason;
      if (jn.blended) {
        const Piece &prev = pieces[i - 1];
        double feed = 0;  // the slower of the two; a rapid takes the feed of the other
        if (prev.feed > 0 && p.feed > 0)
          feed = std::min(prev.feed, p.feed);
        else
          feed = std::max(prev.feed, p.feed);
        push(jn.blend, feed, prev.move, p.move, stop);
        stop = StopReason::None;
      }
    }
    const double s0 = p.cutStart, s1 = p.seg.length - p.cutEnd;
    if (s1 - s0 > 1e-9) {
      push(p.seg.part(s0, s1), p.feed, p.move, p.move, stop);
      stop = StopReason::None;
    }
  }

  // 4. Runs: consecutive segments too short to reach their caps on their
  // own, none starting at rest, with caps within kRunCapSpread of each other,
  // share one profile planned over their total length with the least of
  // their limits (each member's bounds then hold) and cut at the members'
  // ends: speed changes spread over many short segments instead of each
  // starting and ending with zero acceleration.
  const size_t n = out.segments.size();
  struct Run {
    size_t first = 0, last = 0;
    double length = 0;
    PathLimits limits;
  };
  auto isShort = [&](size_t k) {
    const PathLimits &l = out.info[k].limits;
    return out.segments[k].length < rampDistance(0, l.v, l.a, l.j);
  };
  std::vector<Run> runs;
  for (size_t k = 0; k < n;) {
    Run r;
    r.first = r.last = k;
    r.length = out.segments[k].length;
    r.limits = out.info[k].limits;
    double highest = r.limits.v;
    if (isShort(k)) {
      while (r.last + 1 < n && out.info[r.last + 1].stop == StopReason::None && isShort(r.last + 1)) {
        const PathLimits &l = out.info[r.last + 1].limits;
        if (std::min(r.limits.v, l.v) < kRunCapSpread * std::max(highest, l.v))
          break;
        ++r.last;
        r.length += out.segments[r.last].length;
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
  for (size_t r = 1; r < m; ++r)
    vj[r] = out.info[runs[r].first].stop != StopReason::None ? 0 : std::min(runs[r - 1].limits.v, runs[r].limits.v);
  for (size_t r = m; r-- > 0;)
    vj[r] = std::min(vj[r], reachableSpeed(vj[r + 1], runs[r].length, runs[r].limits.a, runs[r].limits.j));
  for (size_t r = 0; r < m; ++r)
    vj[r + 1] = std::min(vj[r + 1], reachableSpeed(vj[r], runs[r].length, runs[r].limits.a, runs[r].limits.j));

  // 6. Profiles: one per run, cut at its members' ends.
  out.profiles.reserve(n);
  for (size_t r = 0; r < m; ++r) {
    const Run &run = runs[r];
    const Profile whole = planProfile(vj[r], vj[r + 1], run.length, run.limits);
    if (run.first == run.last) {
      out.profiles.push_back(whole);
      continue;
    }
    double t0 = 0, along = 0;
    for (size_t k = run.first; k <= run.last; ++k) {
      along += out.segments[k].length;
      const double t1 = k == run.last ? whole.duration() : whole.timeAt(along);
      out.profiles.push_back(whole.slice(t0, t1));
      out.info[k].limits = run.limits;
      t0 = t1;
    }
  }
  return out;
}

} // namespace stepnc::runtime
