// Pass pipelines as the commands run them: the pipelines `compile` builds
// from its options (the toolpath passes, plan-motion) and running a pipeline
// given as text over a module, with the pass manager's printing and counters.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::driver {

/// What shapes the toolpath pipeline: the machine (for adapt-feed's bounds
/// and cycle times; may be empty) and the feed-adaptation choices.
struct ToolpathPipelineOptions {
  std::string machine;
  bool adaptFeed = true;
  bool compensateDeflection = true;
  std::string cuttingData;  ///< a user cutting-data file, or empty
  bool allowFeedIncrease = false;
  bool allowOutOfRange = false;  ///< check-limits reports warnings, not errors
};

/// What `compile --emit=toolpath-ir` runs: resolve-feeds, expand-strategies,
/// check-limits, adapt-feed and compensate-deflection (unless turned off),
/// verify-toolpaths.
std::string toolpathPipeline(const ToolpathPipelineOptions &options);

/// The plan-motion pass for a machine (file or shipped name) and tolerance.
/// `workOffset`: "X,Y,Z" mm where the workpiece's origin is on a 5-axis
/// machine (steps that tilt the tool are planned on its joints); empty: none.
std::string planMotionPipeline(const std::string &machine, std::optional<double> tolerance,
                               const std::string &workOffset = "");

struct PipelineRun {
  bool verifyEach = false;
  bool printAfterAll = false;
  std::vector<std::string> printAfter;
  bool stats = false;  ///< print each pass's counters and reports to `log`
  /// Where the IR printed after passes (and before a pass that broke
  /// verification) and the counters go; null: nowhere.
  std::ostream *log = nullptr;
  /// When given, receives each pass's report lines as "pass: line".
  std::vector<std::string> *reports = nullptr;
};

/// Runs the pipeline `text` over `module`. Returns kExitOk; kExitUsage when
/// the pipeline does not parse, with `usageError` saying where and why; or
/// kExitDiagnostics when a pass fails (reported to `diags`).
int runPipeline(ir::Module &module, const std::string &text, const PipelineRun &run, DiagnosticEngine &diags,
                std::string &usageError);

} // namespace stepnc::driver
