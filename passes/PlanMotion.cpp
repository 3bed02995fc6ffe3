// plan-motion: plans the whole program's moves on a machine (runtime/Planner)
// and writes the trajectory into the IR as `motion` nodes (ir/motion/MotionIR).
#include "ir/motion/LathePlan.h"
#include "ir/motion/MotionIR.h"
#include "ir/Program.h"
#include "passes/Pass.h"
#include "passes/PassRegistry.h"
#include "runtime/Kinematics.h"
#include "runtime/Machine.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <memory>

namespace stepnc::passes {

namespace {

class PlanMotionPass final : public Pass {
public:
  PlanMotionPass(std::string machinePath, std::optional<double> tolerance, std::optional<std::array<double, 3>> offset)
      : machinePath_(std::move(machinePath)), tolerance_(tolerance), workOffset_(offset) {}

  std::string_view name() const override { return "plan-motion"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    // Kept for the life of the pass: diagnostics point into it.
    const auto machine = runtime::loadMachine(machinePath_, machineFile_, diags);
    if (!machine)
      return {false, false};
    if (machine->kinematics.chain == runtime::Chain::Lathe)
      return runLathe(module, *machine, diags, stats);
    // Steps that tilt the tool are planned on the joints of a 5-axis
    // machine, told where the workpiece sits on it; every step on those of
    // a generic chain (a parallel-kinematic machine), whose solver moves
    // axes that are not the tip's x, y, z.
    std::unique_ptr<runtime::Kinematics> kinematics;
    auto makeKinematics = [&]() {
      std::string error;
      std::unique_ptr<runtime::Kinematics> made = runtime::makeKinematics(*machine, error);
      if (!made)
        diags.error({}, "plan-motion: the machine's kinematics: " + error);
      return made;
    };
    const bool generic = machine->kinematics.chain == runtime::Chain::Generic;
    const bool fiveAxis = machine->kinematics.fiveAxis() || generic;
    const std::vector<const ir::Node *> order = ir::programOrder(module);
    const auto tilted = std::find_if(order.begin(), order.end(), [](const ir::Node *e) { return ir::tiltsTool(*e); });
    if (tilted != order.end()) {
      const ir::Node &at = **tilted;
      const std::string needs = !fiveAxis ? "a 5-axis machine (" + machine->name + " has no two rotary axes that turn "
                                                                                   "the tool)"
                                : !workOffset_ ? "where the workpiece's origin is on the machine (--work-offset, or "
                                                 "plan-motion<work-offset=X:Y:Z>)"
                                               : "";
      if (!needs.empty()) {
        diags.error(at.origin.loc, "workingstep " + at.symbol + " tilts the tool: plan-motion plans it on the "
                                                                "machine's joints, which needs " + needs)
            .entity(at.origin.entityId);
        return {false, false};
      }
      if (!(kinematics = makeKinematics()))
        return {false, false};
    }
    if (generic && !kinematics) {
      if (!workOffset_) {
        diags.error({}, "plan-motion: the machine \"" + machine->name + "\" moves its joints through the solver '" +
                            machine->kinematics.solver + "': plan-motion plans every move on them, which needs where "
                            "the workpiece's origin is on the machine (--work-offset, or plan-motion<work-offset=X:Y:Z>)");
        return {false, false};
      }
      if (!(kinematics = makeKinematics()))
        return {false, false};
    }
    // Deposition steps are planned as any 3-axis moves (the head's state
    // changes take no time); the native format refuses them.
    if (!ir::requireThreeAxisMilling(module, "plan-motion", diags, ir::ArcPlanes::Principal,
                                     ir::OtherProcesses::Refuse, ir::Deposition::Take,
                                     kinematics ? ir::ToolAxes::Take : ir::ToolAxes::Refuse))
      return {false, false};
    // The planner moves x, y and z: a generic chain is refused rather than
    // planned with its axes taken for x, y, z.
    if (const std::string why = machine->whyNotThreeAxis(); !why.empty() && !generic) {
      diags.error({}, "plan-motion: " + why);
      return {false, false};
    }
    // An empty program has nothing to plan, and is no mistake: the native
    // target writes it with no segments.
    if (!ir::hasMachiningSteps(module))
      return {true, false};
    const ir::ProgramPath program = ir::programPath(module);
    if (program.path.moves.empty()) {
      diags.warning({}, "plan-motion: the program has no moves to plan (run expand-strategies first)");
      return {true, false};
    }
    if (generic && !reachable(program, *kinematics, diags))
      return {false, false};
    runtime::PlanOptions options;
    if (tolerance_)
      options.tolerance = *tolerance_;
    if (kinematics) {
      options.kinematics = kinematics.get();
      options.workOffset = runtime::Vec3((*workOffset_)[0], (*workOffset_)[1], (*workOffset_)[2]);
    }
    const runtime::Trajectory trajectory = runtime::plan(program.path, *machine, options);
    ir::attachMotion(module, program, trajectory);
    count(program, trajectory, stats);
    return {true, true};
  }

private:
  /// On a generic chain, whether every move's end is a pose the machine
  /// reaches (each solution nearest the one before); the first that is not
  /// is an error at its step with the solver's reason. (Between the ends
  /// the player checks every sample's joints: their travel, their limits
  /// and the solver's reach.)
  bool reachable(const ir::ProgramPath &program, const runtime::Kinematics &kinematics, DiagnosticEngine &diags) const {
    const runtime::Vec3 offset((*workOffset_)[0], (*workOffset_)[1], (*workOffset_)[2]);
    runtime::Joints near;
    for (size_t i = 0; i < program.path.moves.size(); ++i) {
      const runtime::PathMove &move = program.path.moves[i];
      const runtime::InverseResult at =
          kinematics.inverse({move.to + offset, move.axis}, near.size() ? &near : nullptr);
      if (at.joints) {
        near = *at.joints;
        continue;
      }
      const ir::Node *owner = i < program.owners.size() ? program.owners[i] : nullptr;
      const std::string point = formatTrimmed(move.to.x(), 4) + ", " + formatTrimmed(move.to.y(), 4) + ", " +
                                formatTrimmed(move.to.z(), 4);
      const std::string text = "the machine cannot reach the move to (" + point + ") mm with the work offset given: " +
                               at.why;
      if (owner)
        diags.error(owner->origin.loc, owner->kindName() + " " + owner->symbol + ": " + text)
            .entity(owner->origin.entityId);
      else
        diags.error({}, "plan-motion: " + text);
      return false;
    }
    return true;
  }

