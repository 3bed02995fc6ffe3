// Reading the toolpath IR (see MoveWalk.h).
//
// Arcs: the tool turns about `center` (its z is not used) from where the move
// starts to `to`, in the direction `dir`, after `turns` full turns. The angle
// turned is 2*pi*turns plus the last partial angle from the start to `to`,
// which is itself a whole turn when `to` is over the start (the toolpath IR's
// rule: `turns` counts the turns *before* the last arc, so a full circle has
// turns 0 and a helix of three whole turns down one axis position turns 2).
// A change of height spreads evenly over the angle: a helix.
#include "ir/geom/MoveWalk.h"

#include "ir/Kinds.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::ir {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

geom::Vec2 xy(const ir::Vec3 &p) { return p.head<2>(); }

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
  const geom::Vec2 a = xy(*m.from), b = xy(m.to), c = xy(m.center);
  const double turns = static_cast<double>(std::max<int64_t>(m.turns, 0));
  const double last = samePlanarPoint(a, b) ? kTwoPi : partialAngle(a, b, c, m.ccw);
  return kTwoPi * turns + last;
}

/// True for an arc whose start lies on its centre: it has no radius to turn on.
bool degenerateArc(const Move &m) { return (xy(*m.from) - xy(m.center)).norm() <= geom::kEps; }

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
  const double radius = (xy(*from) - xy(center)).norm();
  const double planar = radius * arcAngle(*this);
  const double dz = to.z() - from->z();
  return std::sqrt(planar * planar + dz * dz);
}

std::vector<geom::Seg> Move::planar() const {
  if (!from)
    return {};
  const geom::Vec2 a = xy(*from), b = xy(to);
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
  const geom::Vec2 c = xy(center), u = xy(a) - c;
  const double angle = (ccw ? 1 : -1) * s / u.norm();
  const geom::Vec2 p =
      c + geom::Vec2(u.x() * std::cos(angle) - u.y() * std::sin(angle), u.x() * std::sin(angle) + u.y() * std::cos(angle));
  return {p.x(), p.y(), a.z()};
}

namespace {

void walk(const ir::Node &parent, const ir::Node *cycle, std::optional<ir::Vec3> &at, PathKind path,
          std::vector<Move> &out) {
  for (const ir::Node &n : parent.children) {
    switch (n.kind) {
    case ir::Kind::Cycle:
      walk(n, &n, at, path, out);
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
    if (m.kind == MoveKind::Dwell)
      m.to = at.value_or(ir::Vec3::Zero());
    at = m.to;
    out.push_back(std::move(m));
  }
}

} // namespace

std::vector<Move> walkMoves(const ir::Node &moves, std::optional<ir::Vec3> start, PathKind path) {
  std::vector<Move> out;
  std::optional<ir::Vec3> at = start;
  walk(moves, nullptr, at, path, out);
  return out;
}

} // namespace stepnc::ir
