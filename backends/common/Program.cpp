#include "backends/common/Program.h"

#include "backends/common/Words.h"
#include "ir/Kinds.h"
#include "ir/Printer.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "support/Format.h"

#include <algorithm>
#include <map>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace stepnc::backends {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kSame = 1e-9;
/// How far a tool table's diameter may be from the STEP-NC tool's.
constexpr double kDiameterTolMm = 0.001;
constexpr double kMmPerInch = 25.4;

CycleKind cycleKindOf(const ir::Node &cycle) {
  const std::string type = cycle.text("type").value_or("");
  return type == "peck" ? CycleKind::Peck : type == "bore" ? CycleKind::Bore : type == "tap" ? CycleKind::Tap
                                                                                              : CycleKind::Drill;
}

/// The canned cycle expansion recorded (the IR verifier checked it).
HoleCycle holeCycle(const ir::Node &cycle, double secplane) {
  HoleCycle c;
  c.kind = cycleKindOf(cycle);
  const ir::Vec3 at = cycle.vec("at").value_or(ir::Vec3::Zero());
  c.at = at.head<2>();
  c.surfaceZ = at.z();
  c.initialZ = secplane;
  c.retractZ = cycle.number("clearance").value_or(0);
  c.depthZ = cycle.number("bottom").value_or(0);
  if (const ir::Value *pecks = cycle.get("pecks"))
    c.pecks = pecks->numbers;
  else
    c.pecks = {c.depthZ};
  c.reapproach = cycle.number("reapproach").value_or(0);
  c.feed = cycle.number("feed").value_or(0);
  c.feedOut = cycle.number("feed_out").value_or(0);
  c.dwell = cycle.number("dwell").value_or(0);
  c.dwellStep = cycle.number("dwell_step").value_or(0);
  c.startFeed = cycle.number("start_feed").value_or(0);
  c.startDepth = cycle.number("start_depth").value_or(0);
  c.endFeed = cycle.number("end_feed").value_or(0);
  c.endDepth = cycle.number("end_depth").value_or(0);
  return c;
}

class Builder {
public:
  Builder(const ir::Module &m, const ToolTable *table, DiagnosticEngine &diags, ir::OutOfPlaneArcs arcs)
      : module_(m), table_(table), diags_(diags), arcs_(arcs) {}

  std::optional<Program> build() {
    program_.name = module_.root.label.empty() ? module_.root.symbol : module_.root.label;
    program_.toolsFromTable = table_ != nullptr;
    for (const ir::Node &n : module_.root.children) {
      if (n.kind == ir::Kind::Workpiece && !program_.blank)
        blank(n);
      if (n.kind == ir::Kind::Setup && n.has("work_offset"))
        program_.clampings.emplace_back(static_cast<int>(*n.count("work_offset")), n.text("instruction").value_or(""));
    }
    reclamps_ = !program_.clampings.empty();
    if (reclamps_)
      program_.clampings.insert(program_.clampings.begin(), {1, "work offset 1: the workpiece as clamped first, its top up"});
    for (const ir::Node *e : ir::programOrder(module_))
      executable(*e);
    if (!ok_)
      return std::nullopt;
    return std::move(program_);
  }

private:
  void blank(const ir::Node &workpiece) {
    const ir::Node *raw = workpiece.child(ir::Kind::Rawpiece);
    if (!raw || raw->text("shape") != "block" || !raw->has("size"))
      return;
    auto frame = ir::planeFrame(*raw);
    if (!frame.frame)
      return;
    const Vec3 size = *raw->vec("size");
    geom::Box box;
    for (const geom::Vec2 &c : {geom::Vec2(0, 0), geom::Vec2(size.x(), 0), geom::Vec2(size.x(), size.y()),
                                geom::Vec2(0, size.y())})
      box.add(frame.frame->map(c));
    program_.blank = std::pair(Vec3(box.lo.x(), box.lo.y(), frame.frame->z),
                               Vec3(box.hi.x(), box.hi.y(), frame.frame->z + size.z()));
  }

