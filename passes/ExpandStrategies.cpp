// expand-strategies: from features to moves.
//
// Each machining workingstep gets a `moves` child: the tool-centre path in
// workpiece coordinates, made from the feature's shape (passes/FeatureShape),
// the operation (allowances, depths of cut, stepover), its strategy, approach
// and retract. The plan of every milling workingstep is the same:
//   1. levels: from the feature's top down to its floor plus the bottom
//      allowance, in equal steps no deeper than the axial depth of cut;
//   2. per level, the plane paths of the strategy (contour rings, zigzag or
//      one-way strokes) inside the area the tool centre may reach: the region
//      shrunk by the tool radius and the side allowance, islands grown by both;
//   3. each path entered by the approach strategy (plunge, ramp, helix) and
//      left by the retract; between paths the tool rises to the security plane
//      unless a straight link at depth stays inside the reachable area.
// Hole making is a sequence of axial moves (the backends may turn it back into
// a canned cycle). Explicit toolpaths are lowered piece by piece: lines stay
// lines, circles and helices stay arcs.
#include "passes/Pass.h"

#include "geom/Boolean.h"
#include "ir/Kinds.h"
#include "passes/Curves.h"
#include "passes/FeatureShape.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::passes {

namespace {

using geom::Loop;
using geom::Region;
using geom::Seg;
using geom::Vec2;
using ir::Node;
using ir::Value;
using ir::Vec3;

constexpr double kPi = std::numbers::pi;
/// Height above a feature's top where plunges start when the operation gives no retract plane (mm).
constexpr double kDefaultClearance = 2.0;
/// Extra depth past the floor of a through hole, beyond the tool's point, when
/// the operation's overcut is smaller (mm).
constexpr double kBreakthrough = 1.0;

Vec3 at(const Vec2 &p, double z) { return {p.x(), p.y(), z}; }

/// Writes moves under a `moves` node and keeps track of where the tool is.
class Emitter {
public:
  Emitter(Node &moves, double secplane) : moves_(moves), secplane_(secplane) {}

  const Vec3 &position() const { return pos_; }
  bool positioned() const { return positioned_; }
  double secplane() const { return secplane_; }

  void rapid(const Vec3 &to, const char *role = "position") {
    if (positioned_ && (to - pos_).norm() <= geom::kEps)
      return;
    Node &m = moves_.add(Node("rapid"));
    m.set("to", Value::point(to));
    m.set("role", Value::word(role));
    pos_ = to;
    positioned_ = true;
  }

  void linear(const Vec3 &to, double feed, const char *role) {
    if ((to - pos_).norm() <= geom::kEps)
      return;
    Node &m = moves_.add(Node("linear"));
    m.set("to", Value::point(to));
    m.set("feed", Value::feed(feed));
    m.set("role", Value::word(role));
    pos_ = to;
  }

  void arc(const Vec3 &to, const Vec2 &centre, bool ccw, int64_t turns, double feed, const char *role) {
    Node &m = moves_.add(Node("arc"));
    m.set("to", Value::point(to));
    m.set("center", Value::point(at(centre, pos_.z())));
    m.set("dir", Value::word(ccw ? "ccw" : "cw"));
    if (turns > 0)
      m.set("turns", Value::integer(turns));
    m.set("feed", Value::feed(feed));
    m.set("role", Value::word(role));
    pos_ = to;
  }

  /// A plane segment cut at height z (the tool is at its start).
  void seg(const Seg &s, double z, double feed, const char *role = "cut") {
    if (s.isArc())
      arc(at(s.b, z), s.c, s.turn > 0, 0, feed, role);
    else
      linear(at(s.b, z), feed, role);
  }

  /// Up to the security plane (if below it), across, and down along the axis to `z`.
  void travel(const Vec2 &xy, double z) {
    if (!positioned_)
      rapid(at(xy, secplane_), "position");
    else if (pos_.z() < secplane_)
      rapid(Vec3(pos_.x(), pos_.y(), secplane_), "retract");
    rapid(at(xy, secplane_));
    rapid(at(xy, z), "approach");
  }

