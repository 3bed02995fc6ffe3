// Plane geometry of lines and arcs: exact areas and lengths, arc boxes, point
// location, distances and intersections (expected values worked out by hand),
// and the segment grid checked against brute force on random input.
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

/// Counter-clockwise rectangle with corners rounded to radius r.
Loop roundedRect(double x0, double y0, double x1, double y1, double r) {
  return roundedRectangle({x0, y0}, {x1, y1}, r);
}

/// The L of two 10 wide arms: [0,20]x[0,10] and [0,10]x[0,20].
Loop lShape() { return polygon({{0, 0}, {20, 0}, {20, 10}, {10, 10}, {10, 20}, {0, 20}}); }

/// Arc about c of radius r from angle `from` to angle `to` (degrees).
Seg arcDeg(const Vec2 &c, double r, double from, double to, bool ccw) {
  const double f = from * pi / 180, t = to * pi / 180;
  return Seg::arc(c + r * Vec2(std::cos(f), std::sin(f)), c + r * Vec2(std::cos(t), std::sin(t)), c, ccw);
}

bool near(const Vec2 &p, const Vec2 &q, double tol = 1e-9) { return (p - q).norm() <= tol; }

bool hasPoint(const std::vector<Vec2> &pts, const Vec2 &q) {
  return std::any_of(pts.begin(), pts.end(), [&](const Vec2 &p) { return near(p, q, 1e-9); });
}

} // namespace

TEST_CASE("loop areas are exact for lines and arcs", "[geom]") {
  CHECK(rect(0, 0, 1, 1).area() == Approx(1.0).epsilon(1e-14));
  CHECK(roundedRect(0, 0, 60, 40, 8).area() == Approx(2400 - (4 - pi) * 64).epsilon(1e-13));
  CHECK(circleLoop({3, -2}, 5, true).area() == Approx(25 * pi).epsilon(1e-13));
  CHECK(circleLoop({3, -2}, 5, false).area() == Approx(-25 * pi).epsilon(1e-13));
  CHECK(lShape().area() == Approx(300).epsilon(1e-14));

  // Far from the origin the area is still exact.
  Loop far = roundedRect(1e5, 1e5, 1e5 + 60, 1e5 + 40, 8);
  CHECK(far.area() == Approx(2400 - (4 - pi) * 64).epsilon(1e-9));

  Loop reversed = roundedRect(0, 0, 60, 40, 8);
  reversed.reverse();
  CHECK(reversed.area() == Approx(-(2400 - (4 - pi) * 64)).epsilon(1e-13));

  // A square with a circular hole: the hole is clockwise and counts negative.
  Region withHole{{rect(0, 0, 40, 40), circleLoop({20, 20}, 5, false)}};
  CHECK(withHole.area() == Approx(1600 - 25 * pi).epsilon(1e-13));
  // An arc longer than a half circle: a 270 degree sector.
  Loop sector{
      {Seg::line({0, 0}, {2, 0}), Seg::arc({2, 0}, {0, -2}, {0, 0}, true), Seg::line({0, -2}, {0, 0})}};
  CHECK(sector.area() == Approx(0.75 * pi * 4).epsilon(1e-13));
}

TEST_CASE("lengths of loops and chains", "[geom]") {
  CHECK(roundedRect(0, 0, 60, 40, 8).length() == Approx(136 + 16 * pi).epsilon(1e-13));
  CHECK(circleLoop({0, 0}, 5, true).length() == Approx(10 * pi).epsilon(1e-13));
  Chain open{{Seg::line({0, 0}, {3, 4}), arcDeg({3, 0}, 4, 90, 0, false)}};
  CHECK(!open.closed());
  CHECK(open.length() == Approx(5 + 2 * pi).epsilon(1e-13));
  Chain closed{circleLoop({0, 0}, 1, true).segs};
  CHECK(closed.closed());
}

