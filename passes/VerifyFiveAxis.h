// The check verify-toolpaths makes of the steps that tilt the tool (5-axis
// moves, docs/five-axis.md), in code of its own: the tool as a body (a flat,
// bull-nose or ball end mill of its radius and corner radius, as long as its
// cutting edge) at poses sampled along every move (the tip along the line,
// the axis turning evenly in the plane of its two ends: the IR's rule), and
// the walls of the step's feature as FeatureWalls reads them (passes/
// FeatureWalls.h: the islands' outlines at their foot, shrunk with height by
// their slope), sampled as points on the wall with the wall's normal.
//
// - Walls: at every wall point, the nearest any pose of the tool comes
//   (negative inside the tool). Inside by more than the side allowance plus
//   the tolerance is a gouge; for a step that finishes walls, further than
//   the allowance plus the tolerance from every pose is uncut wall.
// - Floor: the lowest point of the body never below the feature's floor
//   (plus its bottom allowance) less the tolerance.
// - Safety: a rapid runs at or above the security plane, or along the tool
//   axis (the axis held) with its lower end at or above the feature's top;
//   the tool turns only at or above the security plane.
// - The axis: no move at feed turns it by 90 degrees or more (a flip).
#pragma once

#include "ir/Node.h"
#include "passes/Pass.h"
#include "support/Diagnostics.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::passes {

/// Checks every workingstep of `module` that tilts the tool; false after an
/// error. `tolerance` absent: the workpiece's global tolerance, else 0.01 mm.
/// Appends a line of figures per step to `reports`.
bool verifyFiveAxis(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                    std::optional<double> tolerance, std::vector<std::string> *reports);

} // namespace stepnc::passes
