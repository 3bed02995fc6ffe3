// `stepnc opt IN --passes=PIPELINE`: reads IR text (or a STEP-NC file,
// lowered first), verifies it, runs a pass pipeline over it and writes the
// IR; the steps are compile's (Compile.cpp). `--list-passes` and the help
// list the passes with their options as the registry declares them
// (passes/Passes.def).
#include "passes/PassRegistry.h"
#include "tools/stepnc/Commands.h"
#include "tools/stepnc/Compile.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace stepnc::tool {

namespace {

int listPasses() {
  for (const passes::PassInfo &p : passes::registeredPasses())
    std::cout << passes::describePass(p);
  std::cout << passes::describeOptionTypes();
  std::cout.flush();
  return kExitOk;
}

/// The passes by name, for the end of `opt --help`.
std::string passNames() {
  std::string names;
  for (const passes::PassInfo &p : passes::registeredPasses())
    names += (names.empty() ? "" : ", ") + std::string(p.name);
  return "Passes: " + names + " (--list-passes: what each does, its options and their defaults).";
}

} // namespace

void registerOpt(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<CompileOptions>();
  opts->command = "opt";
  CLI::App *cmd = app.add_subcommand(
      "opt", "Read process IR text (or a STEP-NC file, lowered first), verify it, run a pass\n"
             "pipeline over it (--passes) and print it.");
  cmd->add_option("input", opts->input, "IR text or STEP-NC file");
  cmd->add_option("--passes", opts->passes,
                  "Pass pipeline to run, e.g. 'resolve-feeds' or 'a,b<key=value>' (-passes= works too)");
  cmd->add_option("--print-after", opts->printAfter, "Print the IR to stderr after this pass (repeatable)");
  cmd->add_flag("--print-after-all", opts->printAfterAll, "Print the IR to stderr after every pass");
  cmd->add_flag("--verify-each", opts->verifyEach, "Verify the IR after every pass, naming a pass that breaks it");
  cmd->add_flag("--list-passes", opts->listPasses, "List the passes stepnc knows, with their options, and exit");
  addCommonOptions(*cmd, *opts);
  cmd->footer(passNames());
  // --list-passes needs no input; everything else does.
  cmd->callback([opts, setResult] {
    if (opts->listPasses)
      return setResult(listPasses());
    if (opts->input.empty()) {
      printToolError("opt: an input file is required");
      return setResult(kExitUsage);
    }
    setResult(runCompile(*opts));
  });
}

} // namespace stepnc::tool
