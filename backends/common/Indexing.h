// 3+2 (indexed) machining: a program whose features lie on several faces of
// the workpiece, which lowering made a clamping per face (docs/setups.md),
// written for a machine with two rotary axes turns those axes to bring each
// face to the tool instead of stopping for the operator to re-clamp. Each
// step's moves, planned in its face's frame, are written in the frame of the
// workpiece as clamped once (one work offset), through the machine's inverse
// kinematics with the rotary axes held for the whole face
// (docs/five-axis.md).
#pragma once

#include "backends/common/Program.h"
#include "runtime/Machine.h"
#include "support/Diagnostics.h"

namespace stepnc::backends {

/// Turns the re-clamps of `p` (built from `module`) into turns of
/// `machine`'s rotary axes: every step on another face gets its moves in
/// the first clamping's frame (the workpiece's origin at `workOffset`, in
/// machine coordinates with every axis at 0) and, where the face changes,
/// the rotary positions (Step::index); the re-clamp stops and their messages
/// go. Nothing changes when `p` does not re-clamp, nor (with a warning
/// naming the step and why) when the machine cannot turn some face to the
/// tool within its travel or a turned face has an arc outside the XY plane:
/// the re-clamps stay. False (reported) when the kinematics cannot be made.
bool indexClampings(Program &p, const ir::Module &module, const runtime::Machine &machine, const Vec3 &workOffset,
                    DiagnosticEngine &diags);

} // namespace stepnc::backends
