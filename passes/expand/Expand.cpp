// expand-strategies: from features to moves.
//
// Each machining workingstep gets a `moves` child: the tool-centre path in
// workpiece coordinates, made from the feature's shape (ir/geom/FeatureShape),
// the operation (allowances, depths of cut, stepover), its strategy, approach
// and retract. This file is the pass: it walks the workplans, finds each
// step's operation, feature and tool, builds the Plan (feeds, allowances,
// the clearance height), and hands the step to the family registered for the
// kind of its strategy node (see kFamilies below). It also says, with a
// warning at the node the file gives, where the moves do not follow what the
// operation asks: an approach or retract stepnc does not make, a pattern
// strategy it does not know. Warnings never change the moves.
#include "passes/expand/Expand.h"

#include "ir/geom/TurnedShape.h"

#include "ir/Plausible.h"
#include "ir/Verifier.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <set>

namespace stepnc::passes {

namespace expand {

namespace {

// What each family does with the operation's approach. The families write
// the moves; these lists only say which approach types those moves follow.
constexpr std::string_view kAxisOnly[] = {"plunge_toolaxis"};
constexpr std::string_view kAxisHelixRamp[] = {"plunge_toolaxis", "plunge_helix", "plunge_ramp"};
constexpr std::string_view kAxisHelix[] = {"plunge_toolaxis", "plunge_helix"};

/// The registry: one family per kind of the node that selects it. An
/// operation's toolpaths select explicit toolpaths, hole making its
/// (optional) drilling strategy, milling its strategy or pattern strategy.
constexpr Family kFamilies[] = {
    {ir::Kind::Toolpath, "explicit toolpaths", false, kAxisOnly, "reaching each toolpath's start down the tool axis",
     expandExplicitToolpaths},
    {ir::Kind::DrillingStrategy, "hole making", true, kAxisOnly, "feeding down the hole's axis", expandHoleMaking},
    {ir::Kind::Strategy, "2.5D milling", true, kAxisHelixRamp, "plunging along the tool axis", expandMilling2D},
    // The loops enter by a helix, or along the axis when asked; the wall
    // pass after them enters as 2.5D milling does.
    {ir::Kind::TrochoidalStrategy, "trochoidal milling", true, kAxisHelix, "entering each guide path by a helix",
     expandTrochoidal},
    // The plunges are along the axis by nature, whatever the approach; the
    // approach is the wall pass's, which follows a helix or ramp.
    {ir::Kind::PlungeStrategy, "plunge milling", true, kAxisHelixRamp, "plunging along the tool axis",
     expandPlunging},
};

/// The retract stepnc makes in every family: along the tool axis, up to the
/// security plane (at rapid, or at feed out of a bored or tapped hole).
constexpr std::string_view kRetractFollowed = "plunge_toolaxis";

/// The node whose kind selects the family of operation `op`, and that kind.
struct Selected {
  ir::Kind key;
  const Node *node;
};

Selected select(const Node &op) {
  // An operation's toolpaths win over its strategy.
  if (const std::vector<const Node *> tps = op.childrenOf(ir::Kind::Toolpath); !tps.empty())
    return {ir::Kind::Toolpath, tps.front()};
  if (op.is(ir::Trait::HoleMaking))
    return {ir::Kind::DrillingStrategy, op.child(ir::Kind::DrillingStrategy)};
  for (const Node &c : op.children)
    if (c.is(ir::Trait::PatternStrategy))
      return {c.kind, &c};
  return {ir::Kind::Strategy, op.child(ir::Kind::Strategy)};
}


/// Warns where the operation's approach or retract is not what `family`'s
/// moves do, saying what they do instead.
void reportApproachRetract(Expander &x, const Step &step, const Family &family) {
  if (const Node *a = step.op.child(ir::Kind::Approach)) {
    const std::string type = a->text("type").value_or("");
    if (std::ranges::find(family.approaches, type) == family.approaches.end())
      x.assumed(step.ws, *a,
                "approach " + type + " is not supported by " + std::string(family.name) + ": " +
                    std::string(family.otherApproach));
  }
  if (const Node *r = step.op.child(ir::Kind::Retract)) {
    const std::string type = r->text("type").value_or("");
    if (type != kRetractFollowed)
      x.assumed(step.ws, *r,
                "retract " + type + " is not supported: leaving along the tool axis to the security plane");
  }
}

} // namespace

/// True when every point and length of the expanded moves is one a
/// machine tool can go to (ir::kMaxLengthMm either way); else an error at
/// the workingstep naming the first coordinate beyond: a feature whose
/// dimensions run past it (a length in another unit, a typo) would make
/// IR the verifier refuses, and nothing is written.
bool withinMachine(Expander &x, const Node &ws, const Node &feature, const Node &moves) {
  std::optional<double> beyond;
  auto scan = [&](const Node &n, auto &self) -> void {
    for (const ir::Attr &a : n.attrs)
      if (a.value.type == ir::ValueType::Point || a.value.type == ir::ValueType::Length)
        if ((beyond = ir::beyondMachine(a.value)))
          return;
    for (const Node &c : n.children)
      if (!beyond)
        self(c, self);
  };
  scan(moves, scan);
  if (!beyond)
    return true;
  x.report(ws, ws,
            "its toolpath for " + feature.symbol + " reaches " + formatFixed(*beyond, 4) +
                " mm, beyond what a machine tool does (at most " + formatShortest(ir::kMaxLengthMm) +
                " mm either way): check the feature's placement and dimensions (a length in another unit?)");
  return false;
}

std::string coolant(const Node &op) {
  const Node *mf = op.child(ir::Kind::MachineFunctions);
  if (!mf)
    return "off";
  if (mf->flag("through_spindle_coolant").value_or(false))
    return "through_tool";
  if (mf->flag("mist").value_or(false))
    return "mist";
  return mf->flag("coolant").value_or(false) ? "flood" : "off";
}

const Family *findFamily(ir::Kind key) {
  for (const Family &f : kFamilies)
    if (f.key == key)
      return &f;
  return nullptr;
}

Node makeMoves(const Node &exec, const std::string &tool, double spindle, const std::string &coolant,
               const std::string &setup) {
  Node moves(ir::Kind::Moves);
  moves.set("tool", Value::ref(tool));
  moves.set("spindle", Value::spindle(spindle));
  moves.set("coolant", Value::word(coolant));
  if (!setup.empty())
    moves.set("setup", Value::ref(setup));
  moves.set("secplane", Value::length(exec.number("secplane").value_or(0)));
  moves.origin = exec.origin;
  return moves;
}

void Expander::attach(Node &ws, Node moves) {
  (*stats)["workingsteps expanded"]++;
  (*stats)["moves"] += static_cast<long long>(moves.children.size());
  lastTool = moves.text("tool").value_or("");
  lastSpindle = moves.number("spindle").value_or(0);
  lastCoolant = moves.text("coolant").value_or("off");
  ws.add(std::move(moves));
  result.changed = true;
}

void Expander::report(const Node &ws, const Node &at, const std::string &message) {
  const Node &where = at.origin.loc.valid() ? at : ws;
  diags->error(where.origin.loc, ws.kindName() + " " + ws.symbol + ": " + message).entity(where.origin.entityId);
  result.ok = false;
}

void Expander::unsupported(const Node &ws, const std::string &reason) {
  diags->warning(ws.origin.loc, "workingstep " + ws.symbol + " is not expanded: " + reason)
      .entity(ws.origin.entityId);
  (*stats)["workingsteps not expanded"]++;
}

void Expander::warning(const Node &ws, const std::string &message) {
  diags->warning(ws.origin.loc, ws.kindName() + " " + ws.symbol + ": " + message).entity(ws.origin.entityId);
}

void Expander::assumed(const Node &ws, const Node &at, const std::string &message) {
  // Located at what the file gives (the approach, the strategy); a node
  // made by the pass or without an origin falls back to the step's.
  const Node &where = at.origin.loc.valid() ? at : ws;
  diags->assumption(where.origin.loc, ws.kindName() + " " + ws.symbol + ": " + message)
      .entity(where.origin.entityId);
}

namespace {

class ExpandStrategiesPass final : public Pass {
public:
  ExpandStrategiesPass(double maxEngagement, double chordTolerance, std::optional<double> scallopHeight) {
    x_.maxEngagement = maxEngagement;
    x_.chordTolerance = chordTolerance;
    x_.scallopHeight = scallopHeight;
  }

