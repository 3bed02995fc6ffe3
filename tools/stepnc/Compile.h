// What `compile`, `opt` and `sim` share: reading an input into the IR and
// running a pass pipeline over it.
#pragma once

#include "frontend/part21/Part21File.h"
#include "ir/Node.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"
#include "tools/stepnc/SchemaSelection.h"

#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace stepnc::tool {

/// What shapes the toolpath pipeline: the machine (for adapt-feed's bounds
/// and cycle times; may be empty) and the feed-adaptation choices.
struct ToolpathPipelineOptions {
  std::string machine;
  bool adaptFeed = true;
  bool compensateDeflection = true;
  std::string cuttingData;  ///< a user cutting-data file, or empty
  bool allowFeedIncrease = false;
};

/// What `compile --emit=toolpath-ir` runs: resolve-feeds, expand-strategies,
/// adapt-feed and compensate-deflection (unless turned off), verify-toolpaths.
std::string toolpathPipeline(const ToolpathPipelineOptions &options);

/// The plan-motion pass for a machine (file or shipped name) and tolerance.
std::string planMotionPipeline(const std::string &machine, std::optional<double> tolerance);

/// Reads `source` as IR text (a file that starts with the IR's comment line
/// or `project`) or as STEP-NC, which is checked and lowered. Returns null
/// after reporting errors; `usage` is set when the command line is at fault.
/// `file`, when given, receives the Part 21 file read (null for IR text).
std::unique_ptr<ir::Module> loadModule(const SourceFile &source, const SchemaSelection &schemas,
                                       DiagnosticEngine &diags, bool &usage,
                                       std::unique_ptr<p21::Part21File> *file = nullptr);

struct PipelineRun {
  bool verifyEach = false;
  bool printAfterAll = false;
  std::vector<std::string> printAfter;
  bool stats = false;  ///< print each pass's counters to stderr
  /// When given, receives each pass's report lines as "pass: line".
  std::vector<std::string> *reports = nullptr;
};

/// Runs the pipeline `text` over `module`. Returns the exit code: kExitOk,
/// kExitUsage for a bad pipeline, kExitDiagnostics when a pass fails.
int runPipeline(ir::Module &module, const std::string &text, const PipelineRun &run, DiagnosticEngine &diags);

} // namespace stepnc::tool
