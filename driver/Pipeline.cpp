#include "driver/Pipeline.h"

#include <algorithm>

#include "driver/ExitCode.h"
#include "passes/PassManager.h"
#include "support/Format.h"

#include <ostream>

namespace stepnc::driver {

std::string toolpathPipeline(const ToolpathPipelineOptions &options) {
  std::string text = "resolve-feeds,expand-strategies,";
  // The gate sees the cutting data as the file asks for it, before feed
  // adaptation lowers any feed.
  {
    std::string check;
    auto add = [&](const std::string &o) { check += (check.empty() ? "<" : ",") + o; };
    if (!options.machine.empty())
      add("machine=" + options.machine);
    if (options.allowOutOfRange)
      add("allow-out-of-range=true");
    text += "check-limits" + check + (check.empty() ? "" : ">") + ",";
  }
  if (options.adaptFeed) {
    std::string adapt;
    auto add = [&](const std::string &o) { adapt += (adapt.empty() ? "<" : ",") + o; };
    if (!options.machine.empty())
      add("machine=" + options.machine);
    if (!options.cuttingData.empty())
      add("data=" + options.cuttingData);
    if (options.allowFeedIncrease)
      add("allow-increase=true");
    text += "adapt-feed" + adapt + (adapt.empty() ? "" : ">") + ",";
  }
  if (options.compensateDeflection)
    text += options.cuttingData.empty() ? "compensate-deflection,"
                                        : "compensate-deflection<data=" + options.cuttingData + ">,";
  return text + "verify-toolpaths";
}

std::string planMotionPipeline(const std::string &machine, std::optional<double> tolerance,
                               const std::string &workOffset) {
  std::string text = "plan-motion<machine=" + machine;
  if (tolerance)
    text += ",tolerance=" + formatShortest(*tolerance);
  if (!workOffset.empty()) {
    // The pipeline separates options by commas: the point's by colons.
    std::string point = workOffset;
    std::replace(point.begin(), point.end(), ',', ':');
    text += ",work-offset=" + point;
  }
  return text + ">";
}

int runPipeline(ir::Module &module, const std::string &text, const PipelineRun &run, DiagnosticEngine &diags,
                std::string &usageError) {
  auto pipeline = passes::parsePipeline(text, usageError);
  if (!pipeline)
    return kExitUsage;
  passes::PassManagerOptions pmOptions;
  pmOptions.verifyEach = run.verifyEach;
  pmOptions.printAfterAll = run.printAfterAll;
  pmOptions.printAfter.insert(run.printAfter.begin(), run.printAfter.end());
  if (run.log)
    pmOptions.print = [log = run.log](std::string_view t) { *log << t; };
  passes::PassManager manager(std::move(pmOptions));
  manager.add(*pipeline);
  const bool ok = manager.run(module, diags);
  if (run.stats && run.log) {
    for (const auto &[pass, counters] : manager.stats())
      for (const auto &[what, n] : counters)
        *run.log << "stats: " << pass << ": " << n << ' ' << what << '\n';
    for (const auto &[pass, lines] : manager.reports())
      for (const std::string &line : lines)
        *run.log << "report: " << pass << ": " << line << '\n';
  }
  if (run.reports)
    for (const auto &[pass, lines] : manager.reports())
      for (const std::string &line : lines)
        run.reports->push_back(std::string(pass) + ": " + line);
  return ok ? kExitOk : kExitDiagnostics;
}

} // namespace stepnc::driver
