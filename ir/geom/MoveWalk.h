// Reading the toolpath IR: the moves of a `moves` node with the point each one
// starts from, their geometry in space and in the plane, and the state in
// force (tool, spindle, coolant). Every pass that reads moves (verification,
// feed adaptation, the backends) walks them through here.
#pragma once

#include "geom/ArcPlane.h"
#include "geom/Geometry.h"
#include "ir/Node.h"
#include "ir/Program.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::ir {

/// Dwell: the tool waits where it is (`to` is where it stands, `dwell` the time).
enum class MoveKind : uint8_t { Rapid, Linear, Arc, Dwell };

struct Move {
  const ir::Node *node = nullptr;
  MoveKind kind = MoveKind::Rapid;
  /// Where the move starts; unknown for the first move of a program.
  std::optional<ir::Vec3> from;
  ir::Vec3 to = ir::Vec3::Zero();
  ir::Vec3 center = ir::Vec3::Zero();  ///< arcs: the axis position (its coordinate along the axis is not used)
  bool ccw = false;                    ///< arcs, seen from the tip of the plane's normal (+z in XY)
  /// Arcs: the plane they turn in (IR `normal`; XY when it has none). A
  /// normal along -x, -y or -z is read as the plane's with `ccw` turned.
  geom::ArcPlane plane = geom::ArcPlane::xy();
  /// A line that stands for a piece of an arc out of the XY plane (walked
  /// with OutOfPlaneArcs::Chords): `node` is that arc.
  bool chord = false;
  /// Arcs: full turns before the last arc to `to`; that arc is itself a whole
  /// turn when `to` is over `from` in the plane.
  int64_t turns = 0;
  double feed = 0;                     ///< mm/min; 0 for rapids
  std::string role;                    ///< "position", "cut", ... (default: position for rapids, cut otherwise)
  double dwell = 0;                    ///< dwells: s
  const ir::Node *cycle = nullptr;     ///< the canned cycle the move belongs to, if any
  /// The tool axis at the move's end (its own `axis`, else that of `moves`,
  /// else +z; a dwell keeps the one it finds) and at its start (where the
  /// move before left it); between them it turns evenly (turnAxis).
  ir::Vec3 axis = ir::Vec3::UnitZ();
  ir::Vec3 fromAxis = ir::Vec3::UnitZ();

  /// True for a move that cuts at a feed (a line or an arc).
  bool isFeed() const { return kind == MoveKind::Linear || kind == MoveKind::Arc; }
  /// True when the move changes height (a plunge, a ramp, a helix).
  bool changesHeight() const;
  double length() const;  ///< in space; helices included
  /// The move seen from +z: its segments in the plane (a helix's full turns as
  /// half arcs, then the last partial arc; an arc out of the XY plane as its
  /// chords). Empty for a purely axial move.
  std::vector<geom::Seg> planar() const;
  /// The point `s` mm along a line, or along an arc at constant height, from
  /// its start (which must be known).
  ir::Vec3 pointAt(double s) const;
  /// An arc's points from its start to `to`, each chord within `tolerance`
  /// mm of it (a helix's height spread over them); a line's two ends.
  std::vector<ir::Vec3> chordPoints(double tolerance) const;
};

/// The tool axis a fraction t (0..1) of the way through a move whose axis
/// goes from u to w (unit vectors): turning evenly in the plane of the two,
/// the toolpath IR's rule for 5-axis moves (docs/ir.md). u and w opposite
/// have no such plane: u is kept up to the end.
ir::Vec3 turnAxis(const ir::Vec3 &u, const ir::Vec3 &w, double t);

/// The angle between two unit vectors, degrees.
double angleBetween(const ir::Vec3 &u, const ir::Vec3 &w);

/// How far the chords that stand for an arc out of the XY plane may be from
/// it (mm): the chord tolerance of B-splines (ir/geom/Curves.h).
inline constexpr double kOutOfPlaneArcChord = 0.001;

/// How walkMoves gives arcs out of the XY plane (ZX, YZ): as they are (for
/// readers that handle every principal plane: the G-code emitters), or as
/// lines along chords within kOutOfPlaneArcChord, each marked `chord` (for
/// the passes that work in the XY plane: verification, the cutting model,
/// motion planning).
enum class OutOfPlaneArcs : uint8_t { Chords, Exact };

/// Which end point a move is read with. Compensated moves (docs/deflection-
/// compensation.md) are programmed off the part by the deflection the cut is
/// predicted to cause, and record where the bent tool is predicted to go as
/// `nominal`: the backends run the programmed path, verification checks the
/// predicted one (and an arc whose offset changes along it records the
/// centre of its predicted arc as `nominal_center`).
enum class PathKind : uint8_t { Programmed, Predicted };

/// The moves of `moves` in order, each knowing where it starts (`start` is
/// where the tool is before the first one, when known). The moves of a
/// canned cycle are walked in place, each knowing its cycle; a dwell is a
/// move that stays where the tool is (where the first move of a program
/// starts unknown, at the origin).
std::vector<Move> walkMoves(const ir::Node &moves, std::optional<ir::Vec3> start = std::nullopt,
                            PathKind path = PathKind::Programmed, OutOfPlaneArcs arcs = OutOfPlaneArcs::Chords);

/// The moves of a deposition step's `moves` in order, each with whether the
/// head's energy is on while it runs (the `state` changes among them).
std::vector<std::pair<Move, bool>> walkWithEnergy(const ir::Node &moves);

} // namespace stepnc::ir
