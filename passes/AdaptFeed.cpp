// adapt-feed: programs, move by move, the feed the cut can take and the
// machine can follow (docs/feed-adaptation.md).
//
// On the cutting model of the program (passes/CuttingModel), each
// horizontal milling move gets, at every sample along it, the largest feed
// per tooth that keeps
//   - the maximum chip thickness at the material's target h* (chip
//     thinning: h_max = fz x the engagement's chip factor),
//   - the peak cutting force within the tool's limit,
//   - the mean torque within the spindle's torque and power (with a machine),
// and never above the programmed feed unless allow-increase=true (in air,
// never). Moves are split where that feed changes by more than 8 %; each
// piece takes the lowest feed of its samples. With a machine, the program
// is then planned (runtime/Planner) and no feed stays above the speed the
// machine can hold on its move: a feed it cannot reach only hides the truth. Figures before and after go to the `moves`
// comments and the
// `--stats` report.
#include "passes/CuttingModel.h"
#include "ir/Plausible.h"
#include "ir/Program.h"
#include "passes/CuttingPass.h"
#include "ir/motion/MotionIR.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace stepnc::passes {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// What a piece costs in adapt-feed's grouping of samples, as mm of cut
/// at no feed: a piece more is worth it where it gains at least that.
constexpr double kPieceCost = 0.25;
/// Rounds of capping feeds at what the machine reaches (each plans the program).
constexpr int kCapRounds = 64;

enum class Limit { Chip, Force, Spindle, Programmed, Air, Ceiling };
constexpr Limit kLimits[] = {Limit::Chip, Limit::Force, Limit::Spindle, Limit::Programmed, Limit::Air, Limit::Ceiling};
const char *limitName(Limit l) {
  switch (l) {
  case Limit::Chip:
    return "chip thickness";
  case Limit::Force:
    return "tool force";
  case Limit::Spindle:
    return "spindle torque/power";
  case Limit::Programmed:
    return "programmed feed";
  case Limit::Air:
    return "air (programmed feed kept)";
  case Limit::Ceiling:
    return "feed ceiling";
  }
  return "";
}

struct Piece {
  double from = 0, to = 0; ///< mm along the move
  double fz = 0;
  Limit limit = Limit::Programmed;
};

/// Per workingstep: what the report shows.
struct StepFigures {
  double timeBefore = 0, timeAfter = 0;
  double chipBefore = 0, chipAfter = 0;     ///< mm
  double forceBefore = 0, forceAfter = 0;   ///< N
  double torqueBefore = 0, torqueAfter = 0; ///< N m
  std::map<Limit, double> limitedLength;    ///< mm of measured moves per limit
  int split = 0;
};

class AdaptFeedPass final : public CuttingPass {
public:
  AdaptFeedPass(std::string machine, std::string data, bool allowIncrease)
      : CuttingPass(std::move(data)), machineSpec_(std::move(machine)), allowIncrease_(allowIncrease) {}

