// Helpers shared by the IR unit tests: a realistic feature-IR module built by
// hand, and small functions to find nodes in it and to run the IR readers.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::ir::test {

/// A pocket and a hole on one workpiece, two tools, one setup, and a workplan of
/// two workingsteps (rough milling of the pocket, drilling of the hole). The
/// project label has a quote and a non-ASCII character, the setup's placement a
/// negative zero, the strategy a comment; every attribute is set in the kind
/// table's order and every number is exact at its printed precision.
Module sampleModule();

/// The first node, in pre-order, whose symbol is `symbolOrKind` or whose kind
/// is `symbolOrKind`; fails the test when there is none.
Node &find(Node &root, std::string_view symbolOrKind);

/// Diagnostics as "line:col: message", or just "message" when unlocated.
std::vector<std::string> messages(const DiagnosticCollector &c);

/// IR text parsed from a file named "t.ir".
struct Parsed {
  std::unique_ptr<SourceFile> source;
  std::unique_ptr<Module> module;
  std::vector<std::string> errors;  ///< as by messages()
};
Parsed parse(std::string_view text);

} // namespace stepnc::ir::test