  std::string_view name() const override { return "expand-strategies"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    x_.module = &module;
    x_.diags = &diags;
    x_.stats = &stats;
    x_.result = {};
    x_.explicitRuns.clear();
    x_.turnedStock.clear();
    // Workingsteps in the branches of control flow too: each branch is a
    // program of its own, which a target with control flow writes as such.
    leftOut_.clear();
    ir::forEachMachiningStep(module, [&](Node &e, const std::string &setup) {
      if (!e.child(ir::Kind::Moves)) {
        executable(e, setup);
        if (ir::drillsOnTurningAxis(e))
          noteAxialDrilling(x_, e);
      }
    });
    if (!leftOut_.empty())
      leaveOut(module.root);
    if (x_.result.ok) {
      linkExplicitPaths(x_);
      settleExplicitRapids(x_);
    }
    return x_.result;
  }

private:
  void executable(Node &ws, const std::string &setup) {
    if (ws.kind == ir::Kind::RapidMovement) {
      expandRapidMovement(x_, ws, setup);
      return;
    }
    const Node *op = ir::operationOf(ws);
    if (!op)
      return;
    if (op->is(ir::Trait::Turning)) {
      expandTurning(x_, ws, *op, setup);
      return;
    }
    if (op->is(ir::Trait::Additive)) {
      expandDeposition(x_, ws, *op, setup);
      return;
    }
    const Node *feature = ir::findFeature(*x_.module, ws.text("feature").value_or(""));
    const Node *tool = ir::findTool(*x_.module, op->text("tool").value_or(""));
    if (!feature || !tool)
      return;  // the IR verifier reports dangling references
    Plan p;
    p.feature = feature;
    p.op = op;
    p.tool = tool;
    p.radius = tool->number("diameter").value_or(0) / 2;
    const Node *tech = op->child(ir::Kind::Technology);
    p.feed = tech ? tech->number("feed").value_or(0) : 0;
    p.spindle = tech ? tech->number("spindle").value_or(0) : 0;
    p.plungeFeed = p.feed;
    p.allowanceSide = op->number("allowance_side").value_or(0);
    p.allowanceBottom = op->number("allowance_bottom").value_or(0);
    if (p.feed <= 0 && !ir::toolpathsGiveFeeds(*op)) {
      x_.report(ws, tech && tech->has("feed") ? "its operation's feed is 0 mm/min"
                                              : "has no feed for its moves (run resolve-feeds first, or give the "
                                                "operation a feed)");
      return;
    }
    if (p.radius <= 0) {
      x_.report(ws, "its tool " + tool->symbol + " has no diameter");
      return;
    }
    // The family, by the kind of the node that selects it. A pattern
    // strategy stepnc has no family for is followed as its guide alone.
    Selected sel = select(*op);
    const Family *family = findFamily(sel.key);
    if (!family && sel.node && sel.node->is(ir::Trait::PatternStrategy)) {
      if (const Node *guide = sel.node->child(ir::Kind::Strategy)) {
        x_.assumed(ws, *sel.node,
                   sel.node->kindName() + " is not supported: following its guide strategy " +
                       guide->text("type").value_or("") + " without the pattern");
        sel = {ir::Kind::Strategy, guide};
        family = findFamily(sel.key);
      }
    }
    if (!family) {
      x_.unsupported(ws, (sel.node ? sel.node->kindName() : std::string(ir::kindName(sel.key))) +
                             " has no expansion in stepnc");
      return;
    }
    // A tool direction (5-axis) is taken by 2.5D milling (flank milling
    // of side finishing) and by explicit toolpaths (whose points give their
    // own tool axes); no other family tilts the tool.
    if (op->has("tool_direction") && sel.key != ir::Kind::Strategy && sel.key != ir::Kind::Toolpath) {
      x_.report(ws, *op, "a tool direction (ISO 14649-11 its_tool_direction) is not supported by " +
                             std::string(family->name) + ": stepnc tilts the tool for flank milling only");
      return;
    }
    Node moves = makeMoves(ws, tool->symbol, p.spindle, coolant(*op), setup);
    const double retract = retractPlane(ws, *op);
    // Axial approaches start the retract plane above the feature's top, never
    // above the security plane the moves travel at.
    auto clearanceAbove = [&](double top) {
      return std::min(top + retract, moves.number("secplane").value_or(1e300));
    };
    bool expanded = false;
    if (!family->needsShape) {
      // Explicit toolpaths need no shape: they are in the feature's frame.
      ir::FrameResult fr = ir::planeFrame(*feature);
      if (!fr.frame) {
        x_.unsupported(ws, fr.error);
        return;
      }
      p.clearanceZ = clearanceAbove(fr.frame->z);
      expanded = dispatch(*family, Step{ws, *op, sel.node, nullptr, &*fr.frame, p, moves});
    } else {
      ir::ShapeResult shape = ir::featureShape(*x_.module, *feature);
      if (!shape.shape) {
        x_.unsupported(ws, shape.error);
        return;
      }
      const ir::FeatureShape &s = *shape.shape;
      const double secplane = ws.number("secplane").value_or(0);
      const std::optional<ir::RawBlock> raw = ir::rawBlock(ir::workpieceOf(*x_.module, *feature));
      if (raw && s.top <= raw->bottom + 1e-6 && !s.unbounded) {
        // Below the raw piece is what the workpiece stands on: a table, a
        // vise, a fixture. The step is left out, never machined into it.
        x_.assumed(ws, ws, s.symbol + " lies wholly below the raw piece (its top z=" + formatFixed(s.top, 4) +
                               " mm, the raw piece's bottom z=" + formatFixed(raw->bottom, 4) +
                               " mm): machining it would cut into what the workpiece stands on; the "
                               "workingstep is left out of the program");
        leftOut_.insert(&ws);
        return;
      }
      if (raw)
        reportOutsideRaw(ws, s, *raw);
      if (secplane < s.top || (raw && secplane < raw->top))
        raiseSecplane(ws, retract, s, raw, secplane, moves);
      p.clearanceZ = clearanceAbove(s.top);
      expanded = dispatch(*family, Step{ws, *op, sel.node, &s, nullptr, p, moves});
    }
    if (expanded && withinMachine(x_, ws, *feature, moves))
      x_.attach(ws, std::move(moves));
  }

