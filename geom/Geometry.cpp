// Plane geometry of lines and circular arcs: measures, point location,
// distances, intersections and the segment grid. Conventions: Geometry.h.
#include "geom/Geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace stepnc::geom {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// v turned a quarter turn counter-clockwise.
Vec2 perp(const Vec2 &v) { return {-v.y(), v.x()}; }

Vec2 rotate(const Vec2 &v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

// --- Angles along arcs ---------------------------------------------------------
//
// Tests of whether a direction lies within an arc's span use a pseudo-angle:
// a number in [0, 4) that increases with the angle of a vector (0 along +x,
// 1 along +y, 2 along -x, 3 along -y) and needs no trigonometry.

double pseudoAngle(const Vec2 &v) {
  const double sum = std::abs(v.x()) + std::abs(v.y());
  if (sum == 0)
    return 0;
  const double t = v.y() / sum; // in [-1, 1]
  return v.x() >= 0 ? (t >= 0 ? t : 4 + t) : 2 - t;
}

/// Pseudo-angle travelled along the arc `s` (in its direction) from pseudo-angle
/// `from` to pseudo-angle `to`, in [0, 4).
double pseudoTravel(const Seg &s, double from, double to) {
  const double travel = s.turn > 0 ? to - from : from - to;
  return travel < 0 ? travel + 4 : travel;
}

/// The arc's span as a pseudo-angle travel (0 for a degenerate arc, a == b).
double pseudoSweep(const Seg &s, double start) { return pseudoTravel(s, start, pseudoAngle(s.b - s.c)); }

/// Whether the direction of q from the arc's centre lies within the arc's
/// angular span, or q is within `tol` of one of the arc's ends.
bool inSpan(const Seg &s, const Vec2 &q, double tol = 0) {
  if (tol > 0 && ((q - s.a).norm() <= tol || (q - s.b).norm() <= tol))
    return true;
  const double start = pseudoAngle(s.a - s.c);
  return pseudoTravel(s, start, pseudoAngle(q - s.c)) <= pseudoSweep(s, start);
}

/// The circle's points at pseudo-angles 0, 1, 2, 3 (east, north, west, south).
const Vec2 kAxes[4] = {Vec2(1, 0), Vec2(0, 1), Vec2(-1, 0), Vec2(0, -1)};

/// Squared distance from p to the box (0 inside).
double boxDistance2(const Box &b, const Vec2 &p) {
  const double dx = std::max({b.lo.x() - p.x(), 0.0, p.x() - b.hi.x()});
  const double dy = std::max({b.lo.y() - p.y(), 0.0, p.y() - b.hi.y()});
  return dx * dx + dy * dy;
}

/// Distance between two boxes (0 when they overlap).
double boxDistance(const Box &a, const Box &b) {
  const double dx = std::max({a.lo.x() - b.hi.x(), 0.0, b.lo.x() - a.hi.x()});
  const double dy = std::max({a.lo.y() - b.hi.y(), 0.0, b.lo.y() - a.hi.y()});
  return std::hypot(dx, dy);
}

// --- Point location: signed crossings of the ray from p towards +x -----------
//
// Each crossing counts +1 when the boundary goes up through the ray and -1
// when it goes down; the sum over a closed loop is its winding number. The
// test is half-open in y (an end point counts as above when its y is greater
// than p's), so a ray through a shared end point is counted exactly once.

int lineCrossing(const Vec2 &a, const Vec2 &b, const Vec2 &p) {
  const bool aAbove = a.y() > p.y(), bAbove = b.y() > p.y();
  if (aAbove == bAbove)
    return 0;
  const double side = cross(b - a, p - a);
  if (bAbove)
    return side > 0 ? 1 : 0; // going up: the crossing is right of p when p is left of the line
  return side < 0 ? -1 : 0;  // going down: when p is right of the line
}

/// A piece u -> w of the circle (centre c, radius r) that is monotone in y and
/// lies on the circle's east (x >= c.x) or west half.
int monotoneArcCrossing(const Vec2 &u, const Vec2 &w, const Vec2 &c, double r, bool east, const Vec2 &p) {
  const bool uAbove = u.y() > p.y(), wAbove = w.y() > p.y();
  if (uAbove == wAbove)
    return 0;
  const double dy = p.y() - c.y();
  const double dx = std::sqrt(std::max(0.0, r * r - dy * dy));
  const double x = east ? c.x() + dx : c.x() - dx;
  if (x <= p.x())
    return 0;
  return wAbove ? 1 : -1;
}

/// An arc is cut at the top and bottom of its circle into y-monotone pieces.
int arcCrossings(const Seg &s, const Vec2 &p) {
  const double r = s.radius();
  if (p.x() >= s.c.x() + r || std::abs(p.y() - s.c.y()) > 2 * r)
    return 0;
  // Travel (pseudo-angle along the arc) to the top and the bottom of the
  // circle, where the arc is cut; Seg::box uses the same test.
  const double start = pseudoAngle(s.a - s.c), sweep = pseudoSweep(s, start);
  struct Cut {
    double travel;
    Vec2 at;
  };
  Cut cuts[2];
  int count = 0;
  for (int k : {1, 3}) {
    const double travel = pseudoTravel(s, start, k);
    if (travel > 0 && travel < sweep)
      cuts[count++] = {travel, s.c + r * kAxes[k]};
  }
  if (count == 2 && cuts[1].travel < cuts[0].travel)
    std::swap(cuts[0], cuts[1]);
  int sum = 0;
  Vec2 from = s.a;
  double fromTravel = 0;
  for (int k = 0; k <= count; ++k) {
    const Vec2 to = k < count ? cuts[k].at : s.b;
    const double toTravel = k < count ? cuts[k].travel : sweep;
    double mid = start + s.turn * (fromTravel + toTravel) / 2; // pseudo-angle inside the piece
    mid = mid < 0 ? mid + 4 : mid >= 4 ? mid - 4 : mid;
    const bool east = mid < 1 || mid > 3;
    sum += monotoneArcCrossing(from, to, s.c, r, east, p);
    from = to;
    fromTravel = toTravel;
  }
  return sum;
}

int crossings(const Seg &s, const Vec2 &p) {
  return s.isArc() ? arcCrossings(s, p) : lineCrossing(s.a, s.b, p);
}

// --- Intersections -----------------------------------------------------------

/// Adds q to the list unless a point within `tol` is already there; an end
/// point (`exact`) replaces a computed point it coincides with.
void addPoint(std::vector<Vec2> &pts, const Vec2 &q, double tol, bool exact) {
  for (Vec2 &p : pts) {
    if ((p - q).norm() <= tol) {
      if (exact)
        p = q;
      return;
    }
  }
  pts.push_back(q);
}

/// End points of either segment lying on the other (within tol); sb and tb
/// are the segments' boxes grown by tol.
void addTouchingEnds(const Seg &s, const Seg &t, const Box &sb, const Box &tb, double tol,
                     std::vector<Vec2> &pts) {
  for (const Vec2 &e : {s.a, s.b})
    if (boxDistance2(tb, e) == 0 && distance(t, e) <= tol)
      addPoint(pts, e, tol, true);
  for (const Vec2 &e : {t.a, t.b})
    if (boxDistance2(sb, e) == 0 && distance(s, e) <= tol)
      addPoint(pts, e, tol, true);
}

void intersectLines(const Seg &s, const Seg &t, const Box &sBox, const Box &tBox, double tol,
                    std::vector<Vec2> &pts) {
  const Vec2 d1 = s.b - s.a, d2 = t.b - t.a;
  const double l1 = d1.norm(), l2 = d2.norm();
  if (l1 > tol && l2 > tol) {
    // Signed distances of t's ends from s's line, and of s's ends from t's line.
    const double ta = cross(d1, t.a - s.a) / l1, tb = cross(d1, t.b - s.a) / l1;
    const double sa = cross(d2, s.a - t.a) / l2, sb = cross(d2, s.b - t.a) / l2;
    const bool collinear = std::abs(ta) <= tol && std::abs(tb) <= tol;
    const bool tApart = (ta > tol && tb > tol) || (ta < -tol && tb < -tol);
    const bool sApart = (sa > tol && sb > tol) || (sa < -tol && sb < -tol);
    if (!collinear && !tApart && !sApart) {
      // The ends of t are not both strictly on one side, so the lines are not
      // parallel (ta != tb) and the crossing is well defined.
      const double den = cross(d1, d2);
      if (den != 0) {
        const double u = cross(t.a - s.a, d2) / den;
        const double v = cross(t.a - s.a, d1) / den;
        if (u * l1 >= -tol && u * l1 <= l1 + tol && v * l2 >= -tol && v * l2 <= l2 + tol)
          addPoint(pts, s.a + std::clamp(u, 0.0, 1.0) * d1, tol, false);
      }
    }
  }
  // Collinear overlaps end at end points; touching ends and degenerate
  // (point-like) segments are found the same way.
  addTouchingEnds(s, t, sBox, tBox, tol, pts);
}

void intersectLineArc(const Seg &line, const Seg &arc, const Box &lb, const Box &ab, double tol,
                      std::vector<Vec2> &pts) {
  const Vec2 d = line.b - line.a;
  const double len = d.norm();
  const double r = arc.radius();
  if (len > tol) {
    const Vec2 u = d / len;
    const Vec2 f = arc.c - line.a;
    const double along = f.dot(u); // position of the centre's foot along the line
    const double h = cross(u, f);  // signed distance of the centre from the line
    const Vec2 foot = line.a + along * u;
    auto consider = [&](double at, const Vec2 &q) {
      if (at >= -tol && at <= len + tol && inSpan(arc, q, tol))
        addPoint(pts, q, tol, false);
    };
    if (std::abs(std::abs(h) - r) <= tol) {
      consider(along, foot); // tangent
    } else if (std::abs(h) < r) {
      const double half = std::sqrt(r * r - h * h);
      consider(along - half, foot - half * u);
      consider(along + half, foot + half * u);
    }
  }
  addTouchingEnds(line, arc, lb, ab, tol, pts);
}

void intersectArcs(const Seg &s, const Seg &t, const Box &sb, const Box &tb, double tol,
                   std::vector<Vec2> &pts) {
  const double r1 = s.radius(), r2 = t.radius();
  const Vec2 dc = t.c - s.c;
  const double dist = dc.norm();
  if (dist > tol) {
    const Vec2 u = dc / dist;
    auto consider = [&](const Vec2 &q) {
      if (inSpan(s, q, tol) && inSpan(t, q, tol))
        addPoint(pts, q, tol, false);
    };
    if (std::abs(dist - (r1 + r2)) <= tol) {
      consider(s.c + r1 * u); // touching from outside
    } else if (std::abs(dist - std::abs(r1 - r2)) <= tol) {
      consider(r1 >= r2 ? Vec2(s.c + r1 * u) : Vec2(s.c - r1 * u)); // touching from inside
    } else if (dist < r1 + r2 && dist > std::abs(r1 - r2)) {
      const double along = (dist * dist + r1 * r1 - r2 * r2) / (2 * dist);
      const double half = std::sqrt(std::max(0.0, r1 * r1 - along * along));
      const Vec2 base = s.c + along * u;
      consider(base + half * perp(u));
      consider(base - half * perp(u));
    }
  }
  // Same circle (overlapping arcs), touching ends.
  addTouchingEnds(s, t, sb, tb, tol, pts);
}

} // namespace

