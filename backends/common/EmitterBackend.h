// The backend every target is: the program model built from the toolpath IR,
// then written by the target's emitter (a class constructed from the
// descriptor, options and diagnostics, with `run(const Program &)` and
// `stepLines()`), then read back by the dialect's reader (the emitter's
// static `read(text, descriptor)`) and compared with the program model
// (backends/common/ReadBack.h): a program that does not read back is a bug
// in stepnc, reported at its workingstep, and is not returned.
#pragma once

#include "backends/Backend.h"
#include "backends/common/FiveAxis.h"
#include "backends/common/LatheEmitter.h"
#include "backends/common/Indexing.h"
#include "backends/common/Program.h"
#include "backends/common/ReadBack.h"
#include "ir/Program.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>

namespace stepnc::backends {

template <class Emitter> class EmitterBackend final : public Backend {
public:
  explicit EmitterBackend(TargetDescriptor d) : Backend(std::move(d)) {}

  std::optional<std::string> emit(const ir::Module &module, const EmitOptions &options,
                                  DiagnosticEngine &diags) override {
    if (!holdsTolerance(options, diags))
      return std::nullopt;
    if (hasTurningSteps(module)) {
      // A lathe program, from the dialect's lathe emitter where it has one.
      if constexpr (requires { Emitter::lathe(module, descriptor(), options, diags); }) {
        return Emitter::lathe(module, descriptor(), options, diags);
      } else {
        for (const ir::Node *e : ir::programOrder(module))
          if (ir::isTurningStep(*e)) {
            diags.error(e->origin.loc, "workingstep " + e->symbol + " turns: " + descriptor().name +
                                           " does not write lathe programs (docs/turning.md: rs274 and siemens-840d do)")
                .entity(e->origin.entityId);
            break;
          }
        return std::nullopt;
      }
    }
    if (!takesTilts(module, options, diags))
      return std::nullopt;
    std::optional<Program> program =
        buildProgram(module, options.toolTable, diags,
                     descriptor().arcPlanes ? ir::OutOfPlaneArcs::Exact : ir::OutOfPlaneArcs::Chords,
                     descriptor().deposition ? ir::Deposition::Take : ir::Deposition::Refuse, descriptor().name,
                     descriptor().jointMoves || !descriptor().tcpOn.empty() ? ir::ToolAxes::Take
                                                                            : ir::ToolAxes::Refuse);
    if (!program || !index(*program, options, diags))
      return std::nullopt;
    if (options.machine && descriptor().jointMoves && options.workOffset &&
        !jointMoves(*program, *options.machine, *options.workOffset, diags))
      return std::nullopt;
    if (options.machine && !descriptor().jointMoves && !descriptor().tcpOn.empty() &&
        !tcpMoves(*program, *options.machine, options.workOffset, diags))
      return std::nullopt;
    Emitter emitter(descriptor(), options, diags);
    std::optional<std::string> text = emitter.run(*program);
    if (!text)
      return std::nullopt;
    const double tolerance = options.tolerance.value_or(descriptor().tolerance);
    // The head's codes are the machine's, not the dialect's: the reader
    // reads the program without their lines.
    std::string motion = *text;
    if constexpr (requires { emitter.processLines(); })
      motion = blankLines(*text, emitter.processLines());
    TargetDescriptor reading = descriptor();
    reading.feedsWithoutSpindle = std::any_of(program->steps.begin(), program->steps.end(),
                                              [](const Step &s) { return s.deposits; });
    if (!checkReadBack(*program, descriptor(), emitter.stepLines(), *text, Emitter::read(motion, reading), tolerance,
                       diags))
      return std::nullopt;
    return text;
  }

private:
  /// Steps that tilt the tool need a target that writes joints, a 5-axis
  /// machine and where the workpiece is on it: said at the first such step
  /// when one is missing.
  bool takesTilts(const ir::Module &module, const EmitOptions &options, DiagnosticEngine &diags) const {
    const std::vector<const ir::Node *> order = ir::programOrder(module);
    const auto tilted = std::find_if(order.begin(), order.end(), [](const ir::Node *e) { return ir::tiltsTool(*e); });
    if (tilted == order.end())
      return true;
    const ir::Node &at = **tilted;
    std::string missing;
    if (!descriptor().jointMoves && descriptor().tcpOn.empty()) {
      diags.error(at.origin.loc, "workingstep " + at.symbol + " tilts the tool (5-axis): " + descriptor().name +
                                     " does not write such steps yet (rs274 does, as the machine's joints; "
                                     "siemens-840d with TRAORI, heidenhain-tnc with FUNCTION TCPM: docs/five-axis.md)")
          .entity(at.origin.entityId);
      return false;
    }
    const bool tcp = !descriptor().jointMoves;
    if (!options.machine)
      missing = "a 5-axis machine (--machine=table-table-5axis, head-table-5axis, head-head-5axis or a file of "
                "one's own)";
    else if (options.machine->kinematics.chain == runtime::Chain::Generic)
      missing = "a serial 5-axis machine (" + options.machine->name + " is a generic chain moved by the solver '" +
                options.machine->kinematics.solver + "': its programs give the tip's X Y Z for a controller that "
                "runs its kinematics, and steps that tilt the tool are not written for it yet)";
    else if (!options.machine->kinematics.fiveAxis())
      missing = "a 5-axis machine (" + options.machine->name + " has no two rotary axes that turn the tool)";
    else if (!options.workOffset && !tcp)
      missing = "where the workpiece's origin is on the machine (--work-offset=X,Y,Z, machine coordinates with "
                "every axis at 0)";
    if (missing.empty())
      return true;
    diags.error(at.origin.loc, "workingstep " + at.symbol + " tilts the tool (5-axis): " + descriptor().name +
                                   (tcp ? " writes it with " + descriptor().tcpOn + " and the machine's rotary axes"
                                        : std::string(" writes it as the machine's joints")) +
                                   ", which needs " + missing)
        .entity(at.origin.entityId);
    return false;
  }

  /// A program that re-clamps for features on other faces, for a machine
  /// with two rotary axes (table-table, head-table, head-head): they turn each face to the tool
  /// (Indexing.h) where the target writes it, with the workpiece's place on
  /// the table given; elsewhere the re-clamps stay, and a warning says why.
  bool index(Program &program, const EmitOptions &options, DiagnosticEngine &diags) const {
    if (program.clampings.empty() || !options.machine || !options.machine->kinematics.fiveAxis())
      return true;
    if (!descriptor().rotaryIndexing && !descriptor().workingPlanes) {
      diags.warning(SourceLoc{}, descriptor().name + " does not turn the rotary axes to each face yet (rs274, heidenhain-tnc and "
                                 "siemens-840d do): "
                                 "the program stops for the operator to re-clamp the workpiece for each face");
      return true;
    }
    if (!options.workOffset) {
      // Said at the first step on another face.
      const auto other = std::find_if(program.steps.begin(), program.steps.end(),
                                      [](const Step &s) { return s.kind == Step::Kind::Moves && s.workOffset > 1; });
      const ir::Node *at = other != program.steps.end() ? other->exec : nullptr;
      diags.error(at ? at->origin.loc : SourceLoc{},
                  "workingstep " + (at ? at->symbol + " " : std::string()) + "is on another face of the workpiece (" +
                      std::to_string(program.clampings.size()) +
                      " faces in all), which the machine's rotary table turns to the tool: give where the "
                      "workpiece's origin is on the machine (--work-offset=X,Y,Z, machine coordinates with every "
                      "axis at 0)")
          .entity(at ? at->origin.entityId : 0);
      return false;
    }
    return indexClampings(program, *options.machine, *options.workOffset, descriptor().arcPlanes,
                          descriptor().workingPlanes, diags);
  }

  /// Positions printed in steps coarser than half the contour tolerance
  /// (--target-opt decimals=N) cannot keep the path within it: the ends of
  /// a move move by half a step, an arc's centre by more. Refused, with the
  /// decimals that would do.
  bool holdsTolerance(const EmitOptions &options, DiagnosticEngine &diags) const {
    const double tolerance = options.tolerance.value_or(descriptor().tolerance);
    const double step = std::pow(10.0, -descriptor().coordDecimals);
    if (step <= tolerance / 2 * (1 + 1e-9))
      return true;
    int enough = descriptor().coordDecimals;
    while (std::pow(10.0, -enough) > tolerance / 2 * (1 + 1e-9))
      ++enough;
    diags.error(SourceLoc{}, "positions written with " + std::to_string(descriptor().coordDecimals) +
                                 " decimals (steps of " + formatFixed(step, descriptor().coordDecimals) +
                                 " mm) cannot keep the path within the contour tolerance " +
                                 formatFixed(tolerance, 4) + " mm of " + descriptor().name + ": write " +
                                 std::to_string(enough) + " decimals or more (--target-opt decimals=" +
                                 std::to_string(enough) + "), or give a larger --tolerance");
    return false;
  }
};

} // namespace stepnc::backends
