#include "ir/motion/LathePlan.h"

#include "geom/ArcPlane.h"
#include "ir/Program.h"
#include "ir/geom/MoveWalk.h"
#include "ir/geom/TurnedShape.h"
#include "ir/motion/LatheSpindle.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace stepnc::ir {

namespace {

using runtime::PathMove;
using runtime::Vec3;

/// How much the spindle's asked speed may change over one piece of a cut
/// at constant surface speed (relative): the feed per revolution is held
/// within this below the programmed one.
constexpr double kSpindleStep = 0.02;
/// Re-plans allowed to slow cuts and add waits for the spindle.
constexpr int kMaxRounds = 8;
/// The lathe's ZX plane: its coordinates (z, x, y) are the planner's.
constexpr geom::ArcPlane kZX{1};

/// How a move sets the spindle.
enum class Drive : uint8_t {
  Free,    ///< a rapid or a dwell: the spindle goes where the next cut needs it
  Driven,  ///< a cut: the speed its step asks where the tool is
  Thread,  ///< a thread pass: the step's speed, synchronised
};

/// One move to plan, before the waits and slow-downs of a round.
struct Item {
  PathMove move;  ///< in the frame (z, x, y)
  const Node *owner = nullptr, *node = nullptr;
  Drive drive = Drive::Free;
  size_t spindle = 0;  ///< the step's LatheSpindle
  double scale = 1;    ///< of its feed, to let the spindle keep up
  double wait = 0;     ///< s to wait before it for the spindle
};

/// A point of a move `t` (0..1) of the way along it, in IR coordinates.
Vec3 along(const Move &m, double t) { return t >= 1 ? m.to : m.pointAt(t * m.length()); }

/// The lowest and highest speed `spindle` asks over the part [t0, t1] of a
/// cut, from samples (and the axis, where a line crosses it).
std::pair<double, double> spindleRange(const Move &m, const LatheSpindle &spindle, double t0, double t1) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  auto take = [&](double t) {
    const double n = spindle.at(along(m, t).x());
    lo = std::min(lo, n);
    hi = std::max(hi, n);
  };
  constexpr int kSamples = 8;
  for (int k = 0; k <= kSamples; ++k)
    take(t0 + (t1 - t0) * k / kSamples);
  if (m.kind != MoveKind::Arc) {
    const double x0 = along(m, t0).x(), x1 = along(m, t1).x();
    if ((x0 < 0) != (x1 < 0) && x0 != x1)
      take(t0 + (t1 - t0) * x0 / (x0 - x1));
  }
  return {lo, hi};
}

/// The pieces [t_k, t_k+1] of a cut over which the asked speed changes by
/// at most kSpindleStep, halving where it changes more.
void pieces(const Move &m, const LatheSpindle &spindle, double t0, double t1, int depth, std::vector<double> &ends) {
  const auto [lo, hi] = spindleRange(m, spindle, t0, t1);
  if (depth < 16 && lo > 0 && hi > lo * (1 + kSpindleStep)) {
    const double mid = (t0 + t1) / 2;
    pieces(m, spindle, t0, mid, depth + 1, ends);
    pieces(m, spindle, mid, t1, depth + 1, ends);
    return;
  }
  ends.push_back(t1);
}

class Planner {
public:
  Planner(const Module &module, const runtime::Machine &machine, const runtime::PlanOptions &options,
          DiagnosticEngine &diags)
      : module_(module), lathe_(machine), frame_(runtime::latheFrameMachine(machine)), options_(options),
        diags_(diags) {}

  std::optional<LathePlan> run() {
    if (!collect())
      return std::nullopt;
    LathePlan out;
    for (int round = 0;; ++round) {
      out.rounds = round + 1;
      out.program = path();
      out.trajectory = runtime::plan(out.program.path, frame_, options_);
      out.trajectory.frame = runtime::Frame::Zxy;
      if (!spindlePlan(out) || round == kMaxRounds)
        break;
    }
    if (!fixes_.empty()) {
      diags_.error(fixes_.front()->owner->origin.loc,
                   fixes_.front()->owner->kindName() + " " + fixes_.front()->owner->symbol +
                       ": the lathe motion planner could not fit the spindle's speed changes within its "
                       "acceleration (a bug in stepnc)")
          .entity(fixes_.front()->owner->origin.entityId);
      return std::nullopt;
    }
    if (!checkThreads(out))
      return std::nullopt;
    for (const Item &item : items_)
      out.spindleWaits += item.wait > 0;
    return out;
  }

private:
  static Vec3 frame(const Vec3 &p) { return kZX.local(p); }

