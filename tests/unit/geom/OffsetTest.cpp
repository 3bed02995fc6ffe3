// Offsets and clipping: exact areas of shrunk and grown shapes (worked out by
// hand), arcs where corners are rounded, holes, shapes that split or merge,
// invariants on random star polygons checked against the distance to the
// boundary, and clipping a segment to a region.
#include "geom/Geometry.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

using namespace stepnc::geom;

namespace {

constexpr double pi = std::numbers::pi;

Loop rect(double x0, double y0, double x1, double y1) {
  return polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}});
}

Loop reversed(Loop l) {
  l.reverse();
  return l;
}

/// Counter-clockwise rectangle with corners rounded to radius r.
Loop roundedRect(double x0, double y0, double x1, double y1, double r) {
  return roundedRectangle({x0, y0}, {x1, y1}, r);
}

/// The L of two 10 wide arms: [0,20]x[0,10] and [0,10]x[0,20]; reflex corner at (10, 10).
Loop lShape() { return polygon({{0, 0}, {20, 0}, {20, 10}, {10, 10}, {10, 20}, {0, 20}}); }

/// A star-shaped polygon about the origin: radii from `radius` at n sorted random angles.
template <class Radius> Loop star(std::mt19937 &rng, int n, Radius radius) {
  std::uniform_real_distribution<double> angle(0, 2 * pi);
  std::vector<double> angles(n);
  for (double &a : angles)
    a = angle(rng);
  std::sort(angles.begin(), angles.end());
  std::vector<Vec2> pts;
  for (double a : angles) {
    const double r = radius(a);
    pts.push_back(r * Vec2(std::cos(a), std::sin(a)));
  }
  return polygon(pts);
}

/// Whether no two segments of the loop meet except consecutive ones at their shared end.
bool simple(const Loop &l) {
  const size_t n = l.segs.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const std::vector<Vec2> pts = intersect(l.segs[i], l.segs[j]);
      const bool consecutive = j == i + 1 || (i == 0 && j == n - 1);
      if (pts.size() > (consecutive ? 1u : 0u))
        return false;
    }
  }
  return true;
}

int arcCount(const Region &r) {
  int n = 0;
  for (const Loop &l : r.loops)
    for (const Seg &s : l.segs)
      n += s.isArc();
  return n;
}

int segCount(const Region &r) {
  int n = 0;
  for (const Loop &l : r.loops)
    n += int(l.segs.size());
  return n;
}

/// Every loop is closed, with exactly meeting ends, and has no degenerate piece.
void checkLoops(const Region &r) {
  for (const Loop &l : r.loops) {
    REQUIRE(l.segs.size() >= 2);
    for (size_t k = 0; k < l.segs.size(); ++k) {
      const Seg &s = l.segs[k];
      CHECK(s.b == l.segs[(k + 1) % l.segs.size()].a);
      CHECK(s.length() > kEps);
      if (s.isArc())
        CHECK(std::abs(s.radius() - (s.b - s.c).norm()) < 1e-9);
    }
  }
}

/// The signed areas of the loops, sorted.
std::vector<double> loopAreas(const Region &r) {
  std::vector<double> areas;
  for (const Loop &l : r.loops)
    areas.push_back(l.area());
  std::sort(areas.begin(), areas.end());
  return areas;
}

/// Checks offset(p, d) against the definition, using the distance to p's
/// boundary: the result's vertices and segment midpoints are at distance |d|
/// on the right side, and sample points clearly nearer or farther than |d|
/// are outside or inside the result.
void checkOffset(const Region &p, double d, const Region &result, int samples, int vertexStride = 1) {
  const SegIndex boundary = SegIndex::of(p);
  const double ad = std::abs(d);
  checkLoops(result);
  int checked = 0;
  for (const Loop &l : result.loops) {
    for (size_t k = 0; k < l.segs.size(); k += vertexStride) {
      const Seg &s = l.segs[k];
      CHECK(boundary.distance(s.a) >= ad - 1e-6);
      CHECK(boundary.distance(s.at(0.5)) == Approx(ad).margin(1e-6));
      CHECK(p.contains(s.at(0.5)) == (d < 0));
      ++checked;
    }
  }
  // Point location: a grid of sample points over the grown box.
  const Box box = p.box().grown(std::max(d, 0.0) + 1);
  const SegIndex resultIndex = SegIndex::of(result);
  int wrong = 0;
  for (int i = 0; i < samples; ++i) {
    for (int j = 0; j < samples; ++j) {
      const Vec2 x(box.lo.x() + (box.hi.x() - box.lo.x()) * (i + 0.5) / samples,
                   box.lo.y() + (box.hi.y() - box.lo.y()) * (j + 0.5) / samples);
      const double dist = boundary.distance(x);
      if (std::abs(dist - ad) < 1e-6 || dist < 1e-6)
        continue;
      const bool inP = p.contains(x);
      const bool expected = d < 0 ? inP && dist > ad : inP || dist < ad;
      wrong += (resultIndex.winding(x) != 0) != expected;
    }
  }
  CHECK(wrong == 0);
}

} // namespace