  /// The operation's retract plane: the height above the feature's top at
  /// which axial approaches and drilling cycles start, kDefaultClearance
  /// when the file gives none. One below the top would start them inside
  /// the material (a drilling cycle's R below its bottom, which controllers
  /// refuse): the default is assumed instead, and said.
  double retractPlane(const Node &ws, const Node &op) {
    const std::optional<double> given = op.number("retract_plane");
    if (!given)
      return kDefaultClearance;
    if (*given < 0) {
      x_.assumed(ws, op,
                 "retract_plane " + formatFixed(*given, 4) +
                     " mm is below the feature's top: approaches and cycles would start inside the material; "
                     "assumed " + formatFixed(kDefaultClearance, 4) + " mm above it");
      return kDefaultClearance;
    }
    return *given;
  }

  /// A security plane below the feature's top or the raw piece's leaves no
  /// safe height to travel at as written (generators write a fixed height,
  /// or place the feature above the raw piece); the raw piece's top is where
  /// material may remain. The step then travels at the feature's
  /// top or the raw piece's, whichever is higher, plus the retract plane:
  /// an assumption, reported (an error with --strict).
  void raiseSecplane(Node &ws, double retract, const ir::FeatureShape &s, const std::optional<ir::RawBlock> &raw,
                     double secplane, Node &moves) {
    const double top = raw ? std::max(s.top, raw->top) : s.top;
    const double raised = top + retract;
    const bool belowRaw = raw && raw->top > s.top;
    std::string why = "its security plane z=" + formatFixed(secplane, 4) + " mm is below the top of " +
                      (belowRaw ? "the raw piece" : s.symbol) + " (z=" + formatFixed(top, 4) +
                      " mm): no safe height to travel at as written; assumed z=" +
                      formatFixed(raised, 4) + " mm (the top of " +
                      (belowRaw ? "the raw piece" : s.symbol) +
                      " plus the retract plane) for this workingstep";
    // The workingstep keeps the file's plane; its moves travel at the raised
    // one (the STEP-NC write-back writes it as the step's security plane).
    x_.assumed(ws, ws, why);
    moves.set("secplane", ir::Value::length(raised));
  }