  /// The items of every lathe step, in program order.
  bool collect() {
    std::optional<Vec3> position;
    bool stop = false, ok = true;
    std::string tool, setup;
    std::optional<double> rpm;
    std::vector<Item> leadingDwells;  // dwells before the first point named wait there
    for (const Node *e : programOrder(module_)) {
      if (e->kind == Kind::ProgramStop || e->kind == Kind::OptionalStop) {
        stop = true;
        continue;
      }
      const Node *moves = e->child(Kind::Moves);
      if (!moves)
        continue;
      if (!isTurningStep(*e) && !drillsOnTurningAxis(*e)) {
        diags_.error(e->origin.loc, e->kindName() + " " + e->symbol +
                                        " mills or drills off the spindle axis: the lathe \"" + lathe_.name +
                                        "\" plans turning steps and holes drilled on its axis only")
            .entity(e->origin.entityId);
        ok = false;
        continue;
      }
      const std::string t = moves->text("tool").value_or(""), s = moves->text("setup").value_or("");
      const double sp = moves->number("spindle").value_or(0);
      if (!items_.empty() && (t != tool || s != setup || !rpm || *rpm != sp))
        stop = true;
      tool = t;
      setup = s;
      rpm = sp;
      spindles_.push_back(LatheSpindle::of(*moves, lathe_));
      const size_t spindle = spindles_.size() - 1;
      bool afterThread = false;
      for (const Move &m : walkMoves(*moves, position, PathKind::Programmed, OutOfPlaneArcs::Exact)) {
        Item item;
        item.owner = e;
        item.node = m.node;
        item.spindle = spindle;
        item.move.stopBefore = stop || afterThread;
        stop = afterThread = false;
        if (m.kind == MoveKind::Dwell) {
          item.move.kind = PathMove::Kind::Dwell;
          item.move.dwellS = m.dwell;
          if (position) {
            item.move.to = frame(*position);
            items_.push_back(item);
          } else {
            leadingDwells.push_back(item);
          }
          continue;
        }
        if (m.kind == MoveKind::Arc && m.plane.normal != kZX.normal) {
          diags_.error(m.node->origin.loc, e->kindName() + " " + e->symbol + ": an arc in the " + m.plane.name() +
                                               " plane; a lathe's arcs turn in the ZX plane")
              .entity(e->origin.entityId);
          ok = false;
          continue;
        }
        if (!position) {
          start_ = frame(m.to);
          position = m.to;
          for (Item &d : leadingDwells) {
            d.move.to = start_;
            items_.push_back(d);
          }
          leadingDwells.clear();
        }
        Move walked = m;
        walked.from = *position;
        position = m.to;
        if (!m.isFeed()) {
          item.move.to = frame(m.to);
          items_.push_back(item);
          continue;
        }
        const LatheSpindle &ask = spindles_[spindle];
        const double perRev = m.node ? m.node->number("feed_per_rev").value_or(0) : 0;
        item.drive = Drive::Driven;
        if (m.feed > 0 || perRev <= 0) {  // a feed per minute (a drill): one piece
          add(item, walked, 1, m.feed);
          continue;
        }
        if (m.role == "thread") {
          item.drive = Drive::Thread;
          item.move.stopBefore = true;  // it starts at the spindle's index, from rest
          afterThread = true;
          add(item, walked, 1, perRev * std::abs(ask.constant));
          continue;
        }
        std::vector<double> ends;
        pieces(walked, ask, 0, 1, 0, ends);
        double t0 = 0;
        for (const double t1 : ends) {
          add(item, walked, t1, perRev * spindleRange(walked, ask, t0, t1).first);
          item.move.stopBefore = false;
          t0 = t1;
        }
      }
    }
    for (Item &d : leadingDwells) {  // a program of dwells alone waits at the origin
      d.move.to = start_;
      items_.push_back(d);
    }
    return ok && !failed_;
  }