// --- Seg ---------------------------------------------------------------------

double Seg::radius() const { return isArc() ? (a - c).norm() : 0.0; }

double Seg::sweep() const {
  if (!isArc())
    return 0;
  const Vec2 u = a - c, v = b - c;
  double angle = std::atan2(cross(u, v), u.dot(v)); // in (-pi, pi]
  if (angle == 0)
    return 0; // a == b: degenerate (a full circle is two arcs)
  if (turn > 0 && angle < 0)
    angle += kTwoPi;
  else if (turn < 0 && angle > 0)
    angle -= kTwoPi;
  return angle;
}

double Seg::length() const { return isArc() ? radius() * std::abs(sweep()) : (b - a).norm(); }

Vec2 Seg::at(double t) const {
  if (t <= 0)
    return a;
  if (t >= 1)
    return b;
  if (!isArc())
    return a + t * (b - a);
  return c + rotate(a - c, t * sweep());
}

Vec2 Seg::tangent(double t) const {
  if (!isArc()) {
    const Vec2 d = b - a;
    const double n = d.norm();
    return n > 0 ? Vec2(d / n) : Vec2(1, 0);
  }
  const Vec2 radial = at(t) - c;
  const double n = radial.norm();
  return n > 0 ? Vec2(double(turn) * perp(radial) / n) : Vec2(1, 0);
}

