// The check verify-toolpaths makes of lathe moves (docs/turning.md,
// Verification): in the half plane of the turning axis, the insert swept
// along every move against the stock as the moves before left it and the
// finished part the turned features describe. It shares with turning
// expansion only the reading of the features (ir/geom/TurnedShape.h); the
// insert, its sweep and the material are its own.
#pragma once

#include "ir/Node.h"
#include "passes/Pass.h"
#include "support/Diagnostics.h"

#include <optional>

namespace stepnc::passes {

/// Checks every turning workingstep of `module`; false after an error. A
/// feed move that cuts into the part (beyond the step's allowance and
/// `tolerance`), a rapid that meets the stock, or a finishing step that
/// leaves material thicker than `tolerance` where the insert could have
/// reached is an error at the step; material a finishing step leaves in a
/// corner narrower than the insert's nose is a warning naming where.
/// `tolerance` absent: the workpiece's global tolerance, else 0.01 mm.
bool verifyTurning(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                   std::optional<double> tolerance);

} // namespace stepnc::passes