  void retract() {
    if (positioned_ && pos_.z() < secplane_)
      rapid(Vec3(pos_.x(), pos_.y(), secplane_), "retract");
  }

private:
  Node &moves_;
  double secplane_;
  Vec3 pos_ = Vec3::Zero();
  bool positioned_ = false;
};

/// A loop started at the point nearest to p (the segment there is split).
Loop startNearest(const Loop &l, const Vec2 &p) {
  size_t best = 0;
  double bestDist = 1e300;
  Vec2 bestPoint = l.segs.front().a;
  for (size_t i = 0; i < l.segs.size(); ++i) {
    const Vec2 q = geom::closestPoint(l.segs[i], p);
    if (double d = (q - p).norm(); d < bestDist - 1e-9) {
      bestDist = d;
      best = i;
      bestPoint = q;
    }
  }
  Loop out;
  const Seg &s = l.segs[best];
  auto split = [&](const Vec2 &a, const Vec2 &b) {
    Seg piece = s;
    piece.a = a;
    piece.b = b;
    return piece;
  };
  const bool inside = (bestPoint - s.a).norm() > 1e-7 && (bestPoint - s.b).norm() > 1e-7;
  if (inside)
    out.segs.push_back(split(bestPoint, s.b));
  else if ((bestPoint - s.b).norm() <= 1e-7)
    ++best, bestPoint = l.segs[best % l.segs.size()].a;
  const size_t first = inside ? best + 1 : best;
  for (size_t k = 0; k < l.segs.size(); ++k) {
    const size_t i = (first + k) % l.segs.size();
    if (inside && i == best)
      break;
    out.segs.push_back(l.segs[i]);
  }
  if (inside)
    out.segs.push_back(split(s.a, bestPoint));
  return out;
}

/// The smallest interior angle at a convex corner of the region (pi when none).
double sharpestCorner(const Region &r) {
  double sharpest = kPi;
  for (const Loop &l : r.loops)
    for (size_t i = 0; i < l.segs.size(); ++i) {
      const Seg &s = l.segs[i], &t = l.segs[(i + 1) % l.segs.size()];
      const Vec2 u = s.tangent(1), v = t.tangent(0);
      const double turn = std::atan2(geom::cross(u, v), u.dot(v));
      // Outer loops run counter-clockwise: a left turn is a convex corner of the area.
      if (turn > 1e-6)
        sharpest = std::min(sharpest, kPi - turn);
    }
  return sharpest;
}

struct Plan {
  const Node *feature = nullptr;
  const Node *op = nullptr;
  const Node *tool = nullptr;
  double radius = 0;
  double feed = 0;
  double plungeFeed = 0;
  double spindle = 0;
  double allowanceSide = 0;
  double allowanceBottom = 0;
  double clearanceZ = 0;  ///< where axial approaches start
};

class ExpandStrategiesPass final : public Pass {
public:
  std::string_view name() const override { return "expand-strategies"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    module_ = &module;
    diags_ = &diags;
    stats_ = &stats;
    result_ = {};
    for (Node &n : module.root.children)
      if (n.kind == "workplan")
        workplan(n, n.text("setup").value_or(""));
    return result_;
  }

private:
  // --- Walking the program ------------------------------------------------------

  void workplan(Node &plan, const std::string &setup) {
    for (Node &e : plan.children) {
      if (e.kind == "workplan")
        workplan(e, e.text("setup").value_or(setup));
      else if ((e.kind == "workingstep" || e.kind == "rapid_movement") && !e.child("moves"))
        executable(e, setup);
    }
  }

