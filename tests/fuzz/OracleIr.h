// The check the IR-producing fuzz targets share (Oracle.h has the rest): a
// module a reader produced verifies with located errors.
#pragma once

#include "ir/Node.h"
#include "ir/Verifier.h"
#include "tests/fuzz/Oracle.h"

namespace stepnc::fuzz {

/// Verifies `module`: the verifier's diagnostics render, its errors point
/// into `sources`, and its answer agrees with what it reported (tag
/// verifier).
inline void checkVerifies(const ir::Module &module, std::initializer_list<const SourceFile *> sources,
                          std::string_view input) {
  DiagnosticCollector verified;
  DiagnosticEngine diags(verified);
  const bool valid = ir::verifyModule(module, diags);
  renderDiagnostics(verified.diags);
  checkLocations(verified.diags, sources, true);
  if (valid == diags.hasErrors())
    violation("verifier", "verifyModule's answer disagrees with the errors it reported",
              textOf(verified.diags) + "--- input ---\n" + clip(input));
}

} // namespace stepnc::fuzz
