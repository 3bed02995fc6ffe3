// Planning a lathe program's motion (docs/turning.md, "Native motion"): the
// turning steps' moves, and holes drilled on the spindle axis, planned by the
// same jerk-limited planner as a mill's (runtime/Planner.h), in the lathe's
// ZX plane, with the spindle planned alongside.
//
// The planner takes a path of lines and arcs about its third coordinate; the
// lathe's moves are given to it in the ZX plane's own coordinates (z, x, y),
// where the lathe's arcs are such arcs (Frame::Zxy, runtime/Trajectory.h),
// on the lathe's z and x axes (runtime::latheFrameMachine).
//
// A feed per revolution becomes a feed in mm/min from the spindle's speed
// where the tool is. At constant surface speed that speed follows the
// radius, so a cut is planned in pieces over which the asked speed changes
// by at most 2 %, each at its feed per revolution times the lowest speed on
// it: the tool never moves more than the programmed feed per revolution,
// and at most 2 % less. The spindle's plan is written on every segment (its
// speed at both ends, linear in time between): on a cut, the speed the
// surface speed asks at each end; a cut is slowed where the spindle could not
// change speed that fast (the machine's spindle acceleration); over rapids the
// spindle goes from one cut's speed to the next's, and the tool waits (a
// dwell) before a cut the spindle cannot reach in time. A thread pass starts
// and ends at rest, keeps the spindle's speed and moves with it (sync).
#pragma once

#include "ir/motion/MotionIR.h"
#include "runtime/Machine.h"

#include <optional>

namespace stepnc::ir {

struct LathePlan {
  /// The moves planned, in the trajectory's frame (z, x, y): cuts in
  /// pieces, a dwell where the tool waits for the spindle (its node null).
  ProgramPath program;
  runtime::Trajectory trajectory;  ///< Frame::Zxy, each segment with its spindle
  int spindleWaits = 0;            ///< dwells added for the spindle to reach a cut's speed
  int rounds = 0;                  ///< plans made (each after slowing cuts and adding waits)
};

/// Plans the lathe program `module` on the lathe `machine`. Errors (a step
/// that mills or drills off the spindle axis, an arc out of the ZX plane, a
/// thread pass the z axis cannot follow) are reported at their node;
/// nullopt then. A thread pass that reaches its feed only past two leads
/// from its start, or leaves it more than two leads before its end, is
/// warned about: those turns are cut at a shorter lead.
std::optional<LathePlan> planLathe(const Module &module, const runtime::Machine &machine,
                                   const runtime::PlanOptions &options, DiagnosticEngine &diags);

} // namespace stepnc::ir
