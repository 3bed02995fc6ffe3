// `stepnc convert IN -o OUT`: re-writes a STEP file in stepnc's canonical Part 21
// form, or as Part 28 XML when OUT ends in .stpx or .xml; the input may be
// either. Nothing is written when the input has errors; the output appears
// atomically (temporary file + rename), and one that is the input or
// read-only is refused before reading (checkOutput).
#include "frontend/part21/Part21File.h"
#include "frontend/part21/Writer.h"
#include "support/OutputFile.h"
#include "tools/stepnc/CommandLine.h"
#include "tools/stepnc/Commands.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace stepnc::tool {

namespace {

struct ConvertOptions {
  std::string input;
  std::string output;
  driver::SchemaOptions schema;
  DiagnosticOptions diag;
};

int runConvert(const ConvertOptions &opts) {
  const bool toXml = isPart28Path(opts.output);
  // First, so that with --diagnostics=json every message of the command is
  // in the one array on stderr.
  DiagnosticSession session(opts.diag);
  DiagnosticEngine &diags = session.engine();
  // Refused before reading: an output that is the input, or one the user
  // may not write.
  if (const int rc = checkOutput("convert", opts.input, opts.output); rc != kExitOk)
    return rc;
  auto source = openInput(opts.input);
  if (!source)
    return kExitUsage;
  driver::SchemaSelection schemas(opts.schema);
  if (const int rc = loadSchemas(schemas, diags); rc != kExitOk)
    return rc;
  auto nothingWritten = [&] {
    printStatus(opts.input + " has errors; nothing written");
    return kExitDiagnostics;
  };
  if (!schemas.readAsPart21(source, diags))
    return nothingWritten();
  auto file = p21::readPart21(*source, diags);
  if (diags.hasErrors())
    return nothingWritten();
  OutputFile out;
  std::string error;
  if (!out.open(opts.output, error)) {
    printToolError(error);
    return kExitUsage;
  }
  if (toXml) {
    p21::checkInstances(*file, diags);  // syntax and references, as the Part 21 writer checks them
    if (diags.hasErrors())
      return nothingWritten();
    if (std::string usageError; !schemas.writeAsPart28(*file, out, diags, usageError)) {
      if (!usageError.empty())
        printToolError(usageError);
      return diags.hasErrors() ? nothingWritten() : kExitUsage;
    }
  } else if (!p21::writePart21(*file, out, diags, {.checkReferences = true})) {
    // One pass: decode, check references and write; on any error `out`
    // discards the temporary file.
    return nothingWritten();
  }
  if (!out.commit(error)) {
    printToolError(error);
    return kExitUsage;
  }
  return kExitOk;
}

} // namespace

void registerConvert(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<ConvertOptions>();
  CLI::App *cmd = app.add_subcommand(
      "convert", "Re-write a STEP file in stepnc's canonical Part 21 form (sorted ids, one\n"
                 "instance per line, shortest exact reals), or as Part 28 XML when the output ends\n"
                 "in .stpx or .xml. The input may be Part 21 or Part 28. The output is written\n"
                 "atomically and not at all when the input has errors.");
  cmd->add_option("input", opts->input, "Input Part 21 or Part 28 file")->required();
  cmd->add_option("-o,--output", opts->output, "Output file ('-' for standard output)")->required();
  addSchemaOptions(*cmd, opts->schema);
  addDiagnosticOptions(*cmd, opts->diag);
  addStrictOption(*cmd, opts->diag);
  cmd->callback([opts, setResult] { setResult(runConvert(*opts)); });
}

} // namespace stepnc::tool
