// The walls of a feature, read from the IR by the verifier's own code, and how
// far a tool's disc at a point reaches into them: what verify-toolpaths
// measures every feed move against (docs/toolpaths.md, "The wall check").
//
// It shares nothing with strategy expansion's reading of features
// (ir/geom/FeatureShape.h): not the regions, not the offsets, not the exact
// Booleans. A pocket's corner radius, an open pocket's open side, a slot's
// ends, a step's side and the islands are read again here, and distances are
// measured to lines and arcs directly, so that a misreading on either side
// shows as a gouge. Only the conversion of IR curve nodes to lines and arcs
// (ir/geom/Curves.h, tested on its own) and the walk of the moves
// (ir/geom/MoveWalk.h) are common.
#pragma once

#include "geom/Geometry.h"
#include "ir/Program.h"
#include "ir/geom/MoveWalk.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::passes {

/// A piece of wall in the plane: a line from `a` to `b`, or an arc about
/// `centre` from `a` to `b` turning `sweep` radians (counter-clockwise
/// positive; +-2 pi is a whole circle).
struct WallPiece {
  geom::Vec2 a = geom::Vec2::Zero(), b = geom::Vec2::Zero();
  bool arc = false;
  geom::Vec2 centre = geom::Vec2::Zero();
  double radius = 0, sweep = 0;

  static WallPiece line(const geom::Vec2 &a, const geom::Vec2 &b);
  static WallPiece arcFrom(const geom::Vec2 &centre, const geom::Vec2 &a, double sweep);
  /// The point of the piece nearest p.
  geom::Vec2 nearest(const geom::Vec2 &p) const;
  double distance(const geom::Vec2 &p) const { return (nearest(p) - p).norm(); }
  /// The direction of travel at the start (t = 0) or the end (t = 1).
  geom::Vec2 tangent(int end) const;
};

/// A closed outline of pieces end to end (either orientation).
struct Outline {
  std::vector<WallPiece> pieces;
  /// True when p is enclosed (even-odd; arcs counted exactly).
  bool contains(const geom::Vec2 &p) const;
  /// The distance from p to the outline, positive inside.
  double clearance(const geom::Vec2 &p) const;
  /// The outline of its inside shrunk by e > 0: each piece moved e inwards
  /// (lines along their normal, arcs about their centre), pieces meeting at
  /// convex corners cut where the moved pieces cross, concave corners rounded
  /// by an arc of radius e about the corner. None when a piece would vanish
  /// or turn round (the shrinking changes the outline's shape).
  std::optional<Outline> inset(double e) const;
};

/// The tool as a body, for walls that are not vertical: at height h above
/// its tip a disc of radius `radius` - `corner` + sqrt(corner^2 - (corner -
/// h)^2) through its corner, `radius` above; `radius` and `corner` grown by
/// the side allowance, the tip `lowered` by it below the tip's height `tip`.
struct ToolBody {
  double corner = 0;
  double lowered = 0;
  double tip = 0;
};

/// The radius of a tool body of `radius` and `corner` at height h above its
/// tip; -1 below it.
double bodyRadius(double radius, double corner, double h);

/// How a disc stands against the walls: how far it reaches into material
/// (negative: the room it has to spare) and which wall that is
/// (FeatureWalls::describe says it in words).
struct WallContact {
  enum class Where : uint8_t { Wall, Corner, FlatEnd, Island };
  double depth = -1e300;
  Where where = Where::Wall;
  size_t island = 0;  ///< Where::Island: which of the feature's islands
};

class FeatureWalls {
public:
  /// The walls of `feature`, a feature node of `module`; nullopt with
  /// `error` set when stepnc cannot read them (a feature kind or a profile
  /// this reader does not know).
  static std::optional<FeatureWalls> read(const ir::Module &module, const ir::Node &feature, std::string &error);

  /// A disc of `radius` centred at p at height z: how far it reaches into
  /// the walls in force there. The feature's walls hold below its top less
  /// `tol`, an island's below its own top less `tol`.
  /// A boss whose walls lean in is met by the tool's `body` (its tip at
  /// body.tip) at heights sampled through its corner.
  WallContact contact(const geom::Vec2 &p, double z, double radius, double tol, const ToolBody &body = {}) const;

  /// The heights at which the walls in force change: the feature's top and
  /// the islands' tops, each less `tol`.
  std::vector<double> levels(double tol) const;

  /// What a contact is against, for messages: "a wall of %pocket", "a corner
  /// of radius 5.0000 mm of %pocket", "the flat end of %slot", "island %boss".
  std::string describe(const WallContact &c) const;

  /// A boss; one whose walls lean in (slope > 0, the tan of the lean) has
  /// `outline` at its foot and, at height v, that outline shrunk by
  /// (v - foot) * slope.
  struct Island {
    std::string symbol;
    Outline outline;
    double top = 0;
    double foot = 0;
    double slope = 0;
    /// Its section's outline at height v.
    Outline sectionAt(double v) const;
    /// The heights sampled for the last tip height and body (moves at one
    /// level share them): the body's radius there and the section's outline.
    struct Heights {
      double tip = 0, lowered = 0, radius = 0, corner = 0;
      std::vector<std::pair<double, Outline>> at;
    };
    mutable Heights heights;
  };
  /// The islands, as read.
  const std::vector<Island> &islands() const { return islands_; }
  /// Whether the feature has walls of its own besides its islands' (a
  /// pocket's, a slot's, a step's).
  bool hasOwnWalls() const { return bound_ != Bound::None; }
  /// The height of the feature's top.
  double top() const { return top_; }

private:
  enum class Bound : uint8_t { None, Outline, Tube, HalfPlane };
  /// A slot's flat end: the square past it that the slot does not reach.
  struct FlatEnd {
    geom::Vec2 at = geom::Vec2::Zero(), out = geom::Vec2::UnitX();
    double half = 0;
  };

  WallContact outlineContact(const geom::Vec2 &p, double radius) const;
  double slopedDepth(const Island &i, const geom::Vec2 &p, double radius, const ToolBody &body) const;
  double distanceToCentres(const geom::Vec2 &p, double clearance) const;
  WallContact tubeContact(const geom::Vec2 &p, double radius) const;

  std::string symbol_;
  double top_ = 0;
  Bound bound_ = Bound::None;
  Outline outline_;            ///< Bound::Outline
  double fillet_ = 0;          ///< the radius between its walls (a pocket's orthogonal_radius)
  std::vector<WallPiece> course_;  ///< Bound::Tube: a slot's course, open ends continued
  double halfWidth_ = 0;
  std::vector<FlatEnd> flatEnds_;
  geom::Vec2 planeAt_ = geom::Vec2::Zero(), planeIn_ = geom::Vec2::UnitX();  ///< Bound::HalfPlane
  std::vector<Island> islands_;

  friend class WallsReader;
};

/// The deepest a move takes a disc of `radius` into the walls, and where.
struct MoveContact {
  WallContact contact;
  ir::Vec3 at = ir::Vec3::Zero();
  size_t samples = 0;
};

/// Samples the move (a feed move whose start is known) along its path in
/// the plane, lines, arcs and helices alike, as closely as `tol` needs:
/// far from the walls by the room the disc has there, near them every
/// tol / 2 (at least 0.001 mm), so that a gouge deeper than 1.25 tol is
/// always found and none shallower than tol is reported.
/// `corner` and `lowered` make the tool a body (ToolBody) for bosses whose
/// walls lean in.
MoveContact deepestContact(const FeatureWalls &walls, const ir::Move &move, double radius, double tol,
                           double corner = 0, double lowered = 0);

} // namespace stepnc::passes
