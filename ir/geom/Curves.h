// IR curves (lines, polylines, circles, helices, trimmed and composite curves,
// B-splines) as straight and circular pieces in space: what a general
// profile's outline, a slot's course and an explicit toolpath are made of.
// Circles and helices stay circular; B-splines become chords within
// kSplineChordTolerance of the curve.
#pragma once

#include "geom/ArcPlane.h"
#include "geom/Geometry.h"
#include "ir/Node.h"
#include "ir/Program.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::ir {

/// A straight piece, or a circular (helical when `to` is at another height
/// along the plane's normal) piece about an axis through `center` along the
/// normal of `plane` (z unless the caller allows the other principal planes).
struct CurvePiece {
  bool arc = false;
  ir::Vec3 from = ir::Vec3::Zero();
  ir::Vec3 to = ir::Vec3::Zero();
  ir::Vec3 center = ir::Vec3::Zero();
  bool ccw = true;    ///< seen from the tip of the plane's normal (+z in XY)
  /// Full turns before the last arc to `to`, which is itself a whole turn when
  /// `to` is over `from` (the toolpath IR's rule for arcs).
  int64_t turns = 0;
  geom::ArcPlane plane = geom::ArcPlane::xy();
};

/// How far a B-spline's chords may stray from the curve, mm: a tenth of the
/// verifier's default tolerance.
inline constexpr double kSplineChordTolerance = 0.001;
/// mm an arc's ends may lie off its circle (the circle's radius from its
/// centre, measured in its plane): what a file's rounding of its points
/// gives. Further off, the arc is refused: every target would have to move
/// its centre or an end, each its own way (LinuxCNC refuses it).
inline constexpr double kArcEndTolerance = 0.001;
/// Whole turns a trimmed helix may make: a 100 mm bore thread-milled at a
/// 0.01 mm pitch. A pitch that makes more is outside physical sense (a typo,
/// another unit) and the curve is refused: every turn is motion the
/// controller runs and the stock check walks.
inline constexpr double kMaxHelixTurns = 10000;

/// A B-spline curve node (ISO 10303-42: uniform, quasi-uniform, Bezier or
/// with knots; rational with weights on its points) as a function of its
/// parameter over [start, end]. Built once per curve; nullopt with `error`
/// set when the node does not make one (too few points for its degree,
/// knots that do not fit).
struct BSpline {
  int degree = 0;
  std::vector<Vec3> points;
  std::vector<double> weights;  ///< one per point (1 when not rational)
  std::vector<double> knots;    ///< expanded by multiplicity: points + degree + 1 values
  double start = 0, end = 0;
  Vec3 at(double u) const;
};
std::optional<BSpline> bspline(const ir::Node &curve, std::string &error);

struct CurveResult {
  std::vector<CurvePiece> pieces;
  std::string error;  ///< why the curve could not be converted; pieces are then incomplete
};

/// The pieces of `curve` (a node of category "curve") in the coordinates it is
/// written in, in its direction of travel. `planes`: circles about z only
/// (profiles, outlines and courses of features, which lie in their plane), or
/// about any of x, y and z (explicit toolpaths: arcs in the XY, ZX and YZ
/// planes).
CurveResult curvePieces(const ir::Node &curve, ArcPlanes planes = ArcPlanes::XYOnly);

/// The pieces as plane segments (z dropped). Full turns become full circles.
std::vector<geom::Seg> planarSegs(const std::vector<CurvePiece> &pieces);

} // namespace stepnc::ir