  /// The piece of `m` that ends `t1` of the way along it (from where the one
  /// before ended) as an item at `feed` mm/min.
  void add(Item item, const Move &m, double t1, double feed) {
    if (!(feed > 0)) {
      // A feed of 0 would be planned as a rapid.
      const Node &ws = *item.owner;
      diags_.error(m.node ? m.node->origin.loc : ws.origin.loc,
                   ws.kindName() + " " + ws.symbol + ": a cut with a feed per revolution and the spindle at 0 rev/min")
          .entity(ws.origin.entityId);
      failed_ = true;
      return;
    }
    item.move.to = frame(t1 >= 1 ? m.to : along(m, t1));
    item.move.feed = feed;
    if (m.kind == MoveKind::Arc) {
      item.move.kind = PathMove::Kind::Arc;
      item.move.center = frame(m.center);
      item.move.ccw = m.ccw;
    }
    items_.push_back(item);
  }

  /// The path of this round: every item at its scaled feed, after its wait.
  ProgramPath path() {
    ProgramPath out;
    out.path.start = start_;
    itemOf_.clear();
    for (size_t k = 0; k < items_.size(); ++k) {
      const Item &item = items_[k];
      Vec3 at = out.path.moves.empty() ? start_ : out.path.moves.back().to;
      if (item.wait > 0) {
        PathMove wait;
        wait.kind = PathMove::Kind::Dwell;
        wait.to = at;
        wait.dwellS = item.wait;
        out.path.moves.push_back(wait);
        out.owners.push_back(item.owner);
        out.nodes.push_back(nullptr);
        itemOf_.push_back(std::nullopt);
      }
      PathMove m = item.move;
      m.feed *= item.scale;
      out.path.moves.push_back(m);
      out.owners.push_back(item.owner);
      out.nodes.push_back(item.node);
      itemOf_.push_back(k);
    }
    return out;
  }

  /// The spindle's speed a driven or thread segment asks at frame point `p`.
  double asked(const Item &item, const Vec3 &p) const {
    const LatheSpindle &ask = spindles_[item.spindle];
    return item.drive == Drive::Thread ? ask.constant : ask.signedAt(kZX.world(p).x());
  }

  /// The item a segment follows when it is driven (a blend between two
  /// moves of one step that are both driven is), else null.
  Item *drivenItem(const runtime::SegmentInfo &info) {
    const auto a = itemOf_.at(info.move), b = itemOf_.at(info.nextMove);
    if (!a || !b)
      return nullptr;
    Item &first = items_[*a], &second = items_[*b];
    if (first.drive == Drive::Free || second.drive == Drive::Free || first.spindle != second.spindle)
      return nullptr;
    return &first;
  }

  /// Writes the spindle onto every segment; notes the cuts to slow and the
  /// waits to add where the spindle cannot keep up. True when there were any
  /// (another round is needed).
  bool spindlePlan(LathePlan &plan) {
    fixes_.clear();
    runtime::Trajectory &t = plan.trajectory;
    const double accel = lathe_.spindleAcceleration.value_or(std::numeric_limits<double>::infinity());  // rev/min/s
    double last = 0;      // the speed where the last driven segment ended (at rest before the first)
    size_t freeFrom = 0;  // the first segment of the free stretch since then
    double freeTime = 0;
    auto ramp = [&](size_t to, double target) {
      // Linear in time over the free stretch [freeFrom, to).
      double at = 0;
      for (size_t i = freeFrom; i < to; ++i) {
        const double d = t.profiles[i].duration();
        t.info[i].spindle0 = freeTime > 0 ? last + (target - last) * at / freeTime : target;
        at += d;
        t.info[i].spindle1 = freeTime > 0 ? last + (target - last) * at / freeTime : target;
      }
    };
    for (size_t i = 0; i < t.segments.size(); ++i) {
      runtime::SegmentInfo &info = t.info[i];
      Item *item = drivenItem(info);
      if (!item) {
        freeTime += t.profiles[i].duration();
        continue;
      }
      const double n0 = asked(*item, t.segments[i].start), n1 = asked(*item, t.segments[i].end);
      const double duration = t.profiles[i].duration();
      if (std::abs(n0 - last) > accel * freeTime * (1 + 1e-9) + 1e-9) {
        // The spindle cannot get there over the free stretch: wait before
        // the cut's move for what is missing.
        Item &cut = items_[*itemOf_.at(info.move)];
        cut.wait += (std::abs(n0 - last) / accel - freeTime) * 1.01 + 1e-3;
        note(cut);
      }
      if (std::abs(n1 - n0) > accel * duration * (1 + 1e-9) + 1e-9) {
        // Slowed so that its time lets the spindle follow.
        Item &cut = items_[*itemOf_.at(info.move)];
        cut.scale *= 0.97 * accel * duration / std::abs(n1 - n0);
        note(cut);
      }
      ramp(i, n0);
      info.spindle0 = n0;
      info.spindle1 = n1;
      info.sync = item->drive == Drive::Thread;
      last = n1;
      freeFrom = i + 1;
      freeTime = 0;
    }
    ramp(t.segments.size(), last);
    return !fixes_.empty();
  }