TEST_CASE("arc sweep, points, tangents and reversal", "[geom]") {
  const Seg quarter = Seg::arc({1, 0}, {0, 1}, {0, 0}, true);
  CHECK(quarter.radius() == Approx(1));
  CHECK(quarter.sweep() == Approx(pi / 2));
  CHECK(quarter.length() == Approx(pi / 2));
  CHECK(near(quarter.at(0.5), Vec2(std::sqrt(0.5), std::sqrt(0.5)), 1e-12));
  CHECK(near(quarter.tangent(0), Vec2(0, 1), 1e-12));
  CHECK(near(quarter.tangent(1), Vec2(-1, 0), 1e-12));
  const Seg back = quarter.reversed();
  CHECK(back.turn == -1);
  CHECK(back.sweep() == Approx(-pi / 2));
  CHECK(near(back.tangent(0), Vec2(1, 0), 1e-12));
  // The same end points the long way round.
  const Seg longWay = Seg::arc({1, 0}, {0, 1}, {0, 0}, false);
  CHECK(longWay.sweep() == Approx(-1.5 * pi));
  CHECK(near(longWay.at(0.5), Vec2(-std::sqrt(0.5), -std::sqrt(0.5)), 1e-12));

  const Seg line = Seg::line({1, 1}, {4, 5});
  CHECK(line.length() == Approx(5));
  CHECK(near(line.at(0.2), Vec2(1.6, 1.8), 1e-12));
  CHECK(near(line.tangent(0.7), Vec2(0.6, 0.8), 1e-12));
}

TEST_CASE("arc boxes include the axis extremes the arc passes", "[geom]") {
  const double s3 = std::sqrt(3.0), s2 = std::sqrt(2.0);
  Box b = arcDeg({0, 0}, 2, 30, 120, true).box(); // passes the top
  CHECK(b.lo.x() == Approx(-1));
  CHECK(b.hi.x() == Approx(s3));
  CHECK(b.lo.y() == Approx(1));
  CHECK(b.hi.y() == Approx(2));
  b = arcDeg({0, 0}, 2, 45, -45, false).box(); // clockwise through the right
  CHECK(b.lo.x() == Approx(s2));
  CHECK(b.hi.x() == Approx(2));
  CHECK(b.lo.y() == Approx(-s2));
  CHECK(b.hi.y() == Approx(s2));
  b = arcDeg({1, 1}, 2, 45, -45, true).box(); // counter-clockwise the long way
  CHECK(b.lo.x() == Approx(-1));
  CHECK(b.hi.x() == Approx(1 + s2));
  CHECK(b.lo.y() == Approx(-1));
  CHECK(b.hi.y() == Approx(3));
  CHECK(roundedRect(0, 0, 60, 40, 8).box().lo.isApprox(Vec2(0, 0)));
}

TEST_CASE("circle() makes two half arcs from the start point", "[geom]") {
  const std::vector<Seg> c = circle({1, 2}, 3, true, {10, 2});
  REQUIRE(c.size() == 2);
  CHECK(near(c[0].a, Vec2(4, 2)));
  CHECK(near(c[0].b, Vec2(-2, 2)));
  CHECK(near(c[1].b, Vec2(4, 2)));
  CHECK(c[0].sweep() == Approx(pi));
  CHECK(c[1].sweep() == Approx(pi));
  CHECK(Loop{c}.area() == Approx(9 * pi));
  CHECK(Loop{circle({1, 2}, 3, false, {1, 0})}.area() == Approx(-9 * pi));
}

TEST_CASE("winding numbers and containment", "[geom]") {
  const Loop rr = roundedRect(0, 0, 60, 40, 8);
  CHECK(rr.winding({30, 20}) == 1);
  CHECK(rr.winding({2, 2}) == 0); // cut off by the corner arc: |(2,2) - (8,8)| > 8
  CHECK(rr.winding({3, 3}) == 1); // |(3,3) - (8,8)| < 8
  CHECK(rr.winding({58, 39}) == 0);
  CHECK(rr.winding({-1, 20}) == 0);
  CHECK(rr.winding({30, 40.5}) == 0);

  // Rays through the shared end points of the half arcs, and past the top.
  const Loop c = circleLoop({0, 0}, 5, true);
  CHECK(c.winding({0, 0}) == 1);
  CHECK(c.winding({-7, 0}) == 0);
  CHECK(c.winding({4.9, 0}) == 1);
  CHECK(c.winding({-10, 5}) == 0);
  CHECK(c.winding({0, 4.99}) == 1);
  CHECK(circleLoop({0, 0}, 5, false).winding({1, -1}) == -1);

  const Region withHole{{rect(0, 0, 40, 40), circleLoop({20, 20}, 5, false)}};
  CHECK(!withHole.contains({20, 20}));
  CHECK(!withHole.contains({20, 24.5}));
  CHECK(withHole.contains({20, 25.5}));
  CHECK(withHole.contains({1, 39}));
  CHECK(!withHole.contains({41, 20}));

  const Loop l = lShape();
  CHECK(l.winding({5, 15}) == 1);
  CHECK(l.winding({15, 15}) == 0);
  CHECK(l.winding({15, 5}) == 1);
  CHECK(l.winding({5, 10}) == 1); // the ray runs along the edge y = 10
}

