// check-limits: the gate between what a file asks for and what a machine
// and a tool can do. Every operation's cutting data, as resolve-feeds left
// it, is checked:
//   - against the machine, when one is given: the spindle speed within its
//     spindle's range, the feed within the fastest it feeds (the
//     controller's max_feed, else its fastest linear axis);
//   - against plausibility otherwise: a spindle speed up to 100,000 rev/min,
//     a feed up to 100,000 mm/min (the fastest machines stepnc targets
//     reach neither);
//   - against the tool, always: a cutting speed up to 3,000 m/min and a feed
//     per tooth up to a tenth of the tool's diameter (beyond either the tool
//     breaks or the value is a mistake).
// With a machine, the program's extent on each linear axis must also fit
// that axis's travel (no work offset could fit a longer one).
//
// A value out of range is an error at the technology instance (or the
// operation) naming the value, the limit and the unit; nothing is written.
// `allow-out-of-range` (stepnc's --allow-out-of-range) turns them into
// warnings, for the rare case where the file is right and the limit is not.
// The pass changes nothing.
#include "passes/Pass.h"

#include "ir/Kinds.h"
#include "ir/Plausible.h"
#include "ir/Program.h"
#include "ir/geom/MoveWalk.h"
#include "runtime/Machine.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace stepnc::passes {

namespace {

/// Room for the printed rounding of values that sit on a limit.
constexpr double kSlack = 1e-6;

class CheckLimitsPass final : public Pass {
public:
  CheckLimitsPass(std::string machine, bool allowOutOfRange)
      : machineSpec_(std::move(machine)), allow_(allowOutOfRange) {}

  std::string_view name() const override { return "check-limits"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    PassResult result;
    if (!machineSpec_.empty()) {
      machine_ = runtime::loadMachine(machineSpec_, machineFile_, diags);
      if (!machine_) {
        result.ok = false;
        return result;
      }
    }
    diags_ = &diags;
    stats_ = &stats;
    for (const ir::Node &n : module.root.children)
      if (n.kind == ir::Kind::Tool)
        tools_[n.symbol] = &n;
    visit(module.root);
    if (machine_)
      travel(module);
    result.ok = errors_ == 0;
    return result;
  }

private:
  void visit(const ir::Node &node) {
    for (const ir::Node &child : node.children) {
      if (ir::isOperation(child.kind))
        operation(child);
      visit(child);
    }
  }

  /// Reports `message` at `at` (its origin): an error, or a warning when
  /// out-of-range values are allowed.
  void outOfRange(const ir::Node &at, const std::string &message) {
    if (allow_) {
      diags_->warning(at.origin.loc, message + " (allowed by --allow-out-of-range)").entity(at.origin.entityId);
    } else {
      diags_->error(at.origin.loc, message + "; --allow-out-of-range makes it a warning").entity(at.origin.entityId);
      ++errors_;
    }
    ++(*stats_)["values out of range"];
  }

