// Reading the toolpath IR (see MoveWalk.h).
//
// Arcs: the tool turns about `center` (its z is not used) from where the move
// starts to `to`, in the direction `dir`, after `turns` full turns. The angle
// turned is 2*pi*turns plus the last partial angle from the start to `to`,
// which is itself a whole turn when `to` is over the start (the toolpath IR's
// rule: `turns` counts the turns *before* the last arc, so a full circle has
// turns 0 and a helix of three whole turns down one axis position turns 2).
// A change of height spreads evenly over the angle: a helix. Arcs out of the
// XY plane (IR `normal` along x or y) follow the same rules in their plane's
// coordinates (geom/ArcPlane.h), "height" being along the normal.
#include "ir/geom/MoveWalk.h"

#include "ir/Kinds.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

namespace stepnc::ir {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

geom::Vec2 xy(const ir::Vec3 &p) { return p.head<2>(); }
/// A point in the plane of an arc move: its (first, second) coordinates.
geom::Vec2 inPlane(const Move &m, const ir::Vec3 &p) { return m.plane.local(p).head<2>(); }

/// True when the two points are the same point in the plane.
bool samePlanarPoint(const geom::Vec2 &a, const geom::Vec2 &b) { return (a - b).norm() <= geom::kEps; }

/// The angle (> 0) turned from `a` to `b` about `c` in the given direction; 0 when the points coincide.
double partialAngle(const geom::Vec2 &a, const geom::Vec2 &b, const geom::Vec2 &c, bool ccw) {
  const geom::Vec2 u = a - c, v = b - c;
  const double ccwAngle = std::atan2(geom::cross(u, v), u.dot(v));  // in [-pi, pi]
  double angle = ccw ? ccwAngle : -ccwAngle;
  if (angle <= 0)
    angle += kTwoPi;
  return angle;
}

/// The planar angle an arc move turns through (see the file comment); 0 for a
/// degenerate arc (start on its centre).
double arcAngle(const Move &m) {
  const geom::Vec2 a = inPlane(m, *m.from), b = inPlane(m, m.to), c = inPlane(m, m.center);
  const double turns = static_cast<double>(std::max<int64_t>(m.turns, 0));
  const double last = samePlanarPoint(a, b) ? kTwoPi : partialAngle(a, b, c, m.ccw);
  return kTwoPi * turns + last;
}

/// True for an arc whose start lies on its centre: it has no radius to turn on.
bool degenerateArc(const Move &m) { return (inPlane(m, *m.from) - inPlane(m, m.center)).norm() <= geom::kEps; }

Move readMove(const ir::Node &n, PathKind path) {
  Move m;
  m.node = &n;
  switch (n.kind) {
  case ir::Kind::Rapid: m.kind = MoveKind::Rapid; break;
  case ir::Kind::Linear: m.kind = MoveKind::Linear; break;
  case ir::Kind::Dwell:
    m.kind = MoveKind::Dwell;
    m.dwell = n.number("time").value_or(0);
    m.role = "dwell";
    return m;
  default: m.kind = MoveKind::Arc; break;
  }
  std::optional<ir::Vec3> to = path == PathKind::Predicted ? n.vec("nominal") : std::nullopt;
  m.to = to ? *to : n.vec("to").value_or(ir::Vec3::Zero());
  std::optional<ir::Vec3> center = path == PathKind::Predicted ? n.vec("nominal_center") : std::nullopt;
  m.center = center ? *center : n.vec("center").value_or(ir::Vec3::Zero());
  m.ccw = n.text("dir") == "ccw";
  if (auto normal = n.vec("normal")) {
    // Principal normals only (ir::beyondThreeAxisMilling refuses others).
    bool positive = true;
    if (std::optional<geom::ArcPlane> plane = geom::ArcPlane::about(*normal, positive)) {
      m.plane = *plane;
      if (!positive)
        m.ccw = !m.ccw;
    }
  }
  m.turns = n.count("turns").value_or(0);
  m.feed = m.isFeed() ? n.number("feed").value_or(0.0) : 0.0;
  m.role = n.text("role").value_or(m.isFeed() ? "cut" : "position");
  return m;
}

} // namespace

