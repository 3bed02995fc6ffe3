// Facts about a program that every layer asks: the executables in the order
// the machine runs them, a workingstep's operation, the resources a symbol
// names. Passes, backends and the tools ask here instead of walking the tree
// each their own way.
#pragma once

#include "ir/Node.h"

#include <string_view>
#include <vector>

namespace stepnc::ir {

/// The executables the machine runs, in program order: every workingstep,
/// rapid movement, program stop, optional stop and display message of the
/// module's workplans, nested workplans flattened where they stand.
std::vector<const Node *> programOrder(const Module &module);

/// A workingstep's operation (its child of category operation), or null.
const Node *operationOf(const Node &step);
Node *operationOf(Node &step);

/// The resource of `kind` (tool, setup, workpiece) the project lists under
/// `symbol`, or null.
const Node *findResource(const Module &module, Kind kind, std::string_view symbol);
inline const Node *findTool(const Module &module, std::string_view symbol) {
  return findResource(module, Kind::Tool, symbol);
}

/// The feature node a symbol names (features live under their workpiece), or null.
const Node *findFeature(const Module &module, std::string_view symbol);
/// The workpiece that holds `feature`, or null.
const Node *workpieceOf(const Module &module, const Node &feature);

/// Whether an executable's moves are its operation's explicit toolpaths,
/// every one of them required (ISO 14649 `its_priority`): they run as the
/// file writes them: no pass changes their path, and adapt-feed changes a
/// feed only to what the machine reaches on the move (which changes nothing
/// the machine does).
bool runsAsWritten(const Node &executable);

} // namespace stepnc::ir
