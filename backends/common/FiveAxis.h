// Steps that tilt the tool (5-axis moves of the toolpath IR), written for a
// machine without tool-centre-point control: every pose (tool tip and axis
// in the workpiece) goes through the machine's inverse kinematics, and the
// program gives the joints: X Y Z (less the work offset) and the rotary
// axes' angles, the feed in inverse time (docs/five-axis.md).
//
// - Between two blocks the controller moves every joint in proportion, which
//   takes the tip off the IR's straight line when the rotary axes turn:
//   a move is cut in halves until the tip and axis halfway along each block
//   are within `tolerance` (and 0.01 deg) of the IR's move.
// - Of the inverse kinematics' solutions, the one nearest the joints before
//   (runtime/Kinematics.h): the rotary axes turn least, no flip mid-path; a
//   pose along a rotary axis keeps that axis where it is.
// - The feed: each block takes the time the IR's feed gives its share of the
//   tip's path (G93, F = 1 / minutes), so the tip keeps the programmed feed
//   whatever the joints do.
// - The tool turns to a new axis only with the tool up: at the start of the
//   step, and at any rapid that changes the axis, the tool goes up to the top
//   of z in machine coordinates, the rotary axes turn alone, then the tool
//   goes across at the top and down along z (as for a 3+2 turn). After the
//   step, the next step that does not tilt the tool turns them back to 0.
#pragma once

#include "backends/common/Program.h"
#include "runtime/Machine.h"
#include "support/Diagnostics.h"

#include <optional>

namespace stepnc::backends {

/// mm and deg the tip and axis may be off the IR's move between two blocks.
inline constexpr double kJointTolerance = 0.002;
inline constexpr double kJointAxisTolerance = 0.01;

/// Rewrites the steps of `p` that tilt the tool as `machine`'s joints (the
/// workpiece's origin at `workOffset`, machine coordinates with every axis at
/// 0). False (reported at the step) when a pose is out of the machine's reach
/// or travel, the tool would have to flip within a move, or the step is of a
/// kind not written yet (on another face, with arcs); true and nothing
/// changed when no step tilts the tool.
bool jointMoves(Program &p, const runtime::Machine &machine, const Vec3 &workOffset, DiagnosticEngine &diags);

/// Rewrites the steps of `p` that tilt the tool for a controller with
/// tool-centre-point control (siemens-840d's TRAORI): X Y Z stay the tool
/// tip in the workpiece, each move gets the rotary axes' angles for its tool
/// axis (the machine's inverse kinematics, the solution nearest the one
/// before; at a rapid that turns the tool, nearest the middle of the
/// travel), and a move whose rotary axes, moving in proportion, would take
/// the tool axis further than 0.01 deg from the IR's is cut in halves (the
/// controller keeps the tip on the line). The step ends with the rotary
/// axes back at 0, the tip still. `workOffset`, when given, also checks the
/// linear axes' travel. False (reported) as jointMoves.
bool tcpMoves(Program &p, const runtime::Machine &machine, const std::optional<Vec3> &workOffset,
              DiagnosticEngine &diags);

} // namespace stepnc::backends