  void executable(Node &ws, const std::string &setup) {
    if (ws.kind == "rapid_movement") {
      rapidMovement(ws, setup);
      return;
    }
    const Node *op = nullptr;
    for (const Node &c : ws.children)
      if (const ir::KindSpec *k = ir::findKind(c.kind); k && k->category == "operation")
        op = &c;
    if (!op)
      return;
    const Node *feature = findFeature(*module_, ws.text("feature").value_or(""));
    const Node *tool = findTool(op->text("tool").value_or(""));
    if (!feature || !tool)
      return;  // the IR verifier reports dangling references
    Plan p;
    p.feature = feature;
    p.op = op;
    p.tool = tool;
    p.radius = tool->number("diameter").value_or(0) / 2;
    const Node *tech = op->child("technology");
    p.feed = tech ? tech->number("feed").value_or(0) : 0;
    p.spindle = tech ? tech->number("spindle").value_or(0) : 0;
    p.plungeFeed = p.feed;
    p.allowanceSide = op->number("allowance_side").value_or(0);
    p.allowanceBottom = op->number("allowance_bottom").value_or(0);
    if (p.feed <= 0) {
      report(ws, tech && tech->has("feed") ? "its operation's feed is 0 mm/min"
                                           : "has no feed for its moves (run resolve-feeds first, or give the "
                                             "operation a feed)");
      return;
    }
    if (p.radius <= 0) {
      report(ws, "its tool " + tool->symbol + " has no diameter");
      return;
    }
    // Axial approaches start the retract plane above the feature's top, never
    // above the security plane.
    auto clearanceAbove = [&](double top) {
      return std::min(top + op->number("retract_plane").value_or(kDefaultClearance),
                      ws.number("secplane").value_or(1e300));
    };
    Node moves = makeMoves(ws, tool->symbol, p.spindle, coolant(*op), setup);
    // Explicit toolpaths need no shape: they are in the feature's frame.
    if (!op->childrenOf("toolpath").empty()) {
      FrameResult fr = planeFrame(*feature);
      if (!fr.frame) {
        unsupported(ws, fr.error);
        return;
      }
      p.clearanceZ = clearanceAbove(fr.frame->z);
      explicitToolpaths(ws, *op, *fr.frame, p, moves);
      attach(ws, std::move(moves));
      return;
    }
    ShapeResult shape = featureShape(*module_, *feature);
    if (!shape.shape) {
      unsupported(ws, shape.error);
      return;
    }
    const FeatureShape &s = *shape.shape;
    const double secplane = ws.number("secplane").value_or(0);
    if (secplane < s.top) {
      report(ws, "its security plane z=" + formatFixed(secplane, 4) + " mm is below the top of " + s.symbol +
                     " (z=" + formatFixed(s.top, 4) + " mm): there is no safe height to travel at");
      return;
    }
    p.clearanceZ = clearanceAbove(s.top);
    // Hole-making operations are those that take a drilling strategy.
    const bool holeMaking = ir::inList(ir::findKind(op->kind)->children, "drilling_strategy");
    if (holeMaking ? expandHoleMaking(ws, *op, s, p, moves) : milling(ws, *op, s, p, moves))
      attach(ws, std::move(moves));
  }

  /// An empty `moves` for the executable `exec`, with the state in force.
  static Node makeMoves(const Node &exec, const std::string &tool, double spindle, const std::string &coolant,
                        const std::string &setup) {
    Node moves("moves");
    moves.set("tool", Value::ref(tool));
    moves.set("spindle", Value::spindle(spindle));
    moves.set("coolant", Value::word(coolant));
    if (!setup.empty())
      moves.set("setup", Value::ref(setup));
    moves.set("secplane", Value::length(exec.number("secplane").value_or(0)));
    moves.origin = exec.origin;
    return moves;
  }

  void attach(Node &ws, Node moves) {
    (*stats_)["workingsteps expanded"]++;
    (*stats_)["moves"] += static_cast<long long>(moves.children.size());
    lastTool_ = moves.text("tool").value_or("");
    ws.add(std::move(moves));
    result_.changed = true;
  }

  static std::string coolant(const Node &op) {
    const Node *mf = op.child("machine_functions");
    if (!mf)
      return "off";
    if (mf->flag("through_spindle_coolant").value_or(false))
      return "through_tool";
    if (mf->flag("mist").value_or(false))
      return "mist";
    return mf->flag("coolant").value_or(false) ? "flood" : "off";
  }

  const Node *findTool(std::string_view symbol) const {
    for (const Node &n : module_->root.children)
      if (n.kind == "tool" && n.symbol == symbol)
        return &n;
    return nullptr;
  }

  void report(const Node &ws, const std::string &message) {
    diags_->error(ws.origin.loc, ws.kind + " " + ws.symbol + ": " + message).entity(ws.origin.entityId);
    result_.ok = false;
  }

  void unsupported(const Node &ws, const std::string &reason) {
    diags_->warning(ws.origin.loc, "workingstep " + ws.symbol + " is not expanded: " + reason)
        .entity(ws.origin.entityId);
    (*stats_)["workingsteps not expanded"]++;
  }

  // --- Explicit toolpaths -------------------------------------------------------

  void explicitToolpaths(const Node &ws, const Node &op, const PlaneFrame &frame, const Plan &p, Node &moves) {
    Emitter e(moves, ws.number("secplane").value_or(0));
    for (const Node *tp : op.childrenOf("toolpath")) {
      const Node *tech = tp->child("technology");
      const double feed = tech && tech->number("feed") ? *tech->number("feed") : p.feed;
      for (const Node &curve : tp->children) {
        if (ir::findKind(curve.kind) == nullptr || ir::findKind(curve.kind)->category != "curve")
          continue;
        CurveResult cr = curvePieces(curve);
        if (!cr.error.empty()) {
          report(ws, "its explicit toolpath: " + cr.error);
          return;
        }
        const bool reversed = tp->flag("reversed").value_or(false);
        if (reversed) {
          std::reverse(cr.pieces.begin(), cr.pieces.end());
          for (CurvePiece &c : cr.pieces) {
            std::swap(c.from, c.to);
            c.ccw = !c.ccw;
          }
        }
        for (const CurvePiece &c : cr.pieces)
          explicitPiece(frame, c, feed, p.clearanceZ, e);
      }
    }
    e.retract();
  }