  void executable(const ir::Node &e) {
    if (e.kind == ir::Kind::DisplayMessage) {
      Step s;
      s.kind = Step::Kind::Message;
      s.exec = &e;
      s.label = e.text("message").value_or("");
      program_.steps.push_back(std::move(s));
      return;
    }
    if (e.kind == ir::Kind::ProgramStop || e.kind == ir::Kind::OptionalStop) {
      Step s;
      s.kind = e.kind == ir::Kind::ProgramStop ? Step::Kind::Stop : Step::Kind::OptionalStop;
      s.exec = &e;
      s.reclamp = e.flag("reclamp").value_or(false);
      reclamped_ = reclamped_ || s.reclamp;
      program_.steps.push_back(std::move(s));
      return;
    }
    const ir::Node *moves = e.child(ir::Kind::Moves);
    if (!moves) {
      diags_.error(e.origin.loc, e.kindName() + " " + e.symbol +
                                     " has no moves to write: expand-strategies made none (its warning says "
                                     "why)")
          .entity(e.origin.entityId);
      ok_ = false;
      return;
    }
    Step s;
    s.exec = &e;
    s.label = e.label.empty() ? e.symbol : e.label;
    if (const ir::Node *op = ir::operationOf(e))
      s.operation = op->kind;
    s.tool = toolIndex(*moves);
    s.spindle = moves->number("spindle").value_or(0);
    s.coolant = moves->text("coolant").value_or("off");
    s.secplane = moves->number("secplane").value_or(0);
    s.deposits = ir::isAdditiveStep(e);
    s.tilted = ir::tiltsTool(e);
    // The head's state changes, each before the move that follows it (the
    // walk gives moves in the order of their nodes; a state is no move).
    std::map<const ir::Node *, std::vector<ProcessChange>> changesBefore;
    std::vector<ProcessChange> pending;
    for (const ir::Node &c : moves->children) {
      if (c.kind != ir::Kind::State) {
        if (!pending.empty())
          changesBefore[&c] = std::move(pending);
        pending.clear();
        continue;
      }
      ProcessChange change;
      change.node = &c;
      if (auto energy = c.text("energy"))
        change.energy = *energy == "on";
      change.power = c.number("power");
      change.powder = c.number("powder_feed");
      change.wire = c.number("wire_feed");
      pending.push_back(change);
    }
    s.after = std::move(pending);
    // The moves as every reader of the toolpath IR sees them (ir/geom/MoveWalk).
    std::set<const ir::Node *> chorded;  // arcs out of the XY plane written as lines
    for (const ir::Move &m : ir::walkMoves(*moves, position_, ir::PathKind::Programmed, arcs_)) {
      if (m.chord)
        chorded.insert(m.node);
      Move mv;
      mv.node = m.node;
      mv.from = m.from.value_or(position_);
      mv.to = m.to;
      mv.role = m.role;
      switch (m.kind) {
      case ir::MoveKind::Rapid: mv.kind = Move::Kind::Rapid; break;
      case ir::MoveKind::Linear: mv.kind = Move::Kind::Linear; break;
      case ir::MoveKind::Arc: mv.kind = Move::Kind::Arc; break;
      case ir::MoveKind::Dwell: mv.kind = Move::Kind::Dwell; break;
      }
      mv.dwell = m.dwell;
      mv.feed = m.feed;
      mv.smooth = mv.kind == Move::Kind::Linear && m.node && m.node->flag("smooth").value_or(false);
      mv.centre = m.plane.local(m.center).head<2>();
      mv.plane = m.plane;
      mv.ccw = m.ccw;
      mv.turns = m.turns;
      mv.fromAxis = m.fromAxis;
      mv.axis = m.axis;
      if (auto it = changesBefore.find(m.node); it != changesBefore.end()) {
        mv.before = std::move(it->second);
        changesBefore.erase(it);
      }
      s.moves.push_back(std::move(mv));
    }
    if (!chorded.empty())
      diags_.remark(e.origin.loc, e.kindName() + " " + e.symbol + ": " + std::to_string(chorded.size()) +
                                      (chorded.size() == 1 ? " arc" : " arcs") +
                                      " in the ZX or YZ plane written as lines, none more than " +
                                      formatShortest(ir::kOutOfPlaneArcChord) +
                                      " mm from its arc: the target writes arcs in the XY plane only")
          .entity(e.origin.entityId);
    if (const std::optional<std::string> setup = moves->text("setup"))
      s.setup = ir::findResource(module_, ir::Kind::Setup, *setup);
    // A program that re-clamps selects each setup's work offset.
    if (reclamps_) {
      const std::string setup = moves->text("setup").value_or("");
      if (!started_ || setup != lastSetup_) {
        const ir::Node *node = ir::findResource(module_, ir::Kind::Setup, setup);
        s.workOffset = node ? static_cast<int>(node->count("work_offset").value_or(1)) : 1;
      }
      lastSetup_ = setup;
    }
    if (!s.moves.empty()) {
      position_ = s.moves.back().to;
      // After a re-clamp where the tool is over the workpiece is unknown:
      // the step starts as after a tool change.
      if (!started_ || s.tool != lastTool_ || reclamped_)
        startClear(s);
      started_ = true;
      reclamped_ = false;
      lastTool_ = s.tool;
    }
    // A step that is one canned cycle is written as the controller's cycle
    // where the target has it; cycles among other moves are written as
    // their moves (expansion makes none yet).
    if (moves->children.size() == 1 && moves->children.front().kind == ir::Kind::Cycle)
      s.cycle = holeCycle(moves->children.front(), s.secplane);
    program_.steps.push_back(std::move(s));
  }