Seg Seg::reversed() const { return {b, a, c, int8_t(-turn)}; }

Box Seg::box() const {
  Box bx;
  bx.add(a);
  bx.add(b);
  if (!isArc())
    return bx;
  const double r = radius(), start = pseudoAngle(a - c), span = pseudoSweep(*this, start);
  for (int k = 0; k < 4; ++k) {
    const double travel = pseudoTravel(*this, start, k);
    if (travel > 0 && travel < span)
      bx.add(c + r * kAxes[k]);
  }
  return bx;
}

std::vector<Seg> circle(const Vec2 &c, double r, bool ccw, const Vec2 &start) {
  const Vec2 dir = start - c;
  const double n = dir.norm();
  const Vec2 s = c + r * (n > 0 ? Vec2(dir / n) : Vec2(1, 0));
  const Vec2 opposite = 2 * c - s;
  return {Seg::arc(s, opposite, c, ccw), Seg::arc(opposite, s, c, ccw)};
}

Loop polygon(const std::vector<Vec2> &pts) {
  Loop l;
  for (size_t i = 0; i < pts.size(); ++i)
    l.segs.push_back(Seg::line(pts[i], pts[(i + 1) % pts.size()]));
  return l;
}

Loop roundedRectangle(const Vec2 &lo, const Vec2 &hi, double radius) {
  const double r = std::min({radius, (hi.x() - lo.x()) / 2, (hi.y() - lo.y()) / 2});
  if (r <= kEps)
    return polygon({lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}});
  Loop l;
  auto edge = [&](const Vec2 &a, const Vec2 &b) {
    if ((b - a).norm() > kEps)
      l.segs.push_back(Seg::line(a, b));
  };
  // Corner arcs from where one side ends to where the next begins, so that
  // pieces meet exactly.
  auto corner = [&](const Vec2 &a, const Vec2 &b, const Vec2 &c) { l.segs.push_back(Seg::arc(a, b, c, true)); };
  const double x0 = lo.x(), y0 = lo.y(), x1 = hi.x(), y1 = hi.y();
  edge({x0 + r, y0}, {x1 - r, y0});
  corner({x1 - r, y0}, {x1, y0 + r}, {x1 - r, y0 + r});
  edge({x1, y0 + r}, {x1, y1 - r});
  corner({x1, y1 - r}, {x1 - r, y1}, {x1 - r, y1 - r});
  edge({x1 - r, y1}, {x0 + r, y1});
  corner({x0 + r, y1}, {x0, y1 - r}, {x0 + r, y1 - r});
  edge({x0, y1 - r}, {x0, y0 + r});
  corner({x0, y0 + r}, {x0 + r, y0}, {x0 + r, y0 + r});
  return l;
}