TEST_CASE("distance from a point to a line or an arc", "[geom]") {
  const Seg line = Seg::line({0, 0}, {10, 0});
  CHECK(distance(line, {5, 3}) == Approx(3));
  CHECK(distance(line, {-3, 4}) == Approx(5));
  CHECK(near(closestPoint(line, {12, -1}), Vec2(10, 0)));

  const Seg arc = Seg::arc({5, 0}, {0, 5}, {0, 0}, true);      // quarter, radius 5
  CHECK(distance(arc, {6, 6}) == Approx(std::sqrt(72.0) - 5)); // outside the circle, within the span
  CHECK(distance(arc, {2, 2}) == Approx(5 - std::sqrt(8.0)));  // inside the circle, within the span
  CHECK(distance(arc, {0, -3}) == Approx(std::sqrt(34.0)));    // outside the span: the end (5, 0)
  CHECK(distance(arc, {-4, 1}) == Approx(std::sqrt(32.0)));    // outside the span: the end (0, 5)
  CHECK(near(closestPoint(arc, {6, 8}), Vec2(3, 4)));
}

TEST_CASE("distance between segments", "[geom]") {
  // Parallel lines.
  CHECK(distance(Seg::line({0, 0}, {10, 0}), Seg::line({2, 3}, {12, 3})) == Approx(3));
  // Crossing and touching segments are at distance 0.
  CHECK(distance(Seg::line({0, 0}, {10, 10}), Seg::line({0, 10}, {10, 0})) == 0);
  CHECK(distance(Seg::line({0, 0}, {10, 0}), Seg::line({10, 0}, {10, 5})) == 0);
  // Line and arc: the closest pair is interior to both (on the perpendicular
  // from the centre): the line x + y = 10 is 10/sqrt(2) from the centre.
  const Seg quarter = Seg::arc({5, 0}, {0, 5}, {0, 0}, true);
  CHECK(distance(quarter, Seg::line({10, 0}, {0, 10})) == Approx(10 / std::sqrt(2.0) - 5));
  CHECK(distance(Seg::line({10, 0}, {0, 10}), quarter) == Approx(10 / std::sqrt(2.0) - 5));
  // A line inside the circle, below the arc's top: its end (1, 2) is nearest,
  // to the arc point in its direction, at 5 - |(1, 2)|.
  CHECK(distance(arcDeg({0, 0}, 5, 60, 120, true), Seg::line({-1, 2}, {1, 2})) == Approx(5 - std::sqrt(5.0)));
  // The perpendicular foot outside the line: the ends (0, 5) and (-5, -3).
  CHECK(distance(quarter, Seg::line({-10, -3}, {-5, -3})) == Approx(std::sqrt(25.0 + 64)));
  // Two arcs facing each other along the line of centres: (1,0) and (3,0).
  const Seg right = arcDeg({0, 0}, 1, -45, 45, true);
  const Seg left = arcDeg({5, 0}, 2, 135, 225, true);
  CHECK(distance(right, left) == Approx(2));
  // Not facing: the end (5, 2) of the second is nearest, to the first arc's
  // point in its direction (21.8 degrees, within -45..45): |(5, 2)| - 1.
  const Seg upper = arcDeg({5, 0}, 2, 45, 90, true);
  CHECK(distance(right, upper) == Approx(std::sqrt(29.0) - 1));
  CHECK(distance(upper, right) == Approx(std::sqrt(29.0) - 1));
  // Concentric arcs that overlap in angle.
  CHECK(distance(arcDeg({0, 0}, 3, 0, 90, true), arcDeg({0, 0}, 5, 80, 170, true)) == Approx(2));
  // Arcs that cross.
  CHECK(distance(arcDeg({0, 0}, 5, 0, 90, true), arcDeg({6, 0}, 5, 90, 180, true)) == 0);
}

