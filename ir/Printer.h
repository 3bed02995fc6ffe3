// The IR text form, printing side.
//
// One node per line, two spaces of indentation per level, children after their
// parent:
//
//   <kind>[ <symbol>][ "<label>"][ <name>=<value>]...[ loc(<file>:<line>:<col> #<id>)][  ; <comment>]
//
// Attributes come in the order of the kind table (ir/Kinds.def); attributes the
// table does not list follow in insertion order (the verifier reports them).
// Every value has one spelling: fixed decimals per type, the unit as a suffix,
// never `-0`, never an exponent. The parser (ir/Parser.h) accepts exactly this
// spelling, so print -> parse -> print gives the same bytes. Printing assumes a
// module the verifier accepts: a non-finite number or a comment with a line
// break prints, but does not parse back.
#pragma once

#include "ir/Kinds.h"
#include "ir/Node.h"

#include <string>
#include <string_view>

namespace stepnc::ir {

/// Digits after the decimal point of lengths and points.
inline constexpr int kLengthDecimals = 4;

/// True when `a` and `b` print as one point (kLengthDecimals). An arc whose
/// ends do is a whole turn when read back: producers write an arc that
/// turns less than that as the line it is within the printed resolution.
bool printsAsOnePoint(const Vec3 &a, const Vec3 &b);

struct PrintOptions {
  /// Print `loc(file:line:col #id)` on nodes whose origin has a valid location.
  bool locations = false;
};

/// The module as IR text: a header comment line, then the root and its subtree.
std::string printModule(const Module &m, const PrintOptions &o = {});

/// Appends `n` and its subtree to `out`, `n` indented by `depth` levels.
void printNode(const Node &n, std::string &out, const PrintOptions &o, int depth = 0);

/// Appends `v` as it is written after `name=`: `12.5000mm`, `climb`, `"text"`, `(0.000000,0.000000,1.000000)`.
void printValue(const Value &v, std::string &out);

/// The unit written after a number or a point of type `t` ("mm", "deg", "mm/min", "rev/min", "s");
/// empty for ratios, directions and the non-numeric types.
std::string_view unitSuffix(ValueType t);

/// What a value of attribute `a` looks like, for messages: "a length in mm", "one of (climb, conventional)".
std::string describeValue(const AttrSpec &a);

} // namespace stepnc::ir
