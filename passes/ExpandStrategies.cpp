// expand-strategies: from features to moves.
//
// Each machining workingstep gets a `moves` child: the tool-centre path in
// workpiece coordinates, made from the feature's shape (ir/geom/FeatureShape),
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
#include "ir/geom/Curves.h"
#include "ir/geom/FeatureShape.h"
#include "passes/PatternPaths.h"
#include "support/Format.h"

#include <algorithm>
#include <charconv>
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
/// Largest engagement angle of a trochoid's tool (deg) when the pass is not given max-engagement.
constexpr double kDefaultMaxEngagement = 90.0;
/// How far the line segments of a curve the strategy makes (trochoids,
/// rounded links) may stray from it (mm) when the pass is not given chord-tolerance.
constexpr double kDefaultChordTolerance = 0.005;
/// Overlap of neighbouring guide paths of a pattern strategy that gives none:
/// a share of the width one pass of the motif cuts.
constexpr double kPatternOverlap = 0.2;
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
    Node &m = moves_.add(Node(ir::Kind::Rapid));
    m.set("to", Value::point(to));
    m.set("role", Value::word(role));
    pos_ = to;
    positioned_ = true;
  }

  /// `smooth`: a chord of a curvature-continuous curve (IR `smooth`).
  void linear(const Vec3 &to, double feed, const char *role, bool smooth = false) {
    if ((to - pos_).norm() <= geom::kEps)
      return;
    Node &m = moves_.add(Node(ir::Kind::Linear));
    m.set("to", Value::point(to));
    m.set("feed", Value::feed(feed));
    m.set("role", Value::word(role));
    if (smooth)
      m.set("smooth", Value::boolean(true));
    pos_ = to;
  }

  void arc(const Vec3 &to, const Vec2 &centre, bool ccw, int64_t turns, double feed, const char *role) {
    Node &m = moves_.add(Node(ir::Kind::Arc));
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

/// The widest stepover between rings of a tool of radius `radius` that
/// leaves no material at the target's sharpest convex corner
/// (R (1 + sin(theta / 2)), REFERENCES), with 2 % to spare.
double ringCoverLimit(const ir::FeatureShape &s, double radius) {
  return radius * (1 + std::sin(sharpestCorner(s.target) / 2)) * 0.98;
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
  ExpandStrategiesPass(double maxEngagement, double chordTolerance, std::string optionError)
      : maxEngagement_(maxEngagement), chordTolerance_(chordTolerance), optionError_(std::move(optionError)) {}

  std::string_view name() const override { return "expand-strategies"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    if (!optionError_.empty()) {
      diags.error({}, optionError_);
      return {false, false};
    }
    module_ = &module;
    diags_ = &diags;
    stats_ = &stats;
    result_ = {};
    for (Node &n : module.root.children)
      if (n.kind == ir::Kind::Workplan)
        workplan(n, n.text("setup").value_or(""));
    return result_;
  }

private:
  // --- Walking the program ------------------------------------------------------

  void workplan(Node &plan, const std::string &setup) {
    for (Node &e : plan.children) {
      if (e.kind == ir::Kind::Workplan)
        workplan(e, e.text("setup").value_or(setup));
      else if ((e.kind == ir::Kind::Workingstep || e.kind == ir::Kind::RapidMovement) && !e.child(ir::Kind::Moves))
        executable(e, setup);
    }
  }

  void executable(Node &ws, const std::string &setup) {
    if (ws.kind == ir::Kind::RapidMovement) {
      rapidMovement(ws, setup);
      return;
    }
    const Node *op = ir::operationOf(ws);
    if (!op)
      return;
    const Node *feature = ir::findFeature(*module_, ws.text("feature").value_or(""));
    const Node *tool = ir::findTool(*module_, op->text("tool").value_or(""));
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
    if (!op->childrenOf(ir::Kind::Toolpath).empty()) {
      ir::FrameResult fr = ir::planeFrame(*feature);
      if (!fr.frame) {
        unsupported(ws, fr.error);
        return;
      }
      p.clearanceZ = clearanceAbove(fr.frame->z);
      explicitToolpaths(ws, *op, *fr.frame, p, moves);
      attach(ws, std::move(moves));
      return;
    }
    ir::ShapeResult shape = ir::featureShape(*module_, *feature);
    if (!shape.shape) {
      unsupported(ws, shape.error);
      return;
    }
    const ir::FeatureShape &s = *shape.shape;
    const double secplane = ws.number("secplane").value_or(0);
    if (secplane < s.top) {
      report(ws, "its security plane z=" + formatFixed(secplane, 4) + " mm is below the top of " + s.symbol +
                     " (z=" + formatFixed(s.top, 4) + " mm): there is no safe height to travel at");
      return;
    }
    p.clearanceZ = clearanceAbove(s.top);
    if (op->is(ir::Trait::HoleMaking) ? expandHoleMaking(ws, *op, s, p, moves) : milling(ws, *op, s, p, moves))
      attach(ws, std::move(moves));
  }

  /// An empty `moves` for the executable `exec`, with the state in force.
  static Node makeMoves(const Node &exec, const std::string &tool, double spindle, const std::string &coolant,
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

  void attach(Node &ws, Node moves) {
    (*stats_)["workingsteps expanded"]++;
    (*stats_)["moves"] += static_cast<long long>(moves.children.size());
    lastTool_ = moves.text("tool").value_or("");
    ws.add(std::move(moves));
    result_.changed = true;
  }

  static std::string coolant(const Node &op) {
    const Node *mf = op.child(ir::Kind::MachineFunctions);
    if (!mf)
      return "off";
    if (mf->flag("through_spindle_coolant").value_or(false))
      return "through_tool";
    if (mf->flag("mist").value_or(false))
      return "mist";
    return mf->flag("coolant").value_or(false) ? "flood" : "off";
  }

  void report(const Node &ws, const std::string &message) { report(ws, ws, message); }

  /// An error about workingstep `ws` located at `at` (a part of it the file gives, such as its strategy).
  void report(const Node &ws, const Node &at, const std::string &message) {
    diags_->error(at.origin.loc, ws.kindName() + " " + ws.symbol + ": " + message).entity(at.origin.entityId);
    result_.ok = false;
  }

  void unsupported(const Node &ws, const std::string &reason) {
    diags_->warning(ws.origin.loc, "workingstep " + ws.symbol + " is not expanded: " + reason)
        .entity(ws.origin.entityId);
    (*stats_)["workingsteps not expanded"]++;
  }

  // --- Explicit toolpaths -------------------------------------------------------

  void explicitToolpaths(const Node &ws, const Node &op, const ir::PlaneFrame &frame, const Plan &p, Node &moves) {
    Emitter e(moves, ws.number("secplane").value_or(0));
    for (const Node *tp : op.childrenOf(ir::Kind::Toolpath)) {
      const Node *tech = tp->child(ir::Kind::Technology);
      const double feed = tech && tech->number("feed") ? *tech->number("feed") : p.feed;
      const ExplicitKind kind = explicitKind(*tp);
      for (const Node &curve : tp->children) {
        if (curve.category() != ir::Category::Curve)
          continue;
        ir::CurveResult cr = ir::curvePieces(curve);
        if (!cr.error.empty()) {
          report(ws, "its explicit toolpath: " + cr.error);
          return;
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
  }

  /// How the moves of an explicit toolpath are made: rapid or at feed, and
  /// the role they get. ISO 14649 types a toolpath by what it does; its
  /// speed name `rapid` makes its moves rapids. A `trajectory_path` says no
  /// more than that it is followed: at feed it cuts.
  struct ExplicitKind {
    bool rapid = false;
    const char *role = "cut";
  };

  static ExplicitKind explicitKind(const Node &tp) {
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

  void rapidMovement(Node &rm, const std::string &setup) {
    // A rapid movement keeps the tool of the workingstep before it; the IR
    // names it where known.
    if (lastTool_.empty())
      return;
    Node moves = makeMoves(rm, lastTool_, 0, "off", setup);
    Emitter e(moves, rm.number("secplane").value_or(0));
    for (const Node *tp : rm.childrenOf(ir::Kind::Toolpath))
      for (const Node &curve : tp->children)
        if (curve.category() == ir::Category::Curve) {
          ir::CurveResult cr = ir::curvePieces(curve);
          if (!cr.error.empty()) {
            report(rm, "its toolpath: " + cr.error);
            return;
          }
          for (const ir::CurvePiece &c : cr.pieces) {
            if (!e.positioned())
              e.travel(c.from.head<2>(), c.from.z());
            e.rapid(c.to);
          }
        }
    attach(rm, std::move(moves));
  }

  // --- Hole making --------------------------------------------------------------

  bool expandHoleMaking(const Node &ws, const Node &op, const ir::FeatureShape &s, const Plan &p, Node &moves) {
    if (!s.holeCentre) {
      unsupported(ws, op.kindName() + " on a " + s.kindName() + ": hole-making operations are expanded on round holes only");
      return false;
    }
    // Spot drills and countersinks are wider than the hole they chamfer.
    const bool chamfers = op.is(ir::Trait::Chamfers);
    if (!chamfers && 2 * p.radius > s.holeDiameter + 1e-6) {
      report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                     " mm) is wider than the hole (" + formatFixed(s.holeDiameter, 3) + " mm)");
      return false;
    }
    const Node &feature = *p.feature;
    // The depth the tool's tip reaches: the floor, or past it for through holes.
    double bottom = s.bottom;
    const double point = ir::pointLength(*p.tool);
    if (feature.text("bottom") == "through")
      bottom -= point + std::max(kBreakthrough, op.number("overcut").value_or(0));
    if (auto depth = op.number("cutting_depth"))
      bottom = std::max(bottom, s.top - *depth);
    if (op.kind == ir::Kind::CenterDrilling && !op.has("cutting_depth"))
      bottom = std::max(bottom, s.top - std::max(point, p.radius));
    Emitter e(moves, ws.number("secplane").value_or(0));
    const Vec2 c = *s.holeCentre;
    e.travel(c, p.clearanceZ);
    if (op.kind == ir::Kind::MultistepDrilling) {
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
    const bool feedOut = op.spec().isAny(ir::Trait::BoreCycle | ir::Trait::TapCycle);
    if (feedOut)
      e.linear(at(c, p.clearanceZ), p.feed * op.number("feed_on_retract").value_or(1.0), "retract");
    e.retract();
    return true;
  }

  // --- Milling ------------------------------------------------------------------

  /// The heights a milling operation cuts at, from the top down to the
  /// floor plus its allowance, in equal steps no deeper than the axial
  /// depth of cut; none (after a warning) when the allowance leaves nothing.
  std::vector<double> levelsOf(const Node &ws, const Node &op, const ir::FeatureShape &s, const Plan &p) {
    const double floorZ = s.bottom + p.allowanceBottom;
    if (floorZ >= s.top - 1e-9) {
      unsupported(ws, "the bottom allowance leaves nothing to cut");
      return {};
    }
    const double ap = op.number("axial_depth").value_or(0);
    const int count = ap > 1e-9 ? std::max(1, static_cast<int>(std::ceil((s.top - floorZ) / ap - 1e-9))) : 1;
    std::vector<double> out;
    for (int i = 1; i <= count; ++i)
      out.push_back(s.top - (s.top - floorZ) * i / count);
    return out;
  }

  bool milling(const Node &ws, const Node &op, const ir::FeatureShape &s, const Plan &p, Node &moves) {
    for (const Node &pattern : op.children)
      if (pattern.is(ir::Trait::PatternStrategy))
        return patternMilling(ws, op, pattern, s, p, moves);
    const Node *strategy = op.child(ir::Kind::Strategy);
    std::string type = strategy ? strategy->text("type").value_or("") : "";
    const bool face = op.is(ir::Trait::FaceOperation) || ir::hasTraits(s.kind, ir::Trait::FaceFeature);
    if (type.empty())
      type = face ? "bidirectional" : "contour_parallel";
    const bool sideOnly = op.is(ir::Trait::SideOnly);

    const std::vector<double> levels = levelsOf(ws, op, s, p);
    if (levels.empty())
      return false;

    // The stepover: the radial depth of cut, else the overlap; never so wide
    // that a ring leaves material at the region's sharpest convex corner.
    double stepover = op.number("radial_depth").value_or(0);
    const double overlap = strategy ? strategy->number("overlap").value_or(-1) : -1;
    if (stepover <= 0 && overlap > 0 && overlap < 1)
      stepover = 2 * p.radius * (1 - overlap);
    if (stepover <= 0)
      stepover = p.radius;
    const double coverLimit = ringCoverLimit(s, p.radius);
    const double limitBidir = 2 * p.radius * 0.98;
    stepover = std::min(stepover, type == "bidirectional" || type == "unidirectional" ? limitBidir : coverLimit);

    const bool followOrientation = counterClockwise(strategy, p.spindle);

    const Vec2 strokeDir = strokeDirection(*p.feature, s, strategy);
    const bool linkAtDepth = type == "contour_spiral" || type == "contour_parallel" || type == "bidirectional" ||
                             type == "contour_bidirectional" || type == "bidirectional_contour";
    Emitter e(moves, ws.number("secplane").value_or(0));
    // The centre area and the paths depend on the level only through the
    // islands standing at it: they are made again only when that set changes.
    std::optional<std::vector<bool>> standing;
    Region centres;
    std::vector<std::vector<Seg>> paths;
    for (size_t i = 0; i < levels.size(); ++i) {
      const double z = levels[i];
      std::vector<bool> here;
      for (const ir::IslandShape &isl : s.islands)
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
          unsupported(ws, "center milling follows the course of travel of a slot; " + s.symbol + " is a " + s.kindName());
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
        if (i > 0) {
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
  static std::optional<std::vector<Seg>> slotCentreline(const ir::FeatureShape::SlotPath &slot, const Plan &p) {
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
  Region centreArea(const ir::FeatureShape &s, const Region &area, const std::vector<Region> &islands, const Plan &p) {
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

  /// Whether a strategy's paths turn counter-clockwise (the orientation of
  /// a Region's outer loops): climb keeps the wall on the tool's right for a
  /// clockwise (M3) spindle, conventional on its left; without a cut mode,
  /// the rotation it names; else counter-clockwise.
  static bool counterClockwise(const Node *strategy, double spindle) {
    const std::string cutmode = strategy ? strategy->text("cutmode").value_or("") : "";
    const std::string rotation = strategy ? strategy->text("rotation").value_or("") : "";
    if (!cutmode.empty())
      return (cutmode == "climb") == (spindle <= 0);
    return rotation.empty() || rotation == "ccw";
  }

  /// The stroke direction: the strategy's feed direction, else the face's
  /// course of travel, else the feature's x axis.
  static Vec2 strokeDirection(const Node &feature, const ir::FeatureShape &s, const Node *strategy) {
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
    // Otherwise the outer strokes run a hair inside the area, not along its
    // boundary, where clipping could lose them.
    const double inset = overtravel > 0 ? overtravel : 1e-6;
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
    const Node *a = op.child(ir::Kind::Approach);
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
    const Node *a = op.child(ir::Kind::Approach);
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

  // --- Pattern strategies (docs/pattern-strategies.md) -------------------------

  bool patternMilling(const Node &ws, const Node &op, const Node &pattern, const ir::FeatureShape &s, const Plan &p,
                      Node &moves) {
    const Node *guide = pattern.child(ir::Kind::Strategy);
    const std::string type = guide ? guide->text("type").value_or("") : "";
    if (type.empty() || type == "explicit") {
      report(ws, "its " + pattern.kindName() +
                     " needs an ordinary strategy as its guide (contour parallel, "
                     "bidirectional, center milling, ...), found " +
                     (type.empty() ? "none" : "'" + type + "'"));
      return false;
    }
    const std::vector<double> levels = levelsOf(ws, op, s, p);
    if (levels.empty())
      return false;
    return pattern.kind == ir::Kind::TrochoidalStrategy ? trochoidal(ws, op, pattern, *guide, s, p, levels, moves)
                                                 : plunging(ws, op, pattern, *guide, s, p, levels, moves);
  }

  /// The guide's paths at height z for a motif that reaches `reach.radius`
  /// from the guide (the tool's radius plus the motif's), `spacing` apart,
  /// kept `margin` further from the walls; `area` receives where the guide
  /// may run. None after a diagnostic when the motif does not fit.
  std::optional<std::vector<std::vector<Seg>>> guidePaths(const Node &ws, const Node &op, const Node &guide,
                                                          const ir::FeatureShape &s, const Plan &reach, double z,
                                                          double spacing, double margin, Region &area) {
    const std::string type = guide.text("type").value_or("");
    area = centreArea(s, s.unbounded ? s.target : s.limit, islandsAt(s, z, reach.allowanceSide), reach);
    if (margin > 0 && !area.empty())
      area = geom::offset(area, -margin);
    auto tooWide = [&](const std::string &what) {
      report(ws, "its tool " + reach.tool->symbol + " with the motif of its pattern strategy reaches " +
                     formatFixed(reach.radius, 3) + " mm from the guide and does not fit in " + what +
                     " with the side allowance");
    };
    if (s.slot && (type == "center_milling" || area.empty())) {
      std::optional<std::vector<Seg>> line = slotCentreline(*s.slot, reach);
      if (!line) {
        tooWide("slot " + s.symbol + " (width " + formatFixed(s.slot->width, 3) + " mm)");
        return std::nullopt;
      }
      area = geom::offset(s.target, -geom::kEps);
      return std::vector<std::vector<Seg>>{std::move(*line)};
    }
    if (type == "center_milling") {
      unsupported(ws, "center milling follows the course of travel of a slot; " + s.symbol + " is a " + s.kindName());
      return std::nullopt;
    }
    if (area.empty()) {
      tooWide(s.symbol);
      return std::nullopt;
    }
    const bool face = op.is(ir::Trait::FaceOperation) || ir::hasTraits(s.kind, ir::Trait::FaceFeature);
    const bool sideOnly = op.is(ir::Trait::SideOnly);
    auto made = strategyPaths(type, face, s.unbounded, sideOnly, area, strokeDirection(*reach.feature, s, &guide),
                              spacing, counterClockwise(&guide, reach.spindle), reach.radius);
    if (!made) {
      unsupported(ws, "strategy '" + type + "' is not expanded yet");
      return std::nullopt;
    }
    return made;
  }

  /// The islands standing at height z, grown by the side allowance.
  static std::vector<Region> islandsAt(const ir::FeatureShape &s, double z, double allowance) {
    std::vector<Region> out;
    for (const ir::IslandShape &isl : s.islands)
      if (isl.top > z + 1e-9)
        out.push_back(geom::offset(isl.region, allowance));
    return out;
  }

  /// After a motif at height z: one contour of the tool along every wall,
  /// climb, taking what the motif leaves there (its scallops or cusps
  /// between loops or plunges, and corners tighter than its reach).
  void wallPass(Emitter &e, const Node &op, const ir::FeatureShape &s, const Plan &p, double z, bool ccw) {
    const Region centres = centreArea(s, s.unbounded ? s.target : s.limit, islandsAt(s, z, p.allowanceSide), p);
    if (centres.empty())
      return;
    for (const std::vector<Seg> &ring : rings(centres, p.radius, ccw, /*all=*/false, p.radius))
      cutPath(e, ring, z, p, op, centres, /*mayLink=*/true, s.unbounded);
  }

  /// Paths joined into chains: each path goes on from the end of the one
  /// before by a straight link when the link stays inside `area`; a closed
  /// path starts where it is nearest to that end.
  static std::vector<std::vector<Seg>> chains(const std::vector<std::vector<Seg>> &paths, const Region &area) {
    std::vector<std::vector<Seg>> out;
    for (const std::vector<Seg> &path : paths) {
      if (path.empty())
        continue;
      std::vector<Seg> next = path;
      const bool closed = path.size() > 1 && (path.front().a - path.back().b).norm() < 1e-7;
      if (!out.empty() && closed) {
        Loop ring{path};
        next = startNearest(ring, out.back().back().b).segs;
      }
      if (!out.empty()) {
        const Vec2 from = out.back().back().b, to = next.front().a;
        double inside = 0;
        for (const Seg &piece : geom::clip(area, from, to))
          inside += piece.length();
        if (std::abs(inside - (to - from).norm()) < 1e-6) {
          if ((to - from).norm() > geom::kEps)
            out.back().push_back(Seg::line(from, to));
          out.back().insert(out.back().end(), next.begin(), next.end());
          continue;
        }
      }
      out.push_back(std::move(next));
    }
    return out;
  }

  /// The spacing of guide paths for a motif as wide as a tool of radius
  /// `radius`: from the pattern's overlap (default kPatternOverlap), never
  /// so wide that a ring leaves material at the region's sharpest corner.
  static double guideSpacing(const Node &pattern, const ir::FeatureShape &s, double radius) {
    double overlap = pattern.number("overlap").value_or(kPatternOverlap);
    if (overlap <= 0 || overlap >= 1)
      overlap = kPatternOverlap;
    return std::min(2 * radius * (1 - overlap), ringCoverLimit(s, radius));
  }

  bool trochoidal(const Node &ws, const Node &op, const Node &pattern, const Node &guide, const ir::FeatureShape &s,
                  const Plan &p, const std::vector<double> &levels, Node &moves) {
    const double loop = pattern.number("radius").value_or(0);
    const double step = pattern.number("step").value_or(0);
    if (loop <= 0 || step <= 0) {
      report(ws, pattern, "its trochoidal strategy needs a positive trochoid radius and step per revolution");
      return false;
    }
    if (step >= 2 * kPi * loop) {
      report(ws, pattern,
             "its trochoidal step per revolution " + formatFixed(step, 3) +
                 " mm is not less than 2 pi times the trochoid radius (" + formatFixed(2 * kPi * loop, 3) +
                 " mm): the tool would stop on every loop");
      return false;
    }
    // The step the engagement allows, on a straight guide in full material.
    const double used = largestTrochoidStep(p.radius, loop, maxEngagement_ * kPi / 180, step);
    if (used <= 0) {
      report(ws, pattern,
             "no trochoid of radius " + formatFixed(loop, 3) + " mm keeps the engagement of its tool under " +
                 formatFixed(maxEngagement_, 1) + " deg");
      return false;
    }
    const TrochoidMotif motif{loop, used, counterClockwise(&pattern, p.spindle)};
    const double w = trochoidSmoothing(used, loop);
    Plan reach = p;
    reach.radius = p.radius + loop;
    const double spacing = guideSpacing(pattern, s, reach.radius);
    const Node *a = op.child(ir::Kind::Approach);
    const std::string entry = a ? a->text("type").value_or("plunge_helix") : "plunge_helix";
    const double angle = std::max(a ? a->number("angle").value_or(5.0) : 5.0, 0.5) * kPi / 180;
    Emitter e(moves, ws.number("secplane").value_or(0));
    long loops = 0;
    for (double z : levels) {
      Region area;
      auto paths = guidePaths(ws, op, guide, s, reach, z, spacing, SmoothGuide::arcShrink(w, reach.radius), area);
      if (!paths)
        return false;
      for (std::vector<Seg> &chain : chains(*paths, area)) {
        const SmoothGuide g(std::move(chain), w);
        const std::vector<Vec2> points = trochoidPoints(g, motif, chordTolerance_);
        loops += trochoidLoops(g, used);
        // Down about the guide's start on the first loop: a helix, unless
        // the operation asks for a plunge along the tool axis.
        e.travel(points.front(), p.clearanceZ);
        if (entry == "plunge_toolaxis") {
          e.linear(at(points.front(), z), p.plungeFeed, "plunge");
        } else {
          const double perTurn = 2 * kPi * loop * std::tan(angle);
          const int64_t turns = static_cast<int64_t>(std::ceil((p.clearanceZ - z) / perTurn - 1e-9));
          e.arc(at(points.front(), z), g.raw(0), motif.ccw, std::max<int64_t>(turns - 1, 0), p.plungeFeed, "plunge");
          // One more turn at the bottom takes the ramp the helix leaves, so
          // that the first loop meets only what the loops are sized for.
          e.arc(at(points.front(), z), g.raw(0), motif.ccw, 0, p.plungeFeed, "plunge");
        }
        for (size_t k = 1; k < points.size(); ++k)
          e.linear(at(points[k], z), p.feed, "cut", /*smooth=*/true);
      }
      wallPass(e, op, s, p, z, motif.ccw);
    }
    e.retract();
    std::string note = "trochoid radius " + formatFixed(loop, 3) + " mm, step " + formatFixed(used, 3) + " mm";
    if (used < step)
      note += " (" + formatFixed(step, 3) + " lowered: engagement at most " + formatFixed(maxEngagement_, 1) + " deg)";
    ir::replaceCommentPart(moves, {"trochoid "}, note + ", " + std::to_string(loops) + " loops");
    (*stats_)["trochoid loops"] += loops;
    return true;
  }

  bool plunging(const Node &ws, const Node &op, const Node &pattern, const Node &guide, const ir::FeatureShape &s,
                const Plan &p, const std::vector<double> &levels, Node &moves) {
    const double clearance = pattern.number("clearance").value_or(0);
    const double backOff = std::max(0.0, pattern.number("retract_offset").value_or(0));
    const double bottom = pattern.number("bottom_radius").value_or(0);
    const double pitch = pattern.number("radial_step").value_or(0);
    const double linkRadius = std::max(0.0, pattern.number("link_radius").value_or(0));
    if (bottom <= 0 || bottom > p.radius + 1e-9) {
      report(ws, pattern,
             "its plunge bottom radius " + formatFixed(bottom, 3) + " mm is not within the radius of its tool " +
                 p.tool->symbol + " (" + formatFixed(p.radius, 3) + " mm)");
      return false;
    }
    // Plunges on a square grid of pitch p cover the area when p <= sqrt(2) R.
    if (pitch <= 0 || pitch > std::sqrt(2.0) * bottom * (1 + 1e-9)) {
      report(ws, pattern,
             "its plunge radial step " + formatFixed(pitch, 3) + " mm leaves material between plunges: at most " +
                 "sqrt(2) times the plunge bottom radius, " + formatFixed(std::sqrt(2.0) * bottom, 3) + " mm");
      return false;
    }
    if (clearance <= 0) {
      report(ws, pattern,
             "its plunge clearance height " + formatFixed(clearance, 3) +
                 " mm does not take the tool out of the material between plunges");
      return false;
    }
    const double secplane = ws.number("secplane").value_or(0);
    const double above = std::min(s.top + clearance, secplane);
    // Rounded corners stay above the material: the way down is a plunge.
    const double corner = std::min(linkRadius, above - s.top);
    Emitter e(moves, secplane);
    long plunges = 0;
    for (double z : levels) {
      Region area;
      auto paths = guidePaths(ws, op, guide, s, p, z, pitch, 0, area);
      if (!paths)
        return false;
      for (std::vector<Seg> path : *paths) {
        const bool closed = path.size() > 1 && (path.front().a - path.back().b).norm() < 1e-7;
        if (closed && e.positioned())
          path = startNearest(Loop{path}, e.position().head<2>()).segs;
        const std::vector<Vec2> centres = plungeCentres(path, pitch, bottom);
        for (size_t k = 0; k < centres.size(); ++k) {
          const Vec2 c = centres[k];
          if (k == 0)
            e.travel(c, above);
          else
            link(e, e.position().head<2>(), c, above, corner, p.feed);
          e.linear(at(c, z), p.plungeFeed, "plunge");
          ++plunges;
          // Away from the wall just cut, into the hole of the plunge before,
          // then straight up.
          Vec2 out = c;
          if (k > 0 && backOff > 0) {
            const Vec2 back = centres[k - 1] - c;
            out = c + back * std::min(1.0, backOff / back.norm());
            e.linear(at(out, z), p.feed, "retract");
          }
          e.rapid(at(out, k + 1 < centres.size() ? above - corner : secplane), "retract");
        }
      }
      wallPass(e, op, s, p, z, counterClockwise(&pattern, p.spindle));
    }
    e.retract();
    const double cusp = bottom - std::sqrt(bottom * bottom - pitch * pitch / 4);
    ir::replaceCommentPart(moves, {"plunges "},
                           "plunges " + std::to_string(plunges) + " on a " + formatFixed(pitch, 3) +
                               " mm pitch, wall cusp " + formatFixed(cusp, 3) + " mm");
    (*stats_)["plunges"] += plunges;
    return true;
  }

  /// From `from`, `corner` below the height `above`, to over `to` at `corner`
  /// below it: up, across and down in the vertical plane through both, the
  /// two bends rounded to radius `corner` (shortened to half the way
  /// across), as feed moves within the chord tolerance.
  void link(Emitter &e, const Vec2 &from, const Vec2 &to, double above, double corner, double feed) {
    const double across = (to - from).norm();
    if (across <= geom::kEps)
      return;
    const Vec2 u = (to - from) / across;
    const double r = std::min(corner, across / 2);
    // The bends start `corner` below `above`: lower them when r is shorter.
    if (r < corner)
      e.rapid(at(from, above - r), "retract");
    const int n =
        r > chordTolerance_ ? std::max(2, int(std::ceil(kPi / 2 / (2 * std::acos(1 - chordTolerance_ / r))))) : 1;
    for (int i = 1; i <= n; ++i) { // up into the horizontal
      const double a = kPi / 2 * i / n;
      e.linear(Vec3(from.x() + u.x() * r * (1 - std::cos(a)), from.y() + u.y() * r * (1 - std::cos(a)),
                    above - r + r * std::sin(a)),
               feed, "link");
    }
    e.linear(at(to - u * r, above), feed, "link");
    for (int i = 1; i <= n; ++i) { // across into the vertical
      const double a = kPi / 2 * i / n;
      const Vec2 xy = to - u * (r * (1 - std::sin(a)));
      e.linear(Vec3(xy.x(), xy.y(), above - r + r * std::cos(a)), feed, "link");
    }
  }

  double maxEngagement_ = kDefaultMaxEngagement;   ///< deg
  double chordTolerance_ = kDefaultChordTolerance; ///< mm
  std::string optionError_;
  ir::Module *module_ = nullptr;
  DiagnosticEngine *diags_ = nullptr;
  PassStats *stats_ = nullptr;
  PassResult result_;
  std::string lastTool_;
};

} // namespace

std::unique_ptr<Pass> createExpandStrategiesPass(const PassOptions &options) {
  double maxEngagement = kDefaultMaxEngagement, chord = kDefaultChordTolerance;
  std::string error;
  if (auto it = options.find("max-engagement"); it != options.end()) {
    double v = 0;
    const char *first = it->second.data(), *last = first + it->second.size();
    std::string_view unit;
    auto [end, ec] = std::from_chars(first, last, v);
    unit = std::string_view(end, size_t(last - end));
    if (ec != std::errc() || !(v > 0 && v <= 180) || !(unit.empty() || unit == "deg"))
      error = "expand-strategies: max-engagement='" + it->second +
              "' is not an angle: expected degrees in (0, 180], such as max-engagement=60";
    else
      maxEngagement = v;
  }
  if (auto it = options.find("chord-tolerance"); it != options.end()) {
    if (auto v = parseLengthOption(it->second))
      chord = *v;
    else
      error = "expand-strategies: chord-tolerance='" + it->second +
              "' is not a length: expected a positive number of mm, such as chord-tolerance=0.005";
  }
  return std::make_unique<ExpandStrategiesPass>(maxEngagement, chord, std::move(error));
}

} // namespace stepnc::passes
