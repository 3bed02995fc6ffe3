// The runtime's own parallel-kinematic solver, "linear-tripod": a hybrid
// 5-axis machine in the spirit of Fatronik's VERNE (PROCESSES.md C5), made
// simpler. Three vertical guideways stand at 120 deg round a circle about
// the machine's z axis; on each a slider carries a pair of struts of fixed
// length (a parallelogram, so that the platform translates and never tilts)
// down to the spindle platform; the tool hangs along the platform's axis
// (+z). A serial tilting table with two rotary axes (A carrying C, say)
// turns the workpiece under it. The VERNE itself has three non-identical
// legs and a platform that tilts as it moves (the table compensates); this
// model is the symmetric linear tripod (a "linear delta"), its geometry
// numbers in the machine file (docs/machine-model.md, docs/five-axis.md).
//
// Joints, in order: the three sliders (mm, the height of each slider's strut
// joints in machine z, guideway 1 at `first_guideway`, 2 and 3 at +120 and
// +240 deg), then the table's two rotary axes from the base outwards (deg).
//
// Inverse: the table chain's inverse (the table-table chain of
// runtime/Kinematics.h, the same choice of solution, wrap and singularity)
// gives the tip in machine coordinates; each strut then joins the slider's
// joint, on its guideway's line, to the platform's joint at the strut's
// length, so the slider is above the platform by the strut's vertical part
// (Pythagoras): s_i = z_p + sqrt(L^2 - d_i^2), d_i the horizontal distance
// from the platform's joint to the guideway, z_p = tip z + tool_length. The
// sliders are above the platform (the struts hang down from them), which is
// how the machine is built: the other root would put the platform above them.
// Forward: the platform's joint point lies on a sphere of radius L about each
// slider's joint moved in by the platform's radius; three spheres meet in
// two points mirrored in the plane of their centres, and the lower is the
// platform's (the branch the machine is built on).
//
// Refused with the reason: a pose whose strut cannot reach (d_i >= L), or
// leans beyond `max_strut_angle` from its guideway (towards lying across it,
// where the slider no longer pushes the platform: a serial singularity) or
// within `min_strut_angle` of it (towards all three standing parallel, where
// the platform could move sideways with the sliders still: a parallel
// singularity).
#pragma once

#include "runtime/Kinematics.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::runtime {

/// The solver's name in machine files (`solver = "linear-tripod"`).
inline constexpr std::string_view kLinearTripodSolver = "linear-tripod";

/// Every parameter it reads from `[kinematics.parameters]`, with its range.
std::vector<SolverParameter> linearTripodParameters();

/// The solver for `machine` (a generic chain naming it); null with `error`
/// set when a parameter is missing or out of range, the geometry cannot be
/// built, or the joints are not three linear axes and two rotary ones.
std::unique_ptr<Kinematics> makeLinearTripod(const Machine &machine, std::string &error);

} // namespace stepnc::runtime