  /// Says, once per feature, where it lies outside the raw piece: wholly
  /// (its machining cuts no material: a generator's misplaced feature, as a
  /// rule) or in part in the plane (that part is cut in air).
  void reportOutsideRaw(const Node &ws, const ir::FeatureShape &s, const ir::RawBlock &raw) {
    if (s.unbounded || !outsideReported_.insert(s.symbol).second)
      return;
    const geom::Box box = s.target.box();
    if (box.empty())
      return;
    constexpr double eps = 1e-6;
    auto extent = [](const geom::Box &b, double low, double high) {
      return "x " + formatFixed(b.lo.x(), 4) + " .. " + formatFixed(b.hi.x(), 4) + ", y " + formatFixed(b.lo.y(), 4) +
             " .. " + formatFixed(b.hi.y(), 4) + ", z " + formatFixed(low, 4) + " .. " + formatFixed(high, 4) +
             " mm";
    };
    const std::string where =
        " (" + extent(box, s.bottom, s.top) + "; the raw piece " + extent(raw.box, raw.bottom, raw.top) + ")";
    const geom::Box inside = raw.box.grown(eps);
    const bool apart = !box.overlaps(inside) || s.bottom >= raw.top - eps || s.top <= raw.bottom + eps;
    const bool beyond = box.lo.x() < inside.lo.x() || box.lo.y() < inside.lo.y() || box.hi.x() > inside.hi.x() ||
                        box.hi.y() > inside.hi.y();
    if (apart)
      x_.diags->warning(ws.origin.loc, ws.kindName() + " " + ws.symbol + ": " + s.symbol +
                                           " lies wholly outside the raw piece" + where +
                                           ": its machining cuts no material")
          .entity(ws.origin.entityId);
    else if (beyond)
      x_.diags->warning(ws.origin.loc, ws.kindName() + " " + ws.symbol + ": " + s.symbol +
                                           " extends beyond the raw piece in x or y" + where +
                                           ": what lies outside is cut in air")
          .entity(ws.origin.entityId);
  }

