// What the passes that work on the cutting model (adapt-feed,
// compensate-deflection) share: the cutting data they load (shipped, with a
// user file on top) and the report lines `--stats` prints.
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
  explicit CuttingPass(std::string dataPath) : dataPath_(std::move(dataPath)) {}

  std::vector<std::string> report() const override { return report_; }

protected:
  /// Clears the last report and loads the cutting data; nullopt (errors
  /// reported) when it cannot be read.
  std::optional<cutting::CuttingData> start(DiagnosticEngine &diags) {
    report_.clear();
    return cutting::loadCuttingData(dataPath_, dataFile_, diags);
  }

  std::vector<std::string> report_;

private:
  std::string dataPath_;
  std::unique_ptr<SourceFile> dataFile_; ///< the user file diagnostics point into
};

} // namespace stepnc::passes