Loop circleLoop(const Vec2 &c, double r, bool ccw) {
  const Vec2 east = c + Vec2(r, 0), west = c - Vec2(r, 0);
  Loop l;
  l.segs = {Seg::arc(east, west, c, ccw), Seg::arc(west, east, c, ccw)};
  return l;
}

// --- Loop, Region, Chain -----------------------------------------------------

double Loop::area() const {
  if (segs.empty())
    return 0;
  // Green's theorem about the first point (for precision far from the origin):
  // each chord adds its triangle; an arc adds the circular segment between the
  // chord and the arc, (r^2 * sweep - cross(a - c, b - c)) / 2, signed by turn.
  const Vec2 o = segs.front().a;
  double twice = 0;
  for (const Seg &s : segs) {
    twice += cross(s.a - o, s.b - o);
    if (s.isArc()) {
      const double r2 = ((s.a - s.c).squaredNorm() + (s.b - s.c).squaredNorm()) / 2;
      twice += r2 * s.sweep() - cross(s.a - s.c, s.b - s.c);
    }
  }
  return twice / 2;
}

double Loop::length() const {
  double sum = 0;
  for (const Seg &s : segs)
    sum += s.length();
  return sum;
}

Box Loop::box() const {
  Box bx;
  for (const Seg &s : segs)
    bx.add(s.box());
  return bx;
}

void Loop::reverse() {
  std::reverse(segs.begin(), segs.end());
  for (Seg &s : segs)
    s = s.reversed();
}

int Loop::winding(const Vec2 &p) const {
  int sum = 0;
  for (const Seg &s : segs)
    sum += crossings(s, p);
  return sum;
}

double Region::area() const {
  double sum = 0;
  for (const Loop &l : loops)
    sum += l.area();
  return sum;
}

Box Region::box() const {
  Box bx;
  for (const Loop &l : loops)
    bx.add(l.box());
  return bx;
}

