// Tests of ir/geom/MoveWalk.h: where each move starts, lengths of lines, arcs
// and helices (worked out by hand), and what the moves are in the plane.
#include "ir/geom/MoveWalk.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace stepnc;
using namespace stepnc::ir;
using ir::Node;
using ir::Value;
using ir::Vec3;

namespace {

constexpr double kPi = std::numbers::pi;

Node &rapid(Node &moves, const Vec3 &to) {
  Node &m = moves.add(Node(ir::Kind::Rapid));
  m.set("to", Value::point(to));
  return m;
}

Node &linear(Node &moves, const Vec3 &to) {
  Node &m = moves.add(Node(ir::Kind::Linear));
  m.set("to", Value::point(to)).set("feed", Value::feed(600));
  return m;
}

Node &arc(Node &moves, const Vec3 &to, const Vec3 &centre, bool ccw, int64_t turns = 0) {
  Node &m = moves.add(Node(ir::Kind::Arc));
  m.set("to", Value::point(to))
      .set("center", Value::point(centre))
      .set("dir", Value::word(ccw ? "ccw" : "cw"));
  if (turns > 0)
    m.set("turns", Value::integer(turns));
  m.set("feed", Value::feed(300));
  return m;
}

double totalSweep(const std::vector<geom::Seg> &segs) {
  double sum = 0;
  for (const geom::Seg &s : segs)
    sum += s.sweep();
  return sum;
}

} // namespace

TEST_CASE("walkMoves knows where every move starts", "[verify][movewalk]") {
  Node moves(ir::Kind::Moves);
  rapid(moves, Vec3(0, 0, 50));
  rapid(moves, Vec3(10, 0, 5)).set("role", Value::word("approach"));
  linear(moves, Vec3(10, 0, 0));
  arc(moves, Vec3(30, 0, 0), Vec3(20, 0, 0), false);
  moves.add(Node(ir::Kind::Motion));  // not a move: skipped

  std::vector<ir::Move> walk = ir::walkMoves(moves);
  REQUIRE(walk.size() == 4);
  CHECK_FALSE(walk[0].from);
  CHECK(walk[0].length() == 0);  // from an unknown position
  REQUIRE(walk[1].from);
  CHECK(*walk[1].from == Vec3(0, 0, 50));
  CHECK(*walk[2].from == Vec3(10, 0, 5));
  CHECK(*walk[3].from == Vec3(10, 0, 0));
  CHECK(walk[0].role == "position");
  CHECK(walk[1].role == "approach");
  CHECK(walk[2].role == "cut");
  CHECK(walk[2].feed == 600);
  CHECK(walk[0].feed == 0);
  CHECK_FALSE(walk[0].isFeed());
  CHECK(walk[3].kind == ir::MoveKind::Arc);
  CHECK_FALSE(walk[3].ccw);
  CHECK(walk[2].changesHeight());
  CHECK_FALSE(walk[3].changesHeight());

  // A known start makes the first move measurable.
  std::vector<ir::Move> known = ir::walkMoves(moves, Vec3(0, 0, 20));
  REQUIRE(known[0].from);
  CHECK(known[0].length() == Approx(30));
}

TEST_CASE("lengths of lines, arcs and helices", "[verify][movewalk]") {
  Node moves(ir::Kind::Moves);
  rapid(moves, Vec3(0, 0, 0));
  linear(moves, Vec3(30, 40, 0));                              // 50
  arc(moves, Vec3(50, 40, 0), Vec3(40, 40, 0), false);         // cw half circle, r 10: 10 pi
  arc(moves, Vec3(40, 50, 0), Vec3(40, 40, 0), true);          // ccw from (50,40) to (40,50): a quarter
  arc(moves, Vec3(40, 50, 0), Vec3(40, 40, 0), false);         // start == end: a whole turn, 20 pi
  arc(moves, Vec3(50, 40, -6), Vec3(40, 40, 0), false, 2);     // helix: 2 turns + 1/4 cw, down 6
  linear(moves, Vec3(50, 40, -10));                             // axial: 4

  std::vector<ir::Move> w = ir::walkMoves(moves);
  REQUIRE(w.size() == 7);
  CHECK(w[1].length() == Approx(50));
  CHECK(w[2].length() == Approx(10 * kPi));
  CHECK(w[3].length() == Approx(10 * kPi / 2));
  CHECK(w[4].length() == Approx(20 * kPi));
  const double helixPlanar = 10 * (2 * 2 * kPi + kPi / 2);
  CHECK(w[5].length() == Approx(std::sqrt(helixPlanar * helixPlanar + 36)));
  CHECK(w[5].changesHeight());
  CHECK(w[6].length() == Approx(4));
}

