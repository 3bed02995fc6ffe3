// `stepnc check FILE...`: reads each file, reports its diagnostics and prints a
// one-line summary per file (and an entity histogram with --stats). Files are
// read against their schema as compile reads them (driver::bindOptions):
// drift whose meaning is clear is a warning, an error with --strict. A
// STEP-NC file of a schema stepnc compiles is then lowered to the process IR
// as compile lowers it, so that the two report the same diagnostics of the
// file; compile goes on to the toolpaths, whose diagnostics are its own.
#include "driver/LoadModule.h"
#include "frontend/binding/Binder.h"
#include "frontend/express/Builtin.h"
#include "frontend/lowering/Lowering.h"
#include "frontend/part21/Part21File.h"
#include "support/VerifyDiagnostics.h"
#include "tools/stepnc/CommandLine.h"
#include "tools/stepnc/Commands.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <map>

namespace stepnc::tool {

namespace {

struct CheckOptions {
  std::vector<std::string> files;
  bool stats = false;
  bool verify = false;
  driver::SchemaOptions schema;
  DiagnosticOptions diag;
  UnitOptions units;
};

void printStats(const p21::Part21File &file) {
  std::map<std::string, size_t> counts;
  for (const p21::InstanceEntry &e : file.entries())
    ++counts[file.describe(e)];
  std::vector<std::pair<std::string, size_t>> rows(counts.begin(), counts.end());
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto &a, const auto &b) { return a.second > b.second; });
  size_t width = 1;
  for (const auto &r : rows)
    width = std::max(width, std::to_string(r.second).size());
  for (const auto &[name, n] : rows) {
    std::string count = std::to_string(n);
    std::cout << "  " << std::string(width - count.size(), ' ') << count << "  " << name << '\n';
  }
}

/// Reads and checks one file: Part 21 syntax and references, then the schema,
/// then (a STEP-NC file of a schema stepnc compiles, without errors so far)
/// its lowering. Returns the schema checked against (null if none).
const express::Schema *checkFile(const p21::Part21File &file, const driver::SchemaSelection &schemas,
                                 const CheckOptions &opts, DiagnosticEngine &diags) {
  if (diags.limitReached())
    return nullptr;
  const express::Model *model = nullptr;
  const express::Schema *schema = schemas.select(file, diags, model);
  if (!schema) {
    p21::checkInstances(file, diags);
    return schema;
  }
  // The bind includes the Part 21 reference check.
  auto bound = binding::bind(file, *model, *schema, diags, driver::bindOptions(diags));
  if (bound && !diags.hasErrors() && schema == express::findBuiltinSchema(file.schemaNames()).schema)
    lowering::lowerToFeatureIR(*bound, diags, lowering::LowerOptions{opts.units.conventions()});
  return schema;
}

} // namespace

// --verify-diagnostics: collect instead of printing, then match the
// expectations written in each file's comments.
int verifyFiles(const CheckOptions &opts) {
  int status = kExitOk;
  DiagnosticSession session(opts.diag);
  driver::SchemaSelection schemas(opts.schema);
  if (const int rc = loadSchemas(schemas, session.engine()); rc != kExitOk)
    return rc;
  for (const std::string &path : opts.files) {
    auto source = openInput(path);
    if (!source) {
      status = kExitUsage;
      continue;
    }
    DiagnosticCollector collector;
    DiagnosticEngine diags(collector);
    diags.setStrict(opts.diag.strict);
    auto file = p21::readPart21(*source, diags);
    checkFile(*file, schemas, opts, diags);
    if (!verifyDiagnostics(*source, collector.diags, std::cerr) && status == kExitOk)
      status = kExitDiagnostics;
  }
  return status;
}

int runCheckFiles(const CheckOptions &opts) {
  if (opts.verify)
    return verifyFiles(opts);
  DiagnosticSession session(opts.diag);
  DiagnosticEngine &diags = session.engine();
  driver::SchemaSelection schemas(opts.schema);
  if (const int rc = loadSchemas(schemas, diags); rc != kExitOk)
    return rc;
  int status = kExitOk;
  for (const std::string &path : opts.files) {
    auto source = openInput(path);
    if (!source) {
      status = kExitUsage;
      continue;
    }
    diags.resetCounts();
    if (!schemas.readAsPart21(source, diags)) {
      std::cout << path << ": not read; " << diags.errorCount() << (diags.errorCount() == 1 ? " error" : " errors")
                << '\n';
      status = kExitDiagnostics;
      continue;
    }
    auto file = p21::readPart21(*source, diags);
    const express::Schema *checked = checkFile(*file, schemas, opts, diags);
    std::string names;
    for (const std::string &s : file->schemaNames())
      names += (names.empty() ? "" : ", ") + s;
    std::cout << path << ": " << file->entries().size()
              << (file->entries().size() == 1 ? " instance, schema " : " instances, schema ")
              << (names.empty() ? "(none)" : names)
              << (checked ? " (checked against " + checked->name + ")" : std::string(" (syntax only)"))
              << "; " << diags.errorCount()
              << (diags.errorCount() == 1 ? " error, " : " errors, ") << diags.warningCount()
              << (diags.warningCount() == 1 ? " warning" : " warnings") << '\n';
    if (opts.stats)
      printStats(*file);
    if (diags.hasErrors() && status == kExitOk)
      status = kExitDiagnostics;
  }
  std::cout.flush();
  return status;
}

void registerCheck(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<CheckOptions>();
  CLI::App *cmd = app.add_subcommand(
      "check", "Read STEP-NC files, check them against their schema and lower them to the process IR as compile\n"
               "does (the same diagnostics of the file), report their diagnostics and print a summary of each.\n"
               "Exit status: 0 no errors (warnings allowed), 1 errors found, 2 usage or I/O error.");
  cmd->add_option("files", opts->files, "Part 21 files to check")->required();
  cmd->add_flag("--stats", opts->stats, "Also print a histogram of entity types");
  cmd->add_flag("--verify-diagnostics", opts->verify,
                "Check diagnostics against 'expected-error@+1 {{text}}' annotations in the "
                "files' comments instead of printing them (exit 0 when all match)");
  addSchemaOptions(*cmd, opts->schema);
  addUnitOptions(*cmd, opts->units);
  addDiagnosticOptions(*cmd, opts->diag);
  addStrictOption(*cmd, opts->diag);
  cmd->callback([opts, setResult] { setResult(runCheckFiles(*opts)); });
}

} // namespace stepnc::tool
