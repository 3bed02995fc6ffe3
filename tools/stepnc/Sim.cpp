// `stepnc sim IN`: plays a program on a machine with the reference player
// (runtime/Player.h) and reports its cycle time, the feed it actually
// reaches, where and why it is slower, and any limit it breaks. IN may be the
// native format, IR text (with motion, or moves to plan) or STEP-NC (compiled
// to moves and planned first). Besides the axes' dynamics it checks the
// spindle speed of every move against the machine's range (IR and STEP-NC in:
// the native format has no spindle speeds) and the axes' travel: each
// position where the program origin is on the machine (--work-offset), else
// only that the program's extent fits the travel. Machines whose chain the
// player cannot move a 3-axis program on (generic chains) are refused with
// the reason. On a lathe the turning steps are timed instead
// (ir/motion/LatheTime.h: constant surface speed, spindle acceleration).
#include "driver/LoadModule.h"
#include "driver/Pipeline.h"
#include "ir/motion/LatheTime.h"
#include "ir/motion/MotionIR.h"
#include "ir/geom/MoveWalk.h"
#include "ir/geom/TurnedShape.h"
#include "runtime/Machine.h"
#include "runtime/NativeFormat.h"
#include "runtime/Player.h"
#include "support/Format.h"
#include "support/OutputFile.h"
#include "tools/stepnc/CommandLine.h"
#include "tools/stepnc/Commands.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <map>

