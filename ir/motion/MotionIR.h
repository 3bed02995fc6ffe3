// The motion IR: a planned trajectory written into the IR. Each workingstep
// (and rapid movement) that has moves gains a `motion` child holding the
// segments that follow its moves, each with its geometry and its speed
// profile, in exact numbers (shortest round trip), so that the text form
// plays back identically (docs/motion.md).
//
// Also the programmed path of a module in program order, as the planner and
// the player take it.
#pragma once

#include "ir/Node.h"
#include "runtime/Planner.h"
#include "runtime/Trajectory.h"
#include "support/Diagnostics.h"

#include <optional>
#include <vector>

namespace stepnc::ir {

/// Every move of the module in program order.
struct ProgramPath {
  runtime::PathInput path;
  std::vector<const ir::Node *> owners;  ///< per move: the executable whose moves hold it
  std::vector<const ir::Node *> nodes;   ///< per move: its node
};

/// The moves of every workingstep and rapid movement in program order. The
/// tool starts at rest at the first move's end point. The tool stops before
/// a change of tool, setup or spindle and at program and optional stops. A
/// dwell is a PathMove of kind Dwell at the point where the tool is (one
/// before the first move, at that move's end point, where the tool starts).
ProgramPath programPath(const ir::Module &module);

/// Writes `trajectory` (planned from programPath(module)) into the module:
/// one `motion` child per executable that has segments, replacing any
/// there was.
void attachMotion(ir::Module &module, const ProgramPath &program, const runtime::Trajectory &trajectory);

/// Reads the trajectory back from the `motion` nodes (errors located at the
/// node that is wrong); nullopt when there are none or one is wrong. A
/// program with no step that moves (ir::hasMachiningSteps) has an empty
/// trajectory: no segments, no machine's name, starting at the origin.
std::optional<runtime::Trajectory> readMotion(const ir::Module &module, DiagnosticEngine &diags);

} // namespace stepnc::ir