bool Region::contains(const Vec2 &p) const {
  int sum = 0;
  for (const Loop &l : loops)
    sum += l.winding(p);
  return sum != 0;
}

double Chain::length() const {
  double sum = 0;
  for (const Seg &s : segs)
    sum += s.length();
  return sum;
}

// --- Distances and intersections ---------------------------------------------

Vec2 balancedCentre(const Vec2 &from, const Vec2 &to, const Vec2 &centre) {
  const Vec2 chord = to - from;
  const double len = chord.norm();
  if (len < 1e-12)
    return centre;
  // Project the centre onto the chord's perpendicular bisector.
  const Vec2 mid = (from + to) / 2;
  const Vec2 along = chord / len;
  return centre - along * (centre - mid).dot(along);
}

Vec2 closestPoint(const Seg &s, const Vec2 &p) {
  if (!s.isArc()) {
    const Vec2 d = s.b - s.a;
    const double l2 = d.squaredNorm();
    if (l2 == 0)
      return s.a;
    return s.a + std::clamp((p - s.a).dot(d) / l2, 0.0, 1.0) * d;
  }
  const Vec2 v = p - s.c;
  const double n = v.norm();
  if (n > 0 && inSpan(s, p))
    return s.c + v * (s.radius() / n);
  return (p - s.a).squaredNorm() <= (p - s.b).squaredNorm() ? s.a : s.b;
}

double distance(const Seg &s, const Vec2 &p) { return (closestPoint(s, p) - p).norm(); }

double distance(const Seg &s, const Seg &t) {
  if (!intersect(s, t).empty())
    return 0;
  // The segments are apart, so a closest pair has an end point of one of them,
  // or is interior to both; then the line joining the pair is normal to both.
  double best = std::min({distance(s, t.a), distance(s, t.b), distance(t, s.a), distance(t, s.b)});
  if (!s.isArc() && !t.isArc())
    return best;
  if (s.isArc() != t.isArc()) {
    // Line and arc: the pair lies on the perpendicular from the centre to the line.
    const Seg &line = s.isArc() ? t : s;
    const Seg &arc = s.isArc() ? s : t;
    const Vec2 d = line.b - line.a;
    const double l2 = d.squaredNorm();
    if (l2 > 0) {
      const double along = (arc.c - line.a).dot(d) / l2;
      if (along > 0 && along < 1) {
        const Vec2 foot = line.a + along * d;
        const Vec2 v = foot - arc.c;
        const double n = v.norm();
        if (n > 0) {
          const Vec2 q = arc.c + v * (arc.radius() / n);
          if (inSpan(arc, q))
            best = std::min(best, (q - foot).norm());
        }
      }
    }
    return best;
  }
  // Two arcs: the pair lies on the line of centres. (Concentric arcs have no
  // such pair, and an end point of one then gives the distance.)
  const Vec2 dc = t.c - s.c;
  const double n = dc.norm();
  if (n > 0) {
    const Vec2 u = dc / n;
    const double r1 = s.radius(), r2 = t.radius();
    for (double sign1 : {-1.0, 1.0}) {
      const Vec2 q1 = s.c + sign1 * r1 * u;
      if (!inSpan(s, q1))
        continue;
      for (double sign2 : {-1.0, 1.0}) {
        const Vec2 q2 = t.c + sign2 * r2 * u;
        if (inSpan(t, q2))
          best = std::min(best, (q1 - q2).norm());
      }
    }
  }
  return best;
}

std::vector<Vec2> intersect(const Seg &s, const Seg &t) {
  std::vector<Vec2> pts;
  const Box sb = s.box().grown(kEps), tb = t.box().grown(kEps);
  if (!sb.overlaps(tb))
    return pts;
  if (!s.isArc() && !t.isArc())
    intersectLines(s, t, sb, tb, kEps, pts);
  else if (!s.isArc())
    intersectLineArc(s, t, sb, tb, kEps, pts);
  else if (!t.isArc())
    intersectLineArc(t, s, tb, sb, kEps, pts);
  else
    intersectArcs(s, t, sb, tb, kEps, pts);
  return pts;
}

// --- SegIndex ----------------------------------------------------------------

