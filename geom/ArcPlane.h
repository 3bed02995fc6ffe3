// The principal plane an arc lies in, named by the axis it turns about: +z
// (the XY plane, G17), +y (ZX, G18) or +x (YZ, G19). The plane's local
// coordinates are a cyclic permutation of x, y, z: its first axis, its second
// axis, then the normal (XY: x y z; ZX: z x y; YZ: y z x). Being cyclic, the
// permutation keeps the right hand: "counterclockwise seen from the normal's
// tip" is counterclockwise in (first, second), as G3 is in every plane of
// ISO 6983 and RS274NGC, and an arc's code can work in local coordinates
// alone, with the normal coordinate as the helix's axis.
#pragma once

#include "geom/Geometry.h"

#include <cmath>
#include <optional>

namespace stepnc::geom {

using Vec3 = Eigen::Vector3d;

struct ArcPlane {
  int normal = 2;  ///< the axis turned about: 0 x, 1 y, 2 z

  static ArcPlane xy() { return {2}; }
  bool isXY() const { return normal == 2; }
  int first() const { return (normal + 1) % 3; }
  int second() const { return (normal + 2) % 3; }
  /// A point or vector in the plane's coordinates (first, second, normal).
  Vec3 local(const Vec3 &p) const { return {p[first()], p[second()], p[normal]}; }
  /// Back from the plane's coordinates.
  Vec3 world(const Vec3 &q) const {
    Vec3 p;
    p[first()] = q.x();
    p[second()] = q.y();
    p[normal] = q.z();
    return p;
  }
  Vec3 normalVector() const { return Vec3::Unit(normal); }
  /// "XY", "ZX", "YZ".
  const char *name() const { return normal == 2 ? "XY" : normal == 1 ? "ZX" : "YZ"; }
  bool operator==(const ArcPlane &) const = default;

  /// The plane an axis along a coordinate axis turns in (`positive`: the
  /// axis points the normal's way, else the other way, which turns arcs the
  /// other way round); nullopt for an axis along none of x, y, z (within 1e-9).
  static std::optional<ArcPlane> about(const Vec3 &axis, bool &positive) {
    for (int k = 0; k < 3; ++k)
      if (std::abs(std::abs(axis[k]) - 1) <= 1e-9) {
        positive = axis[k] > 0;
        return ArcPlane{k};
      }
    return std::nullopt;
  }
};

} // namespace stepnc::geom