  void operation(const ir::Node &op) {
    const ir::Node *tech = op.child(ir::Kind::Technology);
    if (!tech)
      return;
    const ir::Node &at = tech->origin.loc.valid() ? *tech : op;
    const std::string subject = op.kindName() + " '" + op.label + "'";
    const ir::Node *tool = nullptr;
    if (auto symbol = op.text("tool"))
      if (auto it = tools_.find(*symbol); it != tools_.end())
        tool = it->second;
    const double diameter = tool ? tool->number("diameter").value_or(0) : 0;

    if (auto spindle = tech->number("spindle"); spindle && *spindle != 0) {
      const double n = std::abs(*spindle);
      const std::string value = subject + ": spindle speed " + formatTrimmed(n, 3) + " rev/min";
      if (machine_ && n > machine_->spindleMax + kSlack)
        outOfRange(at, value + " is above the machine's maximum " + formatTrimmed(machine_->spindleMax, 3) +
                           " rev/min (" + machine_->name + ")");
      else if (machine_ && n < machine_->spindleMin - kSlack)
        outOfRange(at, value + " is below the machine's minimum " + formatTrimmed(machine_->spindleMin, 3) +
                           " rev/min (" + machine_->name + ")");
      else if (!machine_ && n > ir::kPlausibleMaxSpindleRpm)
        outOfRange(at, value + " is above " + formatTrimmed(ir::kPlausibleMaxSpindleRpm, 3) +
                           " rev/min, more than any spindle stepnc knows turns (without --machine)");
      else if (!machine_ && n < ir::kPlausibleMinSpindleRpm - kSlack)
        outOfRange(at, value + " is below " + formatTrimmed(ir::kPlausibleMinSpindleRpm, 3) +
                           " rev/min, slower than a spindle turns to cut (the file may use another unit: "
                           "--spindle-unit)");
    }
    if (auto feed = tech->number("feed"); feed && *feed > 0) {
      const std::string value = subject + ": feed " + formatTrimmed(*feed, 3) + " mm/min";
      if (*feed < ir::kPlausibleMinFeedMmPerMin - kSlack) {
        outOfRange(at, value + " is below " + formatTrimmed(ir::kPlausibleMinFeedMmPerMin, 3) +
                           " mm/min, slower than any machine is programmed to feed (the file may use another "
                           "unit: --feed-unit)");
      } else if (machine_) {
        const double limit = machineFeed();
        if (limit > 0 && *feed > limit + kSlack)
          outOfRange(at, value + " is above the " + formatTrimmed(limit, 3) + " mm/min the machine feeds at most (" +
                             machine_->name + ", " + (machine_->maxFeed ? "its controller's max_feed" : "its fastest axis") +
                             ")");
      } else if (*feed > ir::kPlausibleMaxFeedMmPerMin) {
        outOfRange(at, value + " is above " + formatTrimmed(ir::kPlausibleMaxFeedMmPerMin, 3) +
                           " mm/min, faster than any machine stepnc knows feeds (without --machine)");
      }
    }
    if (auto vc = tech->number("cutting_speed"); vc && *vc / 1000 > ir::kPlausibleMaxCuttingSpeedMPerMin)
      outOfRange(at, subject + ": cutting speed " + formatTrimmed(*vc / 1000, 3) + " m/min is above " +
                         formatTrimmed(ir::kPlausibleMaxCuttingSpeedMPerMin, 3) + " m/min, more than any tool cuts at");
    if (auto fz = tech->number("feed_per_tooth"); fz && diameter > 0 &&
                                                  *fz > ir::kPlausibleChipLoadShare * diameter + kSlack)
      outOfRange(at, subject + ": feed per tooth " + formatTrimmed(*fz, 4) + " mm is above " +
                         formatTrimmed(ir::kPlausibleChipLoadShare * diameter, 3) + " mm, a tenth of the tool's diameter " +
                         formatTrimmed(diameter, 3) + " mm (tool " + tool->symbol + ")");
  }

  /// The fastest feed of the machine, mm/min: the controller's max_feed,
  /// else the fastest of its linear axes.
  double machineFeed() const {
    if (machine_->maxFeed)
      return *machine_->maxFeed;
    double fastest = 0;
    for (const runtime::Axis &a : machine_->axes)
      if (!a.rotary)
        fastest = std::max(fastest, a.velocity);
    return fastest;
  }

  /// The program's extent on x, y and z against each axis's travel: where
  /// the extent first grows past it, the workingstep is reported (once
  /// per axis).
  void travel(const ir::Module &module) {
    static constexpr std::array<const char *, 3> kNames = {"x", "y", "z"};
    std::array<double, 3> lo{}, hi{}, length{};
    std::array<bool, 3> reported{};
    for (int k = 0; k < 3; ++k) {
      const int index = machine_->axisIndex(kNames[static_cast<size_t>(k)]);
      length[static_cast<size_t>(k)] =
          index < 0 ? -1 : machine_->axes[static_cast<size_t>(index)].travelMax -
                               machine_->axes[static_cast<size_t>(index)].travelMin;
    }
    bool first = true;
    ir::Vec3 at = ir::Vec3::Zero();
    for (const ir::Node *e : ir::programOrder(module)) {
      const ir::Node *moves = e->child(ir::Kind::Moves);
      if (!moves)
        continue;
      for (const ir::Move &m : ir::walkMoves(*moves, at)) {
        at = m.to;
        for (size_t k = 0; k < 3; ++k) {
          lo[k] = first ? m.to[static_cast<int>(k)] : std::min(lo[k], m.to[static_cast<int>(k)]);
          hi[k] = first ? m.to[static_cast<int>(k)] : std::max(hi[k], m.to[static_cast<int>(k)]);
          if (!reported[k] && length[k] >= 0 && hi[k] - lo[k] > length[k] + kSlack) {
            reported[k] = true;
            outOfRange(*e, e->kindName() + " " + e->symbol + ": the program spans " + formatFixed(hi[k] - lo[k], 3) +
                               " mm on " + kNames[k] + " by here, more than the axis's travel of " +
                               formatFixed(length[k], 3) + " mm (" + machine_->name + "): no work offset fits it");
          }
        }
        first = false;
      }
    }
  }

  std::string machineSpec_;
  bool allow_ = false;
  std::unique_ptr<SourceFile> machineFile_;
  std::optional<runtime::Machine> machine_;
  std::map<std::string, const ir::Node *, std::less<>> tools_;
  DiagnosticEngine *diags_ = nullptr;
  PassStats *stats_ = nullptr;
  long long errors_ = 0;
};

} // namespace

std::unique_ptr<Pass> createCheckLimitsPass(const PassOptions &options) {
  return std::make_unique<CheckLimitsPass>(options.text("machine"), options.flag("allow-out-of-range"));
}

} // namespace stepnc::passes