bool Move::changesHeight() const { return from && std::abs(to.z() - from->z()) > geom::kEps; }

double Move::length() const {
  if (!from)
    return 0;  // the start is unknown
  if (kind != MoveKind::Arc || degenerateArc(*this))
    return (to - *from).norm();
  const double radius = (inPlane(*this, *from) - inPlane(*this, center)).norm();
  const double planar = radius * arcAngle(*this);
  const double dz = to[plane.normal] - (*from)[plane.normal];
  return std::sqrt(planar * planar + dz * dz);
}

std::vector<ir::Vec3> Move::chordPoints(double tolerance) const {
  const ir::Vec3 a = from.value_or(to);
  if (kind != MoveKind::Arc || !from || degenerateArc(*this))
    return {a, to};
  const ir::Vec3 la = plane.local(a), lb = plane.local(to), lc = plane.local(center);
  const geom::Vec2 u = la.head<2>() - lc.head<2>();
  const double radius = u.norm(), angle = arcAngle(*this);
  // A chord over the angle 2 acos(1 - tol / r) strays tol from its arc.
  const double step = 2 * std::acos(std::clamp(1 - tolerance / radius, -1.0, 1.0));
  const int pieces = std::max(1, static_cast<int>(std::ceil(angle / std::max(step, 1e-6))));
  std::vector<ir::Vec3> points{a};
  for (int k = 1; k < pieces; ++k) {
    const double t = angle * k / pieces, turn = ccw ? t : -t;
    const geom::Vec2 p = lc.head<2>() + geom::Vec2(u.x() * std::cos(turn) - u.y() * std::sin(turn),
                                                   u.x() * std::sin(turn) + u.y() * std::cos(turn));
    points.push_back(plane.world(ir::Vec3(p.x(), p.y(), la.z() + (lb.z() - la.z()) * k / pieces)));
  }
  points.push_back(to);
  return points;
}

std::vector<geom::Seg> Move::planar() const {
  if (!from)
    return {};
  const geom::Vec2 a = xy(*from), b = xy(to);
  if (kind == MoveKind::Arc && !plane.isXY()) {
    std::vector<geom::Seg> segs;
    const std::vector<ir::Vec3> points = chordPoints(kOutOfPlaneArcChord);
    for (size_t k = 1; k < points.size(); ++k)
      if (!samePlanarPoint(xy(points[k - 1]), xy(points[k])))
        segs.push_back(geom::Seg::line(xy(points[k - 1]), xy(points[k])));
    return segs;
  }
  if (kind != MoveKind::Arc || degenerateArc(*this)) {
    if (samePlanarPoint(a, b))
      return {};  // purely axial
    return {geom::Seg::line(a, b)};
  }
  const geom::Vec2 c = xy(center);
  const double radius = (a - c).norm();
  std::vector<geom::Seg> segs;
  const int64_t fullTurns = std::max<int64_t>(turns, 0);
  for (int64_t i = 0; i < fullTurns; ++i)
    for (const geom::Seg &s : geom::circle(c, radius, ccw, a))
      segs.push_back(s);
  if (samePlanarPoint(a, b)) {
    for (const geom::Seg &s : geom::circle(c, radius, ccw, a))
      segs.push_back(s);  // the last arc is a whole turn
  } else {
    segs.push_back(geom::Seg::arc(a, b, c, ccw));
  }
  return segs;
}

ir::Vec3 Move::pointAt(double s) const {
  const ir::Vec3 a = from.value_or(to);
  if (kind != MoveKind::Arc || degenerateArc(*this)) {
    const double len = length();
    return len > 0 ? ir::Vec3(a + (to - a) * (s / len)) : to;
  }
  const geom::Vec2 c = inPlane(*this, center), u = inPlane(*this, a) - c;
  const double angle = (ccw ? 1 : -1) * s / u.norm();
  const geom::Vec2 p =
      c + geom::Vec2(u.x() * std::cos(angle) - u.y() * std::sin(angle), u.x() * std::sin(angle) + u.y() * std::cos(angle));
  return plane.world(ir::Vec3(p.x(), p.y(), plane.local(a).z()));
}

