// Explicit toolpaths: an operation's `toolpath` children (freeform
// operations, and any operation that gives its path) lowered exactly, in
// order, from the feature's frame to workpiece coordinates: polylines as
// lines, trimmed circles as arcs, trimmed helices as helical arcs, composite
// curves segment by segment. A toolpath typed by what it does gives its
// moves that role; the speed name `rapid` makes them rapids. Rapid
// movements (a workingstep of their own) become rapids through their points
// with the tool of the step before.
#include "passes/expand/Expand.h"

#include <algorithm>

namespace stepnc::passes::expand {

namespace {

/// How the moves of an explicit toolpath are made: rapid or at feed, and
/// the role they get. ISO 14649 types a toolpath by what it does; its
/// speed name `rapid` makes its moves rapids. A `trajectory_path` says no
/// more than that it is followed: at feed it cuts.
struct ExplicitKind {
  bool rapid = false;
  const char *role = "cut";
};

ExplicitKind explicitKind(const Node &tp) {
  const bool rapid = tp.flag("rapid").value_or(false);
  const std::string type = tp.text("role").value_or("trajectory_path");
  struct Row {
    const char *type, *rapidRole, *feedRole;
  };
  static constexpr Row kRoles[] = {{"non_contact", "position", "position"}, {"approach", "approach", "plunge"},
                                   {"contact", "cut", "cut"},               {"connect", "link", "link"},
                                   {"lift", "retract", "retract"},          {"trajectory_path", "position", "cut"}};
  for (const Row &r : kRoles)
    if (type == r.type)
      return {rapid, rapid ? r.rapidRole : r.feedRole};
  // The IR allows only the words above; a new one would cut, at feed.
  return {rapid, rapid ? "position" : "cut"};
}

/// One piece of an explicit toolpath, mapped from the feature's frame.
void explicitPiece(const ir::PlaneFrame &f, const ir::CurvePiece &c, const ExplicitKind &kind, double feed,
                   double clearanceZ, Emitter &e) {
  const Vec3 from = at(f.map(c.from.head<2>()), f.z + c.from.z());
  const Vec3 to = at(f.map(c.to.head<2>()), f.z + c.to.z());
  if (!e.positioned() || (e.position() - from).norm() > 1e-6) {
    // Reach the start: over it at the security plane, down in free space to
    // the clearance height at most, then at feed. A start at or above the
    // security plane, or of rapids, is reached by rapids alone.
    if (kind.rapid) {
      e.travel(from.head<2>(), from.z());
    } else {
      e.travel(from.head<2>(), std::max(from.z(), std::min(clearanceZ, e.secplane())));
      e.linear(from, feed, "plunge");
    }
  }
  if (kind.rapid)
    e.rapid(to, kind.role);
  else if (!c.arc)
    e.linear(to, feed, kind.role);
  else
    e.arc(to, f.map(c.center.head<2>()), c.ccw != f.mirrored(), c.turns, feed, kind.role);
}

} // namespace

bool expandExplicitToolpaths(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  const ir::PlaneFrame &frame = *step.frame;
  const Plan &p = step.plan;
  Emitter e(step.moves, step.moves.number("secplane").value_or(0));
  for (const Node *tp : op.childrenOf(ir::Kind::Toolpath)) {
    const Node *tech = tp->child(ir::Kind::Technology);
    const double feed = tech && tech->number("feed") ? *tech->number("feed") : p.feed;
    const ExplicitKind kind = explicitKind(*tp);
    for (const Node &curve : tp->children) {
      if (curve.category() != ir::Category::Curve)
        continue;
      ir::CurveResult cr = ir::curvePieces(curve);
      if (!cr.error.empty()) {
        x.report(ws, "its explicit toolpath: " + cr.error);
        // The moves made so far are attached as they are: the error stops
        // the pipeline before anything is written.
        return true;
      }
      const bool reversed = tp->flag("reversed").value_or(false);
      if (reversed) {
        std::reverse(cr.pieces.begin(), cr.pieces.end());
        for (ir::CurvePiece &c : cr.pieces) {
          std::swap(c.from, c.to);
          c.ccw = !c.ccw;
        }
      }
      for (const ir::CurvePiece &c : cr.pieces)
        explicitPiece(frame, c, kind, feed, p.clearanceZ, e);
    }
  }
  e.retract();
  return true;
}

void expandRapidMovement(Expander &x, Node &rm, const std::string &setup) {
  // A rapid movement keeps the tool of the workingstep before it; the IR
  // names it where known.
  if (x.lastTool.empty()) {
    x.diags->warning(rm.origin.loc, rm.kindName() + " " + rm.symbol +
                                        " is not expanded: no workingstep before it names the tool it moves")
        .entity(rm.origin.entityId);
    return;
  }
  Node moves = makeMoves(rm, x.lastTool, 0, "off", setup);
  Emitter e(moves, rm.number("secplane").value_or(0));
  for (const Node *tp : rm.childrenOf(ir::Kind::Toolpath))
    for (const Node &curve : tp->children)
      if (curve.category() == ir::Category::Curve) {
        ir::CurveResult cr = ir::curvePieces(curve);
        if (!cr.error.empty()) {
          x.report(rm, "its toolpath: " + cr.error);
          return;
        }
        for (const ir::CurvePiece &c : cr.pieces) {
          if (!e.positioned())
            e.travel(c.from.head<2>(), c.from.z());
          e.rapid(c.to);
        }
      }
  x.attach(rm, std::move(moves));
}

} // namespace stepnc::passes::expand
