// `stepnc compile IN --emit=feature-ir`: reads a STEP-NC file, checks it
// against its schema, lowers it to the feature IR, verifies the IR and prints
// it. `stepnc opt IN` does the same from IR text too. Later stages (strategy
// expansion, passes, targets) extend these commands. Nothing is written when
// there are errors; files are written atomically.
#include "frontend/binding/Binder.h"
#include "frontend/lowering/Lowering.h"
#include "frontend/part21/Part21File.h"
#include "ir/Parser.h"
#include "ir/Printer.h"
#include "ir/Verifier.h"
#include "passes/PassManager.h"
#include "support/OutputFile.h"
#include "tools/stepnc/Driver.h"
#include "tools/stepnc/SchemaSelection.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace stepnc::tool {

namespace {

/// What `compile --emit=toolpath-ir` runs.
constexpr std::string_view kToolpathPipeline = "resolve-feeds,expand-strategies,verify-toolpaths";

struct CompileOptions {
  std::string input;
  std::string output = "-";
  std::string emit = "feature-ir";
  bool printLocations = false;
  // opt only
  std::string passes;
  std::vector<std::string> printAfter;
  bool printAfterAll = false;
  bool verifyEach = false;
  bool listPasses = false;
  bool stats = false;
  SchemaOptions schema;
  DiagnosticOptions diag;
};

// Reads `path` as IR text (a file that starts with the IR's comment line or
// `project`) or as STEP-NC, which is checked and lowered. Returns null after
// reporting errors.
std::unique_ptr<ir::Module> loadModule(const SourceFile &source, const SchemaSelection &schemas,
                                       DiagnosticEngine &diags, bool &usage) {
  std::string_view text = source.text();
  while (!text.empty() && (text[0] == ' ' || text[0] == '\n' || text[0] == '\r' || text[0] == '\t'))
    text.remove_prefix(1);
  if (text.starts_with(";") || text.starts_with("project")) {
    auto module = ir::parseModule(source, diags);
    if (!module || diags.hasErrors())
      return nullptr;
    return module;
  }
  auto file = p21::readPart21(source, diags);
  if (diags.hasErrors())
    return nullptr;
  const express::Model *model = nullptr;
  const express::Schema *schema = schemas.select(*file, diags, model);
  if (!schema) {
    printToolError("cannot compile " + std::string(source.name()) +
                   " without a schema: give its EXPRESS file with --schema FILE.exp");
    usage = true;
    return nullptr;
  }
  binding::BindOptions bindOptions;
  bindOptions.lenient = true;
  auto bound = binding::bind(*file, *model, *schema, diags, bindOptions);
  if (diags.hasErrors())
    return nullptr;
  auto module = lowering::lowerToFeatureIR(*bound, diags);
  if (!module || diags.hasErrors())
    return nullptr;
  return module;
}

int writeText(const std::string &path, const std::string &text) {
  OutputFile out;
  std::string error;
  if (!out.open(path, error)) {
    printToolError(error);
    return kExitUsage;
  }
  out.write(text);
  if (!out.commit(error)) {
    printToolError(error);
    return kExitUsage;
  }
  return kExitOk;
}

int runCompile(const CompileOptions &opts) {
  auto source = openInput(opts.input);
  if (!source)
    return kExitUsage;
  DiagnosticSession session(opts.diag);
  DiagnosticEngine &diags = session.engine();
  SchemaSelection schemas(opts.schema);
  bool usage = false;
  if (!schemas.load(diags, usage))
    return usage ? kExitUsage : kExitDiagnostics;
  auto module = loadModule(*source, schemas, diags, usage);
  if (module && !ir::verifyModule(*module, diags))
    module.reset();
  if (!module) {
    if (usage)
      return kExitUsage;
    std::cerr << "stepnc: " << opts.input << " has errors; nothing written\n";
    return kExitDiagnostics;
  }
  // The toolpath IR is the feature IR after the passes that make and check moves.
  const std::string pipelineText =
      opts.emit == "toolpath-ir" && opts.passes.empty() ? std::string(kToolpathPipeline) : opts.passes;
  if (!pipelineText.empty() || opts.listPasses) {
    std::string error;
    auto pipeline = passes::parsePipeline(pipelineText, error);
    if (!pipeline) {
      printToolError(error);
      return kExitUsage;
    }
    passes::PassManagerOptions pmOptions;
    pmOptions.verifyEach = opts.verifyEach;
    pmOptions.printAfterAll = opts.printAfterAll;
    pmOptions.printAfter.insert(opts.printAfter.begin(), opts.printAfter.end());
    pmOptions.print = [](std::string_view text) { std::cerr << text; };
    passes::PassManager manager(std::move(pmOptions));
    manager.add(*pipeline);
    const bool ok = manager.run(*module, diags);
    if (opts.stats)
      for (const auto &[pass, counters] : manager.stats())
        for (const auto &[what, n] : counters)
          std::cerr << "stats: " << pass << ": " << n << ' ' << what << '\n';
    if (!ok) {
      std::cerr << "stepnc: the pass pipeline failed on " << opts.input << "; nothing written\n";
      return kExitDiagnostics;
    }
  }
  ir::PrintOptions printOptions;
  printOptions.locations = opts.printLocations;
  return writeText(opts.output, ir::printModule(*module, printOptions));
}

int listPasses() {
  for (const passes::PassInfo &p : passes::registeredPasses()) {
    std::cout << p.name << "\n    " << p.description << '\n';
    if (!p.options.empty())
      std::cout << "    options: " << p.options << '\n';
  }
  std::cout.flush();
  return kExitOk;
}

// Options compile and opt share: output, locations, schema, diagnostics.
void addCommonOptions(CLI::App &cmd, const std::shared_ptr<CompileOptions> &opts,
                      const std::function<void(int)> &setResult) {
  cmd.add_option("-o,--output", opts->output, "Output file ('-', the default, for standard output)");
  cmd.add_flag("--print-locs", opts->printLocations, "Print each IR node's source location (file:line:col #id)");
  cmd.add_flag("--stats", opts->stats, "Print each pass's counters to stderr");
  addSchemaOptions(cmd, opts->schema);
  addDiagnosticOptions(cmd, opts->diag);
  cmd.callback([opts, setResult] { setResult(runCompile(*opts)); });
}

} // namespace

void registerOpt(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<CompileOptions>();
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
  addCommonOptions(*cmd, opts, setResult);
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

void registerCompile(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<CompileOptions>();
  CLI::App *cmd = app.add_subcommand(
      "compile", "Compile a STEP-NC file: read it, check it against its schema, lower it to the\n"
                 "process IR and write the result: the feature IR (--emit=feature-ir, the default)\n"
                 "or the toolpath IR (--emit=toolpath-ir: resolve-feeds, expand-strategies and\n"
                 "verify-toolpaths run over it); controller programs come next.\n"
                 "Nothing is written when the input has errors.");
  cmd->add_option("input", opts->input, "STEP-NC file (Part 21)")->required();
  cmd->add_option("--emit", opts->emit,
                  "What to write: feature-ir (the lowered process IR) or toolpath-ir (with moves, verified)")
      ->check(CLI::IsMember({"feature-ir", "toolpath-ir"}))
      ->default_str("feature-ir");
  addCommonOptions(*cmd, opts, setResult);
}

} // namespace stepnc::tool
