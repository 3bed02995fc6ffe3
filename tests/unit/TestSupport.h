// Helpers shared by the unit tests.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace stepnc::test {

/// The third-party sample corpus: $STEPNC_CORPUS, else the CMake setting.
/// Empty when it does not exist (tests that need it then WARN and skip).
inline std::string corpusDir() {
  const char *env = std::getenv("STEPNC_CORPUS");
  std::string dir = env && *env ? env : STEPNC_DEFAULT_CORPUS_DIR;
  return std::filesystem::is_directory(dir) ? dir : std::string();
}

} // namespace stepnc::test
