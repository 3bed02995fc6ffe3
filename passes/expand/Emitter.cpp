// The move writer of expand-strategies (see Emitter.h). Moves shorter than
// geom::kEps are dropped here, once, so that no family writes a move that
// goes nowhere (a backend would write a block that does nothing, and the
// verifier would measure a zero-length sweep).
#include "passes/expand/Emitter.h"

#include "ir/Printer.h"

namespace stepnc::passes::expand {

using ir::Node;
using ir::Value;
using ir::Vec3;

namespace {
Vec3 at(const geom::Vec2 &p, double z) { return {p.x(), p.y(), z}; }
} // namespace

Node Emitter::rapidNode(const Vec3 &to, const char *role) {
  Node m(ir::Kind::Rapid);
  m.set("to", Value::point(to));
  m.set("role", Value::word(role));
  return m;
}

Node Emitter::tilted(Node move, const Vec3 &axis) {
  move.set("axis", ir::Value::direction(axis));
  return move;
}

Node Emitter::linearNode(const Vec3 &to, double feed, const char *role) {
  Node m(ir::Kind::Linear);
  m.set("to", Value::point(to));
  m.set("feed", Value::feed(feed));
  m.set("role", Value::word(role));
  return m;
}

void Emitter::rapid(const Vec3 &to, const char *role) {
  if (positioned_ && (to - pos_).norm() <= geom::kEps)
    return;
  moves_.add(rapidNode(to, role));
  pos_ = to;
  positioned_ = true;
}

void Emitter::linear(const Vec3 &to, double feed, const char *role, bool smooth) {
  if ((to - pos_).norm() <= geom::kEps)
    return;
  Node &m = moves_.add(linearNode(to, feed, role));
  if (smooth)
    m.set("smooth", Value::boolean(true));
  pos_ = to;
}

void Emitter::arc(const Vec3 &to, const geom::Vec2 &centre, bool ccw, int64_t turns, double feed, const char *role) {
  arc(to, at(centre, pos_.z()), geom::ArcPlane::xy(), ccw, turns, feed, role);
}

void Emitter::arc(const Vec3 &to, const Vec3 &centre, geom::ArcPlane plane, bool ccw, int64_t turns, double feed,
                  const char *role) {
  // An arc under half a turn whose ends print as one point would read back
  // as a whole circle: it is the line it is within the printed resolution.
  const Vec3 start = plane.local(pos_), end = plane.local(to), c = plane.local(centre);
  const geom::Vec2 a = start.head<2>() - c.head<2>(), b = end.head<2>() - c.head<2>();
  const bool underHalf = (ccw ? 1 : -1) * (a.x() * b.y() - a.y() * b.x()) > 0 && a.dot(b) > 0;
  if (turns == 0 && underHalf &&
      ir::printsAsOnePoint(Vec3(start.x(), start.y(), 0), Vec3(end.x(), end.y(), 0))) {
    linear(to, feed, role);
    return;
  }
  Node &m = moves_.add(Node(ir::Kind::Arc));
  m.set("to", Value::point(to));
  // The centre at the start's height along the normal, as in the XY plane.
  m.set("center", Value::point(plane.world(Vec3(c.x(), c.y(), start.z()))));
  if (!plane.isXY())
    m.set("normal", Value::direction(plane.normalVector()));
  m.set("dir", Value::word(ccw ? "ccw" : "cw"));
  if (turns > 0)
    m.set("turns", Value::integer(turns));
  m.set("feed", Value::feed(feed));
  m.set("role", Value::word(role));
  pos_ = to;
}

void Emitter::dwell(double seconds) {
  if (seconds <= 0)
    return;
  moves_.add(Node(ir::Kind::Dwell)).set("time", Value::time(seconds));
}

void Emitter::seg(const geom::Seg &s, double z, double feed, const char *role) {
  if (s.isArc())
    arc(at(s.b, z), s.c, s.turn > 0, 0, feed, role);
  else
    linear(at(s.b, z), feed, role);
}

void Emitter::travel(const geom::Vec2 &xy, double z) {
  if (!positioned_)
    rapid(at(xy, secplane_), "position");
  else if (pos_.z() < secplane_)
    rapid(Vec3(pos_.x(), pos_.y(), secplane_), "retract");
  rapid(at(xy, secplane_));
  rapid(at(xy, z), "approach");
}

void Emitter::retract() {
  if (positioned_ && pos_.z() < secplane_)
    rapid(Vec3(pos_.x(), pos_.y(), secplane_), "retract");
}

} // namespace stepnc::passes::expand