  /// One piece of an explicit toolpath, mapped from the feature's frame.
  void explicitPiece(const PlaneFrame &f, const CurvePiece &c, double feed, double clearanceZ, Emitter &e) {
    const Vec3 from = at(f.map(c.from.head<2>()), f.z + c.from.z());
    const Vec3 to = at(f.map(c.to.head<2>()), f.z + c.to.z());
    if (!e.positioned() || (e.position() - from).norm() > 1e-6) {
      // Reach the start: over it at the security plane, down in free space to
      // the clearance height at most, then at feed.
      e.travel(from.head<2>(), std::max(from.z(), std::min(clearanceZ, e.secplane())));
      e.linear(from, feed, "plunge");
    }
    if (!c.arc)
      e.linear(to, feed, "cut");
    else
      e.arc(to, f.map(c.center.head<2>()), c.ccw != f.mirrored(), c.turns, feed, "cut");
  }

  void rapidMovement(Node &rm, const std::string &setup) {
    // A rapid movement keeps the tool of the workingstep before it; the IR
    // names it where known.
    if (lastTool_.empty())
      return;
    Node moves = makeMoves(rm, lastTool_, 0, "off", setup);
    Emitter e(moves, rm.number("secplane").value_or(0));
    for (const Node *tp : rm.childrenOf("toolpath"))
      for (const Node &curve : tp->children)
        if (const ir::KindSpec *k = ir::findKind(curve.kind); k && k->category == "curve") {
          CurveResult cr = curvePieces(curve);
          if (!cr.error.empty()) {
            report(rm, "its toolpath: " + cr.error);
            return;
          }
          for (const CurvePiece &c : cr.pieces) {
            if (!e.positioned())
              e.travel(c.from.head<2>(), c.from.z());
            e.rapid(c.to);
          }
        }
    attach(rm, std::move(moves));
  }

  // --- Hole making --------------------------------------------------------------

  bool expandHoleMaking(const Node &ws, const Node &op, const FeatureShape &s, const Plan &p, Node &moves) {
    if (!s.holeCentre) {
      unsupported(ws, op.kind + " on a " + s.kind + ": hole-making operations are expanded on round holes only");
      return false;
    }
    // Spot drills and countersinks are wider than the hole they chamfer.
    const bool chamfers = op.kind == "center_drilling" || op.kind == "counter_sinking";
    if (!chamfers && 2 * p.radius > s.holeDiameter + 1e-6) {
      report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                     " mm) is wider than the hole (" + formatFixed(s.holeDiameter, 3) + " mm)");
      return false;
    }
    const Node &feature = *p.feature;
    // The depth the tool's tip reaches: the floor, or past it for through holes.
    double bottom = s.bottom;
    const double point = pointLength(*p.tool);
    if (feature.text("bottom") == "through")
      bottom -= point + std::max(kBreakthrough, op.number("overcut").value_or(0));
    if (auto depth = op.number("cutting_depth"))
      bottom = std::max(bottom, s.top - *depth);
    if (op.kind == "center_drilling" && !op.has("cutting_depth"))
      bottom = std::max(bottom, s.top - std::max(point, p.radius));
    Emitter e(moves, ws.number("secplane").value_or(0));
    const Vec2 c = *s.holeCentre;
    e.travel(c, p.clearanceZ);
    if (op.kind == "multistep_drilling") {
      const double first = op.number("first_depth").value_or(s.top - bottom);
      const double step = std::max(op.number("depth_increment").value_or(first), 0.1);
      double reached = p.clearanceZ;
      for (double target = s.top - first;; target -= step) {
        target = std::max(target, bottom);
        if (reached < p.clearanceZ)
          e.rapid(at(c, std::min(reached + 0.5, p.clearanceZ)), "approach");
        e.linear(at(c, target), p.plungeFeed, "plunge");
        reached = target;
        if (target <= bottom + 1e-9)
          break;
        // Chip clearing: out of the hole, back down in free space.
        e.rapid(at(c, p.clearanceZ), "retract");
      }
    } else {
      e.linear(at(c, bottom), p.plungeFeed, "plunge");
    }
    // Reamers, boring bars and taps leave at feed (a tap with the spindle
    // reversed: the backend's tapping cycle); drills leave at rapid.
    const bool feedOut = op.kind == "reaming" || op.kind == "boring" || op.kind == "tapping" ||
                         op.kind == "thread_drilling";
    if (feedOut)
      e.linear(at(c, p.clearanceZ), p.feed * op.number("feed_on_retract").value_or(1.0), "retract");
    e.retract();
    return true;
  }

