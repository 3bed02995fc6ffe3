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
#include "passes/CuttingPass.h"
#include "passes/MotionIR.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace stepnc::passes {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Samples whose feeds differ by less than this ratio share a piece.
constexpr double kPieceRatio = 0.92;
/// Rounds of capping feeds at what the machine reaches (each plans the program).
constexpr int kCapRounds = 8;

enum class Limit { Chip, Force, Spindle, Programmed, Air };
constexpr Limit kLimits[] = {Limit::Chip, Limit::Force, Limit::Spindle, Limit::Programmed, Limit::Air};
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
  AdaptFeedPass(std::string machine, std::string data, bool allowIncrease, std::string error)
      : CuttingPass(std::move(data), std::move(error)), machineSpec_(std::move(machine)),
        allowIncrease_(allowIncrease) {}

  std::string_view name() const override { return "adapt-feed"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
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
    const CutAnalysis before = analyseCuts(module, options);
    const std::map<const ir::Node *, double> timeBefore = stepTimes(module, machine);

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
          double feed = ps[i].limit == Limit::Programmed || ps[i].limit == Limit::Air
                            ? cm->move.feed
                            : cm->feedFor(ps[i].fz);
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

    // What the machine reaches with these feeds bounds them.
    // Lower feeds change the plan (blends, look-ahead), and so what the
    // machine reaches: cap again until the plan reaches every feed left.
    long long dynamics = 0;
    for (int round = 0; machine && round < kCapRounds; ++round) {
      const long long capped = capByDynamics(module, *machine);
      dynamics += capped;
      if (capped == 0)
        break;
    }

    const CutAnalysis after = analyseCuts(module, options);
    const std::map<const ir::Node *, double> timeAfter = stepTimes(module, machine);
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
        writeComment(*const_cast<ir::Node *>(step.movesNode), f, machine.has_value());
    }
    writeReport(before, after, figures, machine ? machine->name : std::string());

    double total0 = 0, total1 = 0;
    for (const auto &[exec, f] : figures) {
      total0 += f.timeBefore;
      total1 += f.timeAfter;
    }
    stats["moves split"] = split;
    stats["feeds lowered"] = lowered;
    stats["feeds raised"] = raised;
    stats["feeds capped by machine dynamics"] = dynamics;
    if (machine) {
      stats["cycle time before (ms)"] = (long long)std::llround(total0 * 1000);
      stats["cycle time after (ms)"] = (long long)std::llround(total1 * 1000);
    }
    return {true, split + lowered + raised + dynamics > 0};
  }

private:
  /// Pieces of one measured move with their feed per tooth.
  std::vector<Piece> plan(const CutMove &cm, const CutStep &step) const {
    const double hStar = step.material->chipThickness;
    struct Want {
      double fz;
      Limit limit;
    };
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
      wants.push_back(w);
    }
    // A move with whole turns (a circle at depth) is one piece.
    const bool splittable = cm.move.turns == 0;
    std::vector<Piece> out;
    size_t i = 0;
    while (i < wants.size()) {
      double lo = wants[i].fz, hi = wants[i].fz;
      Limit limit = wants[i].limit;
      size_t j = i + 1;
      for (; j < wants.size(); ++j) {
        const double l = std::min(lo, wants[j].fz), h = std::max(hi, wants[j].fz);
        if (splittable && l < kPieceRatio * h)
          break;
        if (wants[j].fz < lo)
          limit = wants[j].limit;
        lo = l;
        hi = h;
      }
      Piece p;
      p.from = out.empty() ? 0 : out.back().to;
      p.to = cm.pieceEnd(j);
      // The piece reaches halfway to the samples on either side, where the
      // engagement is not known: it must suit them too.
      if (i > 0 && wants[i - 1].fz < lo) {
        lo = wants[i - 1].fz;
        limit = wants[i - 1].limit;
      }
      if (j < wants.size() && wants[j].fz < lo) {
        lo = wants[j].fz;
        limit = wants[j].limit;
      }
      p.fz = lo;
      p.limit = limit;
      // Pieces with the same feed are one.
      if (!out.empty() && out.back().fz == p.fz && out.back().limit == p.limit)
        out.back().to = p.to;
      else
        out.push_back(p);
      i = j;
    }
    return out;
  }

  /// Seconds per executable of the program as planned on the machine.
  static std::map<const ir::Node *, double> stepTimes(const ir::Module &module,
                                                      const std::optional<runtime::Machine> &machine) {
    std::map<const ir::Node *, double> out;
    if (!machine)
      return out;
    const ProgramPath program = programPath(module);
    if (program.path.moves.empty())
      return out;
    const runtime::Trajectory t = runtime::plan(program.path, *machine);
    for (size_t k = 0; k < t.segments.size(); ++k)
      out[program.owners[t.info[k].move]] += t.profiles[k].duration();
    return out;
  }

  /// Lowers every feed above the highest speed the machine can hold on its
  /// move: the planner's speed cap there (axis velocities, acceleration and
  /// jerk on the path's curvature, the controller's max feed). The speed a
  /// short move actually reaches is lower still, but that is acceleration,
  /// not a feed to program: capping there would only slow the plan down.
  static long long capByDynamics(ir::Module &module, const runtime::Machine &machine) {
    const ProgramPath program = programPath(module);
    if (program.path.moves.empty())
      return 0;
    const runtime::Trajectory t = runtime::plan(program.path, machine);
    std::vector<double> peak(program.path.moves.size(), 0);
    for (size_t k = 0; k < t.segments.size(); ++k)
      peak[t.info[k].move] = std::max(peak[t.info[k].move], t.profiles[k].peak() * 60);
    long long capped = 0;
    for (size_t k = 0; k < program.nodes.size(); ++k) {
      auto *node = const_cast<ir::Node *>(program.nodes[k]);
      const std::optional<double> feed = node->kind == "rapid" ? std::nullopt : node->number("feed");
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
    report_.push_back(machineName.empty() ? std::string("no machine: feeds not bounded by machine dynamics "
                                                        "or spindle; no cycle times "
                                                        "(give adapt-feed<machine=...> or --machine)")
                                          : "cycle times planned on " + machineName);
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
      const std::string name = step.executable->symbol.empty() ? step.executable->kind : step.executable->symbol;
      report_.push_back("  " + name + ": " +
                        (machineName.empty() ? std::string("-")
                                             : formatFixed(f.timeBefore, 2) + " -> " + formatFixed(f.timeAfter, 2)) +
                        ", " + formatFixed(f.chipBefore, 3) + " -> " + formatFixed(f.chipAfter, 3) + ", " +
                        formatFixed(f.forceBefore, 0) + " -> " + formatFixed(f.forceAfter, 0) + ", " + limits +
                        (f.split ? ", " + std::to_string(f.split) + " splits" : ""));
    }
  }

  std::string machineSpec_;
  bool allowIncrease_ = false;
  std::unique_ptr<SourceFile> machineFile_;
};

} // namespace

std::unique_ptr<Pass> createAdaptFeedPass(const PassOptions &options) {
  std::string machine, data, error;
  bool allowIncrease = false;
  if (auto it = options.find("machine"); it != options.end())
    machine = it->second;
  if (auto it = options.find("data"); it != options.end())
    data = it->second;
  if (auto it = options.find("allow-increase"); it != options.end()) {
    if (it->second == "true")
      allowIncrease = true;
    else if (it->second != "false")
      error = "adapt-feed: allow-increase='" + it->second + "' must be true or false";
  }
  return std::make_unique<AdaptFeedPass>(std::move(machine), std::move(data), allowIncrease, std::move(error));
}

} // namespace stepnc::passes
