// The verifier's own reading of walls: outlines shrunk as a boss whose walls
// lean in is at each height (Outline::inset), checked by distances worked
// out by hand.
#include "passes/FeatureWalls.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace stepnc;
using namespace stepnc::passes;
using geom::Vec2;

namespace {

Outline polygon(std::initializer_list<Vec2> points) {
  Outline o;
  std::vector<Vec2> p(points);
  for (size_t i = 0; i < p.size(); ++i)
    o.pieces.push_back(WallPiece::line(p[i], p[(i + 1) % p.size()]));
  return o;
}

} // namespace

TEST_CASE("an outline shrunk keeps its convex corners sharp", "[walls]") {
  for (const bool clockwise : {false, true}) {
    Outline square = clockwise ? polygon({{0, 0}, {0, 30}, {30, 30}, {30, 0}}) : polygon({{0, 0}, {30, 0}, {30, 30}, {0, 30}});
    const std::optional<Outline> in = square.inset(5);
    REQUIRE(in);
    REQUIRE(in->pieces.size() == 4);
    // The 20 x 20 square from (5, 5): its corner is 5 * sqrt(2) from (0, 0)'s
    // side, 5 from each wall.
    CHECK(in->clearance({15, 15}) == Approx(10));
    CHECK(in->clearance({0, 0}) == Approx(-5 * std::sqrt(2.0)));
    CHECK(in->clearance({15, 0}) == Approx(-5));
    CHECK(in->contains({5.01, 5.01}));
    CHECK_FALSE(in->contains({4.99, 15}));
  }
}

TEST_CASE("an outline shrunk rounds its concave corners, shrinks its arcs, and says when it changes shape", "[walls]") {
  // An L: the concave corner at (10, 10) becomes an arc of radius 2 about it.
  const Outline l = polygon({{0, 0}, {30, 0}, {30, 10}, {10, 10}, {10, 30}, {0, 30}});
  const std::optional<Outline> in = l.inset(2);
  REQUIRE(in);
  CHECK(in->pieces.size() == 7);
  // Along the diagonal into the L from the concave corner, the arc is 2 from
  // it; (9, 9) is within 2 of the corner, so outside what is left.
  const Vec2 onArc = Vec2(10, 10) - Vec2(1, 1).normalized() * 2;
  CHECK(std::abs(in->clearance(onArc)) < 1e-9);
  CHECK(in->clearance({9, 9}) == Approx(-(2 - std::sqrt(2.0))));
  CHECK(in->clearance({5, 5}) == Approx(3));
  // A circle of radius 10 shrinks to one of 7.
  Outline circle;
  circle.pieces.push_back(WallPiece::arcFrom({0, 0}, {10, 0}, 2 * std::numbers::pi));
  const std::optional<Outline> small = circle.inset(3);
  REQUIRE(small);
  CHECK(small->clearance({0, 0}) == Approx(7));
  CHECK(small->clearance({9, 0}) == Approx(-2));
  // Shrunk by more than the L's arm is wide, a side turns round: none.
  CHECK_FALSE(l.inset(6));
  CHECK_FALSE(circle.inset(10));
}
