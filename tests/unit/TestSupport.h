// Helpers shared by the unit tests.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::test {

/// The third-party sample corpus: $STEPNC_CORPUS, else the CMake setting.
/// Empty when it does not exist (tests that need it then WARN and skip).
inline std::string corpusDir() {
  const char *env = std::getenv("STEPNC_CORPUS");
  std::string dir = env && *env ? env : STEPNC_DEFAULT_CORPUS_DIR;
  return std::filesystem::is_directory(dir) ? dir : std::string();
}

/// True if `t` holds Part 21: ISO-10303-21 after white space and comments.
inline bool looksLikePart21(std::string_view t) {
  size_t i = 0;
  for (;;) {
    while (i < t.size() && (t[i] == ' ' || t[i] == '\t' || t[i] == '\r' || t[i] == '\n'))
      ++i;
    if (t.substr(i, 2) != "/*")
      break;
    size_t end = t.find("*/", i + 2);
    if (end == std::string_view::npos)
      return false;
    i = end + 2;
  }
  return t.substr(i).starts_with("ISO-10303-21");
}

/// Every file below `dir`, sorted (the corpus: Part 21 files, schemas, tool
/// tables, notes; callers pick with looksLikePart21 after reading).
inline std::vector<std::filesystem::path> filesBelow(const std::string &dir) {
  std::vector<std::filesystem::path> paths;
  for (const auto &entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.is_regular_file())
      paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  return paths;
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