  std::string_view name() const override { return "adapt-feed"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    if (!takes(module, diags, "its feeds"))
      return {false, false};
    const auto data = start(diags);
    if (!data)
      return {false, false};
    std::optional<runtime::Machine> machine;
    if (!machineSpec_.empty()) {
      machine = runtime::loadMachine(machineSpec_, machineFile_, diags);
      if (!machine)
        return {false, false};
    }
    CutOptions options{&*data, machine ? &*machine : nullptr};
    // The planner moves a milling tool in x, y, z: on a lathe (or a generic
    // chain) the feeds are not bounded by a plan, nor the steps timed here
    // (plan-motion and sim plan and time a lathe's steps in its ZX plane).
    std::optional<runtime::Machine> planned = machine;
    if (machine && !machine->whyNotThreeAxis().empty()) {
      planned.reset();
      notPlanned_ = true;
      report_.push_back("the machine \"" + machine->name + "\" is no 3-axis mill: feeds not bounded by its dynamics "
                        "here and steps not timed (plan-motion and sim do, docs/turning.md for a lathe)");
    }
    const CutAnalysis before = analyseCuts(module, options);
    const std::map<const ir::Node *, double> timeBefore = stepTimes(module, planned);

    std::map<const ir::Node *, StepFigures> figures;
    long long split = 0, lowered = 0, raised = 0;
    for (const CutStep &step : before.steps) {
      StepFigures &f = figures[step.executable];
      f.timeBefore = timeBefore.count(step.executable) ? timeBefore.at(step.executable) : 0;
      std::map<const ir::Node *, std::vector<Piece>> pieces;
      for (const CutMove &cm : step.moves) {
        if (!cm.measured || cm.samples.empty())
          continue;
        std::vector<Piece> ps = plan(cm, step);
        for (const Piece &p : ps)
          f.limitedLength[p.limit] += p.to - p.from;
        for (const CutSample &s : cm.samples) {
          f.chipBefore = std::max(f.chipBefore, cm.fz * s.chipFactor);
          f.forceBefore = std::max(f.forceBefore, s.force);
          f.torqueBefore = std::max(f.torqueBefore, s.torque);
        }
        pieces[cm.move.node] = std::move(ps);
      }
      // Rewrite the step's moves.
      auto *movesNode = const_cast<ir::Node *>(step.movesNode);
      std::vector<ir::Node> children;
      children.reserve(movesNode->children.size());
      size_t cursor = 0;
      for (ir::Node &child : movesNode->children) {
        const CutMove *cm = step.moveOf(child, cursor);
        auto it = cm ? pieces.find(cm->move.node) : pieces.end();
        if (it == pieces.end()) {
          children.push_back(std::move(child));
          continue;
        }
        const std::vector<Piece> &ps = it->second;
        split += (long long)ps.size() - 1;
        f.split += int(ps.size()) - 1;
        for (size_t i = 0; i < ps.size(); ++i) {
          ir::Node piece = child;
          double feed =
              ps[i].limit == Limit::Programmed || ps[i].limit == Limit::Air ? cm->move.feed : cm->feedFor(ps[i].fz);
          if (!allowIncrease_)
            feed = std::min(feed, cm->move.feed);
          lowered += feed < cm->move.feed;
          raised += feed > cm->move.feed;
          piece.set("feed", ir::Value::feed(feed));
          if (i + 1 < ps.size())
            piece.set("to", ir::Value::point(cm->move.pointAt(ps[i].to)));
          children.push_back(std::move(piece));
        }
      }
      movesNode->children = std::move(children);
    }

    // The pieces measured on their own samples (the engagement between the
    // samples the feeds were chosen on): any still over a limit is lowered.
    const long long rechecked = lowerOverLimits(module, options);
    lowered += rechecked;

    // What the machine reaches with these feeds bounds them.
    // Lower feeds change the plan (blends, look-ahead), and so what the
    // machine reaches: cap again until the plan reaches every feed left.
    long long dynamics = 0;
    for (int round = 0; planned && round < kCapRounds; ++round) {
      const long long capped = capByDynamics(module, *planned);
      dynamics += capped;
      if (capped == 0)
        break;
    }

    const CutAnalysis after = analyseCuts(module, options);
    const std::map<const ir::Node *, double> timeAfter = stepTimes(module, planned);
    for (const CutStep &step : after.steps) {
      StepFigures &f = figures[step.executable];
      f.timeAfter = timeAfter.count(step.executable) ? timeAfter.at(step.executable) : 0;
      for (const CutMove &cm : step.moves)
        for (const CutSample &s : cm.samples) {
          f.chipAfter = std::max(f.chipAfter, cm.fz * s.chipFactor);
          f.forceAfter = std::max(f.forceAfter, s.force);
          f.torqueAfter = std::max(f.torqueAfter, s.torque);
        }
      if (step.tool && step.tool->mill && f.limitedLength.size())
        writeComment(*const_cast<ir::Node *>(step.movesNode), f, planned.has_value());
    }
    writeReport(before, after, figures, planned ? planned->name : std::string());

    double total0 = 0, total1 = 0;
    for (const auto &[exec, f] : figures) {
      total0 += f.timeBefore;
      total1 += f.timeAfter;
    }
    stats["moves split"] = split;
    stats["feeds lowered"] = lowered;
    stats["feeds raised"] = raised;
    stats["feeds capped by machine dynamics"] = dynamics;
    if (planned) {
      stats["cycle time before (ms)"] = (long long)std::llround(total0 * 1000);
      stats["cycle time after (ms)"] = (long long)std::llround(total1 * 1000);
    }
    return {true, split + lowered + raised + dynamics > 0};
  }

private:
  /// The feed per tooth a sample wants, and what sets it.
  struct Want {
    double fz;
    Limit limit;
  };
  /// Consecutive samples that share one feed: the lowest they want.
  struct Group {
    size_t first, last; ///< samples
    Want want;
  };

