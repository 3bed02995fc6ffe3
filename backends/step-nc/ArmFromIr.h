// An ISO 14649 ARM file written from the toolpath IR alone: the
// machine-optimised write-back of an AP238 AIM file (docs/feedback.md,
// docs/ap238.md).
//
// The ARM write-back of an ARM file patches the file's own instances
// (OptimisedFile.h); an AIM file has none to patch. This writes a fresh file
// of the built-in ARM (FILE_SCHEMA MACHINING_SCHEMA) that says what the
// compiled program does: the project, its workpieces (material, stock block,
// clamping points), its tools (ISO 14649-111 bodies and dimensions), one
// setup, the workplans as the IR nests them, and each machining workingstep
// as a `toolpath_feature` at its feature's placement machined by a
// `freeform_operation` whose toolpath list is the step's moves (Toolpaths.h:
// the feed of every move, rapids, dwells as feedstops, canned cycles as the
// moves they make), with the operation's tool, technology and machine
// functions; rapid movements, program stops, optional stops and messages as
// themselves. Every instance is written with the schema's attribute list, by
// name. Read again, the file compiles to the program the AIM file compiles
// to (canned cycles as moves). What it does not say is the machining
// features and strategies the moves were made from: the feature a step
// machined keeps its name and placement only.
#pragma once

#include "backends/step-nc/OptimisedFile.h"

namespace stepnc::backends {

/// The ARM file as Part 21 text: `input` is the file `module` was lowered
/// from (its FILE_NAME is kept, its description follows the options'),
/// `module` the toolpath IR after the passes. Empty after reporting errors
/// (a tool with no ISO 14649-111 body, a move the toolpath model cannot
/// carry, a construct beyond a straight milling program).
std::string writeArmFromIr(const p21::Part21File &input, const ir::Module &module,
                           const OptimisedFileOptions &options, DiagnosticEngine &diags);

} // namespace stepnc::backends
