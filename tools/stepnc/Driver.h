// Pieces shared by the stepnc subcommands: diagnostic output set-up, exit
// codes, and reading input files.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>
#include <string>
#include <string_view>

namespace CLI {
class App;
}

namespace stepnc::tool {

/// Process exit codes, the same for every subcommand.
enum ExitCode : int {
  kExitOk = 0,          ///< success; warnings allowed
  kExitDiagnostics = 1, ///< the input has errors
  kExitUsage = 2,       ///< bad command line, or a file could not be read or written
};

/// Options every subcommand that reads input shares.
struct DiagnosticOptions {
  std::string format = "text";  ///< "text" or "json"
  unsigned maxErrors = 50;
  bool warningsAsErrors = false;
};

void addDiagnosticOptions(CLI::App &cmd, DiagnosticOptions &opts);

/// Owns the consumer and engine configured from DiagnosticOptions.
class DiagnosticSession {
public:
  explicit DiagnosticSession(const DiagnosticOptions &opts);
  ~DiagnosticSession();
  DiagnosticEngine &engine() { return *engine_; }

private:
  std::unique_ptr<DiagnosticConsumer> consumer_;
  std::unique_ptr<DiagnosticEngine> engine_;
};

/// True if an output path asks for Part 28 XML: it ends in .stpx or .xml
/// (any case).
bool isPart28Path(std::string_view path);

/// Opens an input file; on failure prints "stepnc: error: ..." and returns null.
std::unique_ptr<SourceFile> openInput(const std::string &path);

/// Writes `text` to `path` ('-': standard output) atomically; on failure
/// prints "stepnc: error: ..." and returns kExitUsage, else kExitOk.
int writeText(const std::string &path, const std::string &text);

/// Prints "stepnc: error: message" to stderr.
void printToolError(const std::string &message);


} // namespace stepnc::tool
