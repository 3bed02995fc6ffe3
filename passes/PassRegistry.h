// Building passes by name and parsing pipelines such as
// `resolve-feeds,other-pass<key=value>`.
#pragma once

#include "passes/Pass.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::passes {

struct PassInfo {
  std::string_view name;
  std::string_view description;
  std::string_view options;  ///< "key=meaning; ..." or empty
};

/// Every registered pass, in Passes.def order.
const std::vector<PassInfo> &registeredPasses();

/// One element of a parsed pipeline.
struct PipelineEntry {
  std::string name;
  PassOptions options;
};

/// Parses `a,b<k=v,k2=v2>,c`. On a syntax error, an unknown pass or an
/// option the pass does not take, returns nullopt and sets `error`.
std::optional<std::vector<PipelineEntry>> parsePipeline(std::string_view text, std::string &error);

/// Builds a registered pass with its options; null for an unknown name.
std::unique_ptr<Pass> createPass(const PipelineEntry &entry);

} // namespace stepnc::passes