  // --- Milling ------------------------------------------------------------------

  bool milling(const Node &ws, const Node &op, const FeatureShape &s, const Plan &p, Node &moves) {
    const Node *strategy = op.child("strategy");
    std::string type = strategy ? strategy->text("type").value_or("") : "";
    const bool face = op.kind == "plane_rough_milling" || op.kind == "plane_finish_milling" || s.kind == "planar_face";
    if (type.empty())
      type = face ? "bidirectional" : "contour_parallel";
    const bool sideOnly = op.kind == "side_rough_milling" || op.kind == "side_finish_milling";

    // Levels, from the top down to the floor (plus its allowance).
    const double floorZ = s.bottom + p.allowanceBottom;
    if (floorZ >= s.top - 1e-9) {
      unsupported(ws, "the bottom allowance leaves nothing to cut");
      return false;
    }
    const double ap = op.number("axial_depth").value_or(0);
    const int levels = ap > 1e-9 ? std::max(1, static_cast<int>(std::ceil((s.top - floorZ) / ap - 1e-9))) : 1;

    // The stepover: the radial depth of cut, else the overlap; never so wide
    // that a ring leaves material at the region's sharpest convex corner.
    double stepover = op.number("radial_depth").value_or(0);
    const double overlap = strategy ? strategy->number("overlap").value_or(-1) : -1;
    if (stepover <= 0 && overlap > 0 && overlap < 1)
      stepover = 2 * p.radius * (1 - overlap);
    if (stepover <= 0)
      stepover = p.radius;
    const double coverLimit = p.radius * (1 + std::sin(sharpestCorner(s.target) / 2)) * 0.98;
    const double limitBidir = 2 * p.radius * 0.98;
    stepover = std::min(stepover, type == "bidirectional" || type == "unidirectional" ? limitBidir : coverLimit);

    // Cut direction: climb keeps the wall on the tool's right for a clockwise
    // (M3) spindle, which is the Region orientation; conventional reverses it.
    bool followOrientation = true;
    const std::string cutmode = strategy ? strategy->text("cutmode").value_or("") : "";
    const std::string rotation = strategy ? strategy->text("rotation").value_or("") : "";
    if (!cutmode.empty())
      followOrientation = (cutmode == "climb") == (p.spindle <= 0);
    else if (!rotation.empty())
      followOrientation = rotation == "ccw";

    const Vec2 strokeDir = strokeDirection(*p.feature, s, strategy);
    const bool linkAtDepth = type == "contour_spiral" || type == "contour_parallel" || type == "bidirectional" ||
                             type == "contour_bidirectional" || type == "bidirectional_contour";
    Emitter e(moves, ws.number("secplane").value_or(0));
    // The centre area and the paths depend on the level only through the
    // islands standing at it: they are made again only when that set changes.
    std::optional<std::vector<bool>> standing;
    Region centres;
    std::vector<std::vector<Seg>> paths;
    for (int i = 1; i <= levels; ++i) {
      const double z = s.top - (s.top - floorZ) * i / levels;
      std::vector<bool> here;
      for (const IslandShape &isl : s.islands)
        here.push_back(isl.top > z + 1e-9);
      if (standing != here) {
        standing = here;
        std::vector<Region> islands;
        for (size_t k = 0; k < s.islands.size(); ++k)
          if (here[k])
            islands.push_back(geom::offset(s.islands[k].region, p.allowanceSide));
        centres = centreArea(s, s.unbounded ? s.target : s.limit, islands, p);
        paths.clear();
        // Center milling, and slots exactly as wide as the tool: along the course of travel.
        if (s.slot && (type == "center_milling" || centres.empty())) {
          std::optional<std::vector<Seg>> line = slotCentreline(*s.slot, p);
          if (!line) {
            report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                           " mm) does not fit in slot " + s.symbol + " (width " + formatFixed(s.slot->width, 3) +
                           " mm) with the side allowance");
            return false;
          }
          centres = geom::offset(s.target, -geom::kEps);  // links stay in the slot
          paths.push_back(std::move(*line));
        } else if (type == "center_milling") {
          unsupported(ws, "center milling follows the course of travel of a slot; " + s.symbol + " is a " + s.kind);
          return false;
        } else if (!centres.empty()) {
          auto made = strategyPaths(type, face, s.unbounded, sideOnly, centres, strokeDir, stepover, followOrientation, p.radius);
          if (!made) {
            unsupported(ws, "strategy '" + type + "' is not expanded yet");
            return false;
          }
          paths = std::move(*made);
        } else if (!(s.holeCentre && 2 * p.radius <= s.holeDiameter + 1e-6)) {
          report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                         " mm) does not fit in " + s.symbol + " with the side allowance");
          return false;
        }
      }
      if (centres.empty()) {
        // A cutter as wide as the hole: straight down its axis.
        e.travel(*s.holeCentre, p.clearanceZ);
        e.linear(at(*s.holeCentre, z), p.plungeFeed, "plunge");
        e.retract();
        continue;
      }
      if (s.slot && paths.size() == 1 && !geom::Chain{paths[0]}.closed()) {
        // One open path per level (center milling): down at the end where the
        // level before finished, and back along it.
        if (i > 1) {
          Loop back{paths[0]};
          back.reverse();
          paths[0] = std::move(back.segs);
        }
        cutPath(e, paths[0], z, p, op, centres, false, false);
        continue;
      }
      for (size_t k = 0; k < paths.size(); ++k)
        cutPath(e, paths[k], z, p, op, centres, linkAtDepth && k > 0, s.unbounded);
    }
    e.retract();
    return true;
  }

  /// The tool centre's path along a slot: its course of travel, stopped the
  /// tool radius (and side allowance) short of flat ends, short of radiused
  /// ends as far as the tool is narrower than the slot, and run a radius past
  /// open ends. None when the tool is wider than the slot less its allowances.
  static std::optional<std::vector<Seg>> slotCentreline(const FeatureShape::SlotPath &slot, const Plan &p) {
    const double reach = p.radius + p.allowanceSide;
    if (2 * reach > slot.width + 1e-6)
      return std::nullopt;
    auto inset = [&](const std::string &end) {
      if (end == "open")
        return -p.radius;
      if (end == "radiused")
        return std::max(0.0, reach - slot.width / 2);
      return reach;
    };
    const Vec2 along = (slot.to - slot.from).normalized();
    const double length = (slot.to - slot.from).norm();
    const double in1 = inset(slot.end1), in2 = inset(slot.end2);
    if (length - in1 - in2 < -1e-9)
      return std::nullopt;
    const Vec2 a = slot.from + along * in1;
    const Vec2 b = slot.from + along * std::max(in1, length - in2);
    return std::vector<Seg>{Seg::line(a, b)};
  }

  /// The plane paths of a strategy in the centre area; none for a strategy
  /// not expanded yet.
  std::optional<std::vector<std::vector<Seg>>> strategyPaths(const std::string &type, bool face, bool unbounded,
                                                             bool sideOnly,
                                                             const Region &centres, const Vec2 &strokeDir,
                                                             double stepover, bool followOrientation,
                                                             double radius) {
    const bool strokesOnly = type == "bidirectional" || type == "unidirectional";
    if (face && strokesOnly)
      return strokes(centres, strokeDir, stepover, type == "bidirectional", radius);
    if (sideOnly) {
      // Side milling follows the walls; with no walls around (outside
      // profiles, faces) only the rings round what stands.
      std::vector<std::vector<Seg>> out = rings(centres, stepover, followOrientation, /*all=*/false, radius);
      if (face || unbounded)
        std::erase_if(out, [&](const std::vector<Seg> &ring) {
          return (Loop{ring}.area() > 0) == followOrientation;
        });
      return out;
    }
    if (type == "contour_parallel" || type == "contour_spiral")
      return rings(centres, stepover, followOrientation, /*all=*/true, radius);
    if (strokesOnly)
      return strokes(centres, strokeDir, stepover, type == "bidirectional", 0);
    if (type == "contour_bidirectional" || type == "bidirectional_contour") {
      // Zigzag inside the first ring, and the ring: before or after.
      std::vector<std::vector<Seg>> ring = rings(centres, stepover, followOrientation, false, radius);
      std::vector<std::vector<Seg>> zig = strokes(geom::offset(centres, -stepover), strokeDir, stepover, true, 0);
      std::vector<std::vector<Seg>> paths = type == "contour_bidirectional" ? ring : zig;
      const auto &rest = type == "contour_bidirectional" ? zig : ring;
      paths.insert(paths.end(), rest.begin(), rest.end());
      return paths;
    }
    return std::nullopt;
  }

  /// Where the tool centre may be at one level: away from walls and islands by
  /// the radius plus the side allowance; for faces, over the face and past it.
  Region centreArea(const FeatureShape &s, const Region &area, const std::vector<Region> &islands, const Plan &p) {
    const double reach = p.radius + p.allowanceSide;
    Region centres;
    if (s.unbounded) {
      centres = geom::offset(area, p.radius);  // overtravel: the tool's edge reaches the face's edge
    } else {
      centres = geom::offset(area, -reach);
      // Open sides: only where the tool touches the material.
      if (s.limit.area() > s.target.area() + 1e-6)
        centres = geom::intersect(centres, geom::offset(s.target, p.radius - 1e-6));
    }
    for (const Region &isl : islands)
      centres = geom::subtract(centres, geom::offset(isl, p.radius));
    return centres;
  }

  /// Contour-parallel rings: the boundaries of the centre area shrunk by 0,
  /// s, 2s, ... innermost first (all) or the outermost ring only.
  std::vector<std::vector<Seg>> rings(const Region &centres, double stepover, bool followOrientation, bool all,
                                      double radius) {
    std::vector<Region> shells;
    for (Region r = centres; !r.empty(); r = geom::offset(r, -stepover)) {
      shells.push_back(r);
      if (!all || shells.size() > 10000)
        break;
    }
    // The innermost shell's middle may lie further than a radius from its
    // ring (a strip narrower than the stepover): one more thin ring round the
    // middle, at the deepest offset that still leaves an area.
    if (all && !shells.empty()) {
      double lo = 0, hi = stepover;
      for (int i = 0; i < 30 && hi - lo > 1e-4; ++i) {
        const double mid = (lo + hi) / 2;
        (geom::offset(shells.back(), -mid).empty() ? hi : lo) = mid;
      }
      if (lo > radius * 0.9) {
        Region middle = geom::offset(shells.back(), -std::max(lo - std::min(0.1 * radius, lo / 2), 0.0));
        if (!middle.empty())
          shells.push_back(std::move(middle));
      }
    }
    std::vector<std::vector<Seg>> out;
    for (auto it = shells.rbegin(); it != shells.rend(); ++it)
      for (Loop l : it->loops) {
        if (!followOrientation)
          l.reverse();
        out.push_back(std::move(l.segs));
      }
    return out;
  }

  /// The stroke direction: the strategy's feed direction, else the face's
  /// course of travel, else the feature's x axis.
  static Vec2 strokeDirection(const Node &feature, const FeatureShape &s, const Node *strategy) {
    if (strategy)
      if (auto d = strategy->vec("feed_dir"); d && d->head<2>().norm() > 1e-9)
        return s.frame.mapDir(d->head<2>()).normalized();
    if (auto d = feature.vec("travel_dir"))
      return s.frame.mapDir(d->head<2>()).normalized();
    return s.frame.x;
  }

  /// Parallel strokes across the area in direction `dir`, `stepover` apart,
  /// each clipped to the area; alternate strokes reversed when bidirectional.
  std::vector<std::vector<Seg>> strokes(const Region &area, const Vec2 &dir, double stepover, bool bidirectional,
                                        double overtravel) {
    std::vector<std::vector<Seg>> out;
    if (area.empty())
      return out;
    const Vec2 across(-dir.y(), dir.x());
    double lo = 1e300, hi = -1e300, along0 = 1e300, along1 = -1e300;
    for (const Loop &l : area.loops)
      for (const Seg &sg : l.segs)
        for (double t = 0; t <= 1.0; t += 0.125) {
          const Vec2 q = sg.at(t);
          lo = std::min(lo, q.dot(across));
          hi = std::max(hi, q.dot(across));
          along0 = std::min(along0, q.dot(dir));
          along1 = std::max(along1, q.dot(dir));
        }
    // For faces the area is already grown by the radius: strokes run from
    // edge to edge of the face, the first and last a radius inside its sides.
    const double inset = overtravel > 0 ? overtravel : 0;
    const double width = std::max(0.0, hi - lo - 2 * inset);
    const int n = std::max(1, static_cast<int>(std::ceil(width / stepover - 1e-9)) + 1);
    const double pitch = n > 1 ? width / (n - 1) : 0;
    bool forward = true;
    for (int i = 0; i < n; ++i) {
      const double c = n > 1 ? lo + inset + pitch * i : (lo + hi) / 2;
      const Vec2 p0 = across * c + dir * (along0 - 1);
      const Vec2 p1 = across * c + dir * (along1 + 1);
      std::vector<Seg> pieces = geom::clip(area, forward ? p0 : p1, forward ? p1 : p0);
      for (Seg &sg : pieces)
        out.push_back({sg});
      if (bidirectional)
        forward = !forward;
    }
    return out;
  }

  /// One plane path at height z: reached by a link at depth when allowed and
  /// inside the centre area, else from the security plane by the approach.
  void cutPath(Emitter &e, const std::vector<Seg> &path, double z, const Plan &p, const Node &op,
               const Region &centres, bool mayLink, bool unbounded, bool rotated = false) {
    if (path.empty())
      return;
    // A closed ring starts where it is nearest to the tool.
    if (!rotated && e.positioned() && path.size() > 1 && (path.front().a - path.back().b).norm() < 1e-7) {
      Loop ring;
      ring.segs = path;
      return cutPath(e, startNearest(ring, e.position().head<2>()).segs, z, p, op, centres, mayLink, unbounded,
                     /*rotated=*/true);
    }
    const Vec2 start = path.front().a;
    bool linked = false;
    if (mayLink && e.positioned() && std::abs(e.position().z() - z) < 1e-9) {
      const Vec2 here = e.position().head<2>();
      std::vector<Seg> inside = geom::clip(centres, here, start);
      double len = 0;
      for (const Seg &sg : inside)
        len += sg.length();
      if (unbounded || std::abs(len - (start - here).norm()) < 1e-6) {
        e.linear(at(start, z), p.feed, "link");
        linked = true;
      }
    }
    const Node *a = op.child("approach");
    const bool straightDown = !a || a->text("type").value_or("plunge_toolaxis") == "plunge_toolaxis";
    if (!linked && straightDown && e.positioned() && (e.position().head<2>() - start).norm() <= geom::kEps &&
        e.position().z() > z) {
      // Already over the start, in what the level above cut: straight down.
      e.linear(at(start, z), p.plungeFeed, "plunge");
      linked = true;
    }
    if (!linked)
      approach(e, path, z, p, op, centres);
    for (const Seg &sg : path)
      e.seg(sg, z, p.feed);
  }

  /// Down to height z at the start of `path`: along the tool axis, or by a
  /// helix or a ramp when the strategy asks and there is room.
  void approach(Emitter &e, const std::vector<Seg> &path, double z, const Plan &p, const Node &op,
                const Region &centres) {
    const Vec2 start = path.front().a;
    const Node *a = op.child("approach");
    const std::string type = a ? a->text("type").value_or("plunge_toolaxis") : "plunge_toolaxis";
    if (type == "plunge_helix") {
      const double radius = a->number("radius").value_or(p.radius / 2);
      const Vec2 centre = start - Vec2(radius, 0);
      const geom::SegIndex walls = geom::SegIndex::of(centres);
      if (radius > 1e-3 && centres.contains(centre) && walls.distance(centre) >= radius - 1e-9) {
        e.travel(start, p.clearanceZ);
        const double angle = a->number("angle").value_or(5.0) * kPi / 180;
        const double perTurn = 2 * kPi * radius * std::tan(std::max(angle, 0.5 * kPi / 180));
        const int64_t turns = static_cast<int64_t>(std::ceil((p.clearanceZ - z) / perTurn - 1e-9));
        e.arc(at(start, z), centre, true, std::max<int64_t>(turns - 1, 0), p.plungeFeed, "plunge");
        return;
      }
    } else if (type == "plunge_ramp") {
      // Down along the path's first segment and back, as often as needed.
      const double angle = std::max(a->number("angle").value_or(3.0), 0.5) * kPi / 180;
      const Seg &first = path.front();
      if (!first.isArc() && first.length() > 2 * p.radius) {
        e.travel(start, p.clearanceZ);
        double height = p.clearanceZ;
        const double drop = first.length() * std::tan(angle);
        bool out = true;
        while (height > z + 1e-9) {
          height = std::max(z, height - drop);
          e.linear(at(out ? first.b : first.a, height), p.plungeFeed, "plunge");
          out = !out;
        }
        if (!out)
          e.linear(at(first.a, z), p.feed, "plunge");
        return;
      }
    }
    e.travel(start, p.clearanceZ);
    e.linear(at(start, z), p.plungeFeed, "plunge");
  }

  ir::Module *module_ = nullptr;
  DiagnosticEngine *diags_ = nullptr;
  PassStats *stats_ = nullptr;
  PassResult result_;
  std::string lastTool_;
};

} // namespace

std::unique_ptr<Pass> createExpandStrategiesPass(const PassOptions &) {
  return std::make_unique<ExpandStrategiesPass>();
}

} // namespace stepnc::passes