TEST_CASE("shrinking a rectangle keeps its corners sharp", "[geom][offset]") {
  const Region r = offset(Region{{rect(0, 0, 60, 40)}}, -5);
  REQUIRE(r.loops.size() == 1);
  checkLoops(r);
  CHECK(r.area() == Approx(1500).epsilon(1e-12));
  CHECK(segCount(r) == 4);
  CHECK(arcCount(r) == 0);
  CHECK(r.box().lo.isApprox(Vec2(5, 5)));
  CHECK(r.box().hi.isApprox(Vec2(55, 35)));
}

TEST_CASE("growing a rectangle rounds its corners", "[geom][offset]") {
  const Region r = offset(Region{{rect(0, 0, 60, 40)}}, 5);
  REQUIRE(r.loops.size() == 1);
  checkLoops(r);
  // The rectangle, a 5 wide band along its 200 long perimeter, four quarter discs.
  CHECK(r.area() == Approx(2400 + 200 * 5 + 25 * pi).epsilon(1e-12));
  CHECK(segCount(r) == 8);
  CHECK(arcCount(r) == 4);
  for (const Seg &s : r.loops[0].segs) {
    if (s.isArc()) {
      CHECK(s.radius() == Approx(5));
      CHECK(s.turn == 1);
      CHECK(s.sweep() == Approx(pi / 2));
    }
  }
}

TEST_CASE("shrinking a rounded rectangle", "[geom][offset]") {
  const Region rr{{roundedRect(0, 0, 60, 40, 8)}};
  SECTION("by less than the corner radius: the corners stay arcs, radius 8 - 3") {
    const Region r = offset(rr, -3);
    REQUIRE(r.loops.size() == 1);
    checkLoops(r);
    CHECK(r.area() == Approx(54 * 34 - (4 - pi) * 25).epsilon(1e-12));
    CHECK(arcCount(r) == 4);
    for (const Seg &s : r.loops[0].segs)
      if (s.isArc())
        CHECK(s.radius() == Approx(5));
  }
  SECTION("by more than the corner radius: sharp corners") {
    const Region r = offset(rr, -10);
    REQUIRE(r.loops.size() == 1);
    checkLoops(r);
    CHECK(r.area() == Approx(40 * 20).epsilon(1e-12));
    CHECK(segCount(r) == 4);
    CHECK(arcCount(r) == 0);
  }
  SECTION("by the corner radius: the corner arcs shrink to points") {
    for (double d : {8.0, 8.0 - 1e-12, 8.0 + 1e-12}) {
      const Region r = offset(rr, -d);
      REQUIRE(r.loops.size() == 1);
      checkLoops(r);
      CHECK(r.area() == Approx((60 - 2 * d) * (40 - 2 * d)).epsilon(1e-9));
      CHECK(segCount(r) == 4);
    }
  }
  SECTION("growing by 2 gives corner radius 10") {
    const Region r = offset(rr, 2);
    CHECK(r.area() == Approx(64 * 44 - (4 - pi) * 100).epsilon(1e-12));
    CHECK(arcCount(r) == 4);
  }
}

TEST_CASE("offsets of a circle", "[geom][offset]") {
  const Region c{{circleLoop({3, 4}, 10, true)}};
  Region r = offset(c, -4);
  REQUIRE(r.loops.size() == 1);
  checkLoops(r);
  CHECK(r.area() == Approx(36 * pi).epsilon(1e-12));
  for (const Seg &s : r.loops[0].segs) {
    CHECK(s.isArc());
    CHECK(s.radius() == Approx(6));
    CHECK(s.c.isApprox(Vec2(3, 4)));
  }
  CHECK(offset(c, 2.5).area() == Approx(12.5 * 12.5 * pi).epsilon(1e-12));
  CHECK(offset(c, -10.5).empty());
  CHECK(offset(c, -10).empty());
  CHECK(offset(c, 0).area() == Approx(100 * pi));
}

