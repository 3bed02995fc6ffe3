// The tool as a stepped cantilever clamped in its holder: a shank of the
// tool's diameter D from the clamp, then the fluted part, whose stiffness is
// that of a cylinder of effective diameter De (about 0.8 D, Kops & Vo, CIRP
// Annals 1990). A force F at distance `a` from the clamp bends the tool; by
// the unit-load method the deflection at distance x >= a is
//
//   delta(x) = F / E * integral_0^a (a - s)(x - s) / I(s) ds,  I = pi d^4 / 64
//
// and at a point between the clamp and the load (x < a) the integral runs to
// x only; both are integrated exactly piece by piece (I is constant on each
// section). For a uniform tool loaded at its tip this is F L^3 / (3 E I).
#pragma once

namespace stepnc::cutting {

struct ToolBeam {
  double overhang = 40;     ///< mm from the clamp to the tip
  double fluteLength = 20;  ///< mm of fluted part above the tip
  double diameter = 10;     ///< mm, the shank
  double fluteDiameter = 8; ///< mm, effective diameter of the fluted part
  double modulus = 600000;  ///< N/mm^2 (E)
};

/// Deflection (mm) at `pointFromTip` mm above the tip under a force F (N)
/// applied `loadFromTip` mm above the tip.
double deflection(const ToolBeam &beam, double force, double loadFromTip, double pointFromTip);

/// Deflection (mm) at `pointFromTip` under a force F (N) spread evenly over
/// the lowest `height` mm of the tool: what straight flutes engaged over an
/// axial depth of cut take (the sum of kSlices equal loads, midpoint rule).
double deflectionUnderSpreadLoad(const ToolBeam &beam, double force, double height, double pointFromTip);

/// The force (N) that bends the shank at the clamp to `stress` (N/mm^2)
/// when applied `loadFromTip` above the tip: M = F (L - load), sigma = M (D/2)
/// / I.
double forceForClampStress(const ToolBeam &beam, double stress, double loadFromTip);

} // namespace stepnc::cutting