SegIndex::SegIndex(std::vector<Seg> segs) : segs_(std::move(segs)) {
  const size_t n = segs_.size();
  boxes_.reserve(n);
  for (const Seg &s : segs_) {
    boxes_.push_back(s.box());
    box_.add(boxes_.back());
  }
  stamp_.assign(n, 0);
  if (n == 0) {
    cellStart_.assign(2, 0);
    return;
  }
  // About one cell per segment: square cells over the box, but never more than
  // n + 1 cells along a side (a thin box).
  const double w = box_.hi.x() - box_.lo.x(), h = box_.hi.y() - box_.lo.y();
  const double extent = std::max(w, h);
  cell_ = std::max(std::sqrt(w * h / double(n)), extent / double(n));
  if (!(cell_ > 0))
    cell_ = extent > 0 ? extent : 1.0;
  nx_ = int(std::min(w / cell_, double(n))) + 1;
  ny_ = int(std::min(h / cell_, double(n))) + 1;

  // Counting pass, prefix sums, filling pass.
  cellStart_.assign(size_t(nx_) * size_t(ny_) + 1, 0);
  for (const Box &b : boxes_)
    for (int y = cellY(b.lo.y()), y1 = cellY(b.hi.y()); y <= y1; ++y)
      for (int x = cellX(b.lo.x()), x1 = cellX(b.hi.x()); x <= x1; ++x)
        ++cellStart_[size_t(y) * nx_ + x + 1];
  for (size_t k = 1; k < cellStart_.size(); ++k)
    cellStart_[k] += cellStart_[k - 1];
  cellItems_.resize(cellStart_.back());
  std::vector<uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
  for (uint32_t i = 0; i < n; ++i) {
    const Box &b = boxes_[i];
    for (int y = cellY(b.lo.y()), y1 = cellY(b.hi.y()); y <= y1; ++y)
      for (int x = cellX(b.lo.x()), x1 = cellX(b.hi.x()); x <= x1; ++x)
        cellItems_[fill[size_t(y) * nx_ + x]++] = i;
  }
}

SegIndex SegIndex::of(const Region &r) {
  std::vector<Seg> segs;
  for (const Loop &l : r.loops)
    segs.insert(segs.end(), l.segs.begin(), l.segs.end());
  return SegIndex(std::move(segs));
}

int SegIndex::cellX(double x) const {
  const double k = std::floor((x - box_.lo.x()) / cell_);
  return int(std::clamp(k, 0.0, double(nx_ - 1)));
}

int SegIndex::cellY(double y) const {
  const double k = std::floor((y - box_.lo.y()) / cell_);
  return int(std::clamp(k, 0.0, double(ny_ - 1)));
}

uint32_t SegIndex::nextEpoch() const {
  if (++epoch_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    epoch_ = 1;
  }
  return epoch_;
}

double SegIndex::distance(const Vec2 &p) const { return search(p, kInf, false, nullptr); }

bool SegIndex::within(const Vec2 &p, double r, uint32_t *which) const {
  uint32_t found = 0;
  const bool near = search(p, r, true, &found) < r;
  if (near && which)
    *which = found;
  return near;
}

double SegIndex::search(const Vec2 &p, double limit, bool firstOnly, uint32_t *which) const {
  double best = limit, best2 = limit * limit;
  if (segs_.empty() || boxDistance2(box_, p) >= best2)
    return best;
  const int cx = cellX(p.x()), cy = cellY(p.y());
  const uint32_t epoch = nextEpoch();
  bool found = false;
  auto visit = [&](int x, int y) {
    const size_t cellIndex = size_t(y) * nx_ + x;
    for (uint32_t k = cellStart_[cellIndex]; k < cellStart_[cellIndex + 1]; ++k) {
      const uint32_t i = cellItems_[k];
      if (stamp_[i] == epoch)
        continue;
      stamp_[i] = epoch;
      if (boxDistance2(boxes_[i], p) >= best2)
        continue;
      const double d = geom::distance(segs_[i], p);
      if (d < best) {
        best = d;
        best2 = d * d;
        found = true;
        if (which)
          *which = i;
      }
    }
  };
  for (int ring = 0;; ++ring) {
    const int x0 = cx - ring, x1 = cx + ring, y0 = cy - ring, y1 = cy + ring;
    // Visit the cells of this ring that are in the grid.
    for (int x = std::max(x0, 0); x <= std::min(x1, nx_ - 1); ++x) {
      if (y0 >= 0)
        visit(x, y0);
      if (y1 < ny_ && y1 != y0)
        visit(x, y1);
    }
    for (int y = std::max(y0 + 1, 0); y <= std::min(y1 - 1, ny_ - 1); ++y) {
      if (x0 >= 0)
        visit(x0, y);
      if (x1 < nx_ && x1 != x0)
        visit(x1, y);
    }
    if (found && firstOnly)
      return best;
    // Every segment not yet seen lies wholly in cells outside the block visited
    // so far; stop when all of those are farther than the best distance.
    double bound = kInf;
    if (x0 > 0)
      bound = std::min(bound, p.x() - (box_.lo.x() + x0 * cell_));
    if (x1 < nx_ - 1)
      bound = std::min(bound, box_.lo.x() + (x1 + 1) * cell_ - p.x());
    if (y0 > 0)
      bound = std::min(bound, p.y() - (box_.lo.y() + y0 * cell_));
    if (y1 < ny_ - 1)
      bound = std::min(bound, box_.lo.y() + (y1 + 1) * cell_ - p.y());
    if (bound == kInf || bound >= best)
      return best;
  }
}