TEST_CASE("a reflex corner becomes an arc when shrinking", "[geom][offset]") {
  // Points of the L whose disc of radius 2 fits: the two shrunk arms [2,18]x[2,8]
  // and [2,8]x[2,18] (96 + 96 - 36 shared), plus near the reflex corner the
  // square [8,10]^2 less the quarter disc of radius 2 about (10, 10): 4 - pi.
  const Region r = offset(Region{{lShape()}}, -2);
  REQUIRE(r.loops.size() == 1);
  checkLoops(r);
  CHECK(r.area() == Approx(160 - pi).epsilon(1e-12));
  REQUIRE(arcCount(r) == 1);
  for (const Seg &s : r.loops[0].segs) {
    if (s.isArc()) {
      CHECK(s.c.isApprox(Vec2(10, 10)));
      CHECK(s.radius() == Approx(2));
      CHECK(s.turn == -1);
      CHECK(s.sweep() == Approx(-pi / 2));
    }
  }
}

TEST_CASE("growing a polygon puts arcs at its convex corners only", "[geom][offset]") {
  // Area + perimeter * d + the corner wedges (exterior angles 5 * pi/2 in all,
  // d^2 / 2 each radian) - the d x d square counted twice at the reflex corner.
  const Region r = offset(Region{{lShape()}}, 2);
  REQUIRE(r.loops.size() == 1);
  checkLoops(r);
  CHECK(r.area() == Approx(300 + 80 * 2 + 5 * pi - 4).epsilon(1e-12));
  CHECK(arcCount(r) == 5);
  CHECK(segCount(r) == 11);
}

TEST_CASE("the hole grows when the region shrinks, and vanishes when it grows", "[geom][offset]") {
  const Region withHole{{rect(0, 0, 40, 40), circleLoop({20, 20}, 5, false)}};
  Region r = offset(withHole, -2);
  REQUIRE(r.loops.size() == 2);
  checkLoops(r);
  CHECK(r.area() == Approx(36 * 36 - 49 * pi).epsilon(1e-12));
  const std::vector<double> areas = loopAreas(r);
  CHECK(areas[0] == Approx(-49 * pi).epsilon(1e-12)); // the hole, clockwise
  CHECK(areas[1] == Approx(36 * 36).epsilon(1e-12));

  r = offset(withHole, 6);
  REQUIRE(r.loops.size() == 1);
  CHECK(r.area() == Approx(1600 + 160 * 6 + 36 * pi).epsilon(1e-12));

  r = offset(withHole, 3);
  REQUIRE(r.loops.size() == 2);
  CHECK(r.area() == Approx(1600 + 160 * 3 + 9 * pi - 4 * pi).epsilon(1e-12));
}

TEST_CASE("a dumbbell splits in two when shrunk", "[geom][offset]") {
  // Squares [0,20]^2 and [30,50]x[0,20], joined by the corridor [20,30]x[8,12].
  const Region dumbbell{{polygon({{0, 0},
                                  {20, 0},
                                  {20, 8},
                                  {30, 8},
                                  {30, 0},
                                  {50, 0},
                                  {50, 20},
                                  {30, 20},
                                  {30, 12},
                                  {20, 12},
                                  {20, 20},
                                  {0, 20}})}};
  const Region r = offset(dumbbell, -3);
  REQUIRE(r.loops.size() == 2);
  checkLoops(r);
  // Each piece: the shrunk square [3,17]^2, plus a bump into the corridor's
  // mouth between the circles of radius 3 about (20, 8) and (20, 12), for
  // x from 17 to 20 - sqrt(5): with u = 20 - x, the height is 4 - 2 sqrt(9 - u^2),
  // integrated over u from sqrt(5) to 3.
  const double bump = 12 - 2 * std::sqrt(5.0) - 4.5 * pi + 9 * std::asin(std::sqrt(5.0) / 3);
  const std::vector<double> areas = loopAreas(r);
  CHECK(areas[0] == Approx(196 + bump).epsilon(1e-12));
  CHECK(areas[1] == Approx(196 + bump).epsilon(1e-12));
  CHECK(arcCount(r) == 4);
  checkOffset(dumbbell, -3, r, 150);
  // Less than half the corridor's width: one piece.
  CHECK(offset(dumbbell, -1.5).loops.size() == 1);
}