  /// Where a tool change left the tool, or where it is when the program
  /// starts, is the machine's business: it may be low, beside the part.
  /// So the step starts up along Z alone to its clearance height (the
  /// security plane, or the first rapid's height when that is higher),
  /// then moves across at that height, then down: the first rapid is split
  /// when it moves both across and down. Every target writes these moves
  /// as they are; none decides this itself.
  static void startClear(Step &s) {
    s.toolChange = true;
    Move &first = s.moves.front();
    const bool rapid = first.kind == Move::Kind::Rapid;
    const double clearZ = clearanceHeight(s);
    Move up;
    up.kind = Move::Kind::Rapid;
    up.alongZOnly = true;
    up.role = "clearance";
    up.node = first.node;
    up.from = first.from;
    up.to = Vec3(first.from.x(), first.from.y(), clearZ);
    std::vector<Move> start{up};
    if (rapid && first.to.z() < clearZ - kSame && (first.to.head<2>() - up.to.head<2>()).norm() > kSame) {
      Move across = first;
      across.from = up.to;
      across.to = Vec3(first.to.x(), first.to.y(), clearZ);
      start.push_back(across);
      first.from = across.to;
    } else {
      first.from = up.to;
    }
    s.moves.insert(s.moves.begin(), start.begin(), start.end());
  }

  int toolIndex(const ir::Node &moves) {
    const std::string symbol = moves.text("tool").value_or("");
    if (auto it = toolIndex_.find(symbol); it != toolIndex_.end())
      return it->second;
    const ir::Node *tool = ir::findTool(module_, symbol);
    if (!tool)
      return -1;  // the IR verifier reports dangling references
    // Files that write the tool again for each workingstep give one tool
    // several instances (and symbols): a tool the same in every value is
    // one tool, with one number, loaded once.
    const std::string identity = toolIdentity(*tool);
    if (auto it = toolByIdentity_.find(identity); it != toolByIdentity_.end())
      return toolIndex_[symbol] = it->second;
    ToolCall t;
    t.node = tool;
    t.label = tool->label.empty() ? tool->symbol : tool->label;
    t.diameter = tool->number("diameter").value_or(0);
    if (table_ && table_->format() == ToolTable::Format::LinuxCnc) {
      if (!fromLinuxCncTable(*tool, t))
        return -1;
    } else if (table_) {
      const ToolTable::Entry *e = table_->find(*tool);
      if (!e) {
        diags_.error(tool->origin.loc, "tool " + tool->symbol + " (\"" + t.label + "\") is not in the tool table " +
                                           table_->name())
            .entity(tool->origin.entityId);
        ok_ = false;
        return -1;
      }
      t.number = e->number;
      t.length = e->length;
    } else {
      t.number = static_cast<int>(program_.tools.size()) + 1;
    }
    program_.tools.push_back(std::move(t));
    const int index = static_cast<int>(program_.tools.size()) - 1;
    toolByIdentity_[identity] = index;
    return toolIndex_[symbol] = index;
  }

  /// A tool's number from LinuxCNC's tool table (docs/tool-table.md): the
  /// line whose comment is the tool's STEP-NC id, else the next number in
  /// order of first use that no such line takes. The table must list it
  /// (LinuxCNC refuses a tool it does not list: an error) and should give
  /// the tool's diameter (the paths are the tool centre's for the STEP-NC
  /// diameter: a warning).
  bool fromLinuxCncTable(const ir::Node &tool, ToolCall &t) {
    if (!reservedNumbers_) {
      reservedNumbers_.emplace();
      for (const ir::Node &n : module_.root.children)
        if (n.kind == ir::Kind::Tool)
          if (const ToolTable::Entry *e = table_->find(n))
            reservedNumbers_->insert(e->number);
    }
    const ToolTable::Entry *named = table_->find(tool);
    if (named) {
      t.number = named->number;
    } else {
      t.number = nextNumber_;
      while (reservedNumbers_->count(t.number) || usedNumbers_.count(t.number))
        ++t.number;
      nextNumber_ = t.number + 1;
    }
    usedNumbers_.insert(t.number);
    const ToolTable::Entry *e = named ? named : table_->findNumber(t.number);
    const std::string subject = "tool " + tool.symbol + " (\"" + t.label + "\")";
    if (!e) {
      diags_.error(tool.origin.loc, subject + " is T" + std::to_string(t.number) +
                                        " (in order of first use), which the tool table " + table_->name() +
                                        " does not list: LinuxCNC refuses a tool its table lacks")
          .entity(tool.origin.entityId)
          .note("a line of the table whose comment is the tool's id (;" + t.label + ") gives it that line's number");
      ok_ = false;
      return false;
    }
    t.length = e->length;
    if (e->diameter && t.diameter > 0 && std::abs(*e->diameter - t.diameter) > kDiameterTolMm) {
      auto d = diags_.warning(e->diameterLoc.valid() ? e->diameterLoc : e->loc,
                              "tool table: T" + std::to_string(t.number) + " has diameter " +
                                  formatFixed(*e->diameter, 3) + " mm, " + subject + " " +
                                  formatFixed(t.diameter, 3) + " mm: the program's paths are the tool centre's "
                                  "for " + formatFixed(t.diameter, 3) + " mm");
      d.note(tool.origin.loc, subject + " is defined here");
      if (std::abs(*e->diameter * kMmPerInch - t.diameter) <= kDiameterTolMm)
        d.note(formatFixed(*e->diameter, 4) + " in is " + formatFixed(t.diameter, 3) +
               " mm: stepnc reads tool.tbl in mm, as a metric machine's table is; is this an imperial machine's?");
    }
    return true;
  }

