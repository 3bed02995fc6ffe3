// The move writer of expand-strategies: every family writes its moves under
// a `moves` node through an Emitter, which keeps track of where the tool is,
// drops moves that go nowhere, and knows the one safe way to travel: up to
// the security plane, across, and down along the tool axis.
#pragma once

#include "geom/ArcPlane.h"
#include "geom/Boolean.h"
#include "ir/Node.h"

#include <cstdint>

namespace stepnc::passes::expand {

/// Writes moves under a `moves` node and keeps track of where the tool is.
class Emitter {
public:
  Emitter(ir::Node &moves, double secplane) : moves_(moves), secplane_(secplane) {}

  /// Where the last move ended (meaningful once positioned()).
  const ir::Vec3 &position() const { return pos_; }
  /// Whether any move was written: before it the tool's place is unknown.
  bool positioned() const { return positioned_; }
  /// The security plane, a height in workpiece coordinates.
  double secplane() const { return secplane_; }

  /// The node of a rapid to `to`, and of a line at feed: what rapid() and
  /// linear() write, for passes that edit moves already written.
  static ir::Node rapidNode(const ir::Vec3 &to, const char *role);
  static ir::Node linearNode(const ir::Vec3 &to, double feed, const char *role);
  /// A move node with the tool axis at its end (5-axis moves, IR `axis`).
  static ir::Node tilted(ir::Node move, const ir::Vec3 &axis);
  /// The point along the tool axis `axis` (z part above 0) from `from` at
  /// height z: where a tilted tool is reached down, or left up, its axis.
  static ir::Vec3 alongAxisTo(const ir::Vec3 &from, const ir::Vec3 &axis, double z) {
    return from + axis * ((z - from.z()) / axis.z());
  }

  /// A rapid to `to`; none when the tool is already there.
  void rapid(const ir::Vec3 &to, const char *role = "position");

  /// A line at feed to `to`; none when the tool is already there.
  /// `smooth`: a chord of a curvature-continuous curve (IR `smooth`).
  void linear(const ir::Vec3 &to, double feed, const char *role, bool smooth = false);

  /// An arc (a helix when `to` is at another height) about `centre`,
  /// after `turns` whole turns.
  void arc(const ir::Vec3 &to, const geom::Vec2 &centre, bool ccw, int64_t turns, double feed, const char *role);
  /// The same in any principal plane: about the axis along `plane`'s normal
  /// through `centre`, `ccw` seen from the normal's tip (IR `normal`).
  void arc(const ir::Vec3 &to, const ir::Vec3 &centre, geom::ArcPlane plane, bool ccw, int64_t turns, double feed,
           const char *role);

  /// The tool waits where it is for `seconds` (> 0; none otherwise).
  void dwell(double seconds);

  /// A plane segment cut at height z (the tool is at its start).
  void seg(const geom::Seg &s, double z, double feed, const char *role = "cut");

  /// Up to the security plane (if below it), across, and down along the axis to `z`.
  void travel(const geom::Vec2 &xy, double z);

  /// Up to the security plane along the axis, when below it.
  void retract();

private:
  ir::Node &moves_;
  double secplane_;
  ir::Vec3 pos_ = ir::Vec3::Zero();
  bool positioned_ = false;
};

} // namespace stepnc::passes::expand