  std::set<std::string> outsideReported_;
  std::set<const Node *> leftOut_;  ///< workingsteps not to machine (said why)

  /// Removes the leftOut_ steps from the program: top down, so a step is
  /// compared where it was when it was recorded.
  void leaveOut(Node &n) {
    std::erase_if(n.children, [&](const Node &c) { return leftOut_.count(&c) > 0; });
    for (Node &c : n.children)
      if (c.category() == ir::Category::Executable || c.is(ir::Trait::ControlFlow) ||
          c.category() == ir::Category::Branch)
        leaveOut(c);
  }

  /// Runs the family on the step; when it made moves without an error,
  /// says where they do not follow the operation's approach or retract.
  bool dispatch(const Family &family, const Step &step) {
    const unsigned errorsBefore = x_.diags->errorCount();
    if (!family.expand(x_, step))
      return false;
    if (x_.diags->errorCount() == errorsBefore)
      reportApproachRetract(x_, step, family);
    return true;
  }

  Expander x_;
};

} // namespace

} // namespace expand

std::unique_ptr<Pass> createExpandStrategiesPass(const PassOptions &options) {
  return std::make_unique<expand::ExpandStrategiesPass>(options.number("max-engagement").value(),
                                                        options.number("chord-tolerance").value(),
                                                        options.number("scallop-height"));
}

} // namespace stepnc::passes
