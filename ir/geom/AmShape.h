// What an added feature (am_simple_feature, docs/additive.md) is as a solid:
// its sections across the build direction and the channels left empty in
// it. The deposition strategies slice it into layers; the in-process stock
// after deposition is made of it. The deposition verifier does not use it:
// it measures beads against the feature with code of its own.
//
// Everything is in the feature's frame: z along its axis (the build
// direction), 0 on the base surface; x, y its placement's.
#pragma once

#include "geom/Geometry.h"
#include "ir/Node.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::ir {

/// A feature's placement as a rigid frame: local (x, y, z) to the
/// workpiece's coordinates and back.
struct SolidFrame {
  Vec3 origin = Vec3::Zero();
  Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  Vec3 toWorkpiece(const Vec3 &local) const { return origin + local.x() * x + local.y() * y + local.z() * z; }
  Vec3 toLocal(const Vec3 &p) const {
    const Vec3 d = p - origin;
    return {d.dot(x), d.dot(y), d.dot(z)};
  }
};

/// A channel: a disc of `radius` swept along a polyline (within
/// kVoidChordTolerance of the file's curve), in the feature's frame.
struct VoidTube {
  std::string label;
  double radius = 0;
  std::vector<Vec3> points;
};

/// How far a channel's polyline may stray from its curve (mm); the void is
/// grown by as much where the layers keep clear of it.
inline constexpr double kVoidChordTolerance = 0.005;

struct AmShape {
  enum class Form { Extruded, Revolved, Faceted };
  std::string symbol;
  Form form = Form::Extruded;
  SolidFrame frame;
  double height = 0;
  /// Extruded: the base profile (counter-clockwise) and tan(draft), > 0
  /// when the walls lean in. Revolved: `profile` is the meridian (x the
  /// distance from the axis, y the height), counter-clockwise.
  geom::Loop profile;
  double draftTan = 0;
  /// Faceted: each plane as a point and its outward normal; the solid's
  /// corners.
  std::vector<std::pair<Vec3, Vec3>> planes;
  std::vector<Vec3> corners;
  std::vector<VoidTube> voids;

  /// The section at height z (0 <= z <= height), voids not removed.
  geom::Region section(double z) const;
  /// Every point of the solid between heights z0 < z1 seen along z: what a
  /// layer between them must cover (above the top: the top face).
  geom::Region slab(double z0, double z1) const;
  /// Every point of the channels between heights z0 < z1 seen along z, grown
  /// by `margin`: what a layer between them must keep clear of.
  geom::Region voidsIn(double z0, double z1, double margin) const;
};

struct AmShapeResult {
  std::optional<AmShape> shape;
  std::string error;  ///< why the feature is no solid stepnc builds
};

/// The solid of added feature `feature` (an am_simple_feature node of `module`).
AmShapeResult amShape(const Module &module, const Node &feature);

} // namespace stepnc::ir