  /// The tool as the IR prints it without its symbol, location or comment:
  /// its id, type and every value.
  static std::string toolIdentity(const ir::Node &tool) {
    ir::Node copy = tool;
    copy.symbol.clear();
    copy.comment.clear();
    copy.origin = {};
    std::string text;
    ir::printNode(copy, text, {});
    return text;
  }

  const ir::Module &module_;
  const ToolTable *table_;
  DiagnosticEngine &diags_;
  ir::OutOfPlaneArcs arcs_;
  Program program_;
  std::map<std::string, int> toolIndex_;       ///< by symbol
  std::map<std::string, int> toolByIdentity_;  ///< by toolIdentity
  // LinuxCNC tables: the numbers lines take by naming a tool, those given.
  std::optional<std::set<int>> reservedNumbers_;
  std::set<int> usedNumbers_;
  int nextNumber_ = 1;
  Vec3 position_ = Vec3::Zero();
  bool started_ = false;  ///< a step with moves was built
  int lastTool_ = -1;     ///< that step's tool
  bool reclamps_ = false;  ///< the program has setups on other faces (work offsets)
  bool reclamped_ = false; ///< a re-clamp stop since the last step with moves
  std::string lastSetup_;  ///< the setup of the last step with moves
  bool ok_ = true;
};

} // namespace

double Move::sweep() const {
  const geom::Vec2 a = fromInPlane(), b = toInPlane();
  double angle = turnAngle(a - centre, b - centre, ccw);
  if ((b - a).norm() <= kSame)
    angle = kTwoPi;  // over the start: a whole turn
  return angle + kTwoPi * static_cast<double>(turns);
}

double clearanceHeight(const Step &s) {
  // The first move that is not the clearance move itself.
  for (const Move &m : s.moves)
    if (!m.alongZOnly)
      return m.kind == Move::Kind::Rapid ? std::max(s.secplane, m.to.z()) : s.secplane;
  return s.secplane;
}

std::string whyNotCycle(const TargetDescriptor &d, const HoleCycle &c) {
  auto form = d.cycles.find(c.kind);
  if (form == d.cycles.end())
    return d.cycles.empty() ? "cycles are off (--no-cycles or cycles=off)"
                            : d.name + " writes no " + std::string(cycleKindName(c.kind)) + " cycle";
  if (c.dwell > 0 && !form->second.dwell)
    return "its " + std::string(cycleKindName(c.kind)) + " cycle has no dwell at the bottom";
  if (c.dwellStep > 0 && !form->second.dwellStep)
    return "its " + std::string(cycleKindName(c.kind)) + " cycle has no dwell at every peck";
  if ((c.startFeed > 0 || c.endFeed > 0) && !form->second.reducedFeeds)
    return "its " + std::string(cycleKindName(c.kind)) + " cycle has no reduced feeds near the top or bottom";
  return "";
}

std::optional<Program> buildProgram(const ir::Module &module, const ToolTable *table, DiagnosticEngine &diags,
                                    ir::OutOfPlaneArcs arcs, ir::Deposition deposition, std::string_view target,
                                    ir::ToolAxes toolAxes) {
  if (!ir::requireThreeAxisMilling(module, target, diags, ir::ArcPlanes::Principal, ir::OtherProcesses::Refuse,
                                   deposition, toolAxes))
    return std::nullopt;
  return Builder(module, table, diags, arcs).build();
}

} // namespace stepnc::backends