namespace {

/// Where a walk is: the tool's position (when known) and axis, and the
/// axis the moves without one of their own have.
struct WalkState {
  std::optional<ir::Vec3> at;
  ir::Vec3 axis = ir::Vec3::UnitZ();
  ir::Vec3 movesAxis = ir::Vec3::UnitZ();
};

void walk(const ir::Node &parent, const ir::Node *cycle, WalkState &state, PathKind path, OutOfPlaneArcs arcs,
          std::vector<Move> &out) {
  std::optional<ir::Vec3> &at = state.at;
  for (const ir::Node &n : parent.children) {
    switch (n.kind) {
    case ir::Kind::Cycle:
      walk(n, &n, state, path, arcs, out);
      continue;
    case ir::Kind::Rapid:
    case ir::Kind::Linear:
    case ir::Kind::Arc:
    case ir::Kind::Dwell:
      break;
    default:
      continue;
    }
    Move m = readMove(n, path);
    m.cycle = cycle;
    m.from = at;
    m.fromAxis = state.axis;
    m.axis = m.kind == MoveKind::Dwell ? state.axis : n.vec("axis").value_or(state.movesAxis);
    if (m.kind == MoveKind::Dwell)
      m.to = at.value_or(ir::Vec3::Zero());
    at = m.to;
    state.axis = m.axis;
    if (m.kind == MoveKind::Arc && !m.plane.isXY() && m.from && arcs == OutOfPlaneArcs::Chords) {
      const std::vector<ir::Vec3> points = m.chordPoints(kOutOfPlaneArcChord);
      for (size_t k = 1; k < points.size(); ++k) {
        Move line = m;
        line.kind = MoveKind::Linear;
        line.chord = true;
        line.from = points[k - 1];
        line.to = points[k];
        line.fromAxis = turnAxis(m.fromAxis, m.axis, double(k - 1) / double(points.size() - 1));
        line.axis = turnAxis(m.fromAxis, m.axis, double(k) / double(points.size() - 1));
        line.center = ir::Vec3::Zero();
        line.turns = 0;
        out.push_back(std::move(line));
      }
      continue;
    }
    out.push_back(std::move(m));
  }
}

} // namespace

std::vector<Move> walkMoves(const ir::Node &moves, std::optional<ir::Vec3> start, PathKind path,
                            OutOfPlaneArcs arcs) {
  std::vector<Move> out;
  WalkState state;
  state.at = start;
  state.movesAxis = moves.vec("axis").value_or(ir::Vec3::UnitZ());
  state.axis = state.movesAxis;
  walk(moves, nullptr, state, path, arcs, out);
  return out;
}

ir::Vec3 turnAxis(const ir::Vec3 &u, const ir::Vec3 &w, double t) {
  const double c = std::clamp(u.dot(w), -1.0, 1.0);
  const double angle = std::acos(c);
  if (angle < 1e-12 || angle > std::numbers::pi - 1e-9)
    return t >= 1 && angle < 1e-12 ? w : u;
  const double s = std::sin(angle);
  return (std::sin((1 - t) * angle) / s) * u + (std::sin(t * angle) / s) * w;
}

double angleBetween(const ir::Vec3 &u, const ir::Vec3 &w) {
  // atan2 of the cross and dot products: exact for small angles too.
  return std::atan2(u.cross(w).norm(), u.dot(w)) * 180 / std::numbers::pi;
}

std::vector<std::pair<Move, bool>> walkWithEnergy(const ir::Node &moves) {
  std::map<const ir::Node *, std::vector<Move>> walked;
  for (Move &m : walkMoves(moves))
    walked[m.node].push_back(m);
  std::vector<std::pair<Move, bool>> out;
  bool energy = false;
  for (const ir::Node &c : moves.children) {
    if (c.kind == ir::Kind::State) {
      if (auto e = c.text("energy"))
        energy = *e == "on";
      continue;
    }
    if (auto it = walked.find(&c); it != walked.end())
      for (const Move &m : it->second)
        out.emplace_back(m, energy);
  }
  return out;
}

} // namespace stepnc::ir