  /// Splits a move's samples into groups, each at the lowest feed its
  /// samples want, so that every sample keeps at least kFeedRatio of the
  /// feed it wants and, within that, the feed given away (each sample's
  /// share of the length times the fraction of its feed lost) plus
  /// kPieceCost per group is least. A greedy run would let a slope into a
  /// corner pull the whole wall before it down to the corner's feed. A move
  /// with whole turns (a circle at depth) is one group.
  static std::vector<Group> groupSamples(const CutMove &cm, const std::vector<Want> &wants) {
    const size_t n = wants.size();
    if (cm.move.turns != 0)
      return {Group{0, n - 1, *std::min_element(wants.begin(), wants.end(), [](const Want &a, const Want &b) {
                      return a.fz < b.fz;
                    })}};
    // Each sample stands for the length halfway to its neighbours.
    std::vector<double> share(n);
    for (size_t k = 0; k < n; ++k)
      share[k] = (k + 1 < n ? cm.samples[k + 1].s : cm.move.length()) / 2 - (k > 0 ? cm.samples[k - 1].s : 0) / 2;
    // best[j]: least cost of samples [0, j); from[j]: where its last group starts.
    std::vector<double> best(n + 1, kInf);
    std::vector<size_t> from(n + 1, 0);
    best[0] = 0;
    for (size_t j = 1; j <= n; ++j) {
      double lo = kInf, hi = 0, length = 0, perFeed = 0;
      for (size_t i = j; i-- > 0;) {
        lo = std::min(lo, wants[i].fz);
        hi = std::max(hi, wants[i].fz);
        if (lo < kFeedRatio * hi)
          break;
        length += share[i];
        perFeed += share[i] / wants[i].fz;
        // Lost: sum of share x (1 - lo / want).
        const double cost = best[i] + (length - lo * perFeed) + kPieceCost;
        if (cost < best[j]) {
          best[j] = cost;
          from[j] = i;
        }
      }
    }
    std::vector<Group> groups;
    for (size_t j = n; j > 0; j = from[j]) {
      Group g{from[j], j - 1, wants[j - 1]};
      for (size_t k = g.first; k <= g.last; ++k)
        if (wants[k].fz < g.want.fz)
          g.want = wants[k];
      groups.push_back(g);
    }
    std::reverse(groups.begin(), groups.end());
    return groups;
  }

