// The check verify-toolpaths makes of deposition steps (docs/additive.md,
// Verification). It reads the added feature itself (its profile or planes,
// its draft, its channels) with code of its own, not the slicer's
// (ir/geom/AmShape.h), and the beads from the moves with the energy on:
//
// - every point of the feature is inside a bead of its layer (a bead is a
//   rectangle of the technology's width and height about its centre line,
//   standing on the layer below), within `tolerance`, except where the
//   layer's column meets a channel;
// - no bead reaches further from the feature than the operation's
//   allowance plus `tolerance`, nor into a channel;
// - the energy is never on during a rapid, and is off when the step ends;
// - on no move does the head (its nozzle's tip the stand-off above the
//   programmed point, its cone above) meet material deposited before, this
//   step's or an earlier one's.
#pragma once

#include "ir/Node.h"
#include "passes/Pass.h"
#include "support/Diagnostics.h"

#include <optional>

namespace stepnc::passes {

/// Checks every deposition workingstep of `module`; false after an error.
/// `tolerance` absent: 0.05 mm (a twentieth of a typical bead's half width).
bool verifyDeposition(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                      std::optional<double> tolerance, std::vector<std::string> *reports);

} // namespace stepnc::passes