TEST_CASE("two squares merge when grown", "[geom][offset]") {
  // [0,10]^2 and [11.5,21.5]x[0,10] grown by 1 overlap in the strip x in
  // [10.5, 11] (area 5) and in two lenses between the corner arcs about (10, 0)
  // and (11.5, 0) (and at the top): for |y| < Y = sqrt(1 - 0.75^2) the width is
  // 2 sqrt(1 - y^2) - 1.5, which integrates to asin(Y) - 0.75 Y.
  const Region two{{rect(0, 0, 10, 10), rect(11.5, 0, 21.5, 10)}};
  const Region r = offset(two, 1);
  REQUIRE(r.loops.size() == 1);
  checkLoops(r);
  const double y = std::sqrt(1 - 0.75 * 0.75);
  const double overlap = 5 + 2 * (std::asin(y) - 0.75 * y);
  CHECK(r.area() == Approx(2 * (100 + 40 + pi) - overlap).epsilon(1e-12));
  checkOffset(two, 1, r, 150);
  // The gap left between them when grown by less than half of it.
  CHECK(offset(two, 0.7).loops.size() == 2);
}

TEST_CASE("opening and closing the L", "[geom][offset]") {
  const Region l{{lShape()}};
  // Closing (grow, then shrink) fills the reflex corner with a fillet of
  // radius 2: the square [10,12]^2 less the quarter disc about (12, 12).
  const Region closed = offset(offset(l, 2), -2);
  REQUIRE(closed.loops.size() == 1);
  checkLoops(closed);
  CHECK(closed.area() == Approx(300 + 4 - pi).epsilon(1e-12));
  CHECK(arcCount(closed) == 1);
  // Opening (shrink, then grow) rounds the five convex corners, each losing
  // the square of side 2 less its quarter disc.
  const Region opened = offset(offset(l, -2), 2);
  REQUIRE(opened.loops.size() == 1);
  checkLoops(opened);
  CHECK(opened.area() == Approx(300 - 5 * (4 - pi)).epsilon(1e-12));
  CHECK(arcCount(opened) == 5);
}

TEST_CASE("shrinking twice is shrinking by the sum", "[geom][offset]") {
  // Erosions by discs add up; so do dilations.
  Loop lHole = reversed(lShape());
  for (Seg &s : lHole.segs) {
    s.a += Vec2(8, 8);
    s.b += Vec2(8, 8);
  }
  const Region shape{{roundedRect(0, 0, 60, 40, 8), lHole, circleLoop({45, 20}, 4, false)}};
  REQUIRE(shape.area() == Approx(2400 - (4 - pi) * 64 - 300 - 16 * pi));
  double d = 0;
  Region step = shape;
  while (!step.empty()) {
    step = offset(step, -1.25);
    d += 1.25;
    checkLoops(step);
    const Region direct = offset(shape, -d);
    CAPTURE(d);
    CHECK(step.loops.size() == direct.loops.size());
    CHECK(step.area() == Approx(direct.area()).margin(1e-9));
  }
  CHECK(d > 10);
  CHECK(offset(offset(shape, 1.5), 2).area() == Approx(offset(shape, 3.5).area()).epsilon(1e-12));
}

TEST_CASE("offsets of random star polygons follow the definition", "[geom][offset]") {
  std::mt19937 rng(31337);
  std::uniform_real_distribution<double> radius(10, 30), dist(0.3, 4);
  for (int k = 0; k < 30; ++k) {
    const int n = 5 + int(rng() % 40);
    const Region p{{star(rng, n, [&](double) { return radius(rng); })}};
    const double d = dist(rng);
    CAPTURE(k, n, d);
    const Region shrunk = offset(p, -d);
    CHECK(shrunk.area() < p.area());
    CHECK(shrunk.area() >= 0);
    checkOffset(p, -d, shrunk, 60);
    const Region grown = offset(p, d);
    CHECK(grown.area() > p.area());
    REQUIRE(grown.loops.size() >= 1);
    checkOffset(p, d, grown, 60);
  }
}

