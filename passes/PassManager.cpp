#include "passes/PassManager.h"

#include "ir/Printer.h"
#include "ir/Verifier.h"

#include <cstdlib>
#include <optional>

namespace stepnc::passes {

void PassManager::add(std::unique_ptr<Pass> pass) { passes_.push_back(std::move(pass)); }

void PassManager::add(const std::vector<PipelineEntry> &pipeline) {
  for (const PipelineEntry &entry : pipeline)
    if (auto pass = createPass(entry))
      passes_.push_back(std::move(pass));
}

bool PassManager::run(ir::Module &module, DiagnosticEngine &diags) {
  const char *env = std::getenv("STEPNC_VERIFY_EACH");
  const bool verifyEach = options_.verifyEach || (env && std::string_view(env) == "1");
  for (const auto &pass : passes_) {
    PassStats stats;
    const unsigned errorsBefore = diags.errorCount();
    // When verifying, the IR before the pass is kept to show what it broke.
    std::optional<ir::Module> before;
    if (verifyEach)
      before = module;
    const PassResult result = pass->run(module, diags, stats);
    stats_.emplace_back(std::string(pass->name()), std::move(stats));
    if (std::vector<std::string> lines = pass->report(); !lines.empty())
      reports_.emplace_back(std::string(pass->name()), std::move(lines));
    if (!result.ok || diags.errorCount() > errorsBefore)
      return false;
    if (verifyEach && !ir::verifyModule(module, diags)) {
      const std::string name(pass->name());
      InFlightDiagnostic d = diags.error({}, "pass '" + name + "' broke verification");
      if (options_.print) {
        d.note("the IR before it follows on standard error; --print-after=" + name + " shows the IR it produced");
        options_.print("; *** IR before " + name + ", which broke verification ***\n" + ir::printModule(*before));
        if (options_.printAfterAll || options_.printAfter.count(name))
          options_.print("; *** IR after " + name + " (does not verify) ***\n" + ir::printModule(module));
      }
      return false;
    }
    if (options_.print && (options_.printAfterAll || options_.printAfter.count(pass->name()))) {
      std::string text = "; *** IR after " + std::string(pass->name()) + (result.changed ? "" : " (unchanged)") +
                         " ***\n";
      text += ir::printModule(module);
      options_.print(text);
    }
  }
  // Without --verify-each the result is still verified once: what the
  // backends write from is IR that holds its invariants (a cycle's bottom
  // below its clearance, positive feeds), whatever a pass got wrong.
  if (!verifyEach && !passes_.empty() && !ir::verifyModule(module, diags)) {
    diags.error({}, "the IR the pass pipeline produced does not verify (a bug in stepnc); `stepnc opt "
                    "--verify-each` on the lowered IR names the pass that broke it");
    return false;
  }
  return true;
}

} // namespace stepnc::passes