TEST_CASE("planar(): lines, axial moves, full circles and helices", "[verify][movewalk]") {
  Node moves(ir::Kind::Moves);
  rapid(moves, Vec3(10, 0, 5));
  linear(moves, Vec3(10, 0, -5));                              // axial: nothing in the plane
  linear(moves, Vec3(20, 0, -5));                              // one line
  arc(moves, Vec3(20, 0, -5), Vec3(10, 0, 0), true);           // a full circle: two half arcs
  arc(moves, Vec3(10, 10, -9), Vec3(10, 0, 0), true, 2);       // helix: 2 turns then a quarter
  arc(moves, Vec3(10, 10, -12), Vec3(10, 0, 0), false, 2);     // 2 turns then a whole turn back to the start

  std::vector<ir::Move> w = ir::walkMoves(moves);
  REQUIRE(w.size() == 6);
  CHECK(w[1].planar().empty());
  REQUIRE(w[2].planar().size() == 1);
  CHECK_FALSE(w[2].planar()[0].isArc());

  std::vector<geom::Seg> circle = w[3].planar();
  REQUIRE(circle.size() == 2);
  CHECK(totalSweep(circle) == Approx(2 * kPi));
  CHECK(circle.front().a.isApprox(geom::Vec2(20, 0)));
  CHECK(circle.back().b.isApprox(geom::Vec2(20, 0)));

  std::vector<geom::Seg> helix = w[4].planar();
  REQUIRE(helix.size() == 5);  // 4 half arcs, then the quarter to (10, 10)
  CHECK(totalSweep(helix) == Approx(4 * kPi + kPi / 2));
  CHECK(helix.back().b.isApprox(geom::Vec2(10, 10)));
  for (const geom::Seg &s : helix)
    CHECK(s.radius() == Approx(10));

  std::vector<geom::Seg> back = w[5].planar();
  REQUIRE(back.size() == 6);  // 3 whole turns, clockwise
  CHECK(totalSweep(back) == Approx(-6 * kPi));
}

