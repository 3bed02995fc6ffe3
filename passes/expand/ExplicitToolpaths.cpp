// Explicit toolpaths: an operation's `toolpath` children (freeform
// operations, and any operation that gives its path) lowered exactly, in
// order, from the feature's frame to workpiece coordinates: polylines as
// lines, trimmed circles as arcs, trimmed helices as helical arcs, composite
// curves segment by segment. A toolpath typed by what it does gives its
// moves that role; the speed name `rapid` makes them rapids. Rapid
// movements (a workingstep of their own) become rapids through their points
// with the tool, spindle and coolant of the step before.
//
// Once every step has its moves, consecutive paths are joined where one
// starts where the one before ends, and the rapids the file asks for below
// the security plane are read on the in-process stock (linkExplicitPaths,
// settleExplicitRapids): the program then runs the file's path as NIST's
// ISO 14649 interpreter does, wherever that is safe.
#include "passes/expand/Expand.h"

#include "ir/geom/MoveWalk.h"
#include "passes/InProcessStock.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace stepnc::passes::expand {

namespace {

/// How the moves of an explicit toolpath are made: rapid or at feed, and
/// the role they get. ISO 14649 types a toolpath by what it does; its
/// speed name `rapid` makes its moves rapids. A `trajectory_path` says no
/// more than that it is followed: at feed it cuts.
struct ExplicitKind {
  bool rapid = false;
  const char *role = "cut";
  /// A `connect` toolpath that gives no speed (nor a technology with a
  /// feed): its lines are moved at rapid where the stock shows them clear
  /// (settleExplicitRapids).
  bool connectNoSpeed = false;
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
  // A toolpath with a technology of its own asks for its feed.
  const bool noSpeed = !tp.has("rapid") && !tp.has("speed_ratio") && !tp.child(ir::Kind::Technology);
  for (const Row &r : kRoles)
    if (type == r.type)
      return {rapid, rapid ? r.rapidRole : r.feedRole, !rapid && noSpeed && type == "connect"};
  // The IR allows only the words above; a new one would cut, at feed.
  return {rapid, rapid ? "position" : "cut"};
}

/// Why an arc out of the XY plane cannot be placed by the feature's frame:
/// a frame turned about z, or mirrored, would turn its plane out of the
/// principal planes (or its direction); one that only moves it keeps both.
std::string outOfPlaneArcFrame(const ir::PlaneFrame &f, const ir::CurvePiece &c) {
  if (c.plane.isXY() || ((f.x - geom::Vec2::UnitX()).norm() < 1e-9 && (f.y - geom::Vec2::UnitY()).norm() < 1e-9))
    return {};
  return std::string("an arc in the ") + c.plane.name() +
         " plane, in a feature frame turned about z: only arcs in the XY plane turn with their feature";
}

/// One piece of an explicit toolpath, mapped from the feature's frame; the
/// path's run records where it starts and which moves the stock decides.
void explicitPiece(const ir::PlaneFrame &f, const ir::CurvePiece &c, const ExplicitKind &kind, double feed,
                   double clearanceZ, Emitter &e, const Node &toolpath, ExplicitRun &run, const Node &moves) {
  const Vec3 from = at(f.map(c.from.head<2>()), f.z + c.from.z());
  const Vec3 to = at(f.map(c.to.head<2>()), f.z + c.to.z());
  const bool first = !e.positioned();
  if (first || (e.position() - from).norm() > 1e-6) {
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
  if (first) {
    run.leadIn = moves.children.size();
    run.start = from;
  }
  const size_t before = moves.children.size();
  if (kind.rapid)
    e.rapid(to, kind.role);
  else if (!c.arc)
    e.linear(to, feed, kind.role);
  else if (c.plane.isXY())
    e.arc(to, f.map(c.center.head<2>()), c.ccw != f.mirrored(), c.turns, feed, kind.role);
  else  // the frame only moves it (outOfPlaneArcFrame)
    e.arc(to, at(f.map(c.center.head<2>()), f.z + c.center.z()), c.plane, c.ccw, c.turns, feed, kind.role);
  if (moves.children.size() > before && (kind.rapid || (kind.connectNoSpeed && !c.arc)))
    run.decided.push_back({before, !kind.rapid, toolpath.origin});
}

/// The least z part of the tool axis a path may start with: reached down
/// its axis from the security plane, the tool leans 80 deg at most.
constexpr double kMinApproachCos = 0.17364817766693033;  // cos 80 deg

/// Whether any toolpath of `op` gives its tool axes (ISO 14649-11 its_toolaxis:
/// `axis` on the points of its polyline).
bool givesToolAxes(const Node &op) {
  for (const Node *tp : op.childrenOf(ir::Kind::Toolpath))
    for (const Node &curve : tp->children)
      if (curve.kind == ir::Kind::Polyline)
        for (const Node &point : curve.children)
          if (point.has("axis"))
            return true;
  return false;
}

/// The toolpaths of an operation that gives tool axes (5-axis): each point
/// with its axis (a polyline without axes, or a point without one: +z),
/// reached from the security plane down the tool axis of its first point
/// and left up the axis of its last; no path is joined to another or settled
/// on the stock (the verifier checks the step's rapids). False after an error.
bool expandTiltedToolpaths(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  const ir::PlaneFrame &f = *step.frame;
  const Plan &p = step.plan;
  Node &moves = step.moves;
  const double secplane = moves.number("secplane").value_or(0);
  std::optional<Vec3> at;
  Vec3 axis = Vec3::UnitZ();
  auto add = [&](Node m, const Vec3 &to, const Vec3 &a) {
    moves.add(Emitter::tilted(std::move(m), a));
    at = to;
    axis = a;
  };
  const auto upTo = Emitter::alongAxisTo;
  auto leave = [&]() {
    if (at && at->z() < secplane - 1e-9)
      add(Emitter::rapidNode(upTo(*at, axis, secplane), "retract"), upTo(*at, axis, secplane), axis);
  };
  for (const Node *tp : op.childrenOf(ir::Kind::Toolpath)) {
    const Node *tech = tp->child(ir::Kind::Technology);
    const double feed = tech && tech->number("feed") ? *tech->number("feed") : p.feed;
    const ExplicitKind kind = explicitKind(*tp);
    if (tp->has("dwell")) {
      if (at) {
        Node dwell(ir::Kind::Dwell);
        dwell.set("time", ir::Value::time(*tp->number("dwell")));
        moves.add(std::move(dwell));
      }
      continue;
    }
    for (const Node &curve : tp->children) {
      if (curve.category() != ir::Category::Curve)
        continue;
      if (curve.kind != ir::Kind::Polyline) {
        x.report(ws, *tp, "its explicit toolpaths give tool axes: every curve of the operation must be a polyline "
                          "(this one is a " + curve.kindName() + ")");
        return false;
      }
      std::vector<std::pair<Vec3, Vec3>> poses;
      for (const Node &point : curve.children) {
        const Vec3 q = point.vec("at").value_or(Vec3::Zero());
        const Vec3 a = point.vec("axis").value_or(Vec3::UnitZ());
        const geom::Vec2 axy = f.mapDir(a.head<2>());
        poses.emplace_back(ir::Vec3(f.map(q.head<2>()).x(), f.map(q.head<2>()).y(), f.z + q.z()),
                           Vec3(axy.x(), axy.y(), a.z()).normalized());
      }
      if (tp->flag("reversed").value_or(false))
        std::reverse(poses.begin(), poses.end());
      if (poses.empty())
        continue;
      const auto &[start, startAxis] = poses.front();
      const bool joined = at && (*at - start).norm() <= 1e-6 && ir::angleBetween(axis, startAxis) <= 1e-6;
      if (!joined) {
        // Reached down the start's axis from the security plane.
        if (startAxis.z() < kMinApproachCos) {
          x.report(ws, *tp, "its toolpath starts with the tool axis " +
                                formatTuple({startAxis.x(), startAxis.y(), startAxis.z()}, 6) + ", " +
                                formatFixed(std::acos(std::clamp(startAxis.z(), -1.0, 1.0)) * 180 / kPi, 3) +
                                " deg from z: stepnc reaches a path's start down its tool axis from the security "
                                "plane, which needs a tool leaning 80 deg or less");
          return false;
        }
        leave();
        add(Emitter::rapidNode(upTo(start, startAxis, secplane), "position"), upTo(start, startAxis, secplane),
            startAxis);
        const double clearance = std::max(start.z(), std::min(p.clearanceZ, secplane));
        if (kind.rapid || clearance <= start.z() + 1e-9) {
          add(Emitter::rapidNode(start, "approach"), start, startAxis);
        } else {
          add(Emitter::rapidNode(upTo(start, startAxis, clearance), "approach"), upTo(start, startAxis, clearance),
              startAxis);
          add(Emitter::linearNode(start, p.plungeFeed, "plunge"), start, startAxis);
        }
      }
      for (size_t k = 1; k < poses.size(); ++k) {
        const auto &[q, a] = poses[k];
        if ((q - *at).norm() <= 1e-9 && ir::angleBetween(a, axis) <= 1e-9)
          continue;
        add(kind.rapid ? Emitter::rapidNode(q, kind.role) : Emitter::linearNode(q, feed, kind.role), q, a);
      }
    }
  }
  leave();
  return true;
}

} // namespace

bool expandExplicitToolpaths(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  if (givesToolAxes(op))
    return expandTiltedToolpaths(x, step);
  if (const std::optional<std::string> direction = op.text("tool_direction"))
    x.assumed(ws, op, "its tool direction (" + *direction + ") is not followed: its toolpaths give no tool axes "
                      "(its_toolaxis), so the tool stays along z");
  const ir::PlaneFrame &frame = *step.frame;
  const Plan &p = step.plan;
  Emitter e(step.moves, step.moves.number("secplane").value_or(0));
  ExplicitRun run;
  run.exec = const_cast<Node *>(&ws);  // the pass's own module: the step is its to change
  for (const Node *tp : op.childrenOf(ir::Kind::Toolpath)) {
    const Node *tech = tp->child(ir::Kind::Technology);
    const double feed = tech && tech->number("feed") ? *tech->number("feed") : p.feed;
    const ExplicitKind kind = explicitKind(*tp);
    if (auto dwell = tp->number("dwell")) {
      // A feedstop waits where the path before it ended.
      if (e.positioned())
        e.dwell(*dwell);
      else
        x.diags->warning(tp->origin.loc, "workingstep " + ws.symbol +
                                             ": a feedstop before its first toolpath, where the tool is not yet: "
                                             "left out")
            .entity(tp->origin.entityId);
      continue;
    }
    for (const Node &curve : tp->children) {
      if (curve.category() != ir::Category::Curve)
        continue;
      ir::CurveResult cr = ir::curvePieces(curve, ir::ArcPlanes::Principal);
      for (const ir::CurvePiece &c : cr.pieces)
        if (std::string why = outOfPlaneArcFrame(frame, c); !why.empty() && cr.error.empty())
          cr.error = why;
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
        explicitPiece(frame, c, kind, feed, p.clearanceZ, e, *tp, run, step.moves);
    }
  }
  run.end = e.position();
  const size_t before = step.moves.children.size();
  e.retract();
  run.retract = step.moves.children.size() > before;
  if (e.positioned())
    x.explicitRuns[&ws] = run;
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
  Node moves = makeMoves(rm, x.lastTool, x.lastSpindle, x.lastCoolant, setup);
  Emitter e(moves, rm.number("secplane").value_or(0));
  ExplicitRun run;
  run.exec = &rm;
  for (const Node *tp : rm.childrenOf(ir::Kind::Toolpath))
    for (const Node &curve : tp->children)
      if (curve.category() == ir::Category::Curve) {
        ir::CurveResult cr = ir::curvePieces(curve, ir::ArcPlanes::Principal);
        if (!cr.error.empty()) {
          x.report(rm, "its toolpath: " + cr.error);
          return;
        }
        for (const ir::CurvePiece &c : cr.pieces) {
          if (!e.positioned()) {
            e.travel(c.from.head<2>(), c.from.z());
            run.leadIn = moves.children.size();
            run.start = c.from;
          }
          const size_t before = moves.children.size();
          e.rapid(c.to);
          if (moves.children.size() > before)
            run.decided.push_back({before, false, tp->origin});
        }
      }
  run.end = e.position();
  if (e.positioned())
    x.explicitRuns[&rm] = run;
  x.attach(rm, std::move(moves));
}

namespace {

constexpr double kSamePoint = 1e-4;  ///< mm: points this close are one (the file's joins)
constexpr double kStockTolerance = 0.01; ///< mm a rapid may skim the stock's top

Node *movesOf(Node &exec) {
  for (Node &c : exec.children)
    if (c.kind == ir::Kind::Moves)
      return &c;
  return nullptr;
}

/// Whether the tool may go on from one path to the next without leaving the
/// work: the same tool and setup, turning the same way at the same speed,
/// with the same coolant.
bool sameState(const Node &a, const Node &b) {
  return a.text("tool") == b.text("tool") && a.text("setup") == b.text("setup") &&
         a.number("spindle") == b.number("spindle") && a.text("coolant") == b.text("coolant");
}

/// Drops the moves a run made to reach its path's start, keeping its indices true.
void dropLeadIn(ExplicitRun &run, Node &moves) {
  moves.children.erase(moves.children.begin(), moves.children.begin() + long(run.leadIn));
  for (ExplicitRun::Decided &d : run.decided)
    d.index -= run.leadIn;
}

/// A node that only says where in the file something is, for messages (an
/// unknown place falls back to the step's).
Node placeOf(const ir::Origin &origin) {
  Node n;
  n.origin = origin;
  return n;
}

} // namespace

void linkExplicitPaths(Expander &x) {
  ExplicitRun *before = nullptr;
  for (const Node *e : ir::programOrder(*x.module)) {
    auto it = x.explicitRuns.find(e);
    ExplicitRun *run = it == x.explicitRuns.end() ? nullptr : &it->second;
    Node *movesA = before ? movesOf(*before->exec) : nullptr;
    Node *movesB = run ? movesOf(*run->exec) : nullptr;
    if (movesA && movesB && sameState(*movesA, *movesB)) {
      const Vec3 p = before->end, q = run->start;
      const bool samePoint = (p - q).norm() <= kSamePoint;
      // Over the same point in the plane (the same point itself included).
      if ((p.head<2>() - q.head<2>()).norm() <= kSamePoint) {
        if (before->retract) {
          movesA->children.pop_back();
          before->retract = false;
        }
        // Straight along the axis over the same point: up at rapid, down at
        // the feed the approach plunged at (a rapid down is the file's path
        // the stock decides).
        std::optional<Node> joint;
        if (!samePoint) {
          const Node *plunge = nullptr;
          for (size_t k = 0; k < run->leadIn; ++k)
            if (movesB->children[k].kind == ir::Kind::Linear)
              plunge = &movesB->children[k];
          if (q.z() < p.z() && plunge) {
            joint = *plunge;
            joint->set("to", ir::Value::point(q));
          } else {
            joint = Emitter::rapidNode(q, q.z() > p.z() ? "retract" : "approach");
          }
        }
        dropLeadIn(*run, *movesB);
        if (joint) {
          const bool rapidDown = joint->kind == ir::Kind::Rapid && q.z() < p.z();
          movesB->children.insert(movesB->children.begin(), std::move(*joint));
          for (ExplicitRun::Decided &d : run->decided)
            ++d.index;
          if (rapidDown)
            run->decided.insert(run->decided.begin(), {0, false, ir::Origin{}});
        }
        (*x.stats)["explicit paths joined"]++;
      }
    }
    // Only executables that move break or continue a chain: a message does not.
    if (e->kind == ir::Kind::DisplayMessage)
      continue;
    before = run && movesB ? run : nullptr;
  }
}

void settleExplicitRapids(Expander &x) {
  // The moves the stock decides, by node.
  struct Pending {
    ExplicitRun *run;
    ExplicitRun::Decided decided;
  };
  std::map<const Node *, Pending> pending;
  for (auto &[exec, run] : x.explicitRuns)
    if (Node *moves = movesOf(*run.exec))
      for (const ExplicitRun::Decided &d : run.decided)
        pending.emplace(&moves->children[d.index], Pending{&run, d});

  struct Lift {
    size_t index;
    Vec3 from;
    StockHit hit;
  };
  std::set<const Node *> clearConnects;
  std::map<Node *, std::vector<Lift>> lifts;  // by executable
  struct ShortApproach {
    size_t index;
    double z;      ///< where the rapid stops, above the stock
    double stock;  ///< the stock's top under the tool there
  };
  std::map<const Node *, std::vector<ShortApproach>> shortened;  // by executable
  struct RaisedCycle {
    const Node *exec;
    double z;      ///< the cycle's clearance plane, above the stock
    double stock;  ///< the stock's top under the tool there
  };
  // By cycle, in the order the walk meets them: its first hit.
  std::vector<std::pair<const Node *, RaisedCycle>> raisedCycles;
  std::set<const Node *> cyclesMet;
  walkStock(*x.module, rapidCheckCell(*x.module), [&](const StockMove &sm) {
    const ir::Move &m = *sm.move;
    auto it = pending.find(m.node);
    if (it == pending.end()) {
      // A rapid made here down the tool's axis whose way the stock blocks
      // (a feature below the raw piece's top there): it stops the clearance
      // above the stock and the tool goes on at feed.
      if (m.kind != ir::MoveKind::Rapid || m.to.z() >= m.from->z() ||
          (m.to.head<2>() - m.from->head<2>()).norm() > 1e-9)
        return;
      if (auto hit = rapidMeetsStock(*sm.stock, m, sm.radius, sm.point, kStockTolerance)) {
        const double z = std::min(m.from->z(), hit->height + kDefaultClearance);
        if (m.cycle) {
          if (cyclesMet.insert(m.cycle).second)
            raisedCycles.emplace_back(m.cycle, RaisedCycle{sm.executable, z, hit->height});
          return;
        }
        const Node *moves = sm.executable->child(ir::Kind::Moves);
        const size_t index = size_t(m.node - moves->children.data());
        if (index < moves->children.size() && &moves->children[index] == m.node)
          shortened[sm.executable].push_back({index, z, hit->height});
      }
      return;
    }
    const Pending &p = it->second;
    const double secplane = movesOf(*p.run->exec)->number("secplane").value_or(0);
    ir::Move asRapid = m;
    asRapid.kind = ir::MoveKind::Rapid;
    const std::optional<StockHit> hit = rapidMeetsStock(*sm.stock, asRapid, sm.radius, sm.point, kStockTolerance);
    if (p.decided.connect) {
      if (!hit)
        clearConnects.insert(m.node);
      return;
    }
    if (!hit || std::min(m.from->z(), m.to.z()) >= secplane - kStockTolerance)
      return;
    // Lifted: is the way down at the end clear?
    const cutting::HeightMap::Peak below =
        sm.stock->highest(m.to.head<2>(), m.to.head<2>(), std::max(0.0, sm.radius - sm.stock->cell()));
    if (below.height > m.to.z() + sm.point + kStockTolerance) {
      x.report(*p.run->exec, placeOf(p.decided.toolpath),
               "its rapid to (" + formatFixed(m.to.x(), 4) + ", " + formatFixed(m.to.y(), 4) + ", " +
                   formatFixed(m.to.z(), 4) + ") ends in the stock that remains there (up to z=" +
                   formatFixed(below.height, 4) + " mm): no rapid reaches it safely");
      return;
    }
    lifts[p.run->exec].push_back({size_t(m.node - movesOf(*p.run->exec)->children.data()), *m.from, *hit});
  });

  // A lifted rapid becomes up to three; a stopped approach gains a plunge:
  // each executable's edits are made back to front, so that each changes
  // only what follows it. Executables in program order, so that the
  // warnings come in the order of the program.
  auto lift = [&](Node &exec, Node &moves, const ExplicitRun &run, const Lift &l) {
    const double secplane = moves.number("secplane").value_or(0);
    const Vec3 to = *moves.children[l.index].vec("to");
    const double high = std::max({secplane, l.from.z(), to.z()});
    ir::Origin toolpath;
    for (const ExplicitRun::Decided &d : run.decided)
      if (d.index == l.index)
        toolpath = d.toolpath;
    x.assumed(exec, placeOf(toolpath),
              "its rapid from (" + formatFixed(l.from.x(), 4) + ", " + formatFixed(l.from.y(), 4) + ", " +
                  formatFixed(l.from.z(), 4) + ") to (" + formatFixed(to.x(), 4) + ", " + formatFixed(to.y(), 4) +
                  ", " + formatFixed(to.z(), 4) + ") meets the stock that remains (up to z=" +
                  formatFixed(l.hit.height, 4) + " mm at (" + formatFixed(l.hit.at.x(), 4) + ", " +
                  formatFixed(l.hit.at.y(), 4) + ")): lifted: up to the security plane z=" + formatFixed(high, 4) +
                  " mm, across, and down");
    std::vector<Node> path;
    if (l.from.z() < high)
      path.push_back(Emitter::rapidNode(Vec3(l.from.x(), l.from.y(), high), "retract"));
    path.push_back(Emitter::rapidNode(Vec3(to.x(), to.y(), high), "position"));
    path.push_back(Emitter::rapidNode(to, "approach"));
    const auto at = moves.children.begin() + long(l.index);
    for (Node &n : path)
      n.origin = at->origin;
    moves.children.erase(at);
    moves.children.insert(moves.children.begin() + long(l.index), path.begin(), path.end());
    (*x.stats)["explicit rapids lifted"]++;
  };
  auto stopAbove = [&](Node &exec, Node &moves, const ShortApproach &a) {
    Node &rapid = moves.children[a.index];
    const Vec3 to = *rapid.vec("to");
    // The feed the tool goes on at: that of the first move after it that has one.
    std::optional<double> feed;
    for (size_t k = a.index + 1; k < moves.children.size() && !feed; ++k)
      feed = moves.children[k].number("feed");
    if (!feed) {
      x.report(exec, "its approach down to z=" + formatFixed(to.z(), 4) + " mm at (" + formatFixed(to.x(), 4) + ", " +
                         formatFixed(to.y(), 4) + ") meets the stock that remains (up to z=" +
                         formatFixed(a.stock, 4) + " mm), and no feed follows to go on at");
      return;
    }
    x.warning(exec, "its approach at (" + formatFixed(to.x(), 4) + ", " + formatFixed(to.y(), 4) +
                        ") meets the stock that remains (up to z=" + formatFixed(a.stock, 4) +
                        " mm, above the feature): rapid down to z=" + formatFixed(a.z, 4) +
                        " mm, then at feed down to z=" + formatFixed(to.z(), 4) + " mm");
    rapid.set("to", ir::Value::point(Vec3(to.x(), to.y(), a.z)));
    Node plunge = Emitter::linearNode(to, *feed, "plunge");
    plunge.origin = rapid.origin;
    moves.children.insert(moves.children.begin() + long(a.index) + 1, std::move(plunge));
    (*x.stats)["approaches stopped above the stock"]++;
  };
  for (const Node *constExec : ir::programOrder(*x.module)) {
    Node &exec = *const_cast<Node *>(constExec);  // the pass's own module
    Node *moves = movesOf(exec);
    if (!moves)
      continue;
    const auto run = x.explicitRuns.find(constExec);
    if (run != x.explicitRuns.end()) {
      std::set<std::pair<const SourceFile *, uint64_t>> toolpathsSaid;
      for (const ExplicitRun::Decided &d : run->second.decided) {
        Node &m = moves->children[d.index];
        if (!d.connect || !clearConnects.count(&m))
          continue;
        Node r = Emitter::rapidNode(*m.vec("to"), "link");
        r.origin = m.origin;
        m = std::move(r);
        (*x.stats)["connect moves at rapid"]++;
        if (toolpathsSaid.insert({d.toolpath.loc.file, d.toolpath.loc.offset}).second)
          x.assumed(exec, placeOf(d.toolpath),
                    "its connect toolpath gives no speed or feed: moved at rapid where its path is clear of the "
                    "stock that remains (as NIST's ISO 14649 interpreter moves it), at feed where it is not");
      }
    }
    struct Edit {
      size_t index;
      const Lift *lift;
      const ShortApproach *approach;
    };
    std::vector<Edit> edits;
    if (auto l = lifts.find(&exec); l != lifts.end() && run != x.explicitRuns.end())
      for (const Lift &one : l->second)
        edits.push_back({one.index, &one, nullptr});
    if (auto s = shortened.find(constExec); s != shortened.end())
      for (const ShortApproach &one : s->second)
        edits.push_back({one.index, nullptr, &one});
    std::stable_sort(edits.begin(), edits.end(), [](const Edit &a, const Edit &b) { return a.index > b.index; });
    for (const Edit &e : edits) {
      if (e.lift)
        lift(exec, *moves, run->second, *e.lift);
      else
        stopAbove(exec, *moves, *e.approach);
    }
  }

  // A canned cycle's clearance plane (its R plane) within the stock: raised
  // above it, where the cycle's rapids to the plane then end, and its feed
  // out of the hole (a reamer or boring bar leaves at feed up to the R plane).
  for (auto &[constCycle, raise] : raisedCycles) {
    Node &cycle = *const_cast<Node *>(constCycle);  // the pass's own module
    const double old = cycle.number("clearance").value_or(raise.z);
    if (raise.z <= old)
      continue;
    for (Node &c : cycle.children)
      if (c.kind == ir::Kind::Rapid || c.kind == ir::Kind::Linear)
        if (const Vec3 to = *c.vec("to"); std::abs(to.z() - old) < 1e-9)
          c.set("to", ir::Value::point(Vec3(to.x(), to.y(), raise.z)));
    cycle.set("clearance", ir::Value::length(raise.z));
    const Vec3 at = *cycle.vec("at");
    x.warning(*raise.exec, "its cycle at (" + formatFixed(at.x(), 4) + ", " + formatFixed(at.y(), 4) +
                               ") starts in the stock that remains (up to z=" + formatFixed(raise.stock, 4) +
                               " mm, above the feature): its clearance plane is raised from z=" + formatFixed(old, 4) +
                               " to z=" + formatFixed(raise.z, 4) + " mm");
    (*x.stats)["approaches stopped above the stock"]++;
  }
}

} // namespace stepnc::passes::expand