double SegIndex::distance(const Seg &s) const {
  if (segs_.empty())
    return kInf;
  // An upper bound from three of s's points, then every segment whose box
  // comes within that bound of s's box.
  double best = std::min({distance(s.a), distance(s.b), distance(s.at(0.5))});
  if (best == 0)
    return 0;
  const Box sb = s.box();
  std::vector<uint32_t> near;
  query(sb.grown(best), near);
  for (uint32_t i : near)
    if (boxDistance(sb, boxes_[i]) < best)
      best = std::min(best, geom::distance(s, segs_[i]));
  return best;
}

void SegIndex::query(const Box &box, std::vector<uint32_t> &out) const {
  out.clear();
  if (segs_.empty() || box.empty() || !box.overlaps(box_))
    return;
  const uint32_t epoch = nextEpoch();
  for (int y = cellY(box.lo.y()), y1 = cellY(box.hi.y()); y <= y1; ++y) {
    for (int x = cellX(box.lo.x()), x1 = cellX(box.hi.x()); x <= x1; ++x) {
      const size_t cellIndex = size_t(y) * nx_ + x;
      for (uint32_t k = cellStart_[cellIndex]; k < cellStart_[cellIndex + 1]; ++k) {
        const uint32_t i = cellItems_[k];
        if (stamp_[i] == epoch)
          continue;
        stamp_[i] = epoch;
        if (boxes_[i].overlaps(box))
          out.push_back(i);
      }
    }
  }
}

int SegIndex::winding(const Vec2 &p) const {
  if (segs_.empty() || p.y() < box_.lo.y() || p.y() > box_.hi.y() || p.x() > box_.hi.x())
    return 0;
  // The ray from p towards +x meets only segments stored in p's row of cells,
  // at or right of p's cell.
  const uint32_t epoch = nextEpoch();
  const int y = cellY(p.y());
  int sum = 0;
  for (int x = cellX(p.x()); x < nx_; ++x) {
    const size_t cellIndex = size_t(y) * nx_ + x;
    for (uint32_t k = cellStart_[cellIndex]; k < cellStart_[cellIndex + 1]; ++k) {
      const uint32_t i = cellItems_[k];
      if (stamp_[i] == epoch)
        continue;
      stamp_[i] = epoch;
      const Box &b = boxes_[i];
      if (b.hi.x() > p.x() && b.lo.y() <= p.y() && b.hi.y() >= p.y())
        sum += crossings(segs_[i], p);
    }
  }
  return sum;
}

Region mirroredAcrossX(const Region &r) {
  Region m;
  for (const Loop &l : r.loops) {
    Loop back;
    for (auto it = l.segs.rbegin(); it != l.segs.rend(); ++it)
      back.segs.push_back(Seg{Vec2(it->b.x(), -it->b.y()), Vec2(it->a.x(), -it->a.y()), Vec2(it->c.x(), -it->c.y()),
                              it->turn});
    m.loops.push_back(std::move(back));
  }
  return m;
}

std::vector<Vec2> convexHull(std::vector<Vec2> p) {
  std::sort(p.begin(), p.end(),
            [](const Vec2 &a, const Vec2 &b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  p.erase(std::unique(p.begin(), p.end(), [](const Vec2 &a, const Vec2 &b) { return (a - b).norm() < 1e-12; }),
          p.end());
  if (p.size() < 3)
    return p;
  std::vector<Vec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 1e-15)
      --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 1] - h[k - 2], p[i - 1] - h[k - 2]) <= 1e-15)
      --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

} // namespace stepnc::geom
