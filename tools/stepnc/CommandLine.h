// Pieces the stepnc commands share on the command line: exit codes,
// diagnostic and schema options, the diagnostic output, reading input files
// and writing output files.
#pragma once

#include "driver/ExitCode.h"
#include "driver/SchemaSelection.h"
#include "frontend/lowering/Lowering.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace CLI {
class App;
}

namespace stepnc::tool {

using driver::kExitDiagnostics;
using driver::kExitInternal;
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

/// How the speeds and angles of a STEP-NC file are read: "auto" (chosen per
/// file by plausibility, docs/ir.md) or a unit.
struct UnitOptions {
  std::string feed = "auto", cuttingSpeed = "auto", spindle = "auto", angle = "auto";
  lowering::UnitConventions conventions() const;
};

/// --feed-unit, --cutting-speed-unit, --spindle-unit, --angle-unit, for the
/// commands that lower STEP-NC (compile, opt, sim).
void addUnitOptions(CLI::App &cmd, UnitOptions &opts);

/// --schema FILE.exp (repeatable) and --no-schema.
void addSchemaOptions(CLI::App &cmd, driver::SchemaOptions &opts);

/// "X,Y,Z" as three finite numbers (--work-offset of sim and compile).
std::optional<Eigen::Vector3d> parseWorkOffset(const std::string &text);

/// Owns the consumer and engine configured from DiagnosticOptions. With
/// --diagnostics=json, standard error is one JSON array for as long as the
/// session lives: printToolError adds its message to it (an entry without a
/// file) and printStatus prints nothing.
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

/// Refuses, before any work, an output that would replace what `command`
/// reads or what the user may not write: -o naming the input file (the same
/// file by any path), an existing read-only file, a folder that does not
/// exist (OutputFile::writable). Prints "stepnc: error: ..." and returns
/// kExitUsage; kExitOk otherwise.
int checkOutput(std::string_view command, const std::string &input, const std::string &output);

/// Prints "stepnc: error: message" to stderr; while a JSON diagnostic
/// session is open, an error entry without a file in its array instead.
void printToolError(const std::string &message);

/// Prints "stepnc: line" to stderr: what a command wrote, or why it wrote
/// nothing. Nothing while a JSON diagnostic session is open: the array is
/// all standard error holds, and the exit status says the same.
void printStatus(const std::string &line);

} // namespace stepnc::tool
