// Helpers shared by the unit tests.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace stepnc::test {

/// The third-party sample corpus: $STEPNC_CORPUS, else the CMake setting.
/// Empty when it does not exist (tests that need it then WARN and skip).
inline std::string corpusDir() {
  const char *env = std::getenv("STEPNC_CORPUS");
  std::string dir = env && *env ? env : STEPNC_DEFAULT_CORPUS_DIR;
  return std::filesystem::is_directory(dir) ? dir : std::string();
}

/// Each collected diagnostic as "line:col: message", positions in `file`.
inline std::vector<std::string> locatedMessages(const DiagnosticCollector &collector, const SourceFile &file) {
  std::vector<std::string> out;
  for (const Diagnostic &d : collector.diags) {
    const LineCol lc = file.lineCol(d.loc.offset);
    out.push_back(std::to_string(lc.line) + ":" + std::to_string(lc.col) + ": " + d.message);
  }
  return out;
}

} // namespace stepnc::test