TEST_CASE("offsets with arcs on random inputs follow the definition", "[geom][offset]") {
  // A rounded star: every other edge replaced by an arc bulging out or in.
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> radius(12, 30), dist(0.3, 5), bulge(-0.4, 0.4);
  for (int k = 0; k < 20; ++k) {
    const Loop base = star(rng, 6 + int(rng() % 10), [&](double) { return radius(rng); });
    Loop l;
    for (size_t i = 0; i < base.segs.size(); ++i) {
      const Seg &s = base.segs[i];
      const double h = bulge(rng);
      if (i % 2 || std::abs(h) < 0.05) {
        l.segs.push_back(s);
        continue;
      }
      // The circle through a, b and the point h * |ab| to the right of the chord midpoint.
      const Vec2 m = (s.a + s.b) / 2, dir = (s.b - s.a).normalized();
      const double half = (s.b - s.a).norm() / 2, sag = h * 2 * half;
      const Vec2 right(dir.y(), -dir.x());
      // Centre on the chord's bisector at signed offset t from m: (half^2 + t^2) = (sag - t)^2.
      const double t = (sag * sag - half * half) / (2 * sag);
      l.segs.push_back(Seg::arc(s.a, s.b, m + t * right, sag > 0));
    }
    if (!simple(l))
      continue;
    const Region p{{l}};
    const double d = dist(rng);
    CAPTURE(k, d);
    checkOffset(p, -d, offset(p, -d), 60);
    checkOffset(p, d, offset(p, d), 60);
  }
}

TEST_CASE("offset of a 10,000 vertex polygon", "[geom][offset]") {
  // A smooth star (its many nearly collinear edges make raw offsets that
  // cross at very small angles) and a rough one (each edge's offset crossing
  // many others).
  for (double roughness : {0.0, 0.05}) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> noise(-roughness, roughness);
    const Region p{{star(
        rng, 10000, [&](double a) { return 60 + 8 * std::sin(7 * a) + 4 * std::cos(13 * a) + noise(rng); })}};
    CAPTURE(roughness);
    const Region shrunk = offset(p, -2);
    REQUIRE(shrunk.loops.size() == 1);
    CHECK(shrunk.area() < p.area());
    checkOffset(p, -2, shrunk, 40, 97);
    const Region grown = offset(p, 2);
    REQUIRE(grown.loops.size() == 1);
    checkOffset(p, 2, grown, 40, 97);
  }
}

TEST_CASE("clipping a segment to a region", "[geom][offset]") {
  // A square with a square hole [10,25]x[15,25].
  const Region r{{rect(0, 0, 40, 40), reversed(rect(10, 15, 25, 25))}};
  std::vector<Seg> pieces = clip(r, {-10, 20}, {50, 20});
  REQUIRE(pieces.size() == 2);
  CHECK(pieces[0].a.isApprox(Vec2(0, 20)));
  CHECK(pieces[0].length() == Approx(10));
  CHECK(pieces[1].a.isApprox(Vec2(25, 20)));
  CHECK(pieces[1].length() == Approx(15));
  // Ordered from the start point.
  pieces = clip(r, {50, 20}, {-10, 20});
  REQUIRE(pieces.size() == 2);
  CHECK(pieces[0].a.isApprox(Vec2(40, 20)));
  CHECK(pieces[0].b.isApprox(Vec2(25, 20)));
  CHECK(pieces[1].length() == Approx(10));
  // Wholly inside; wholly in the hole; wholly outside.
  pieces = clip(r, {5, 5}, {35, 5});
  REQUIRE(pieces.size() == 1);
  CHECK(pieces[0].a == Vec2(5, 5));
  CHECK(pieces[0].b == Vec2(35, 5));
  CHECK(clip(r, {12, 16}, {20, 22}).empty());
  CHECK(clip(r, {-5, -5}, {-5, 50}).empty());

  // A line across a circle: the chord.
  const Region c{{circleLoop({0, 0}, 5, true)}};
  pieces = clip(c, {-10, 3}, {10, 3});
  REQUIRE(pieces.size() == 1);
  CHECK(pieces[0].a.isApprox(Vec2(-4, 3)));
  CHECK(pieces[0].b.isApprox(Vec2(4, 3)));
  // Starting inside.
  pieces = clip(c, {0, 0}, {0, -10});
  REQUIRE(pieces.size() == 1);
  CHECK(pieces[0].length() == Approx(5));
  // Through the joint of the two half arcs, (5, 0).
  pieces = clip(c, {-10, 0}, {10, 0});
  REQUIRE(pieces.size() == 1);
  CHECK(pieces[0].length() == Approx(10));
}
