// Target descriptor files (docs/targets.md): a controller described in a
// TOML file instead of C++. A descriptor extends a built-in target (or
// another descriptor file) and sets what its controller does otherwise:
// the program file's extension, decimals, block numbers and line length,
// the arc form, whether canned cycles and splines are written. Mistakes are
// reported at their line and column, as in machine files.
//
// What a descriptor cannot say yet (its own words: header, tool change,
// cycles' templates; issue "targets as data") stays with the built-in
// target it extends.
#pragma once

#include "backends/Backend.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>
#include <string>
#include <vector>

namespace stepnc::backends {

/// The target `spec` names for --target: a built-in target (Targets.def),
/// or a descriptor file (a path ending in .toml). Null after located errors
/// in a descriptor (reported to `diags`; the files read are kept in `files`
/// for them), or with `usageError` set when the name or path names nothing.
std::unique_ptr<Backend> loadTarget(const std::string &spec, std::vector<std::unique_ptr<SourceFile>> &files,
                                    DiagnosticEngine &diags, std::string &usageError);

/// Whether `spec` names a descriptor file rather than a built-in target.
bool isTargetFile(const std::string &spec);

} // namespace stepnc::backends
