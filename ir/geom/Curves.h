// IR curves (lines, polylines, circles, helices, trimmed and composite curves)
// as straight and circular pieces in space: what a general profile's outline
// and an explicit toolpath are made of. Circles and helices stay circular.
#pragma once

#include "geom/Geometry.h"
#include "ir/Node.h"

#include <string>
#include <vector>

namespace stepnc::ir {

/// A straight piece, or a circular (helical when `to` is at another height)
/// piece about an axis parallel to z through `center`.
struct CurvePiece {
  bool arc = false;
  ir::Vec3 from = ir::Vec3::Zero();
  ir::Vec3 to = ir::Vec3::Zero();
  ir::Vec3 center = ir::Vec3::Zero();
  bool ccw = true;    ///< seen from +z
  /// Full turns before the last arc to `to`, which is itself a whole turn when
  /// `to` is over `from` (the toolpath IR's rule for arcs).
  int64_t turns = 0;
};

struct CurveResult {
  std::vector<CurvePiece> pieces;
  std::string error;  ///< why the curve could not be converted; pieces are then incomplete
};

/// The pieces of `curve` (a node of category "curve") in the coordinates it is
/// written in, in its direction of travel.
CurveResult curvePieces(const ir::Node &curve);

/// The pieces as plane segments (z dropped). Full turns become full circles.
std::vector<geom::Seg> planarSegs(const std::vector<CurvePiece> &pieces);

} // namespace stepnc::ir