  void note(Item &item) {
    if (std::find(fixes_.begin(), fixes_.end(), &item) == fixes_.end())
      fixes_.push_back(&item);
  }

  /// Each thread pass moves at its feed per revolution times the spindle's
  /// speed (an error when the z axis cannot) and gets there within two
  /// leads of its ends (a warning when not).
  bool checkThreads(const LathePlan &plan) {
    const runtime::Trajectory &t = plan.trajectory;
    bool ok = true;
    std::set<const Node *> refused;
    for (size_t i = 0; i < t.segments.size(); ++i) {
      const runtime::SegmentInfo &info = t.info[i];
      if (!info.sync)
        continue;
      const Item &item = items_[*itemOf_.at(info.move)];
      const Node &ws = *item.owner;
      const double lead = item.node ? item.node->number("feed_per_rev").value_or(0) : 0;
      const std::string what = ws.kindName() + " " + ws.symbol + ": a thread pass of lead " + formatFixed(lead, 4) +
                               " mm at " + formatFixed(std::abs(info.spindle0), 0) + " rev/min";
      // Located at the move when the file gave it (explicit toolpaths), else at the step.
      const SourceLoc at = item.node && item.node->origin.loc.valid() ? item.node->origin.loc : ws.origin.loc;
      if (info.limits.v < info.feed * (1 - 1e-9)) {
        ok = false;
        if (!refused.insert(&ws).second)
          continue;  // once a step
        diags_.error(at,
                     what + " moves " + formatFixed(info.feed * 60, 1) + " mm/min; the lathe \"" + lathe_.name +
                         "\" reaches " + formatFixed(info.limits.v * 60, 1) + " mm/min on it (" +
                         std::string(runtime::speedLimitDescription(info.limitedBy)) + "): give the step a lower spindle speed")
            .entity(ws.origin.entityId);
        continue;
      }
      const runtime::Profile &p = t.profiles[i];
      const double speedUp = p.phases[0].duration + p.phases[1].duration + p.phases[2].duration;
      const double reached = p.at(speedUp).s, left = t.segments[i].length - p.at(speedUp + p.phases[3].duration).s;
      if ((reached > 2 * lead + 1e-9 || left > 2 * lead + 1e-9) && !warned_) {
        warned_ = true;
        diags_.warning(at,
                       what + " reaches its feed " + formatFixed(reached, 3) + " mm after its start and leaves it " +
                           formatFixed(left, 3) + " mm before its end, beyond two leads (" + formatFixed(2 * lead, 3) +
                           " mm): the turns cut there have a shorter lead")
            .entity(ws.origin.entityId);
      }
    }
    return ok;
  }

  const Module &module_;
  const runtime::Machine &lathe_;
  const runtime::Machine frame_;
  runtime::PlanOptions options_;
  DiagnosticEngine &diags_;
  std::vector<LatheSpindle> spindles_;
  std::vector<Item> items_;
  Vec3 start_ = Vec3::Zero();
  std::vector<std::optional<size_t>> itemOf_;  ///< per planned move: its item (none for a wait)
  std::vector<Item *> fixes_;
  bool warned_ = false;
  bool failed_ = false;
};

} // namespace

std::optional<LathePlan> planLathe(const Module &module, const runtime::Machine &machine,
                                   const runtime::PlanOptions &options, DiagnosticEngine &diags) {
  return Planner(module, machine, options, diags).run();
}

} // namespace stepnc::ir
