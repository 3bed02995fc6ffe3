// The geometry of the pattern strategies (docs/pattern-strategies.md): a
// toolpath made of a guide curve and a motif repeated along it,
// OM(t) = C(t) + M(t).
//
// - SmoothGuide: the guide curve C, a chain of lines and arcs, smoothed so
//   that the path built on it is curvature continuous even where C has
//   corners or jumps of curvature.
// - trochoidPoints: the trochoidal motif along a guide, one continuous curve
//   sampled within a chord tolerance.
// - trochoidEngagement / largestTrochoidStep: the engagement angle of a
//   trochoid in full material, computed numerically, and the loop step that
//   keeps it under a target.
// - plungeCentres: places for plunges along a guide, evenly spaced.
#pragma once

#include "geom/Geometry.h"

#include <algorithm>
#include <optional>
#include <vector>

namespace stepnc::passes {

/// A guide curve read by arc length s and smoothed by a triangle kernel of
/// half-width w:
///   G(s) = integral of C(s + x) (w - |x|) / w^2 over x in [-w, w].
/// Its second derivative is (C(s - w) - 2 C(s) + C(s + w)) / w^2, continuous
/// for any continuous C, so G has continuous tangent and curvature through
/// C's corners. G stays inside every convex corner of C (by at most 0.24 w
/// at a right angle) and, on an arc of radius r, moves towards its centre
/// by at most w^2 / (12 r). Beyond the ends of the chain C stays at its end
/// points, so G comes to rest there: G(-w) = C(0), G(L + w) = C(L), with
/// zero first and second derivatives.
class SmoothGuide {
public:
  /// `chain`: segments joined end to start (not empty); w > 0.
  SmoothGuide(std::vector<geom::Seg> chain, double halfWidth);

  double length() const { return length_; }
  double halfWidth() const { return w_; }
  const std::vector<geom::Seg> &chain() const { return segs_; }

  /// C(s), with s clamped to [0, L].
  geom::Vec2 raw(double s) const;
  /// G(s), for any s (constant beyond [-w, L + w]).
  geom::Vec2 at(double s) const;

  /// How far G moves towards the centre of an arc of radius r: the margin
  /// to keep from walls that C follows on the inside of its turns.
  static double arcShrink(double halfWidth, double radius) { return halfWidth * halfWidth / (12 * radius); }

private:
  /// Integral of C(u) (alpha + beta u) du over [u0, u1], u0 <= u1, within [0, L].
  geom::Vec2 weighted(double u0, double u1, double alpha, double beta) const;

  std::vector<geom::Seg> segs_;
  std::vector<double> start_; ///< arc length at the start of each segment
  double length_ = 0, w_ = 0;
};

struct TrochoidMotif {
  double radius = 0; ///< R_t, mm: the loop the tool centre turns about the guide
  double step = 0;   ///< mm the guide advances per loop, at most
  bool ccw = true;   ///< loops counter-clockwise seen from +z
};

/// How many loops trochoidPoints makes along `guide`: as few as keep the
/// advance per loop within `step`. A double: a step far too small for the
/// guide counts past what a long holds.
double trochoidLoops(const SmoothGuide &guide, double step);

/// The trochoid along `guide`: OM(theta) = G(s(theta)) + R_t (cos theta, +-sin theta)
/// with s running evenly from -w to L + w over a whole number of loops (as
/// few as keep the advance per loop within the motif's step), so that it
/// starts and ends at G's end points plus (R_t, 0), the guide at rest there.
/// Sampled at equal angles, as many per loop as keep every chord within
/// `chordTolerance` of the curve. The first point is the start. None when
/// that takes more than `maxPoints` points (a step far too small for the
/// guide), before any is made.
std::optional<std::vector<geom::Vec2>> trochoidPoints(const SmoothGuide &guide, const TrochoidMotif &motif,
                                                      double chordTolerance, double maxPoints);

/// The half-width of the smoothing of a trochoid's guide: short against a
/// loop, so that the guide cuts corners by a fraction of the step.
inline double trochoidSmoothing(double step, double loopRadius) { return std::min(step, loopRadius) / 2; }

/// The largest engagement angle (radians) of a tool of radius `toolRadius`
/// whose centre follows the trochoid trochoidPoints makes along a straight
/// guide smoothed by `halfWidth`, with loops of radius `loopRadius`
/// advancing `step`: from the hole the entry bores about the guide's start
/// (radius loopRadius + toolRadius), the guide speeding up from rest, into
/// the steady state. Measured numerically at one-degree steps as the arc of
/// the tool's circle outside the bore and every disc the tool swept before.
double trochoidEngagement(double toolRadius, double loopRadius, double step, double halfWidth);

/// The largest step (mm, at most `upTo`) whose trochoidEngagement, with the
/// guide smoothed by trochoidSmoothing, stays within `maxAngle` radians.
double largestTrochoidStep(double toolRadius, double loopRadius, double maxAngle, double upTo);

/// Places for plunges of radius `reach` along a chain of segments, evenly
/// spread so that the edges of neighbouring discs, on either side of the
/// chain, are at most `spacing` apart along it: the chain's length with each
/// turn weighted by `reach` (an arc of radius r counts (1 + reach / r) times
/// its length, a corner reach times its angle). Both ends are included for
/// an open chain, the start only for a closed one. None when that takes
/// more than `maxPoints` places (a spacing far too small for the chain),
/// before any is made.
std::optional<std::vector<geom::Vec2>> plungeCentres(const std::vector<geom::Seg> &chain, double spacing,
                                                     double reach, double maxPoints);

} // namespace stepnc::passes