  /// Pieces of one measured move with their feed per tooth.
  std::vector<Piece> plan(const CutMove &cm, const CutStep &step) const {
    const double hStar = step.material->chipThickness;
    std::vector<Want> wants;
    for (const CutSample &s : cm.samples) {
      Want w{kInf, Limit::Chip};
      if (s.chipFactor <= 0) {
        wants.push_back({cm.fz, Limit::Air});
        continue;
      }
      w.fz = hStar / s.chipFactor;
      if (s.fzForce < w.fz)
        w = {s.fzForce, Limit::Force};
      if (s.fzTorque < w.fz)
        w = {s.fzTorque, Limit::Spindle};
      if (!allowIncrease_ && cm.fz <= w.fz)
        w = {cm.fz, Limit::Programmed};
      // An increase stops at the fastest feed stepnc writes: a grazing
      // sample's chip factor near 0 would otherwise ask for any feed at all.
      if (const double ceiling = std::max(cm.fz, cm.fz * ir::kPlausibleMaxFeedMmPerMin / cm.move.feed);
          w.fz > ceiling)
        w = {ceiling, Limit::Ceiling};
      wants.push_back(w);
    }
    const std::vector<Group> groups = groupSamples(cm, wants);
    // Between two groups the engagement is known only at their samples: the
    // stretch between them goes to the group with the lower feed, which
    // suits the samples at both its ends. Each piece so keeps its own feed.
    auto boundary = [&](size_t g) { // mm along the move, between groups g and g + 1
      return groups[g].want.fz <= groups[g + 1].want.fz ? cm.samples[groups[g + 1].first].s
                                                        : cm.samples[groups[g].last].s;
    };
    std::vector<Piece> out;
    for (size_t g = 0; g < groups.size(); ++g) {
      Piece p;
      p.from = g == 0 ? 0 : boundary(g - 1);
      p.to = g + 1 == groups.size() ? cm.move.length() : boundary(g);
      p.fz = groups[g].want.fz;
      p.limit = groups[g].want.limit;
      // A group above both its neighbours that has only one sample gives
      // its place to them.
      if (p.to - p.from <= 1e-9)
        continue;
      // Pieces with the same feed are one.
      if (!out.empty() && out.back().fz == p.fz && out.back().limit == p.limit)
        out.back().to = p.to;
      else
        out.push_back(p);
    }
    return out;
  }

  /// Lowers the feed of every measured move whose chip, force or torque is
  /// over its limit at one of its samples; how many were.
  static long long lowerOverLimits(ir::Module &module, const CutOptions &options) {
    long long count = 0;
    for (const CutStep &step : analyseCuts(module, options).steps)
      for (const CutMove &cm : step.moves) {
        if (!cm.measured || !step.material)
          continue;
        double want = kInf;
        for (const CutSample &s : cm.samples)
          if (s.chipFactor > 0)
            want = std::min({want, step.material->chipThickness / s.chipFactor, s.fzForce, s.fzTorque});
        if (want >= cm.fz)
          continue;
        const_cast<ir::Node *>(cm.move.node)->set("feed", ir::Value::feed(cm.feedFor(want)));
        ++count;
      }
    return count;
  }

  /// Seconds per executable of the program as planned on the machine.
  static std::map<const ir::Node *, double> stepTimes(const ir::Module &module,
                                                      const std::optional<runtime::Machine> &machine) {
    std::map<const ir::Node *, double> out;
    if (!machine)
      return out;
    const ir::ProgramPath program = ir::programPath(module);
    if (program.path.moves.empty())
      return out;
    const runtime::Trajectory t = runtime::plan(program.path, *machine);
    for (size_t k = 0; k < t.segments.size(); ++k)
      out[program.owners[t.info[k].move]] += t.profiles[k].duration();  // dwells too
    return out;
  }

  /// Lowers every feed above the highest speed the machine reaches on its
  /// move in the plan of the program (the runtime's simulated actual feed:
  /// axis velocities, acceleration and jerk on the path's curvature, the
  /// controller's max feed, and on a short move what it gets to between
  /// speeding up and slowing down); how many were.
  static long long capByDynamics(ir::Module &module, const runtime::Machine &machine) {
    const ir::ProgramPath program = ir::programPath(module);
    if (program.path.moves.empty())
      return 0;
    const runtime::Trajectory t = runtime::plan(program.path, machine);
    std::vector<double> peak(program.path.moves.size(), 0);
    for (size_t k = 0; k < t.segments.size(); ++k)
      peak[t.info[k].move] = std::max(peak[t.info[k].move], t.profiles[k].peak() * 60);
    long long capped = 0;
    for (size_t k = 0; k < program.nodes.size(); ++k) {
      // A step that tilts the tool moves joints the 3-axis plan does not
      // see: its feeds stay as programmed (the warning says so).
      if (program.owners[k] && ir::tiltsTool(*program.owners[k]))
        continue;
      auto *node = const_cast<ir::Node *>(program.nodes[k]);
      const std::optional<double> feed = node->kind == ir::Kind::Rapid ? std::nullopt : node->number("feed");
      if (!feed || *feed <= 0 || *feed <= peak[k])
        continue;
      // Feeds are whole mm/min: one within a unit of the peak is reached.
      const double reached = std::max(1.0, std::floor(peak[k]));
      if (*feed - peak[k] <= 1)
        continue;
      node->set("feed", ir::Value::feed(reached));
      ++capped;
    }
    return capped;
  }

