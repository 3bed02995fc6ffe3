// `stepnc compile IN`: reads a STEP-NC file, checks it against its schema,
// lowers it to the feature IR and verifies it; then, by --emit and --target,
// writes the feature IR, or runs the pass pipeline and writes the toolpath IR
// or a controller program. `stepnc opt` (Opt.cpp) runs the same steps with
// its own pipeline. Nothing is written when there are errors; files are
// written atomically, and an output that is the input or read-only is
// refused before reading (checkOutput).
#include "tools/stepnc/Compile.h"

#include "backends/Backend.h"
#include "backends/TargetFile.h"
#include "backends/common/ToolTable.h"
#include "backends/step-nc/OptimisedFile.h"
#include "driver/LoadModule.h"
#include "driver/Phases.h"
#include "driver/Pipeline.h"
#include "frontend/part21/Part21File.h"
#include "frontend/part21/Writer.h"
#include "ir/Printer.h"
#include "ir/Program.h"
#include "ir/Verifier.h"
#include "runtime/Machine.h"
#include "support/Format.h"
#include "support/OutputFile.h"
#include "support/VerifyDiagnostics.h"
#include "tools/stepnc/Commands.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>

namespace stepnc::tool {

namespace {

std::string targetList() {
  std::string names;
  for (const backends::TargetInfo &t : backends::registeredTargets())
    names += (names.empty() ? "" : ", ") + std::string(t.name);
  return "targets: " + names;
}

int listTargets() {
  for (const backends::TargetInfo &t : backends::registeredTargets())
    std::cout << t.name << "\n    " << t.description << '\n';
  std::cout.flush();
  return kExitOk;
}

/// The program name: the output file's stem, else the input's.
std::string programName(const CompileOptions &opts) {
  const std::string &from = opts.output != "-" ? opts.output : opts.input;
  return std::filesystem::path(from).stem().string();
}

/// The options that shaped a program, for its header.
std::string optionsText(const CompileOptions &opts) {
  std::string text;
  auto add = [&](const std::string &part) { text += (text.empty() ? "" : " ") + part; };
  if (!opts.passes.empty())
    add("--passes=" + opts.passes);
  if (!opts.toolTable.empty())
    add("--tool-table " + opts.toolTable);
  if (opts.noCycles)
    add("--no-cycles");
  if (opts.allowOutOfRange)
    add("--allow-out-of-range");
  if (opts.tolerance)
    add("--tolerance " + formatShortest(*opts.tolerance));
  for (const std::string &o : opts.targetOptions)
    add("--target-opt " + o);
  if (!opts.workOffset.empty())
    add("--work-offset " + opts.workOffset);
  return text;
}

/// What FILE_DESCRIPTION says about how an optimised file was made.
std::vector<std::string> optimisedDescription(const CompileOptions &opts, const std::string &pipeline,
                                              const std::vector<std::string> &reports) {
  std::vector<std::string> lines = {
      "machine-optimised STEP-NC written by stepnc compile --emit=stepnc from " +
          std::filesystem::path(opts.input).filename().string(),
      "machine: " + (opts.machine.empty() ? std::string("none given") : opts.machine),
      "passes: " + pipeline,
      opts.noAdaptFeed ? std::string("feeds: as programmed (--no-adapt-feed)")
                       : "feeds: adapted by adapt-feed, per toolpath segment: each trajectory has a "
                         "MILLING_TECHNOLOGY with its feed" +
                             std::string(opts.allowFeedIncrease ? " (--allow-feed-increase)" : ""),
      opts.noCompensateDeflection ? std::string("finishing walls: nominal path (--no-compensate-deflection)")
                                  : std::string("finishing walls: compensated for tool deflection where "
                                                "compensate-deflection reports it"),
  };
  if (!opts.cuttingData.empty())
    lines.push_back("cutting data: " + opts.cuttingData + " on top of the shipped data");
  for (const std::string &r : reports)
    lines.push_back(r);
  return lines;
}

/// Writes the machine-optimised STEP-NC file atomically: canonical Part 21, or
/// Part 28 XML when the output ends in .stpx or .xml.
int writeOptimised(const CompileOptions &opts, const driver::SchemaSelection &schemas, const p21::Part21File &input,
                   const ir::Module &module, const std::string &pipeline, const std::vector<std::string> &reports,
                   DiagnosticEngine &diags) {
  backends::OptimisedFileOptions options;
  options.description = optimisedDescription(opts, pipeline, reports);
  std::unique_ptr<SourceFile> text;
  auto file = backends::buildOptimisedFile(input, module, options, text, diags);
  if (!file) {
    printStatus("cannot write optimised STEP-NC for " + opts.input + "; nothing written");
    return kExitDiagnostics;
  }
  OutputFile out;
  std::string error;
  if (!out.open(opts.output, error)) {
    printToolError(error);
    return kExitUsage;
  }
  std::string usageError;
  if (isPart28Path(opts.output) ? !schemas.writeAsPart28(*file, out, diags, usageError)
                                : !p21::writePart21(*file, out, diags)) {
    if (!usageError.empty())
      printToolError(usageError);
    printStatus("cannot write optimised STEP-NC for " + opts.input + "; nothing written");
    return diags.hasErrors() ? kExitDiagnostics : kExitUsage;
  }
  if (!out.commit(error)) {
    printToolError(error);
    return kExitUsage;
  }
  if (opts.output != "-")
    printStatus("wrote " + opts.output + " (machine-optimised STEP-NC, " + std::to_string(file->entries().size()) +
                " instances)");
  return kExitOk;
}

/// Where phase `index` (from 1) of a multi-machine program is written:
/// `die.ngc` -> `die-1-lathe-2axis.ngc` (the machine as named, a path's stem).
std::string phasePath(const std::string &output, size_t index, const std::string &machine) {
  const std::filesystem::path out(output), m(machine);
  const std::string name = out.stem().string() + "-" + std::to_string(index) + "-" + m.stem().string() +
                           out.extension().string();
  return (out.parent_path() / name).string();
}

/// A multi-process workplan on several machines (driver/Phases.h): a program
/// per phase, each for its machine (its deposition codes), or with no
/// backend the IR of each phase, all made before any is written, so that an
/// error leaves no file.
int writePhases(const CompileOptions &opts, const ir::Module &module, backends::Backend *backend,
                backends::EmitOptions emitOptions, DiagnosticEngine &diags) {
  if (opts.output == "-") {
    printToolError("compile: several --machine write a program per machine: give -o FILE (each is FILE's name "
                   "with the phase and the machine)");
    return kExitUsage;
  }
  std::vector<driver::NamedMachine> machines;
  std::vector<std::unique_ptr<SourceFile>> files;
  for (const std::string &name : opts.machines) {
    files.emplace_back();
    std::optional<runtime::Machine> m = runtime::loadMachine(name, files.back(), diags);
    if (!m) {
      printStatus("the machine " + name + " has errors; nothing written");
      return kExitDiagnostics;
    }
    machines.push_back({name, std::move(*m)});
  }
  std::optional<std::vector<driver::Phase>> phases = driver::splitIntoPhases(module, machines, diags);
  if (!phases) {
    printStatus("cannot assign " + opts.input + "'s workingsteps to the machines given; nothing written");
    return kExitDiagnostics;
  }
  std::vector<std::pair<std::string, std::string>> programs;  // path, text
  for (size_t i = 0; i < phases->size(); ++i) {
    const driver::Phase &phase = (*phases)[i];
    const driver::NamedMachine &m = machines[phase.machine];
    const std::string path = phasePath(opts.output, i + 1, m.name);
    backends::EmitOptions o = emitOptions;
    o.programName = std::filesystem::path(path).stem().string();
    o.optionsText = emitOptions.optionsText + (emitOptions.optionsText.empty() ? "" : " ") + "--machine " + m.name;
    o.deposition = m.machine.deposition ? &*m.machine.deposition : nullptr;
    const ir::Module part = driver::phaseModule(module, phase);
    if (!backend) {
      ir::PrintOptions printOptions;
      printOptions.locations = opts.printLocations;
      programs.emplace_back(path, ir::printModule(part, printOptions));
      continue;
    }
    std::optional<std::string> program = backend->emit(part, o, diags);
    if (!program || diags.hasErrors()) {
      printStatus("cannot write the " + opts.target + " program of phase " + std::to_string(i + 1) + " (" + m.name +
                  ") for " + opts.input + "; nothing written");
      return kExitDiagnostics;
    }
    programs.emplace_back(path, std::move(*program));
  }
  for (size_t i = 0; i < programs.size(); ++i) {
    const auto &[path, text] = programs[i];
    if (const int rc = writeText(path, text); rc != kExitOk)
      return rc;
    const driver::Phase &phase = (*phases)[i];
    printStatus("wrote " + path + " (" + (backend ? opts.target : std::string("process IR")) + ", " +
                std::to_string(std::count(text.begin(), text.end(), '\n')) + " lines: " +
                std::to_string(phase.executables.size()) + " executables on " + machines[phase.machine].name + ")");
  }
  return kExitOk;
}

/// Reads, lowers, runs the pipeline and writes what `emit` asks for, all
/// diagnostics going to `diags`.
int compileSource(const CompileOptions &opts, const std::string &emit, std::unique_ptr<SourceFile> &source,
                  backends::Backend *backend, DiagnosticEngine &diags) {
  const bool needsMotion = emit == "motion-ir" || opts.target == "native";
  driver::SchemaSelection schemas(opts.schema);
  if (const int rc = loadSchemas(schemas, diags); rc != kExitOk)
    return rc;
  std::unique_ptr<p21::Part21File> file;
  std::string usageError;
  std::unique_ptr<ir::Module> module =
      driver::loadModule(source, schemas, diags, usageError, emit == "stepnc" ? &file : nullptr,
                         lowering::LowerOptions{opts.units.conventions()});
  if (module && !ir::verifyModule(*module, diags))
    module.reset();
  if (!module) {
    if (!usageError.empty()) {
      printToolError(usageError);
      return kExitUsage;
    }
    printStatus(opts.input + " has errors; nothing written");
    return kExitDiagnostics;
  }
  if (emit == "stepnc" && !file) {
    printToolError("compile: --emit=stepnc writes a STEP-NC file back: give a STEP-NC input, not IR text");
    return kExitUsage;
  }
  // The tool table is read first: its holder geometry is checked with the
  // toolpaths (docs/tool-table.md).
  std::optional<backends::ToolTable> table;
  std::unique_ptr<SourceFile> tableFile;
  if (!opts.toolTable.empty()) {
    tableFile = openInput(opts.toolTable);
    if (!tableFile)
      return kExitUsage;
    table = backends::ToolTable::parse(*tableFile, diags);
    if (!table) {
      printStatus("the tool table " + opts.toolTable + " has errors; nothing written");
      return kExitDiagnostics;
    }
    table->applyGeometry(*module);
  }
  // The toolpath IR is the feature IR after the passes that make and check
  // moves; a program is written from the toolpath IR.
  // The motion IR and the native target add the motion planned on the machine.
  driver::ToolpathPipelineOptions toolpath;
  toolpath.machine = opts.machine;
  // Several machines: feeds are bounded by the first that mills.
  if (opts.machines.size() > 1)
    for (const std::string &name : opts.machines) {
      std::unique_ptr<SourceFile> machineFile;
      DiagnosticCollector quiet;
      DiagnosticEngine quietDiags(quiet);
      if (auto m = runtime::loadMachine(name, machineFile, quietDiags);
          m && std::find(m->processes.begin(), m->processes.end(), "milling") != m->processes.end()) {
        toolpath.machine = name;
        break;
      }
    }
  toolpath.adaptFeed = !opts.noAdaptFeed;
  toolpath.compensateDeflection = !opts.noCompensateDeflection;
  toolpath.cuttingData = opts.cuttingData;
  toolpath.allowFeedIncrease = opts.allowFeedIncrease;
  toolpath.allowOutOfRange = opts.allowOutOfRange;
  std::string pipelineText =
      emit != "feature-ir" && opts.passes.empty() ? driver::toolpathPipeline(toolpath) : opts.passes;
  if (opts.passes.empty() && needsMotion)
    pipelineText += "," + driver::planMotionPipeline(opts.machine, opts.tolerance, opts.workOffset);
  std::vector<std::string> reports;
  if (!pipelineText.empty()) {
    driver::PipelineRun run;
    run.reports = &reports;
    run.verifyEach = opts.verifyEach;
    run.printAfterAll = opts.printAfterAll;
    run.printAfter = opts.printAfter;
    run.stats = opts.stats;
    run.log = &std::cerr;
    if (const int rc = driver::runPipeline(*module, pipelineText, run, diags, usageError); rc != kExitOk) {
      if (rc == kExitUsage)
        printToolError(usageError);
      if (rc == kExitDiagnostics)
        printStatus("the pass pipeline failed on " + opts.input + "; nothing written");
      return rc;
    }
  }
  if (emit == "stepnc")
    return writeOptimised(opts, schemas, *file, *module, pipelineText, reports, diags);
  if (backend) {
    backends::EmitOptions emitOptions;
    emitOptions.source = std::filesystem::path(opts.input).filename().string();
    emitOptions.programName = programName(opts);
    emitOptions.optionsText = optionsText(opts);
    emitOptions.tolerance = opts.tolerance;
    emitOptions.toolTable = table ? &*table : nullptr;
    if (opts.machines.size() > 1)
      return writePhases(opts, *module, backend, emitOptions, diags);
    // One program is for one machine: a workplan of several processes
    // (turning, deposition, milling) needs a machine for each.
    {
      std::string first;
      for (const ir::Node *e : ir::programOrder(*module)) {
        const std::string process = driver::processOf(*e);
        if (process.empty() || process == first)
          continue;
        if (first.empty()) {
          first = process;
          continue;
        }
        diags.error(e->origin.loc, "workingstep " + e->symbol + " is " + process + ", after " + first +
                                       " steps: one program runs on one machine; give a --machine for each process "
                                       "(such as --machine lathe-2axis --machine hsc-3axis --machine ded-3axis) and "
                                       "a program is written for each (docs/additive.md)")
            .entity(e->origin.entityId);
        printStatus("cannot write a " + opts.target + " program for " + opts.input + "; nothing written");
        return kExitDiagnostics;
      }
    }
    // A deposition program writes the head's codes of --machine.
    std::optional<runtime::Machine> machine;
    std::unique_ptr<SourceFile> machineFile;
    if (!opts.machine.empty()) {
      machine = runtime::loadMachine(opts.machine, machineFile, diags);
      if (!machine) {
        printStatus("the machine " + opts.machine + " has errors; nothing written");
        return kExitDiagnostics;
      }
      if (machine->deposition)
        emitOptions.deposition = &*machine->deposition;
      emitOptions.machine = &*machine;
    }
    if (!opts.workOffset.empty()) {
      emitOptions.workOffset = parseWorkOffset(opts.workOffset);
      if (!emitOptions.workOffset) {
        printToolError("compile: --work-offset='" + opts.workOffset +
                       "' is not a position: expected three numbers of mm, X,Y,Z, such as --work-offset=200,195,-250");
        return kExitUsage;
      }
    }
    std::optional<std::string> program = backend->emit(*module, emitOptions, diags);
    if (!program || diags.hasErrors()) {
      printStatus("cannot write a " + opts.target + " program for " + opts.input + "; nothing written");
      return kExitDiagnostics;
    }
    const int rc = writeText(opts.output, *program);
    if (rc == kExitOk && opts.output != "-")
      printStatus("wrote " + opts.output + " (" + opts.target + ", " +
                  std::to_string(std::count(program->begin(), program->end(), '\n')) + " lines)");
    return rc;
  }
  if (opts.machines.size() > 1 && emit != "motion-ir")
    return writePhases(opts, *module, nullptr, {}, diags);
  ir::PrintOptions printOptions;
  printOptions.locations = opts.printLocations;
  return writeText(opts.output, ir::printModule(*module, printOptions));
}

} // namespace

int runCompile(const CompileOptions &opts) {
  // A target descriptor's files, which its diagnostics point into: they
  // outlive the session that prints them.
  std::vector<std::unique_ptr<SourceFile>> targetFiles;
  // First, so that with --diagnostics=json every message of the command is
  // in the one array on stderr.
  DiagnosticSession session(opts.diag);
  const std::string emit = !opts.emit.empty() ? opts.emit : opts.target.empty() ? "feature-ir" : "program";
  std::unique_ptr<backends::Backend> backend;
  if (emit == "program") {
    if (opts.target.empty()) {
      printToolError("compile: --emit=program needs a --target (" + targetList() + ")");
      return kExitUsage;
    }
    // A built-in target, or a descriptor file (docs/targets.md), whose
    // mistakes are reported at their place.
    std::string usageError;
    backend = backends::loadTarget(opts.target, targetFiles, session.engine(), usageError);
    if (!backend) {
      if (!usageError.empty()) {
        printToolError("compile: " + usageError + " (" + targetList() + ", or a descriptor file NAME.toml)");
        return kExitUsage;
      }
      printStatus("the target descriptor " + opts.target + " has errors; nothing written");
      return kExitDiagnostics;
    }
    if (opts.tolerance && !(*opts.tolerance > 0 && *opts.tolerance < 10)) {
      printToolError("compile: --tolerance " + formatShortest(*opts.tolerance) +
                     " is not a contour tolerance: give a number of mm above 0 and below 10, such as 0.01");
      return kExitUsage;
    }
    std::vector<std::string> overrides = opts.targetOptions;
    if (opts.noCycles)
      overrides.push_back("cycles=off");
    if (std::string error = backends::applyOverrides(backend->descriptor(), overrides); !error.empty()) {
      printToolError("compile: " + error);
      return kExitUsage;
    }
  }
  const bool needsMotion = emit == "motion-ir" || opts.target == "native";
  if (needsMotion && opts.machines.size() > 1) {
    printToolError("compile: " + std::string(emit == "motion-ir" ? "--emit=motion-ir" : "--target=native") +
                   " plans the motion on one machine: give one --machine");
    return kExitUsage;
  }
  if (needsMotion && opts.machine.empty()) {
    std::string names;
    for (const std::string &n : runtime::shippedMachineNames())
      names += (names.empty() ? "" : ", ") + n;
    printToolError("compile: " + std::string(emit == "motion-ir" ? "--emit=motion-ir" : "--target=native") +
                   " plans the motion on a machine: give --machine FILE.toml or a shipped machine (" + names + ")");
    return kExitUsage;
  }
  // Refused before reading: an output that is the input, or one the user
  // may not write.
  if (const int rc = checkOutput(opts.command, opts.input, opts.output); rc != kExitOk)
    return rc;
  auto source = openInput(opts.input);
  if (!source)
    return kExitUsage;
  if (!opts.verifyDiagnostics)
    return compileSource(opts, emit, source, backend.get(), session.engine());
  // --verify-diagnostics: collect instead of printing, then match the
  // expectations written in the input's comments (docs/diagnostics.md).
  DiagnosticCollector collector;
  DiagnosticEngine collecting(collector);
  collecting.setStrict(opts.diag.strict);
  const int rc = compileSource(opts, emit, source, backend.get(), collecting);
  if (rc == kExitUsage)
    return rc;
  return verifyDiagnostics(*source, collector.diags, std::cerr) ? kExitOk : kExitDiagnostics;
}

void addCommonOptions(CLI::App &cmd, CompileOptions &opts) {
  cmd.add_option("-o,--output", opts.output, "Output file ('-', the default, for standard output)");
  cmd.add_flag("--print-locs", opts.printLocations, "Print each IR node's source location (file:line:col #id)");
  cmd.add_flag("--stats", opts.stats, "Print each pass's counters to stderr");
  cmd.add_flag("--verify-diagnostics", opts.verifyDiagnostics,
               "Check the diagnostics against the expected-error/warning comments in the input\n"
               "(exit 0 when they match) instead of printing them");
  addSchemaOptions(cmd, opts.schema);
  addUnitOptions(cmd, opts.units);
  addDiagnosticOptions(cmd, opts.diag);
  addStrictOption(cmd, opts.diag);
}

void registerCompile(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<CompileOptions>();
  CLI::App *cmd = app.add_subcommand(
      "compile", "Compile a STEP-NC file: read it, check it against its schema, lower it to the\n"
                 "process IR, run resolve-feeds, expand-strategies, check-limits (speeds, feeds and\n"
                 "chip loads within the machine's and the tool's range), adapt-feed,\n"
                 "compensate-deflection and verify-toolpaths, and write a controller program for\n"
                 "--target (or stop early with --emit). Without --target the feature IR is written.\n"
                 "Nothing is written when the input has errors.");
  cmd->add_option("input", opts->input, "STEP-NC file (Part 21)");
  cmd->add_option("--target", opts->target, "Controller to write for: siemens-840d, heidenhain-tnc, rs274, "
                                            "native (--list-targets), or a target descriptor file NAME.toml "
                                            "(docs/targets.md)");
  cmd->add_option("--emit", opts->emit,
                  "What to write: program (with --target, the default then), feature-ir (the lowered\n"
                  "process IR; the default without --target), toolpath-ir (with moves, verified) or\n"
                  "motion-ir (with the motion planned on --machine) or stepnc (the input written back\n"
                  "as machine-optimised STEP-NC with the computed toolpaths and feeds, docs/feedback.md)")
      ->check(CLI::IsMember({"feature-ir", "toolpath-ir", "motion-ir", "program", "stepnc"}));
  cmd->add_option("--machine", opts->machines,
                  "Machine to plan the motion on, for --target=native and --emit=motion-ir: a TOML\n"
                  "file (docs/machine-model.md) or a shipped machine (hsc-3axis, conventional-3axis,\n"
                  "table-table-5axis, head-table-5axis, head-head-5axis, lathe-2axis: a lathe program\n"
                  "planned in its ZX plane); feed adaptation also keeps feeds within its dynamics and\n"
                  "spindle; a deposition program writes its [deposition] codes; with --work-offset a\n"
                  "5-axis machine turns each face to the tool (docs/five-axis.md). Given more than once\n"
                  "(a multi-process workplan), each setup or workingstep runs on the first that does its\n"
                  "process and a program is written per phase (docs/additive.md)")
      ->allow_extra_args(false);
  cmd->add_flag("--no-adapt-feed", opts->noAdaptFeed,
                "Keep the programmed feeds: leave out the adapt-feed pass (docs/feed-adaptation.md)");
  cmd->add_flag("--no-compensate-deflection", opts->noCompensateDeflection,
                "Keep finishing walls on the nominal path: leave out the compensate-deflection pass\n"
                "(docs/deflection-compensation.md)");
  cmd->add_option("--cutting-data", opts->cuttingData,
                  "Cutting data (materials, tool overhangs) on top of the shipped data (docs/cutting-data.md)");
  cmd->add_flag("--allow-out-of-range", opts->allowOutOfRange,
                "Write spindle speeds, feeds and extents outside the machine's range (with --machine)\n"
                "or plausibility, and chip loads beyond the tool's, with a warning each instead of\n"
                "refusing them (check-limits, docs/diagnostics.md)");
  cmd->add_option("--work-offset", opts->workOffset,
                  "Where the workpiece's origin is on --machine: X,Y,Z in mm, machine coordinates with every\n"
                  "axis at 0. A 5-axis machine (table-table, head-table, head-head) then turns each face of a\n"
                  "part with features on several faces to the tool (3+2) instead of stopping to\n"
                  "re-clamp (docs/five-axis.md)");
  cmd->add_flag("--allow-feed-increase", opts->allowFeedIncrease,
                "Let feed adaptation raise feeds above the programmed ones where the cut allows");
  cmd->add_option("--tool-table", opts->toolTable,
                  "Tool numbers and lengths by STEP-NC tool id, or LinuxCNC's tool.tbl, whose\n"
                  "numbers and diameters the program's tools are checked against (docs/tool-table.md);\n"
                  "without one, tools are numbered in order of first use");
  cmd->add_flag("--no-cycles", opts->noCycles, "Write hole making as moves, not as the controller's canned cycles");
  cmd->add_option("--tolerance", opts->tolerance, "Contour tolerance for the controller's path mode, mm");
  cmd->add_option("--target-opt", opts->targetOptions,
                  "Override a target capability, key=value (repeatable): " + backends::overrideHelp());
  cmd->add_flag("--list-targets", opts->listTargets, "List the controller targets and exit");
  addCommonOptions(*cmd, *opts);
  cmd->callback([opts, setResult] {
    if (opts->listTargets)
      return setResult(listTargets());
    if (opts->input.empty()) {
      printToolError("compile: an input file is required");
      return setResult(kExitUsage);
    }
    if (!opts->machines.empty())
      opts->machine = opts->machines.front();
    setResult(runCompile(*opts));
  });
}

} // namespace stepnc::tool
