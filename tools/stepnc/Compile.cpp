// `stepnc compile IN --emit=feature-ir`: reads a STEP-NC file, checks it
// against its schema, lowers it to the feature IR, verifies the IR and prints
// it. Later stages (strategy expansion, targets) extend this command. Nothing
// is written when there are errors; files are written atomically.
#include "frontend/binding/Binder.h"
#include "frontend/lowering/Lowering.h"
#include "frontend/part21/Part21File.h"
#include "ir/Printer.h"
#include "ir/Verifier.h"
#include "support/OutputFile.h"
#include "tools/stepnc/Driver.h"
#include "tools/stepnc/SchemaSelection.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace stepnc::tool {

namespace {

struct CompileOptions {
  std::string input;
  std::string output = "-";
  std::string emit = "feature-ir";
  bool printLocations = false;
  SchemaOptions schema;
  DiagnosticOptions diag;
};

int runCompile(const CompileOptions &opts) {
  auto source = openInput(opts.input);
  if (!source)
    return kExitUsage;
  DiagnosticSession session(opts.diag);
  DiagnosticEngine &diags = session.engine();
  SchemaSelection schemas(opts.schema);
  bool io = false;
  if (!schemas.load(diags, io))
    return io ? kExitUsage : kExitDiagnostics;
  auto failed = [&] {
    std::cerr << "stepnc: " << opts.input << " has errors; nothing written\n";
    return kExitDiagnostics;
  };
  auto file = p21::readPart21(*source, diags);
  if (diags.hasErrors())
    return failed();
  const express::Model *model = nullptr;
  const express::Schema *schema = schemas.select(*file, diags, model);
  if (!schema) {
    printToolError("cannot compile " + opts.input +
                   " without a schema: give its EXPRESS file with --schema FILE.exp");
    return kExitUsage;
  }
  binding::BindOptions bindOptions;
  bindOptions.lenient = true;
  auto bound = binding::bind(*file, *model, *schema, diags, bindOptions);
  if (diags.hasErrors())
    return failed();
  auto module = lowering::lowerToFeatureIR(*bound, diags);
  if (!module || diags.hasErrors())
    return failed();
  if (!ir::verifyModule(*module, diags))
    return failed();

  ir::PrintOptions printOptions;
  printOptions.locations = opts.printLocations;
  const std::string text = ir::printModule(*module, printOptions);
  OutputFile out;
  std::string error;
  if (!out.open(opts.output, error)) {
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

} // namespace

void registerCompile(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<CompileOptions>();
  CLI::App *cmd = app.add_subcommand(
      "compile", "Compile a STEP-NC file: read it, check it against its schema, lower it to the\n"
                 "process IR and write the result. Today the output is the feature IR\n"
                 "(--emit=feature-ir, the default); toolpaths and controller programs come next.\n"
                 "Nothing is written when the input has errors.");
  cmd->add_option("input", opts->input, "STEP-NC file (Part 21)")->required();
  cmd->add_option("-o,--output", opts->output, "Output file ('-', the default, for standard output)");
  cmd->add_option("--emit", opts->emit, "What to write: feature-ir (the lowered process IR)")
      ->check(CLI::IsMember({"feature-ir"}))
      ->default_str("feature-ir");
  cmd->add_flag("--print-locs", opts->printLocations,
                "Print each IR node's source location (file:line:col #id)");
  addSchemaOptions(*cmd, opts->schema);
  addDiagnosticOptions(*cmd, opts->diag);
  cmd->callback([opts, setResult] { setResult(runCompile(*opts)); });
}

} // namespace stepnc::tool
