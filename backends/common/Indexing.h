// 3+2 (indexed) machining: a program whose features lie on several faces of
// the workpiece, which lowering made a clamping per face (docs/setups.md),
// written for a machine with two rotary axes (a table-table or head-table
// chain) turns those axes to bring each face to the tool instead of
// stopping for the operator to re-clamp. Each
// step's moves, planned in its face's frame, are written in the frame of the
// workpiece as clamped once (one work offset), through the machine's inverse
// kinematics with the rotary axes held for the whole face
// (docs/five-axis.md).
#pragma once

#include "backends/common/Program.h"
#include "runtime/Kinematics.h"
#include "runtime/Machine.h"
#include "support/Diagnostics.h"

#include <array>
#include <memory>

namespace stepnc::backends {

/// Turns the re-clamps of `p` into turns of
/// `machine`'s rotary axes: every step on another face gets its moves in
/// the first clamping's frame (the workpiece's origin at `workOffset`, in
/// machine coordinates with every axis at 0) and, where the face changes,
/// the rotary positions (Step::index); the re-clamp stops and their messages
/// go. With the tool leaning (a head), canned cycles are written as their
/// moves and a step's first move up along z goes across at the top of z,
/// then down. Nothing changes when `p` does not re-clamp, nor (with a
/// warning naming the step and why) when the machine cannot turn some face
/// to the tool within its travel or an arc lands in no plane the target
/// writes: the re-clamps stay. False (reported) when
/// the kinematics cannot be made or the workpiece could sweep into the tool
/// while it turns.
/// `arcPlanes`: the target writes arcs in the ZX and YZ planes (where a
/// leaning tool puts a face's arcs); an arc that lands in no plane the
/// target writes keeps the re-clamps (with the warning).
/// `workingPlanes`: the target tilts the controller's working plane to each
/// face instead: the moves, cycles and heights stay in the face's frame,
/// and each turn also gets the face's frame (Step::plane); which faces are
/// reached, the rotary solution and the travel of every point are found
/// and checked as for joints.
/// A machine axis's address in a program: its name in capitals ("A").
std::string axisAddress(const runtime::Axis &axis);

/// The axes `joints` puts outside their travel, as a program writes them
/// ("A-130, C400"); "" when none is. `rotaryOnly`: the rotary axes alone.
std::string outsideTravel(const runtime::Machine &machine, const runtime::Joints &joints, bool rotaryOnly = false);

/// The kinematics of `machine` for a program that turns its rotary axes
/// with the workpiece's origin at `workOffset`; null (reported) when it
/// cannot be made, or when the raw block of `p` could sweep above the top of
/// z travel, where the tool waits while the table turns.
std::unique_ptr<runtime::Kinematics> turningKinematics(const Program &p, const runtime::Machine &machine,
                                                       const Vec3 &workOffset, DiagnosticEngine &diags);

bool indexClampings(Program &p, const runtime::Machine &machine, const Vec3 &workOffset, bool arcPlanes,
                    bool workingPlanes, DiagnosticEngine &diags);

/// The angles (deg) that turn coordinates to a working plane whose axes are
/// the columns of `turn` (WorkingPlane::turn): turn = Rz(c) Ry(b) Rx(a),
/// returned as {a, b, c}. That is a about the fixed X, then b about the
/// fixed Y, then c about the fixed Z (heidenhain-tnc's PLANE SPATIAL); or
/// equally c about Z, then b about the turned Y, then a about the twice
/// turned X (siemens-840d's CYCLE800 axis by axis, ZYX). Where b is +-90
/// deg only a - c (or a + c) is fixed: c is 0.
std::array<double, 3> fixedAxisAngles(const Eigen::Matrix3d &turn);

} // namespace stepnc::backends
