// Plane geometry of lines and circular arcs: the shapes strategy expansion
// offsets and clips, and the shapes the toolpath verifier measures.
//
// Everything is in one plane (the feature's xy plane, mm). Arcs stay arcs: a
// pocket's corner radius, a round join between offset passes and a hole are
// circles to the end, so a backend can write G2/G3 instead of polylines.
//
// Conventions used by every function here:
// - A Seg is a straight segment or a circular arc from `a` to `b`. An arc turns
//   counter-clockwise (turn = +1) or clockwise (turn = -1) about `c`; it sweeps
//   strictly between 0 and 2*pi. A full circle is two half arcs.
// - A Loop is a closed chain: each Seg ends where the next begins, the last
//   ends where the first begins.
// - A Region is a set of loops: outer boundaries counter-clockwise, holes
//   clockwise, no two loops crossing. A point is inside when the loops wind
//   around it a non-zero number of times.
// - Lengths are mm; `kEps` (1e-9 mm) is the distance below which two points are
//   the same.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace stepnc::geom {

using Vec2 = Eigen::Vector2d;

inline constexpr double kEps = 1e-9;

inline double cross(const Vec2 &u, const Vec2 &v) { return u.x() * v.y() - u.y() * v.x(); }

struct Box {
  Vec2 lo{1e300, 1e300};
  Vec2 hi{-1e300, -1e300};
  void add(const Vec2 &p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void add(const Box &b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool empty() const { return lo.x() > hi.x(); }
  Box grown(double d) const { return {lo - Vec2(d, d), hi + Vec2(d, d)}; }
  bool overlaps(const Box &b) const {
    return lo.x() <= b.hi.x() && b.lo.x() <= hi.x() && lo.y() <= b.hi.y() && b.lo.y() <= hi.y();
  }
};

struct Seg {
  Vec2 a = Vec2::Zero();
  Vec2 b = Vec2::Zero();
  Vec2 c = Vec2::Zero();  ///< arc centre; unused for lines
  int8_t turn = 0;        ///< 0: line, +1: counter-clockwise arc, -1: clockwise arc

  static Seg line(const Vec2 &a, const Vec2 &b) { return {a, b, Vec2::Zero(), 0}; }
  static Seg arc(const Vec2 &a, const Vec2 &b, const Vec2 &c, bool ccw) { return {a, b, c, int8_t(ccw ? 1 : -1)}; }

  bool isArc() const { return turn != 0; }
  double radius() const;   ///< |a - c|; 0 for lines
  double sweep() const;    ///< signed angle a -> b about c, in (0, 2pi) or (-2pi, 0); 0 for lines
  double length() const;
  Vec2 at(double t) const;       ///< point at fraction t of the length, t in [0, 1]
  Vec2 tangent(double t) const;  ///< unit direction of travel at fraction t
  Seg reversed() const;
  Box box() const;  ///< tight, including arc extremes
};

/// Splits a full circle of centre c and radius r into two half arcs starting at `start`.
std::vector<Seg> circle(const Vec2 &c, double r, bool ccw, const Vec2 &start);

struct Loop {
  std::vector<Seg> segs;

  double area() const;  ///< signed: positive when counter-clockwise; exact for arcs
  double length() const;
  Box box() const;
  void reverse();
  /// Winding number of the loop about p (p not on the loop).
  int winding(const Vec2 &p) const;
};

/// A closed polygon through the points, in their order.
Loop polygon(const std::vector<Vec2> &pts);
/// The counter-clockwise rectangle [lo, hi] with corners rounded to radius r
/// (clamped to half the shorter side; sharp when r is 0), starting on its
/// bottom side.
Loop roundedRectangle(const Vec2 &lo, const Vec2 &hi, double r);
/// A circle as two half arcs, the first from its east point (c + (r, 0)).
Loop circleLoop(const Vec2 &c, double r, bool ccw);

struct Region {
  std::vector<Loop> loops;

  double area() const;  ///< sum of signed loop areas
  Box box() const;
  bool contains(const Vec2 &p) const;  ///< non-zero total winding
  bool empty() const { return loops.empty(); }
};

/// An open or closed chain of segments (a tool-centre path piece).
struct Chain {
  std::vector<Seg> segs;
  bool closed() const { return !segs.empty() && (segs.front().a - segs.back().b).norm() <= kEps * 1e3; }
  double length() const;
};

// --- Distances and intersections ---------------------------------------------

/// The centre nearest to `centre` that lies as far from `from` as from `to`
/// (on the chord's perpendicular bisector): an arc from `from` to `to` about
/// it starts and ends at one radius. A whole circle (from == to) keeps its
/// centre.
Vec2 balancedCentre(const Vec2 &from, const Vec2 &to, const Vec2 &centre);

Vec2 closestPoint(const Seg &s, const Vec2 &p);
double distance(const Seg &s, const Vec2 &p);
/// Smallest distance between two segments (0 when they meet).
double distance(const Seg &s, const Seg &t);
/// Points where two segments meet (0, 1 or 2; overlapping pieces give their end points).
std::vector<Vec2> intersect(const Seg &s, const Seg &t);

/// Answers "how far is p from this set of segments" quickly: a uniform grid
/// over the segments' boxes. Built once per boundary, queried many times.
class SegIndex {
public:
  explicit SegIndex(std::vector<Seg> segs);
  static SegIndex of(const Region &r);
  double distance(const Vec2 &p) const;
  /// Whether some indexed segment is closer than r to p (faster than distance:
  /// stops at the first one found); that segment's index goes to `which`.
  bool within(const Vec2 &p, double r, uint32_t *which = nullptr) const;
  /// Smallest distance from the segment s to any indexed segment.
  double distance(const Seg &s) const;
  /// Indices of the segments whose boxes overlap `box` (replaces the contents of `out`).
  void query(const Box &box, std::vector<uint32_t> &out) const;
  /// Winding number of the indexed segments about p, when they form closed
  /// loops (a Region's segments); p not on them. Visits one row of cells.
  int winding(const Vec2 &p) const;
  const std::vector<Seg> &segs() const { return segs_; }

private:
  /// Ring search about p for segments closer than `limit`; returns the
  /// smallest distance found (`limit` when none) and its segment's index in
  /// `which` (when not null), or stops at the first when `firstOnly`.
  double search(const Vec2 &p, double limit, bool firstOnly, uint32_t *which) const;
  int cellX(double x) const;
  int cellY(double y) const;
  uint32_t nextEpoch() const;

  std::vector<Seg> segs_;
  std::vector<Box> boxes_;  ///< segs_[i].box()
  Box box_;
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<uint32_t> cellStart_;  ///< CSR layout: cellStart_[k]..cellStart_[k+1] index cellItems_
  std::vector<uint32_t> cellItems_;
  mutable std::vector<uint32_t> stamp_;  ///< de-duplication in queries
  mutable uint32_t epoch_ = 0;
};

/// The convex hull of `points`, counter-clockwise from its lowest-x point,
/// without collinear points (Andrew's monotone chain); fewer than three
/// distinct points come back as they are, sorted.
std::vector<Vec2> convexHull(std::vector<Vec2> points);

/// The region's mirror image across the x axis (y negated), each loop
/// reversed so that it keeps its orientation.
Region mirroredAcrossX(const Region &r);

// --- Offsets and clipping (the generator's tools) -----------------------------

/// The region grown (d > 0) or shrunk (d < 0) by |d|: every point at distance
/// <= d from the region, or every point at distance >= -d from its complement.
/// Corners are joined by arcs of radius |d|; arcs stay arcs. The result follows
/// the Region conventions; pieces thinner than kEps vanish.
Region offset(const Region &r, double d);

/// The parts of the segment p -> q inside the region, in order from p.
std::vector<Seg> clip(const Region &r, const Vec2 &p, const Vec2 &q);

} // namespace stepnc::geom
