// The IR verifier: checks a module against the kind table and the rules that
// span nodes, so every pass can assume a well-formed module and the printer's
// text parses back.
//
// Table-driven checks: known kinds, attributes the kind lists with their value
// types and allowed words, required attributes, allowed children, symbol
// sigils. Module checks: `project` is the root and only the root, symbols are
// unique, every reference resolves (and the tool of an operation is a `tool`,
// the feature of a workingstep a feature, ...), a workingstep has exactly one
// operation, an operation at most one of each technology, machine functions,
// strategy, approach and retract. Value checks: numbers finite, directions of
// unit length, dimensions (depth, diameter, width, length, pitch, travel)
// positive and radii not negative.
#pragma once

#include "ir/Kinds.h"
#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <optional>
#include <string>
#include <string_view>

namespace stepnc::ir {

/// Reports every violation at the node's origin.loc (none when it is invalid),
/// naming the node (`closed_pocket %pocket1: ...`). True when there was none.
bool verifyModule(const Module &m, DiagnosticEngine &diags);

/// The number of `v` beyond what a machine tool does (ir/Plausible.h: lengths
/// and coordinates past kMaxLengthMm, angles, times, rates past theirs), the
/// coordinate farthest out for a point; nullopt when it is within. What
/// verifyModule refuses, for a pass that wants to say why first.
std::optional<double> beyondMachine(const Value &v);

} // namespace stepnc::ir