TEST_CASE("segment distances agree with dense sampling", "[geom]") {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> coord(0, 20), radius(0.5, 8), angle(0, 2 * pi),
      sweep(0.05, 2 * pi - 0.05);
  auto randomSeg = [&]() {
    if (rng() % 2)
      return Seg::line({coord(rng), coord(rng)}, {coord(rng), coord(rng)});
    const Vec2 c(coord(rng), coord(rng));
    const double r = radius(rng), a0 = angle(rng), sw = sweep(rng);
    const bool ccw = rng() % 2;
    const double a1 = ccw ? a0 + sw : a0 - sw;
    return Seg::arc(c + r * Vec2(std::cos(a0), std::sin(a0)), c + r * Vec2(std::cos(a1), std::sin(a1)), c,
                    ccw);
  };
  for (int k = 0; k < 300; ++k) {
    const Seg s = randomSeg(), t = randomSeg();
    constexpr int samples = 4000;
    double sampled = 1e300;
    for (int i = 0; i <= samples; ++i)
      sampled = std::min(sampled, distance(t, s.at(double(i) / samples)));
    const double exact = distance(s, t);
    CAPTURE(k, s.turn, t.turn);
    CHECK(exact <= sampled + 1e-9);
    CHECK(exact >= sampled - s.length() / samples); // samples step along s
    CHECK(distance(t, s) == Approx(exact).margin(1e-12));
  }
}

TEST_CASE("intersections of lines and arcs", "[geom]") {
  // Line across the upper half of a circle: two points.
  const Seg upperHalf = Seg::arc({5, 0}, {-5, 0}, {0, 0}, true);
  std::vector<Vec2> pts = intersect(Seg::line({-10, 3}, {10, 3}), upperHalf);
  CHECK(pts.size() == 2);
  CHECK(hasPoint(pts, {4, 3}));
  CHECK(hasPoint(pts, {-4, 3}));
  // Below the arc's span: none.
  CHECK(intersect(Seg::line({-10, -3}, {10, -3}), upperHalf).empty());
  // Tangent line at the top: one point.
  pts = intersect(upperHalf, Seg::line({-10, 5}, {10, 5}));
  CHECK(pts.size() == 1);
  CHECK(hasPoint(pts, {0, 5}));

  // Two circles of radius 5, centres 6 apart, cross at (3, +-4); only (3, 4)
  // is on the upper half of the first.
  const Seg leftOfSecond = Seg::arc({6, 5}, {6, -5}, {6, 0}, true);
  pts = intersect(upperHalf, leftOfSecond);
  CHECK(pts.size() == 1);
  CHECK(hasPoint(pts, {3, 4}));
  pts = intersect(Seg::arc({0, 5}, {0, -5}, {0, 0}, false), leftOfSecond); // right half of the first
  CHECK(pts.size() == 2);
  CHECK(hasPoint(pts, {3, 4}));
  CHECK(hasPoint(pts, {3, -4}));
  // Touching circles: from outside at (1, 0), from inside at (3, 0).
  pts = intersect(arcDeg({0, 0}, 1, -90, 90, true), arcDeg({3, 0}, 2, 90, 270, true));
  CHECK(pts.size() == 1);
  CHECK(hasPoint(pts, {1, 0}));
  pts = intersect(arcDeg({0, 0}, 3, -90, 90, true), arcDeg({1, 0}, 2, -90, 90, true));
  CHECK(pts.size() == 1);
  CHECK(hasPoint(pts, {3, 0}));
  // Almost touching: apart by 1e-6.
  CHECK(intersect(arcDeg({0, 0}, 1, -90, 90, true), arcDeg({3 + 1e-6, 0}, 2, 90, 270, true)).empty());

  // Lines: crossing, collinear overlap (its end points), touching end to end,
  // parallel.
  pts = intersect(Seg::line({0, 0}, {4, 4}), Seg::line({0, 4}, {4, 0}));
  CHECK(pts.size() == 1);
  CHECK(hasPoint(pts, {2, 2}));
  pts = intersect(Seg::line({0, 0}, {10, 0}), Seg::line({15, 0}, {5, 0}));
  CHECK(pts.size() == 2);
  CHECK(hasPoint(pts, {5, 0}));
  CHECK(hasPoint(pts, {10, 0}));
  pts = intersect(Seg::line({0, 0}, {10, 0}), Seg::line({10, 0}, {10, 5}));
  CHECK(pts.size() == 1);
  CHECK(hasPoint(pts, {10, 0}));
  CHECK(intersect(Seg::line({0, 0}, {10, 0}), Seg::line({0, 1e-6}, {10, 1e-6})).empty());
  CHECK(intersect(Seg::line({0, 0}, {10, 0}), Seg::line({10.001, -1}, {10.001, 1})).empty());

  // Same circle, overlapping arcs: the ends of the overlap.
  pts = intersect(arcDeg({0, 0}, 2, 0, 90, true), arcDeg({0, 0}, 2, 45, 180, true));
  CHECK(pts.size() == 2);
  CHECK(hasPoint(pts, {std::sqrt(2.0), std::sqrt(2.0)}));
  CHECK(hasPoint(pts, {0, 2}));
}