  void writeComment(ir::Node &movesNode, const StepFigures &f, bool timed) {
    std::string text = "adapt-feed: h_max " + formatFixed(f.chipBefore, 3) + " -> " + formatFixed(f.chipAfter, 3) +
                       " mm, F_max " + formatFixed(f.forceBefore, 0) + " -> " + formatFixed(f.forceAfter, 0) + " N";
    if (timed)
      text += ", time " + formatFixed(f.timeBefore, 2) + " -> " + formatFixed(f.timeAfter, 2) + " s";
    ir::replaceCommentPart(movesNode, {"adapt-feed:"}, text);
  }

  void writeReport(const CutAnalysis &before, const CutAnalysis &after,
                   const std::map<const ir::Node *, StepFigures> &figures, const std::string &machineName) {
    for (const std::string &note : before.notes)
      report_.push_back(note);
    for (const auto &[symbol, tool] : before.tools) {
      if (!tool.mill || tool.defaulted.empty())
        continue;
      std::string line = "tool " + symbol + " defaulted:";
      for (size_t i = 0; i < tool.defaulted.size(); ++i)
        line += (i ? ", " : " ") + tool.defaulted[i];
      report_.push_back(line);
    }
    if (!machineName.empty())
      report_.push_back("cycle times planned on " + machineName);
    else if (!notPlanned_)  // a machine the planner does not move said so already
      report_.push_back("no machine: feeds not bounded by machine dynamics or spindle; no cycle times "
                        "(give adapt-feed<machine=...> or --machine)");
    report_.push_back("workingstep: time before -> after (s), h_max before -> "
                      "after (mm), F_max before -> after (N), "
                      "feed limited by (share of cutting length)");
    for (const CutStep &step : after.steps) {
      const auto it = figures.find(step.executable);
      if (it == figures.end() || !step.tool || !step.tool->mill)
        continue;
      const StepFigures &f = it->second;
      double total = 0;
      for (const auto &[l, len] : f.limitedLength)
        total += len;
      if (total <= 0)
        continue;
      std::string limits;
      for (Limit l : kLimits)
        if (auto li = f.limitedLength.find(l); li != f.limitedLength.end() && li->second > 0)
          limits += (limits.empty() ? "" : ", ") + std::string(limitName(l)) + " " +
                    formatFixed(100 * li->second / total, 0) + " %";
      const std::string name = step.executable->symbol.empty() ? step.executable->kindName() : step.executable->symbol;
      report_.push_back("  " + name + ": " +
                        (machineName.empty() ? std::string("-")
                                             : formatFixed(f.timeBefore, 2) + " -> " + formatFixed(f.timeAfter, 2)) +
                        ", " + formatFixed(f.chipBefore, 3) + " -> " + formatFixed(f.chipAfter, 3) + ", " +
                        formatFixed(f.forceBefore, 0) + " -> " + formatFixed(f.forceAfter, 0) + ", " + limits +
                        (f.split ? ", " + std::to_string(f.split) + " splits" : ""));
    }
  }

  std::string machineSpec_;
  bool notPlanned_ = false;  ///< a machine given that the planner does not move (a lathe)
  bool allowIncrease_ = false;
  std::unique_ptr<SourceFile> machineFile_;
};

} // namespace

std::unique_ptr<Pass> createAdaptFeedPass(const PassOptions &options) {
  return std::make_unique<AdaptFeedPass>(options.text("machine"), options.text("data"),
                                         options.flag("allow-increase"));
}

} // namespace stepnc::passes
