// What a feature is in the plane of the tool: the area its machining must
// clear, where the tool may go, and the heights between which it lies, in the
// coordinates of its workpiece. Strategy expansion cuts this shape; the
// toolpath verifier measures moves against it. It is the one piece of
// interpretation the two share, so it is tested on its own (exact areas).
//
// Only features whose axis is the tool axis (+z of the workpiece) are 2.5D
// shapes; others are reported as not supported.
#pragma once

#include "geom/Geometry.h"
#include "ir/Node.h"
#include "ir/Program.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::ir {

/// A feature's frame in workpiece coordinates, restricted to the plane.
struct PlaneFrame {
  geom::Vec2 origin = geom::Vec2::Zero();
  geom::Vec2 x = geom::Vec2::UnitX();  ///< local x axis (unit)
  geom::Vec2 y = geom::Vec2::UnitY();  ///< local y axis (unit)
  double z = 0;                        ///< height of the frame's origin

  geom::Vec2 map(const geom::Vec2 &local) const { return origin + local.x() * x + local.y() * y; }
  geom::Vec2 mapDir(const geom::Vec2 &local) const { return local.x() * x + local.y() * y; }
  /// True when the local frame is mirrored (x, y clockwise in workpiece coordinates).
  bool mirrored() const { return geom::cross(x, y) < 0; }
};

/// Material a feature's machining must leave (a boss), up to its top. A boss
/// with a slope leans in going up: `region` is its outline at its foot (its
/// depth below its top), and its section at height z is that outline shrunk
/// by (z - foot) * slope: convex corners stay sharp, concave ones round
/// (docs/toolpaths.md, "Bosses with a slope").
struct IslandShape {
  std::string symbol;
  geom::Region region;
  double top = 0;
  double foot = 0;   ///< z of its foot (the floor it stands on)
  double slope = 0;  ///< tan of the walls' lean from the vertical; 0: vertical walls

  bool sloped() const { return slope > 0; }
  /// The section at height z (foot <= z <= top): `region` when the walls are vertical.
  geom::Region sectionAt(double z) const;
};

/// A slot's cross-section across its course of travel: its walls as one
/// chain of lines and arcs in (u, v), u the distance left of the course
/// (seen along it), v the height above the slot's floor. The chain runs from
/// the top of the right wall (u < 0) down through the floor (its lowest
/// point, v = 0) and up to the top of the left wall (v = depth). Sections
/// are convex and no narrower higher up: the tool comes from above.
struct SlotSection {
  std::vector<geom::Seg> walls;
  double depth = 0;

  /// Where the walls are at height v above the floor: the lowest and highest
  /// u between them; none below the floor. Above the top the walls go on
  /// straight up.
  std::optional<std::pair<double, double>> span(double v) const;
  /// The heights of the chain's vertices (where a wall changes shape), lowest first.
  std::vector<double> breaks() const;
};

struct FeatureShape {
  std::string symbol;
  ir::Kind kind = ir::Kind::ClosedPocket;
  std::string kindName() const { return std::string(ir::kindName(kind)); }
  PlaneFrame frame;
  double top = 0;     ///< z of the feature's top (its placement)
  double bottom = 0;  ///< z of its floor (top - depth)
  /// The area to clear at every depth, islands not removed (see `islands`).
  geom::Region target;
  /// Where the tool may be below the top: `target` plus the open space past
  /// open sides (open pockets, steps, open slot ends). Unused when `unbounded`.
  geom::Region limit;
  /// No walls at all: the tool may pass every side (planar faces).
  bool unbounded = false;
  std::vector<IslandShape> islands;
  /// For round holes: the axis position and the diameter.
  std::optional<geom::Vec2> holeCentre;
  double holeDiameter = 0;
  /// For slots: the course of travel, the width, and how each end is closed
  /// ("open", "radiused", "flat"): what center milling follows.
  struct SlotPath {
    geom::Vec2 from = geom::Vec2::Zero(), to = geom::Vec2::Zero();
    double width = 0;
    std::string end1, end2;
    /// The course from `from` to `to`: one line for a straight slot; lines
    /// and arcs for a slot along a general path (vertical walls only).
    std::vector<geom::Seg> course;
    bool straight() const { return course.size() == 1 && !course.front().isArc(); }
  };
  std::optional<SlotPath> slot;
  /// For slots whose walls are not vertical (vee, partial circular and
  /// rounded-U profiles): the cross-section, which `target` and `limit`
  /// give at the slot's top only.
  std::optional<SlotSection> section;
};

/// The slot as if its walls were vertical, `lo` to `hi` from its course of
/// travel (lo < hi, u as in SlotSection): its target and limit regions and
/// its slot path (the course moved to the middle of the span). What one
/// height of a slot with slanted walls is in the plane.
FeatureShape slotBetween(const FeatureShape &slot, double lo, double hi);

/// The frame of a node with `at`, `axis`, `ref` (features, profiles); an error
/// message when its axis is not +z.
struct FrameResult {
  std::optional<PlaneFrame> frame;
  std::string error;
};
FrameResult planeFrame(const ir::Node &placed);

struct ShapeResult {
  std::optional<FeatureShape> shape;
  std::string error;  ///< why the feature has no shape (not supported, missing data)
};

/// The first closed profile child of `owner` (rectangular, circular or a
/// closed general profile) as a loop in the owner's local coordinates;
/// nullopt with `error` set when it has none.
std::optional<geom::Loop> closedProfileLoop(const ir::Module &module, const ir::Node &owner, std::string &error);

/// The shape of `feature` (a feature node of `module`).
ShapeResult featureShape(const ir::Module &module, const ir::Node &feature);

/// How far a tool's point reaches below its cutting corner: r tan(tip half
/// angle), the angle measured from the plane normal to the tool axis (ISO
/// 14649-111: 0 for a flat end mill; a 140 deg carbide drill has 20 deg).
double pointLength(const ir::Node &tool);

/// The radius of the rounded edge at the tool's end: the ball's radius for
/// a ball end mill, else its corner radius, within [0, diameter / 2].
double cornerRadius(const ir::Node &tool);

/// A workpiece's block raw piece in its coordinates: its extent in the plane
/// and the height of its top; nullopt when it has none or another shape.
struct RawBlock {
  geom::Box box;
  double bottom = 0, top = 0;
};
std::optional<RawBlock> rawBlock(const ir::Node *workpiece);

} // namespace stepnc::ir