TEST_CASE("SegIndex agrees with brute force", "[geom]") {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> coord(0, 100), step(-3, 3), radius(0.2, 4), angle(0, 2 * pi);
  std::vector<Seg> segs;
  for (int i = 0; i < 3000; ++i) {
    const Vec2 a(coord(rng), coord(rng));
    if (i % 3) {
      segs.push_back(Seg::line(a, a + Vec2(step(rng), step(rng))));
    } else {
      const double r = radius(rng), a0 = angle(rng), a1 = a0 + angle(rng) * 0.9 + 0.1;
      const bool ccw = rng() % 2;
      segs.push_back(Seg::arc(a + r * Vec2(std::cos(a0), std::sin(a0)),
                              a + r * Vec2(std::cos(a1), std::sin(a1)), a, ccw));
    }
  }
  // A few long segments crossing many cells.
  segs.push_back(Seg::line({-10, -10}, {110, 90}));
  segs.push_back(Seg::arc({50, -20}, {50, 120}, {50, 50}, true));
  const SegIndex index(segs);

  std::uniform_real_distribution<double> wide(-30, 130);
  for (int k = 0; k < 3000; ++k) {
    const Vec2 p(wide(rng), wide(rng));
    double brute = 1e300;
    for (const Seg &s : segs)
      brute = std::min(brute, distance(s, p));
    REQUIRE(index.distance(p) == brute);
  }
  for (int k = 0; k < 300; ++k) {
    const Vec2 a(wide(rng), wide(rng));
    const Seg s = k % 2 ? Seg::line(a, a + Vec2(step(rng), step(rng)) * 3)
                        : Seg::arc(a + Vec2(2, 0), a + Vec2(0, 2), a, k % 4 == 0);
    double brute = 1e300;
    for (const Seg &t : segs)
      brute = std::min(brute, distance(s, t));
    REQUIRE(index.distance(s) == Approx(brute).margin(1e-12));
  }
  std::vector<uint32_t> found;
  for (int k = 0; k < 200; ++k) {
    Box box;
    box.add(Vec2(wide(rng), wide(rng)));
    box.add(box.lo + Vec2(coord(rng), coord(rng)) * 0.2);
    index.query(box, found);
    std::sort(found.begin(), found.end());
    std::vector<uint32_t> brute;
    for (uint32_t i = 0; i < segs.size(); ++i)
      if (segs[i].box().overlaps(box))
        brute.push_back(i);
    REQUIRE(found == brute);
  }
}

TEST_CASE("SegIndex winding agrees with the loops", "[geom]") {
  Loop squareHole = rect(35, 10, 50, 30);
  squareHole.reverse();
  const Region r{{roundedRect(0, 0, 60, 40, 8), circleLoop({20, 20}, 5, false), squareHole}};
  const SegIndex index = SegIndex::of(r);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-5, 65);
  int inside = 0;
  for (int k = 0; k < 5000; ++k) {
    // Also points on the grid lines of integers, which rays along edges meet.
    const Vec2 p =
        k % 5 ? Vec2(coord(rng), coord(rng)) : Vec2(std::round(coord(rng)) + 0.5, std::round(coord(rng)));
    int w = 0;
    for (const Loop &l : r.loops)
      w += l.winding(p);
    REQUIRE(index.winding(p) == w);
    inside += w != 0;
  }
  CHECK(inside > 1000);
}
