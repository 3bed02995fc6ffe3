// Helpers shared by the unit tests.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
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

/// A file of the corpus, read; `source` is null (and `error` says why) when
/// it cannot be opened.
struct CorpusFile {
  std::filesystem::path path;
  std::unique_ptr<SourceFile> source;
  std::string error;
};

/// The Part 21 files below `dir` in path order, read (the corpus also holds
/// schemas, tool tables and notes, which are left out). A file that cannot
/// be opened is kept, with its error, for the caller to fail on.
inline std::vector<CorpusFile> part21FilesBelow(const std::string &dir) {
  std::vector<std::filesystem::path> paths;
  for (const auto &entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.is_regular_file())
      paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  std::vector<CorpusFile> files;
  for (const std::filesystem::path &path : paths) {
    CorpusFile f{path, nullptr, {}};
    f.source = SourceFile::open(path.string(), f.error);
    if (!f.source || looksLikePart21(f.source->text()))
      files.push_back(std::move(f));
  }
  return files;
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
