// Runs a pipeline of passes over a module: verifies after each pass when
// asked (naming the pass that broke the IR), prints the IR after chosen
// passes, and collects each pass's counters.
#pragma once

#include "passes/PassRegistry.h"

#include <functional>
#include <set>

namespace stepnc::passes {

struct PassManagerOptions {
  /// Verify after every pass; also on when the environment sets
  /// STEPNC_VERIFY_EACH=1 (the test suite does), so tests catch a pass that
  /// breaks the IR even when they do not ask.
  bool verifyEach = false;
  bool printAfterAll = false;
  std::set<std::string, std::less<>> printAfter;
  /// Receives the IR text printed after a pass (with a `; *** IR after <pass> ***` line).
  std::function<void(std::string_view)> print;
};

class PassManager {
public:
  explicit PassManager(PassManagerOptions options) : options_(std::move(options)) {}
  /// Builds the passes of `pipeline` (already parsed and checked).
  void add(const std::vector<PipelineEntry> &pipeline);
  /// Appends one pass (tests run passes of their own this way).
  void add(std::unique_ptr<Pass> pass);
  /// Runs every pass in order; stops at the first failing pass. True on success.
  bool run(ir::Module &module, DiagnosticEngine &diags);
  /// Counters per pass, in pipeline order.
  const std::vector<std::pair<std::string, PassStats>> &stats() const { return stats_; }
  /// Report lines per pass that gave any, in pipeline order.
  const std::vector<std::pair<std::string, std::vector<std::string>>> &reports() const { return reports_; }

private:
  PassManagerOptions options_;
  std::vector<std::unique_ptr<Pass>> passes_;
  std::vector<std::pair<std::string, PassStats>> stats_;
  std::vector<std::pair<std::string, std::vector<std::string>>> reports_;
};

} // namespace stepnc::passes
