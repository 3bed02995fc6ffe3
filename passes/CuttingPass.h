// What the passes that work on the cutting model (adapt-feed,
// compensate-deflection) share: the cutting data they load (shipped, with a
// user file on top), an option error to report when run, and the report
// lines `--stats` prints.
#pragma once

#include "cutting/CuttingData.h"
#include "passes/Pass.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::passes {

class CuttingPass : public Pass {
public:
  CuttingPass(std::string dataPath, std::string optionError)
      : dataPath_(std::move(dataPath)), optionError_(std::move(optionError)) {}

  std::vector<std::string> report() const override { return report_; }

protected:
  /// Clears the last report, reports an option error, and loads the cutting
  /// data; nullopt (errors reported) when the pass cannot run.
  std::optional<cutting::CuttingData> start(DiagnosticEngine &diags) {
    report_.clear();
    if (!optionError_.empty()) {
      diags.error({}, optionError_);
      return std::nullopt;
    }
    return cutting::loadCuttingData(dataPath_, dataFile_, diags);
  }

  std::vector<std::string> report_;

private:
  std::string dataPath_, optionError_;
  std::unique_ptr<SourceFile> dataFile_; ///< the user file diagnostics point into
};

} // namespace stepnc::passes
