// What the passes that work on the cutting model (adapt-feed,
// compensate-deflection) share: the cutting data they load (shipped, with a
// user file on top) and the report lines `--stats` prints.
#pragma once

#include "cutting/CuttingData.h"
#include "ir/Program.h"
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

  /// Whether the module is one the cutting model takes (3-axis milling;
  /// turning and deposition steps are passed over); steps that tilt the
  /// tool are passed over too, each with a warning saying what of it stays
  /// as programmed (`what`: "its feeds").
  bool takes(const ir::Module &module, DiagnosticEngine &diags, std::string_view what) const {
    if (!ir::requireThreeAxisMilling(module, name(), diags, ir::ArcPlanes::Principal, ir::OtherProcesses::Skip,
                                     ir::Deposition::Refuse, ir::ToolAxes::Skip))
      return false;
    for (const ir::Node *e : ir::programOrder(module))
      if (ir::tiltsTool(*e))
        diags.warning(e->origin.loc, std::string(name()) + ": workingstep " + e->symbol +
                                         " tilts the tool, which the cutting model does not (it cuts with the "
                                         "tool along z): " + std::string(what) + " stay as programmed")
            .entity(e->origin.entityId);
    return true;
  }

  std::vector<std::string> report_;

private:
  std::string dataPath_;
  std::unique_ptr<SourceFile> dataFile_; ///< the user file diagnostics point into
};

} // namespace stepnc::passes
