// B-splines as chords (ir/geom/Curves): every vertex on the curve and every
// chord within kSplineChordTolerance of it, checked against closed forms of
// the same curves (a parabola, a circle), not against the evaluator.
#include "ir/geom/Curves.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace stepnc;
using ir::Kind;
using ir::Node;
using ir::Value;
using ir::Vec3;

namespace {

Node spline(int degree, const std::string &form, const std::vector<Vec3> &points,
            const std::vector<double> &weights = {},
            const std::vector<std::pair<double, int>> &knots = {}) {
  Node n(Kind::BSplineCurve);
  n.set("degree", Value::integer(degree));
  n.set("form", Value::word(form));
  for (size_t i = 0; i < points.size(); ++i) {
    Node p(Kind::Point);
    p.set("at", Value::point(points[i]));
    if (!weights.empty())
      p.set("weight", Value::ratio(weights[i]));
    n.add(std::move(p));
  }
  for (const auto &[value, multiplicity] : knots) {
    Node k(Kind::Knot);
    k.set("value", Value::ratio(value));
    k.set("multiplicity", Value::integer(multiplicity));
    n.add(std::move(k));
  }
  return n;
}

/// Largest distance of the chords' vertices and midpoints from a curve given
/// by its distance function.
template <class Distance>
std::pair<double, double> straying(const ir::CurveResult &r, Distance distance) {
  double vertex = 0, middle = 0;
  for (const ir::CurvePiece &p : r.pieces) {
    vertex = std::max({vertex, distance(p.from), distance(p.to)});
    middle = std::max(middle, distance((p.from + p.to) / 2));
  }
  return {vertex, middle};
}

} // namespace

TEST_CASE("a quadratic Bezier is a parabola, in chords within the tolerance", "[curves]") {
  // (0,0), (1,2), (2,0): x = 2t, y = 4t(1-t) = x (2 - x).
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 2, 0}, {2, 0, 0}};
  for (const Node &n : {spline(2, "bezier", pts), spline(2, "quasi_uniform", pts),
                        spline(2, "with_knots", pts, {}, {{0.0, 3}, {1.0, 3}})}) {
    const ir::CurveResult r = ir::curvePieces(n);
    REQUIRE(r.error.empty());
    REQUIRE(r.pieces.size() > 8);
    CHECK((r.pieces.front().from - Vec3(0, 0, 0)).norm() < 1e-12);
    CHECK((r.pieces.back().to - Vec3(2, 0, 0)).norm() < 1e-12);
    // Vertical distance bounds the distance to the parabola from above.
    const auto [vertex, middle] = straying(r, [](const Vec3 &q) { return std::abs(q.y() - q.x() * (2 - q.x())); });
    CHECK(vertex < 1e-12);
    CHECK(middle <= ir::kSplineChordTolerance * 1.01);
  }
}

TEST_CASE("a rational quadratic is an exact quarter circle", "[curves]") {
  const double w = std::sqrt(0.5);
  const Node n = spline(2, "with_knots", {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {1, w, 1}, {{0.0, 3}, {1.0, 3}});
  const ir::CurveResult r = ir::curvePieces(n);
  REQUIRE(r.error.empty());
  const auto [vertex, middle] = straying(r, [](const Vec3 &q) { return std::abs(q.norm() - 1); });
  CHECK(vertex < 1e-12);
  CHECK(middle <= ir::kSplineChordTolerance * 1.01);
}

TEST_CASE("a cubic in two Bezier pieces meets its control points at the joint", "[curves]") {
  const Node n = spline(3, "bezier", {{0, 0, 0}, {1, 1, 0}, {2, 1, 0}, {3, 0, 0}, {4, -1, 0}, {5, -1, 0}, {6, 0, 0}});
  std::string error;
  const std::optional<ir::BSpline> s = ir::bspline(n, error);
  REQUIRE(s);
  CHECK(s->start == 0);
  CHECK(s->end == 2);
  CHECK((s->at(1) - Vec3(3, 0, 0)).norm() < 1e-12);
  CHECK((s->at(0.5) - Vec3(1.5, 0.75, 0)).norm() < 1e-12);  // the first piece's middle: (P0 + 3P1 + 3P2 + P3) / 8
  CHECK(ir::curvePieces(n).error.empty());
}

TEST_CASE("B-splines that do not make a curve are refused, saying why", "[curves]") {
  std::string error;
  CHECK_FALSE(ir::bspline(spline(3, "with_knots", {{0, 0, 0}, {1, 1, 0}}), error));
  CHECK(error.find("needs more than 3 control points") != std::string::npos);
  CHECK_FALSE(ir::bspline(spline(2, "with_knots", {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}}, {}, {{0.0, 3}, {1.0, 2}}), error));
  CHECK(error.find("needs 6 knots") != std::string::npos);
  CHECK_FALSE(ir::bspline(spline(3, "bezier", {{0, 0, 0}, {1, 1, 0}, {2, 1, 0}, {3, 0, 0}, {4, 0, 0}}), error));
  CHECK(error.find("multiple of 3") != std::string::npos);
  CHECK_FALSE(ir::bspline(spline(1, "with_knots", {{0, 0, 0}, {1, 0, 0}}, {1, -1}, {{0.0, 2}, {1.0, 2}}), error));
  CHECK(error.find("weights must be positive") != std::string::npos);
}

TEST_CASE("circles about x or y: arcs in the ZX and YZ planes for explicit toolpaths only", "[curves]") {
  // A circle of radius 5 about +y centred at (3, 2, 1), trimmed from its
  // bottom (3, 2, -4) to (8, 2, 1) along its sense: counterclockwise seen
  // from +y (the long way, by -x and the top).
  Node circle(Kind::Circle);
  circle.set("at", Value::point({3, 2, 1}))
      .set("axis", Value::direction({0, 1, 0}))
      .set("ref", Value::direction({0, 0, 1}))
      .set("radius", Value::length(5));
  Node trimmed(Kind::TrimmedCurve);
  trimmed.set("from_point", Value::point({3, 2, -4})).set("to_point", Value::point({8, 2, 1})).set("sense",
                                                                                                   Value::boolean(true));
  trimmed.add(circle);

  const ir::CurveResult xyOnly = ir::curvePieces(trimmed);
  CHECK(xyOnly.error.find("only circles and helices about the tool axis") != std::string::npos);

  const ir::CurveResult r = ir::curvePieces(trimmed, ir::ArcPlanes::Principal);
  REQUIRE(r.error.empty());
  REQUIRE(r.pieces.size() == 1);
  const ir::CurvePiece &p = r.pieces.front();
  CHECK(p.arc);
  CHECK(p.plane.normal == 1);
  CHECK(p.ccw);  // along the circle's sense about its axis +y
  CHECK((p.center - Vec3(3, 2, 1)).norm() < 1e-12);

  // An end off the circle is refused in that plane too.
  trimmed.set("to_point", Value::point({8.01, 2, 1}));
  CHECK(ir::curvePieces(trimmed, ir::ArcPlanes::Principal).error.find("outside its circle") != std::string::npos);

  // A circle about a slanted axis is none of the principal planes.
  circle.set("axis", Value::direction(Vec3(1, 1, 0).normalized()));
  Node full = circle;
  CHECK(ir::curvePieces(full, ir::ArcPlanes::Principal).error.find("about the x, y or z axis") != std::string::npos);
}