namespace stepnc::tool {

namespace {

constexpr std::string_view kDefaultMachine = "hsc-3axis";

struct SimCommandOptions {
  std::string input;
  std::string machine;
  std::optional<double> tolerance;
  std::optional<double> period;
  std::string workOffset;  ///< "X,Y,Z" mm: the program origin in machine coordinates
  std::string samples;  ///< CSV of every sample
  bool allowOutOfRange = false;
  std::string output = "-";
  driver::SchemaOptions schema;
  UnitOptions units;
  DiagnosticOptions diag;
};

std::string label(const ir::Node &e) {
  std::string s = e.kindName() + " " + e.symbol;
  if (!e.label.empty())
    s += " \"" + e.label + "\"";
  return s;
}

/// The program of an IR or STEP-NC input, with what it lacks made: its
/// moves (the toolpath pipeline on the machine) and, with `motion`, its
/// planned motion (plan-motion; planned again when --tolerance asks). Null
/// after reporting why, with the exit status in `rc`.
std::unique_ptr<ir::Module> loadProgram(const SimCommandOptions &opts, std::unique_ptr<SourceFile> &source,
                                        const std::string &machineName, bool motion, DiagnosticEngine &diags,
                                        int &rc) {
  driver::SchemaSelection schemas(opts.schema);
  if ((rc = loadSchemas(schemas, diags)) != kExitOk)
    return nullptr;
  std::string usageError;
  std::unique_ptr<ir::Module> module =
      driver::loadModule(source, schemas, diags, usageError, nullptr, lowering::LowerOptions{opts.units.conventions()});
  if (!module) {
    rc = usageError.empty() ? kExitDiagnostics : kExitUsage;
    if (!usageError.empty())
      printToolError(usageError);
    return nullptr;
  }
  bool hasMoves = false, hasMotion = false;
  for (const ir::Node *e : ir::programOrder(*module)) {
    hasMoves |= e->child(ir::Kind::Moves) != nullptr;
    hasMotion |= e->child(ir::Kind::Motion) != nullptr;
  }
  std::vector<std::string> passes;
  if (!hasMoves) {
    driver::ToolpathPipelineOptions toolpath;
    toolpath.machine = machineName;
    toolpath.allowOutOfRange = opts.allowOutOfRange;
    passes.push_back(driver::toolpathPipeline(toolpath));
  }
  if (motion && (!hasMotion || opts.tolerance))
    passes.push_back(driver::planMotionPipeline(machineName, opts.tolerance, opts.workOffset));
  if (!passes.empty()) {
    std::string pipeline = passes[0];
    for (size_t k = 1; k < passes.size(); ++k)
      pipeline += "," + passes[k];
    driver::PipelineRun run;
    run.log = &std::cerr;
    if ((rc = driver::runPipeline(*module, pipeline, run, diags, usageError)) != kExitOk) {
      if (rc == kExitUsage)
        printToolError(usageError);
      return nullptr;
    }
  }
  rc = kExitOk;
  return module;
}

/// The deposition steps' figures (docs/additive.md): the time they take,
/// the time the head's energy is on (the segments of the moves it is on
/// for), the powder or wire fed meanwhile, and the beads laid (their length,
/// and as strips of the bead pitch by the layer thickness their volume, and
/// mass where the technology gives the density). Empty without deposition.
std::string depositionReport(const ir::ProgramPath &program, const runtime::Trajectory &trajectory) {
  // Per move of the program: its step's technology when the energy is on.
  std::vector<const ir::Node *> onWith(program.owners.size(), nullptr);
  std::vector<bool> deposits(program.owners.size(), false);
  std::map<const ir::Node *, std::vector<std::pair<ir::Move, bool>>> walked;
  std::map<const ir::Node *, size_t> seen;
  double length = 0, volume = 0, mass = 0;
  bool massKnown = true;
  size_t steps = 0;
  for (size_t k = 0; k < program.owners.size(); ++k) {
    const ir::Node *owner = program.owners[k];
    if (!owner || !ir::isAdditiveStep(*owner))
      continue;
    deposits[k] = true;
    auto it = walked.find(owner);
    if (it == walked.end()) {
      it = walked.emplace(owner, ir::walkWithEnergy(*owner->child(ir::Kind::Moves))).first;
      ++steps;
    }
    const size_t i = seen[owner]++;
    const ir::Node *tech = ir::operationOf(*owner)->child(ir::Kind::DepositionTechnology);
    if (i < it->second.size() && it->second[i].second && it->second[i].first.isFeed() && tech) {
      onWith[k] = tech;
      const double l = it->second[i].first.length();
      // Each bead stands for a strip its pitch wide and a layer high (the
      // overlap with its neighbour counted once).
      const double pitch = tech->number("bead_width").value_or(0) * (1 - tech->number("overlap").value_or(0));
      const double layer = ir::operationOf(*owner)->number("layer_thickness").value_or(
          tech->number("bead_height").value_or(0));
      const double v = l * pitch * layer;
      length += l;
      volume += v;
      if (auto rho = tech->number("density"))
        mass += v / 1000 * *rho;
      else
        massKnown = false;
    }
  }
  if (steps == 0)
    return "";
  double time = 0, on = 0, powder = 0, wire = 0;
  for (size_t s = 0; s < trajectory.segments.size(); ++s) {
    const uint32_t move = trajectory.info[s].move;
    const double d = trajectory.profiles[s].duration();
    if (move < deposits.size() && deposits[move])
      time += d;
    if (move < onWith.size() && onWith[move]) {
      on += d;
      powder += onWith[move]->number("powder_feed").value_or(0) * d / 60;
      wire += onWith[move]->number("wire_feed").value_or(0) * d / 60;
    }
  }
  std::string text = "deposition: " + std::to_string(steps) + (steps == 1 ? " step, " : " steps, ") +
                     formatFixed(time, 1) + " s; energy on " + formatFixed(on, 1) + " s";
  if (powder > 0)
    text += "; powder fed " + formatFixed(powder, 1) + " g";
  if (wire > 0)
    text += "; wire fed " + formatFixed(wire / 1000, 2) + " m";
  text += "; beads " + formatFixed(length / 1000, 2) + " m, " + formatFixed(volume / 1000, 2) + " cm3";
  if (massKnown)
    text += ", " + formatFixed(mass, 1) + " g deposited";
  text += " (each bead a strip of its pitch by a layer)\n";
  return text;
}

/// A lathe's native motion (planned by plan-motion on a lathe, axes z x y):
/// played on the lathe's z and x axes, which checks every axis's limits, and
/// the spindle's speeds against the machine's range.
int playLatheMotion(const SimCommandOptions &opts, const runtime::Machine &machine, const SourceFile &source,
                    DiagnosticEngine &diags) {
  std::optional<runtime::Trajectory> trajectory = runtime::readNative(source, diags);
  if (!trajectory || diags.hasErrors()) {
    printStatus("cannot simulate " + opts.input);
    return kExitDiagnostics;
  }
  if (trajectory->frame != runtime::Frame::Zxy) {
    printToolError("sim: " + opts.input + " is motion planned for a mill (axes x y z); the lathe \"" + machine.name +
                   "\" plays motion planned for a lathe (axes z x y)");
    return kExitUsage;
  }
  if (!trajectory->machine.empty() && trajectory->machine != machine.name)
    diags.warning({}, "the motion was planned for \"" + trajectory->machine + "\" and is played on \"" +
                          machine.name + "\"");
  runtime::SimOptions simOptions;
  double lowest = std::numeric_limits<double>::infinity(), highest = 0;
  size_t threads = 0;
  for (const runtime::SegmentInfo &info : trajectory->info) {
    if (simOptions.spindleRpm.size() <= info.move)
      simOptions.spindleRpm.resize(info.move + 1, 0);
    const double most = std::max(std::abs(info.spindle0), std::abs(info.spindle1));
    simOptions.spindleRpm[info.move] = std::max(simOptions.spindleRpm[info.move], most);
    if (info.feed > 0) {
      lowest = std::min({lowest, std::abs(info.spindle0), std::abs(info.spindle1)});
      highest = std::max(highest, most);
    }
    threads += info.sync;
  }
  const runtime::Machine frame = runtime::latheFrameMachine(machine);
  const runtime::SimReport report = runtime::simulate(*trajectory, frame, simOptions);
  std::string text = runtime::formatReport(report, *trajectory, frame);
  if (std::isfinite(lowest))
    text += "spindle while cutting: " + formatFixed(lowest, 0) + ".." + formatFixed(highest, 0) + " rev/min; " +
            std::to_string(threads) + " thread pass segments synchronised with it\n";
  if (const int rc = writeText(opts.output, text); rc != kExitOk)
    return rc;
  return report.violationCount == 0 ? kExitOk : kExitDiagnostics;
}

/// A lathe: the program's turning steps timed with their spindle
/// (ir/motion/LatheTime.h), not played at the interpolator's cycle.
int runLatheSim(const SimCommandOptions &opts, const runtime::Machine &machine, const std::string &machineName,
                std::unique_ptr<SourceFile> &source, DiagnosticEngine &diags) {
  if (!opts.samples.empty() || !opts.workOffset.empty() || opts.period || opts.tolerance) {
    printToolError("sim: on a lathe the program is timed, or its native motion played as planned: --samples, "
                   "--work-offset, --period and --tolerance are for the player of milling programs");
    return kExitUsage;
  }
  if (source->text().starts_with("STEPNC-MOTION"))
    return playLatheMotion(opts, machine, *source, diags);
  int rc = kExitOk;
  std::unique_ptr<ir::Module> module = loadProgram(opts, source, machineName, false, diags, rc);
  if (!module)
    return rc;
  for (const ir::Node *e : ir::programOrder(*module))
    if (e->child(ir::Kind::Moves) && !ir::isTurningStep(*e) && !ir::drillsOnTurningAxis(*e)) {
      diags.error(e->origin.loc, e->kindName() + " " + e->symbol + " mills or drills off the spindle axis: the lathe \"" +
                                     machine.name + "\" times turning steps and holes drilled on its axis only")
          .entity(e->origin.entityId);
      printStatus("cannot simulate " + opts.input);
      return kExitDiagnostics;
    }
  if (diags.hasErrors()) {
    printStatus("cannot simulate " + opts.input);
    return kExitDiagnostics;
  }
  const ir::LatheTimeReport report = ir::timeLatheProgram(*module, machine);
  if (const int written = writeText(opts.output, ir::formatLatheReport(report, machine)); written != kExitOk)
    return written;
  return report.violations.empty() ? kExitOk : kExitDiagnostics;
}

int runSim(const SimCommandOptions &opts) {
  // First, so that with --diagnostics=json every message of the command is
  // in the one array on stderr.
  DiagnosticSession session(opts.diag);
  DiagnosticEngine &diags = session.engine();
  // The report and the samples may replace neither the input nor a file the
  // user may not write.
  for (const std::string &out : {opts.output, opts.samples})
    if (!out.empty())
      if (const int rc = checkOutput("sim", opts.input, out); rc != kExitOk)
        return rc;
  auto source = openInput(opts.input);
  if (!source)
    return kExitUsage;
  std::unique_ptr<SourceFile> machineFile;
  const std::string machineName = opts.machine.empty() ? std::string(kDefaultMachine) : opts.machine;
  const auto machine = runtime::loadMachine(machineName, machineFile, diags);
  if (!machine)
    return kExitUsage;
  if (machine->kinematics.chain == runtime::Chain::Lathe)
    return runLatheSim(opts, *machine, machineName, source, diags);
  // A generic chain (a parallel-kinematic machine) is played on its joints
  // through its solver, which needs where the program's origin is on it.
  const bool generic = machine->kinematics.chain == runtime::Chain::Generic;
  if (const std::string why = machine->whyNotThreeAxis(); !why.empty() && !generic) {
    printToolError("sim: " + why);
    return kExitUsage;
  }
  if (generic) {
    std::string error;
    if (!runtime::makeKinematics(*machine, error)) {
      printToolError("sim: " + error);
      return kExitUsage;
    }
    if (opts.workOffset.empty()) {
      printToolError("sim: the machine \"" + machine->name + "\" moves its joints through the solver '" +
                     machine->kinematics.solver + "': sim plans and plays every move on them, which needs where the "
                     "program's origin is on the machine (--work-offset=X,Y,Z)");
      return kExitUsage;
    }
  }
  std::optional<runtime::Vec3> workOffset;
  if (!opts.workOffset.empty()) {
    workOffset = parseWorkOffset(opts.workOffset);
    if (!workOffset) {
      printToolError("sim: --work-offset='" + opts.workOffset +
                     "' is not a position: expected three numbers of mm, X,Y,Z, such as --work-offset=100,50,-300");
      return kExitUsage;
    }
  }

  std::optional<runtime::Trajectory> trajectory;
  std::unique_ptr<ir::Module> module;
  std::optional<ir::ProgramPath> program;
  if (source->text().starts_with("STEPNC-MOTION")) {
    trajectory = runtime::readNative(*source, diags);
  } else {
    int rc = kExitOk;
    module = loadProgram(opts, source, machineName, true, diags, rc);
    if (!module)
      return rc;
    trajectory = ir::readMotion(*module, diags);
    program = ir::programPath(*module);
  }
  if (!trajectory || diags.hasErrors()) {
    printStatus("cannot simulate " + opts.input);
    return kExitDiagnostics;
  }
  if (!trajectory->machine.empty() && trajectory->machine != machine->name)
    diags.warning({}, "the motion was planned for \"" + trajectory->machine + "\" and is played on \"" +
                          machine->name + "\"");

  runtime::SimOptions simOptions;
  if (opts.period)
    simOptions.period = *opts.period;
  if (program)
    simOptions.programmed = &program->path;
  if (opts.tolerance)
    simOptions.tolerance = *opts.tolerance;
  simOptions.workOffsetMm = workOffset;
  if (program) {
    // Each move's spindle speed, from the `moves` node that holds it.
    simOptions.spindleRpm.reserve(program->owners.size());
    for (const ir::Node *owner : program->owners) {
      const ir::Node *moves = owner ? owner->child(ir::Kind::Moves) : nullptr;
      simOptions.spindleRpm.push_back(moves ? moves->number("spindle").value_or(0) : 0);
    }
  }

  OutputFile samplesOut;
  std::string error;
  std::function<void(const runtime::Sample &)> onSample;
  if (!opts.samples.empty()) {
    if (!samplesOut.open(opts.samples, error)) {
      printToolError(error);
      return kExitUsage;
    }
    samplesOut.write("t_s,segment,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,ax_mm_s2,ay_mm_s2,az_mm_s2,jx_mm_s3,jy_mm_s3,"
                     "jz_mm_s3,speed_mm_s\n");
    onSample = [&](const runtime::Sample &s) {
      std::string line = formatFixed(s.t, 6) + "," + std::to_string(s.segment);
      for (const runtime::Vec3 *v : {&s.p, &s.v, &s.a, &s.j})
        for (int k = 0; k < 3; ++k)
          line += "," + formatFixed((*v)[k], 6);
      line += "," + formatFixed(s.speed, 6) + "\n";
      samplesOut.write(line);
    };
  }
  const runtime::SimReport report = runtime::simulate(*trajectory, *machine, simOptions, onSample);
  auto nameMove = [&](uint32_t move) -> std::string {
    if (!program || move >= program->owners.size())
      return "move " + std::to_string(move);
    // The move's place within its executable, counted from 1 as a reader counts lines.
    uint32_t first = move;
    while (first > 0 && program->owners[first - 1] == program->owners[move])
      --first;
    return label(*program->owners[move]) + ", move " + std::to_string(move - first + 1);
  };
  std::string text = runtime::formatReport(report, *trajectory, *machine, nameMove);
  if (module && program)
    text += depositionReport(*program, *trajectory);
  if (!opts.samples.empty() && !samplesOut.commit(error)) {
    printToolError(error);
    return kExitUsage;
  }
  if (const int rc = writeText(opts.output, text); rc != kExitOk)
    return rc;
  return report.violationCount == 0 ? kExitOk : kExitDiagnostics;
}

} // namespace

void registerSim(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<SimCommandOptions>();
  CLI::App *cmd = app.add_subcommand(
      "sim", "Play a program on a machine at the controller cycle and report its cycle time,\n"
             "the feed it reaches (where and why it is slower than programmed) and every limit\n"
             "it breaks. IN is native motion, IR text or STEP-NC (planned first). Exit code 1\n"
             "when a limit is broken.");
  cmd->add_option("input", opts->input, "Native motion file, IR text or STEP-NC file")->required();
  cmd->add_option("--machine", opts->machine,
                  "Machine: a TOML file (docs/machine-model.md) or a shipped machine (hsc-3axis, the\n"
                  "default, conventional-3axis, table-table-5axis, or lathe-2axis: a lathe times the\n"
                  "program's turning steps with constant surface speed)");
  cmd->add_option("--tolerance", opts->tolerance, "Path tolerance for blending and the deviation check, mm");
  cmd->add_option("--period", opts->period, "Sampling period, s (default: the machine's cycle time)");
  cmd->add_option("--work-offset", opts->workOffset,
                  "Where the program's origin is on the machine, X,Y,Z in mm (machine coordinates):\n"
                  "every axis position is then checked against its travel (without it, only that\n"
                  "the program's extent fits the travel)");
  cmd->add_flag("--allow-out-of-range", opts->allowOutOfRange,
                "STEP-NC in: play spindle speeds, feeds and extents outside the machine's range with\n"
                "a warning each (and report them as violations) instead of refusing the file");
  cmd->add_option("--samples", opts->samples, "Write every sample (position, velocity, acceleration, jerk) as CSV");
  cmd->add_option("-o,--output", opts->output, "Report file ('-', the default, for standard output)");
  addSchemaOptions(*cmd, opts->schema);
  addUnitOptions(*cmd, opts->units);
  addDiagnosticOptions(*cmd, opts->diag);
  addStrictOption(*cmd, opts->diag);
  cmd->callback([opts, setResult] { setResult(runSim(*opts)); });
}

} // namespace stepnc::tool
