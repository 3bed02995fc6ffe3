// The pass interface. A pass transforms (or analyses) a module, reports
// through the diagnostics engine, and says whether it succeeded and whether
// it changed anything. Passes are listed in Passes.def and built by name.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::passes {

/// Options given to a pass in a pipeline: `name<key=value,key=value>`.
using PassOptions = std::map<std::string, std::string, std::less<>>;

/// A pass option holding a positive length: "0.02" or "0.02mm"; nullopt otherwise.
std::optional<double> parseLengthOption(std::string_view text);

struct PassResult {
  bool ok = true;
  bool changed = false;
};

/// Per-pass counters, printed by `--stats` (LLVM's STATISTIC).
using PassStats = std::map<std::string, long long, std::less<>>;

class Pass {
public:
  virtual ~Pass() = default;
  virtual std::string_view name() const = 0;
  virtual PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) = 0;
  /// Figures of the last run that counters cannot hold (a table per
  /// workingstep, say), printed by `--stats` after the counters; one
  /// line per entry.
  virtual std::vector<std::string> report() const { return {}; }
};

} // namespace stepnc::passes
