// The mechanics of a flat end mill in the cut: how much of its circle meets
// material (engagement), the chip each tooth takes, and the forces, torque
// and power of the mechanistic model (Altintas, Manufacturing Automation,
// ch. 2):
//
//   per tooth in cut, over its engaged height a:
//     Ft = a (Ktc h + Kte)   tangential, against the tooth's motion
//     Fr = a (Krc h + Kre)   radial, pushing the tool off the material
//     h  = fz cos(theta)     theta: the tooth's angle from the feed direction
//
// so h = fz sin(phi) with phi the immersion angle measured from the
// direction normal to the feed. Everything is evaluated numerically over
// kAngles angular positions, so any engagement works: a slot, a wall, a
// corner, the side of a trochoid. Flutes are taken as straight (no helix):
// all of a tooth's engaged height cuts at once, which gives the highest
// peak force (conservative for limits and deflection).
#pragma once

#include "cutting/HeightMap.h"

#include <array>

namespace stepnc::cutting {

struct Cutter {
  double radius = 5; ///< mm
  int flutes = 2;
  double fluteLength = 20; ///< mm of cutting edge above the tip
  bool clockwise = true;   ///< spindle turning clockwise seen from +z (M3)
};

struct CuttingCoefficients {
  double ktc = 0, krc = 0; ///< N/mm^2
  double kte = 0, kre = 0; ///< N/mm
};

/// The material around the cutter at one position: at each of kAngles
/// directions about the axis (direction k at k * 360 / kAngles degrees from
/// +x, counter-clockwise), the height of material the edge meets there
/// (0: none), in mm, limited to the flute length.
struct Engagement {
  static constexpr int kAngles = 720;
  std::array<float, kAngles> depth{};
  Vec2 feedDir = Vec2::UnitX(); ///< unit, direction of travel

  /// Whether any edge in front of the cutter meets material.
  bool cutting() const;
  /// The largest cos(theta) over the engaged directions in front of the
  /// cutter: the chip thickness is fz times this (1 in a slot, sin(phi_e)
  /// on a wall taken to width ae < R).
  double chipFactor() const;
  /// Engaged angle in front of the cutter, radians (pi in a slot).
  double angle() const;
  /// The radial depth that gives this engaged angle on a straight wall:
  /// R (1 - cos(angle)), 2R in a slot.
  double radialDepth(double radius) const;
  /// The largest engaged height, mm.
  double axialDepth() const;
  /// +1 when the engaged material is mostly left of the feed direction, -1
  /// when right, 0 when there is none or it is balanced (a slot).
  int side() const;
};

/// Measures the engagement of `cutter` with its tip at height z and its
/// axis at `centre`, travelling along `feedDir`.
Engagement measureEngagement(const HeightMap &stock, const Vec2 &centre, double z, const Vec2 &feedDir,
                             const Cutter &cutter);

/// A side-milling engagement: a wall on `side` (+1 left, -1 right) taken
/// to radial depth ae over height ap.
Engagement wallEngagement(const Vec2 &feedDir, int side, double ae, double ap, const Cutter &cutter);

/// The forces of one engagement as functions of the feed per tooth fz, at
/// each angular position of the teeth over one tooth pitch: F = A fz + B
/// (N, on the tool, in the plane), and the mean torque over a revolution
/// T = ta fz + tb (N m).
class ForceModel {
public:
  ForceModel(const Engagement &e, const Cutter &cutter, const CuttingCoefficients &k);

  /// The largest force over a revolution at fz (N).
  double peakForce(double fz) const;
  /// The largest force over a revolution pushing the tool away from the
  /// side `normal` points to (N; negative when the tool is pulled towards
  /// it all the time). With straight flutes the tooth generating a wall
  /// takes no chip at that instant, but a real, helical edge does along its
  /// height: the peak is an upper estimate of what bends the tool off the wall.
  double peakPush(const Vec2 &normal, double fz) const;
  /// Mean torque over a revolution (N m).
  double meanTorque(double fz) const { return ta_ * fz + tb_; }
  /// The largest fz (mm) whose peak force stays within `limit` N; 0 when
  /// even fz = 0 exceeds it (edge forces alone), infinity when no fz does.
  double fzForForce(double limit) const;
  /// The largest fz whose mean torque stays within `limit` N m.
  double fzForTorque(double limit) const;

private:
  std::vector<Vec2> a_, b_; ///< per tooth position
  double ta_ = 0, tb_ = 0;
};

} // namespace stepnc::cutting