  /// A lathe program: its turning steps and holes drilled on the axis,
  /// planned in the ZX plane with the spindle (ir/motion/LathePlan.h).
  PassResult runLathe(ir::Module &module, const runtime::Machine &machine, DiagnosticEngine &diags,
                      PassStats &stats) {
    if (!ir::requireThreeAxisMilling(module, "plan-motion", diags, ir::ArcPlanes::Principal, ir::OtherProcesses::Skip))
      return {false, false};
    if (!ir::hasMachiningSteps(module))
      return {true, false};
    runtime::PlanOptions options;
    if (tolerance_)
      options.tolerance = *tolerance_;
    std::optional<ir::LathePlan> plan = ir::planLathe(module, machine, options, diags);
    if (!plan)
      return {false, false};
    if (plan->program.path.moves.empty()) {
      diags.warning({}, "plan-motion: the program has no moves to plan (run expand-strategies first)");
      return {true, false};
    }
    ir::attachMotion(module, plan->program, plan->trajectory);
    count(plan->program, plan->trajectory, stats);
    stats["spindle waits"] = plan->spindleWaits;
    stats["planning rounds"] = plan->rounds;
    return {true, true};
  }

  static void count(const ir::ProgramPath &program, const runtime::Trajectory &trajectory, PassStats &stats) {
    long long blends = 0, dwells = 0, stops = 0;
    for (size_t k = 0; k < trajectory.segments.size(); ++k) {
      blends += trajectory.segments[k].kind == runtime::SegmentKind::Blend;
      dwells += trajectory.segments[k].kind == runtime::SegmentKind::Dwell;
      stops += trajectory.info[k].stop != runtime::StopReason::None;
    }
    stats["moves planned"] = (long long)program.path.moves.size();
    stats["segments"] = (long long)trajectory.segments.size();
    stats["blends"] = blends;
    stats["dwells"] = dwells;
    stats["stops"] = stops;
    stats["cycle time (ms)"] = (long long)std::llround(trajectory.duration() * 1000);
  }

  std::string machinePath_;
  std::unique_ptr<SourceFile> machineFile_;
  std::optional<double> tolerance_;
  std::optional<std::array<double, 3>> workOffset_;
};

} // namespace

std::unique_ptr<Pass> createPlanMotionPass(const PassOptions &options) {
  std::optional<std::array<double, 3>> offset;
  if (options.has("work-offset"))
    offset = parsePoint(options.text("work-offset"));
  return std::make_unique<PlanMotionPass>(options.text("machine"), options.number("tolerance"), offset);
}

} // namespace stepnc::passes
