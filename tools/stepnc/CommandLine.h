// Pieces the stepnc commands share on the command line: exit codes,
// diagnostic and schema options, the diagnostic output, reading input files
// and writing output files.
#pragma once

#include "driver/ExitCode.h"
#include "driver/SchemaSelection.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>
#include <string>
#include <string_view>

namespace CLI {
class App;
}

namespace stepnc::tool {

using driver::kExitDiagnostics;
using driver::kExitOk;
using driver::kExitUsage;

/// Options every subcommand that reads input shares.
struct DiagnosticOptions {
  std::string format = "text";  ///< "text" or "json"
  unsigned maxErrors = 50;
  bool warningsAsErrors = false;
  /// --strict: what stepnc assumes to read an imperfect STEP-NC file is an
  /// error, not a warning.
  bool strict = false;
};

void addDiagnosticOptions(CLI::App &cmd, DiagnosticOptions &opts);

/// --strict, for the commands that read STEP-NC (compile, check, convert,
/// opt, sim).
void addStrictOption(CLI::App &cmd, DiagnosticOptions &opts);

/// --schema FILE.exp (repeatable) and --no-schema.
void addSchemaOptions(CLI::App &cmd, driver::SchemaOptions &opts);

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

/// Loads the --schema files: kExitOk, kExitDiagnostics when they have
/// errors, kExitUsage (printed) when one cannot be read.
int loadSchemas(driver::SchemaSelection &schemas, DiagnosticEngine &diags);

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