// Arcs in the ZX and YZ planes (IR `normal` along y or x): read in their
// plane, exact for the G-code emitters and as chords for the passes that
// work in XY. Worked out by hand: a quarter circle of radius 10 in the
// plane y = 5, from (10, 5, 0) about (0, 5, 0) to (0, 5, 10). Turning about
// +y by the right-hand rule takes +z to +x, so the short way from +x to +z
// is clockwise seen from +y.
TEST_CASE("arcs in the ZX and YZ planes: exact and as chords", "[movewalk]") {
  Node moves(ir::Kind::Moves);
  rapid(moves, {10, 5, 0});
  arc(moves, {0, 5, 10}, {0, 5, 0}, false).set("normal", Value::direction(Vec3::UnitY()));
  // The same arc written about -y: counterclockwise seen from -y.
  rapid(moves, {10, 5, 0});
  arc(moves, {0, 5, 10}, {0, 5, 0}, true).set("normal", Value::direction(-Vec3::UnitY()));
  // A half circle in the YZ plane x = 2, about +x from (2, 0, -4) over (2, 4, 0) to (2, 0, 4):
  // about +x the right-hand rule takes y to z, so -z to +y to +z is counterclockwise.
  rapid(moves, {2, 0, -4});
  arc(moves, {2, 0, 4}, {2, 0, 0}, true).set("normal", Value::direction(Vec3::UnitX()));

  const std::vector<Move> exact = walkMoves(moves, std::nullopt, PathKind::Programmed, OutOfPlaneArcs::Exact);
  REQUIRE(exact.size() == 6);
  for (size_t i : {1u, 3u}) {
    CHECK(exact[i].kind == MoveKind::Arc);
    CHECK(exact[i].plane.normal == 1);
    CHECK_FALSE(exact[i].ccw);  // both read as clockwise about +y
    CHECK(exact[i].length() == Approx(10 * kPi / 2));
    const Vec3 mid = exact[i].pointAt(10 * kPi / 4);
    CHECK(mid.x() == Approx(10 / std::sqrt(2.0)));
    CHECK(mid.y() == Approx(5));
    CHECK(mid.z() == Approx(10 / std::sqrt(2.0)));
  }
  CHECK(exact[5].plane.normal == 0);
  CHECK(exact[5].length() == Approx(4 * kPi));
  CHECK(exact[5].pointAt(2 * kPi).y() == Approx(4));

  // As chords: lines from the arc's start to its end, every vertex on its
  // circle, every chord's middle within kOutOfPlaneArcChord of it.
  const std::vector<Move> chords = walkMoves(moves);
  std::vector<const Move *> first;
  for (const Move &m : chords)
    if (m.chord && m.node == exact[1].node)
      first.push_back(&m);
  REQUIRE(first.size() > 10);
  CHECK((*first.front()->from - Vec3(10, 5, 0)).norm() < 1e-12);
  CHECK((first.back()->to - Vec3(0, 5, 10)).norm() < 1e-12);
  double worst = 0;
  for (const Move *m : first) {
    CHECK(m->kind == MoveKind::Linear);
    CHECK(m->feed == 300);
    CHECK(std::hypot(m->to.x(), m->to.z()) == Approx(10));
    CHECK(m->to.y() == Approx(5));
    const Vec3 middle = (*m->from + m->to) / 2;
    worst = std::max(worst, 10 - std::hypot(middle.x(), middle.z()));
  }
  CHECK(worst <= kOutOfPlaneArcChord);
  CHECK(worst > kOutOfPlaneArcChord / 4);  // not finer than it needs
  // Seen from +z the ZX arc is a line along x: its chords' projections.
  double along = 0;
  for (const geom::Seg &s : exact[1].planar())
    along += s.length();
  CHECK(along == Approx(10));
}

TEST_CASE("tool axes: each move's start and end axis, turning evenly between", "[movewalk][five-axis]") {
  Node moves(ir::Kind::Moves);
  moves.set("axis", Value::direction(Vec3::UnitZ()));
  rapid(moves, Vec3(0, 0, 50));
  const Vec3 tilted = Vec3(std::sin(kPi / 6), 0, std::cos(kPi / 6));  // 30 deg towards +x
  linear(moves, Vec3(10, 0, 0)).set("axis", Value::direction(tilted));
  moves.add(Node(ir::Kind::Dwell)).set("time", Value::time(1));
  linear(moves, Vec3(20, 0, 0));  // no axis of its own: the one `moves` gives
  const std::vector<Move> walked = walkMoves(moves);
  REQUIRE(walked.size() == 4);
  CHECK(walked[0].fromAxis == Vec3::UnitZ());
  CHECK(walked[1].fromAxis == Vec3::UnitZ());
  CHECK(walked[1].axis == tilted);
  CHECK(walked[2].axis == tilted);  // a dwell keeps the axis it finds
  CHECK(walked[3].fromAxis == tilted);
  CHECK(walked[3].axis == Vec3::UnitZ());

  // Evenly: a third of the way, a third of the angle, in the plane of the two.
  const Vec3 third = turnAxis(Vec3::UnitZ(), tilted, 1.0 / 3);
  CHECK(third.norm() == Approx(1).epsilon(1e-12));
  CHECK(angleBetween(Vec3::UnitZ(), third) == Approx(10).epsilon(1e-9));
  CHECK(third.y() == Approx(0).margin(1e-15));
  CHECK(turnAxis(Vec3::UnitZ(), tilted, 0) == Vec3::UnitZ());
  CHECK((turnAxis(Vec3::UnitZ(), tilted, 1) - tilted).norm() < 1e-15);
  // Opposite axes have no plane: the start is kept up to the end.
  CHECK(turnAxis(Vec3::UnitZ(), -Vec3::UnitZ(), 0.5) == Vec3::UnitZ());
  // Small angles stay exact (atan2, not acos).
  CHECK(angleBetween(Vec3::UnitZ(), Vec3(1e-9, 0, 1).normalized()) == Approx(1e-9 * 180 / kPi).epsilon(1e-6));
}
