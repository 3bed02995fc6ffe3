// Turning strategies (ISO 14649-12): the moves of a lathe step, made in the
// half plane of the turning axis (z along the axis, r the radius; points
// are geom::Vec2(z, r)) from the feature's turned shape (ir/geom/TurnedShape.h)
// and the workpiece's stock as the steps before left it.
//
// The tool is modelled by its cutting corner: a turning insert by its nose
// circle, a grooving insert by its two corner circles a cutting width
// apart. Paths are made for the centre of the (chuck-side) corner circle and
// written for the point a lathe programs, the corner's imaginary tip (the
// point touched off on X and Z): the centre moved by the corner radius
// towards -z and towards the axis (inside a bore, away from it). The
// program thus stays G40: nose-radius compensation is computed here
// (docs/turning.md).
//
// Every rapid is checked against the stock as it stands when the rapid is
// made (the insert's corner circles clear of it); where the straight way is
// blocked the tool goes out radially above the stock first.
#include "ir/Printer.h"
#include "passes/expand/Expand.h"

#include "geom/Boolean.h"
#include "ir/geom/Curves.h"
#include "ir/Plausible.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "ir/geom/TurnedShape.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace stepnc::passes::expand {

namespace {

/// How far from the stock approaches start and retracts end (mm).
constexpr double kLatheClearance = 1.0;
/// Depth of cut when neither the strategy nor the tool gives one (mm).
constexpr double kDefaultLatheDepth = 2.0;
/// Lift off the surface after a roughing pass when the file gives none (mm).
constexpr double kDefaultLift = 0.5;
/// How far a pecking plunge backs off when its strategy gives no retract distance (mm).
constexpr double kDefaultPeckRetract = 0.5;
/// Roughing passes shorter than this (mm) are left to the contour pass after them.
constexpr double kMinRoughPass = 0.1;

Vec2 halfPlane(const Vec3 &v) { return Vec2(v.z(), v.x()); }
Vec3 space(const Vec2 &p) { return Vec3(p.y(), 0, p.x()); }

/// The insert as the paths see it.
struct LatheTool {
  bool grooving = false;
  bool threading = false;
  bool knurling = false;
  double rc = 0;     ///< nose (corner) radius
  double width = 0;  ///< a grooving insert's cutting width
  double maxDepth = 0;
  /// The corner circles' centres relative to the reference one (the
  /// chuck-side corner; a face grooving insert's corner nearest the axis).
  std::vector<Vec2> corners{Vec2::Zero()};
  /// The programmed point relative to the chuck-side corner's centre.
  Vec2 tip = Vec2::Zero();
  /// How far the insert reaches towards the chuck beyond its corner circle
  /// (a threading insert's flank, as deep as it cuts).
  double flank = 0;
};

/// Writes the moves of one lathe step: points are corner centres in the
/// half plane; the moves go to the programmed point in space.
class LatheWriter {
public:
  LatheWriter(Node &moves, const LatheTool &t) : moves_(moves), tool_(t) {}

  const Vec2 &position() const { return pos_; }
  bool positioned() const { return positioned_; }

  void rapid(const Vec2 &c, const char *role) {
    if (positioned_ && (c - pos_).norm() <= geom::kEps)
      return;
    Node &m = moves_.add(Node(ir::Kind::Rapid));
    m.set("to", Value::point(space(c + tool_.tip)));
    m.set("role", Value::word(role));
    pos_ = c;
    positioned_ = true;
  }

  void feed(const Vec2 &c, double perRev, const char *role) {
    if ((c - pos_).norm() <= geom::kEps)
      return;
    Node &m = moves_.add(Node(ir::Kind::Linear));
    m.set("to", Value::point(space(c + tool_.tip)));
    m.set("feed_per_rev", Value::feedPerRev(perRev));
    m.set("role", Value::word(role));
    pos_ = c;
  }

  void seg(const Seg &s, double perRev, const char *role) {
    if (!s.isArc()) {
      feed(s.b, perRev, role);
      return;
    }
    // An arc in the ZX plane: counter-clockwise in (z, x) is
    // counter-clockwise seen from +y (z x x = y).
    Node &m = moves_.add(Node(ir::Kind::Arc));
    m.set("to", Value::point(space(s.b + tool_.tip)));
    m.set("center", Value::point(space(s.c + tool_.tip)));
    m.set("dir", Value::word(s.turn > 0 ? "ccw" : "cw"));
    m.set("feed_per_rev", Value::feedPerRev(perRev));
    m.set("role", Value::word(role));
    m.set("normal", Value::direction(Vec3::UnitY()));
    pos_ = s.b;
  }

  /// A pass synchronised with the spindle (G33): the feed per revolution
  /// is the thread's lead.
  void thread(const Vec2 &c, double lead) {
    feed(c, lead, "thread");
  }

  void dwell(double seconds) {
    if (seconds <= 0)
      return;
    moves_.add(Node(ir::Kind::Dwell)).set("time", Value::time(seconds));
  }

private:
  Node &moves_;
  const LatheTool &tool_;
  Vec2 pos_ = Vec2::Zero();
  bool positioned_ = false;
};

Region grown(const Region &r, double d) { return d > geom::kEps ? geom::offset(r, d) : r; }

/// A rectangle (counter-clockwise) between two corners.
Region box(const Vec2 &lo, const Vec2 &hi) {
  return Region{{geom::polygon({lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())})}};
}

double maxR(const Region &r) { return r.empty() ? 0 : r.box().hi.y(); }

/// A region and its mirror image across the axis. The half plane's section
/// of a body of revolution is symmetric about the axis: a tool crossing the
/// axis (facing to the centre) meets what lies at r on the other side.
Region withMirror(const Region &r) { return geom::unite(r, geom::mirroredAcrossX(r)); }

/// Where a corner centre may cut: on the near side of the axis (past it, the
/// tool would cut what it cut already on the other side).
Region nearSide(const Region &r) { return geom::intersect(r, box(Vec2(-1e5, 0), Vec2(1e5, 1e5))); }

/// Whether a turning technology's speeds are ones a lathe turns at; else an
/// error at it (a controller would refuse a feed per revolution at no
/// spindle speed): nothing outside physical sense is written.
bool latheSpeedsInRange(Expander &x, const Node &ws, const Node &tech) {
  auto outside = [&](std::optional<double> v, double scale, double low, double high, const char *what,
                     const char *unit) {
    if (!v || *v == 0 || (std::abs(*v * scale) >= low && std::abs(*v * scale) <= high))
      return false;
    x.report(ws, tech,
             std::string(what) + " " + formatShortest(std::abs(*v * scale)) + " " + unit +
                 " is outside what a lathe turns at (" + formatShortest(low) + " to " + formatShortest(high) + " " +
                 unit + ")");
    return true;
  };
  return !outside(tech.number("cutting_speed"), 1e-3, ir::kPlausibleMinCuttingSpeedMPerMin,
                  ir::kPlausibleMaxCuttingSpeedMPerMin, "its cutting speed", "m/min") &&
         !outside(tech.number("spindle_max"), 1, ir::kPlausibleMinSpindleRpm, ir::kPlausibleMaxSpindleRpm,
                  "its maximum spindle speed", "rev/min") &&
         !outside(tech.number("spindle"), 1, ir::kPlausibleMinSpindleRpm, ir::kPlausibleMaxSpindleRpm,
                  "its spindle speed", "rev/min");
}

/// What the file may ask of a turning operation or its strategy that the
/// strategies here do not do yet, by IR attribute, with the standard's name
/// and what is done instead. Each one given is said at its node (an
/// assumption: --strict refuses it), never dropped without a word.
struct Unfollowed {
  const char *attribute;  ///< IR name
  const char *standard;   ///< ISO 14649-12 name
  const char *instead;
};
constexpr Unfollowed kUnfollowedStrategy[] = {
    {"overcut", "overcut_length", "passes end at the feature's extent plus stepnc's clearance"},
    {"back_path_feed", "back_path_feed", "the tool goes back at rapid"},
    {"lift_feed", "lift_feed", "the tool lifts at rapid"},
    {"downward_feed", "stepover_feed", "the tool steps over at rapid and enters at the operation's feed"},
    {"return_angle", "path_return_angle", nullptr},  // said by the operation (noteUnfollowed)
    {"variable_depth", "variable_depth", "the depths of cut are those listed"},
    {"variable_downward_feed", "variable_stepover_feed", "the feeds are the operation's"},
};
constexpr Unfollowed kUnfollowedOperation[] = {
    {"overcut", "overcut_length", "passes end at the feature's extent plus stepnc's clearance"},
    {"return_amount", "return_amount", "the tool withdraws 1 mm plus its corner radius clear of the stock"},
    {"feed_ratio", "feed_ratio", "the feed is the technology's"},
    {"start_point", "start_point", "each step starts outside the stock's corner at the free end"},
};

/// Says each attribute of `op` and its strategy that is not followed.
void noteUnfollowed(Expander &x, const Node &ws, const Node &op) {
  const bool threading = op.kind == ir::Kind::ThreadingRough || op.kind == ir::Kind::ThreadingFinish;
  auto note = [&](const Node &n, const Unfollowed &u, const std::string &which) {
    if (const ir::Value *v = n.get(u.attribute)) {
      std::string value;
      ir::printValue(*v, value);
      const char *instead = u.instead ? u.instead
                            : threading ? "a thread pass is left straight out from the axis"
                                        : "each pass is left on stepnc's own path (45 degrees back when roughing)";
      x.assumed(ws, n, which + " " + u.standard + " " + value + " is not followed yet: " + instead);
    }
  };
  for (const Unfollowed &u : kUnfollowedOperation)
    note(op, u, "its operation's");
  if (const Node *s = op.child(ir::Kind::TurningStrategy)) {
    for (const Unfollowed &u : kUnfollowedStrategy)
      note(*s, u, "its strategy's");
    if (s->flag("multiple_passes") == false)
      x.assumed(ws, *s,
                "its strategy's allow_multiple_passes false is not followed yet: the material is cut in as many "
                "passes as the depths of cut make");
  }
  for (ir::Kind k : {ir::Kind::Approach, ir::Kind::Retract})
    if (const Node *n = op.child(k))
      x.assumed(ws, *n,
                std::string("its ") + (k == ir::Kind::Approach ? "approach" : "retract") +
                    " strategy is not followed yet on a lathe: the tool comes and goes at rapid on a path clear "
                    "of the stock");
}

class TurningStep {
public:
  TurningStep(Expander &x, Node &ws, const Node &op, const Node &feature, const Node &toolNode, Region &stock,
              const ir::TurnStock &raw, const ir::TurnedShape &shape, Node &moves)
      : x_(x), ws_(ws), op_(op), feature_(feature), toolNode_(toolNode), stock_(stock), raw_(raw), shape_(shape),
        moves_(moves), w_(moves, tool_), removal_(withMirror(shape.removal)),
        chuck_(box(Vec2(raw.z0 - 1e4, -1e4), Vec2(raw.z0, 1e4))) {}

  bool run() {
    if (!readTool() || !readTechnology())
      return false;
    refreshObstacle();
    // Outside the stock's corner at the free end: where every step starts
    // and ends, reached from the tool change position at rapid.
    home_ = Vec2(raw_.z1 + 5 * kLatheClearance + tool_.rc, raw_.radius + 5 * kLatheClearance + tool_.rc);
    w_.rapid(home_, "position");
    if (shape_.towardsChuck && op_.kind != ir::Kind::CuttingIn) {
      x_.report(ws_, feature_,
                shape_.symbol + " looks towards the chuck (its material on the free end's side): no tool faces it "
                                "from there; it is made by parting off (cutting_in)");
      return false;
    }
    const bool threadOp = op_.kind == ir::Kind::ThreadingRough || op_.kind == ir::Kind::ThreadingFinish;
    if (!toolFor(tool_.threading, threadOp, "threading", "cuts threads") ||
        !toolFor(tool_.knurling, op_.kind == ir::Kind::Knurling, "knurling", "rolls knurls"))
      return false;
    if (shape_.inner && !holeToBore())
      return false;
    bool ok = false;
    switch (op_.kind) {
    case ir::Kind::ContouringRough: ok = rough(false); break;
    case ir::Kind::FacingRough: ok = rough(true); break;
    case ir::Kind::ContouringFinish:
    case ir::Kind::FacingFinish: ok = finish(op_.number("allowance").value_or(0)); break;
    case ir::Kind::GroovingRough: ok = grooveRough(); break;
    case ir::Kind::GroovingFinish: ok = grooveFinish(); break;
    case ir::Kind::CuttingIn: ok = cutIn(); break;
    case ir::Kind::ThreadingRough: ok = threading(false); break;
    case ir::Kind::ThreadingFinish: ok = threading(true); break;
    case ir::Kind::Knurling: ok = knurl(); break;
    default:
      x_.report(ws_, op_,
                "its operation " + op_.kindName() + " '" + op_.label +
                    "' has no lathe moves in stepnc yet (docs/turning.md lists the turning operations expanded)");
      return false;
    }
    if (!ok)
      return false;
    travel(home_);
    return x_.result.ok;
  }

private:
  // --- reading the step ---------------------------------------------------------

  /// A threading or knurling tool (`toolIs`) works its own operation only,
  /// and that operation (`opIs`) needs it: else an error at the tool.
  bool toolFor(bool toolIs, bool opIs, const std::string &process, const char *only) {
    if (toolIs == opIs)
      return true;
    x_.report(ws_, toolNode_,
              opIs ? process + " needs a " + process + " tool; " + toolNode_.symbol + " is a " +
                         toolNode_.text("type").value_or("")
                   : "its " + process + " tool " + toolNode_.symbol + " only " + only);
    return false;
  }

  bool readTool() {
    const std::string type = toolNode_.text("type").value_or("");
    tool_.rc = toolNode_.number("corner_radius").value_or(0);
    tool_.maxDepth = toolNode_.number("max_cutting_depth").value_or(toolNode_.number("cutting_edge_length").value_or(0));
    if (type == "grooving_tool") {
      tool_.grooving = true;
      tool_.width = toolNode_.number("cutting_width").value_or(0);
      if (tool_.width <= 0 || 2 * tool_.rc > tool_.width + 1e-9) {
        x_.report(ws_, toolNode_,
                  "its grooving tool " + toolNode_.symbol + " needs a cutting width (at least twice its corner radius)");
        return false;
      }
      // Its corners along the axis, or across it for a face groove.
      const Vec2 across = shape_.faceGroove ? Vec2(0, 1) : Vec2(1, 0);
      tool_.corners = {Vec2::Zero(), across * ((tool_.width - 2 * tool_.rc) / 2), across * (tool_.width - 2 * tool_.rc)};
    } else if (type == "threading_tool") {
      // Programmed at the point of its V, the tip circle's point nearest
      // the axis (inside a bore: farthest from it).
      tool_.threading = true;
      tool_.tip = Vec2(0, shape_.inner ? tool_.rc : -tool_.rc);
      // Its V's flank, as deep as the tool cuts (5 mm when it does not say,
      // as verify-toolpaths reads it).
      const double half = toolNode_.number("thread_angle").value_or(60) * kPi / 360;
      tool_.flank = std::tan(half) * toolNode_.number("max_cutting_depth").value_or(5.0);
      return true;
    } else if (type == "knurling_tool") {
      // Its wheels' rim, as wide along the axis as its cutting length,
      // programmed at its chuck-side end; the rim's ends a micrometre in
      // from the wheels' edges, which meet the knurl's ends exactly.
      tool_.knurling = true;
      tool_.rc = 0;
      tool_.width = toolNode_.number("cutting_width").value_or(0);
      const double in = std::min(1e-3, tool_.width / 2);
      tool_.corners = {Vec2(in, 0), Vec2(tool_.width - in, 0)};
      return true;
    } else if (type != "turning_tool") {
      x_.report(ws_, toolNode_,
                "its tool " + toolNode_.symbol + " is a " + type +
                    ": stepnc turns with turning tools, grooves and cuts in with grooving tools, threads with "
                    "threading tools, knurls with knurling tools");
      return false;
    }
    // Inside a bore the corner's imaginary tip is on its side away from the axis.
    tool_.tip = Vec2(-tool_.rc, shape_.inner ? tool_.rc : -tool_.rc);
    return true;
  }

  bool readTechnology() {
    const Node *tech = op_.child(ir::Kind::Technology);
    perRev_ = tech ? tech->number("feed_per_rev").value_or(0) : 0;
    if (perRev_ <= 0) {
      x_.report(ws_, tech ? *tech : op_, "its operation gives no feed per revolution: a lathe step is fed in mm/rev");
      return false;
    }
    const std::optional<double> vc = tech->number("cutting_speed");
    const std::optional<double> n = tech->number("spindle");
    if (!latheSpeedsInRange(x_, ws_, *tech))
      return false;
    if (vc && *vc > 0) {
      const double clamp = tech->number("spindle_max").value_or(0);
      if (clamp <= 0) {
        x_.report(ws_, *tech,
                  "its constant cutting speed has no maximum spindle speed: the spindle would race as the "
                  "tool nears the axis");
        return false;
      }

      // The spindle turns clockwise (M3) at the speed the stock's diameter
      // asks for, and follows the diameter from there.
      const double start = std::min(std::abs(clamp), *vc / (2 * kPi * raw_.radius));
      moves_.set("spindle", Value::spindle(-start));
      Node state(ir::Kind::State);
      state.set("surface_speed", Value::feed(*vc));
      state.set("spindle_max", Value::spindle(std::abs(clamp)));
      moves_.children.insert(moves_.children.begin(), std::move(state));
    } else if (n && *n != 0) {
      moves_.set("spindle", Value::spindle(*n));
    } else {
      x_.report(ws_, tech ? *tech : op_, "its operation gives no spindle speed nor cutting speed");
      return false;
    }
    moves_.set("x_mode", Value::word("diameter"));
    if (shape_.inner)
      moves_.set("tip", Value::word("inside"));
    return true;
  }

  /// Whether an inner surface has the hole a boring bar works from: the
  /// material to remove must stand off the axis (a hole drilled or bored
  /// before), at least as wide as the bar's minimum cutting diameter.
  bool holeToBore() {
    const Region material = nearSide(geom::intersect(stock_, removal_));
    if (material.empty() || material.area() < 1e-9)
      return true;  // nothing to cut: said by the strategy
    const double hole = 2 * material.box().lo.y();
    if (hole < 1e-3) {
      x_.report(ws_, feature_,
                "the material inside " + shape_.symbol + " reaches the spindle axis: a tool working inside needs a "
                                         "hole to work from (drill or bore it on the axis first)");
      return false;
    }
    if (auto least = toolNode_.number("min_cutting_diameter"); least && hole < *least - 1e-9) {
      x_.report(ws_, toolNode_,
                "its tool " + toolNode_.symbol + " enters holes of " + formatFixed(*least, 4) +
                    " mm and more; the hole inside " + shape_.symbol + " is " + formatFixed(hole, 4) + " mm");
      return false;
    }
    return true;
  }

  // --- safe travel ----------------------------------------------------------------

  /// Whether the insert's corner centres, moved from `a` to `b`, keep out
  /// of `grownRegion` (a region grown by the corner radius).
  bool keepsOut(const Region &grownRegion, const Vec2 &a, const Vec2 &b) const {
    for (const Vec2 &off : tool_.corners) {
      if (grownRegion.contains(a + off) || grownRegion.contains(b + off))
        return false;
      for (const Seg &s : geom::clip(grownRegion, a + off, b + off))
        if ((s.b - s.a).norm() > 1e-6)
          return false;
    }
    return true;
  }

  /// Whether the insert's corner circles, moved from `a` to `b`, stay clear of the stock.
  bool clear(const Vec2 &a, const Vec2 &b) const { return keepsOut(obstacle_, a, b); }

  /// Whether the corner circles moved from `a` to `b` keep out of what the
  /// step must leave (the part, other features' material, the chuck).
  bool spares(const Vec2 &a, const Vec2 &b) const { return keepsOut(guard_, a, b); }

  /// Leaves the surface from `at`: out along `first` by the clearance when
  /// that spares the part, else along `second`; false (after an error) when neither does.
  bool leave(const Vec2 &at, const Vec2 &first, const Vec2 &second, double by, bool atFeed) {
    for (const Vec2 &d : {first, second}) {
      const Vec2 to = at + d * by;
      if (spares(at, to)) {
        if (atFeed)
          w_.feed(to, perRev_, "retract");
        else
          w_.rapid(to, "retract");
        return true;
      }
    }
    x_.report(ws_, "no way off the surface at (z " + formatFixed(at.x(), 4) + ", r " + formatFixed(at.y(), 4) +
                       ") mm that spares what the step must leave");
    return false;
  }

  /// The stock and what the step must leave, grown by the corner radius,
  /// after the stock changed.
  void refreshObstacle() {
    const double r = std::max(tool_.rc, 1e-3) - 1e-4;
    obstacle_ = grown(geom::unite(stock_, chuck_), r);
    guard_ = grown(keepRegion(), r);
  }

  /// What the step must leave: the stock outside the feature's removal, and the chuck.
  Region keepRegion() const { return geom::unite(geom::subtract(stock_, removal_), chuck_); }

  /// Rapids from where the tool is to `to`: straight when clear, else out
  /// above the stock, across and in.
  bool travel(const Vec2 &to) {
    const Vec2 from = w_.position();
    if (clear(from, to)) {
      w_.rapid(to, "position");
      return true;
    }
    // Out above the stock, across and in; else (inside a bore) out along
    // the axis past the stock's free end, across and back in.
    const double above = maxR(stock_) + tool_.rc + kLatheClearance;
    const double front = std::max(stock_.box().hi.x() + tool_.rc + tool_.flank + kLatheClearance, from.x());
    const std::array<std::pair<Vec2, Vec2>, 2> ways{
        std::pair{Vec2(from.x(), std::max(above, from.y())), Vec2(to.x(), std::max(above, from.y()))},
        std::pair{Vec2(front, from.y()), Vec2(front, to.y())}};
    for (const auto &[out, over] : ways)
      if (clear(from, out) && clear(out, over) && clear(over, to)) {
        w_.rapid(out, "retract");
        w_.rapid(over, "position");
        w_.rapid(to, "approach");
        return true;
      }
    x_.report(ws_, "no way at rapid from (z " + formatFixed(from.x(), 4) + ", r " + formatFixed(from.y(), 4) +
                       ") to (z " + formatFixed(to.x(), 4) + ", r " + formatFixed(to.y(), 4) +
                       ") mm clear of the stock (insert corner centres)");
    return false;
  }

  /// A cut from `s` to `e` entered from `entry` (outside the stock) at feed.
  bool cut(const Vec2 &entry, const std::vector<Seg> &path, const char *role = "cut") {
    if (!travel(entry))
      return false;
    if (!spares(entry, path.front().a)) {
      x_.report(ws_, "its approach to (z " + formatFixed(path.front().a.x(), 4) + ", r " +
                         formatFixed(path.front().a.y(), 4) + ") mm would cut into what the step must leave");
      return false;
    }
    w_.feed(path.front().a, perRev_, "approach");
    for (const Seg &s : path)
      w_.seg(s, perRev_, role);
    return true;
  }

  /// The stock less what the corner circles swept along `path`, and the band
  /// outwards of it (`away`, up to the reach) that the insert's edge cuts.
  void removeSwept(const std::vector<Seg> &path, const std::optional<Vec2> &away) {
    std::vector<Region> parts;
    for (const Vec2 &off : tool_.corners)
      for (const Seg &s : path) {
        Seg t = s;
        t.a += off;
        t.b += off;
        t.c += off;
        if (tool_.rc > geom::kEps)
          for (Region &r : geom::sweptDiscParts(t, tool_.rc))
            parts.push_back(std::move(r));
      }
    // A grooving insert is the hull of its corners: its edge between them
    // sweeps what lies between their paths (a plunge's whole width).
    if (const Vec2 w = tool_.corners.back(); w.norm() > geom::kEps)
      for (const Seg &s : path) {
        for (const Vec2 &at : {s.a, s.b})
          for (Region &r : geom::sweptDiscParts(Seg::line(at, at + w), std::max(tool_.rc, 1e-6)))
            parts.push_back(std::move(r));
        if (!s.isArc())
          if (Loop l = geom::polygon({s.a, s.a + w, s.b + w, s.b}); std::abs(l.area()) > 1e-12)
            parts.push_back(Region{{l.area() > 0 ? l : geom::polygon({s.b, s.b + w, s.a + w, s.a})}});
      }
    if (away)
      for (const Seg &s : path) {
        // From the corner centres' path, its ends drawn out along it by the
        // corner radius (the insert is at least as wide as its corner
        // circle beyond it: the edges above a pass's end cut to there too).
        const Vec2 far = *away * 2 * (raw_.radius + raw_.z1 - raw_.z0 + 10);
        const Vec2 a = s.isArc() ? s.a : Vec2(s.a - s.tangent(0) * tool_.rc);
        const Vec2 b = s.isArc() ? s.b : Vec2(s.b + s.tangent(1) * tool_.rc);
        Loop l = geom::polygon({a, b, b + far, a + far});
        if (std::abs(l.area()) > 1e-12) {
          if (l.area() < 0)
            l = geom::polygon({a + far, b + far, b, a});
          // Towards the axis (inside a bore) it stops there: what lies past
          // it is the other side's, which the mirror image gives.
          parts.push_back(away->y() < 0 ? nearSide(Region{{l}}) : Region{{l}});
        }
      }
    if (!parts.empty())
      stock_ = geom::subtract(stock_, withMirror(geom::uniteAll(parts)));
    refreshObstacle();
  }

  // --- the strategies ----------------------------------------------------------

  const Node *strategy() const { return op_.child(ir::Kind::TurningStrategy); }

  std::optional<Vec2> strategyDir(const char *name) const {
    const Node *s = strategy();
    if (!s)
      return std::nullopt;
    if (auto v = s->vec(name)) {
      const Vec2 d = halfPlane(*v);
      if (d.norm() > 1e-9)
        return d.normalized();
    }
    return std::nullopt;
  }

  std::vector<double> depths() {
    if (const Node *s = strategy())
      if (const ir::Value *v = s->get("cutting_depths"); v && !v->numbers.empty()) {
        for (double d : v->numbers)
          if (d <= 0) {
            x_.report(ws_, *s, "its strategy's cutting depths must be positive (" + formatShortest(d) + " mm)");
            return {};
          }
        return v->numbers;
      }
    if (tool_.maxDepth > 0)
      return {tool_.maxDepth};
    x_.assumed(ws_, op_,
               "neither the strategy nor the tool gives a depth of cut: assumed " + formatFixed(kDefaultLatheDepth, 4) +
                   " mm per pass");
    return {kDefaultLatheDepth};
  }

  /// Roughing: passes along the feed direction, one depth of cut apart
  /// across it, each clipped to where the nose has material to cut and
  /// keeps the allowance off every surface the step must leave; then, for
  /// contouring, one pass along the allowance contour.
  bool rough(bool facing) {
    if (tool_.grooving) {
      x_.report(ws_, toolNode_, "roughing with the grooving tool " + toolNode_.symbol + " is not supported");
      return false;
    }
    const double a = op_.number("allowance").value_or(0);
    // By default along the axis towards the chuck stepping in towards the
    // axis (facing: across it towards the axis, stepping towards the chuck);
    // inside a bore outwards instead.
    const double in = shape_.inner ? 1 : -1;
    Vec2 d = strategyDir("feed_dir").value_or(facing ? Vec2(0, in) : Vec2(-1, 0));
    Vec2 s = strategyDir("stepover_dir").value_or(facing ? Vec2(-1, 0) : Vec2(0, in));
    const bool along = std::abs(std::abs(d.x()) - 1) < 1e-9 && std::abs(s.y()) > 1 - 1e-9;
    const bool across = std::abs(std::abs(d.y()) - 1) < 1e-9 && std::abs(s.x()) > 1 - 1e-9;
    if (!along && !across) {
      x_.report(ws_, strategy() ? *strategy() : op_,
                "its roughing passes run along " + formatTuple({d.x(), d.y()}, 6) + " (z, r) stepping over " +
                    formatTuple({s.x(), s.y()}, 6) +
                    ": stepnc roughs along the axis or across it, stepping over at right angles");
      return false;
    }
    const bool bidirectional = strategy() && strategy()->text("type") == "bidirectional";
    // The way back between passes: against the feed direction, at rapid.
    if (const std::optional<Vec2> back = strategyDir("back_path_dir");
        back && (bidirectional || back->dot(-d) < 1 - 1e-9))
      x_.assumed(ws_, *strategy(),
                 "its strategy's back_path_direction " + formatTuple({back->x(), back->y()}, 6) +
                     " (z, r) is not followed yet: " +
                     (bidirectional ? std::string("bidirectional passes have no way back")
                                    : "the tool goes back against its feed direction " +
                                          formatTuple({-d.x(), -d.y()}, 6) + ", at rapid, clear of the stock"));
    const std::vector<double> cuts = depths();
    if (cuts.empty())
      return false;
    if (tool_.maxDepth > 0)
      for (double c : cuts)
        if (c > tool_.maxDepth + 1e-9) {
          x_.report(ws_, strategy() ? *strategy() : op_,
                    "its depth of cut " + formatFixed(c, 4) + " mm is more than its tool " + toolNode_.symbol +
                        " cuts (" + formatFixed(tool_.maxDepth, 4) + " mm)");
          return false;
        }
    const Region keep = keepRegion();
    const Region material = geom::intersect(stock_, removal_);
    if (material.empty() || material.area() < 1e-9) {
      x_.warning(ws_, shape_.symbol + " has no material left to rough (the steps before removed it)");
      return true;
    }
    const Region forbidden = grown(keep, tool_.rc + a);
    const Region centres = nearSide(geom::subtract(grown(material, tool_.rc), forbidden));
    const Vec2 out = -s;  // from the part towards the stock's outside
    auto u = [&](const Vec2 &p) { return p.dot(out); };
    // The material on the near side of the axis (its mirror image past it
    // would put the first level off by the bore's diameter inside a bore).
    const geom::Box cb = centres.box(), mb = nearSide(material).box();
    if (centres.empty()) {
      x_.warning(ws_, shape_.symbol + ": the allowance leaves nothing to rough");
      return true;
    }
    auto corners = [](const geom::Box &b) {
      return std::vector<Vec2>{b.lo, b.hi, Vec2(b.lo.x(), b.hi.y()), Vec2(b.hi.x(), b.lo.y())};
    };
    double uTop = -1e300, uFloor = 1e300;
    for (const Vec2 &p : corners(mb))
      uTop = std::max(uTop, u(p));
    // The deepest level: the lowest the nose may go within the material's
    // extent across the passes (round the stock's outer corner it may go
    // lower, cutting nothing).
    geom::Box extent = cb;
    if (std::abs(d.x()) > 0.5) {
      extent.lo.x() = std::max(cb.lo.x(), mb.lo.x());
      extent.hi.x() = std::min(cb.hi.x(), mb.hi.x());
    } else {
      extent.lo.y() = std::max(cb.lo.y(), mb.lo.y());
      extent.hi.y() = std::min(cb.hi.y(), mb.hi.y());
    }
    const Region within = geom::intersect(centres, box(extent.lo, extent.hi));
    for (const Vec2 &p : corners(within.empty() ? cb : within.box()))
      uFloor = std::min(uFloor, u(p));
    std::vector<double> levels;
    double level = uTop + tool_.rc;
    for (size_t k = 0; level > uFloor + 1e-6; ++k) {
      level -= cuts[std::min(k, cuts.size() - 1)];
      // Contouring ends with a pass along the allowance, which takes the
      // last depth (less than a depth of cut) along the floor too.
      if (!facing && level <= uFloor + 1e-6)
        break;
      levels.push_back(std::max(level, uFloor + 1e-6));
      if (static_cast<int>(levels.size()) > kMaxLevels) {
        x_.report(ws_, "its depth of cut makes more than " + std::to_string(kMaxLevels) + " passes");
        return false;
      }
    }
    const double lift = liftHeight();
    double dirSign = 1;
    double span0 = 1e300, span1 = -1e300;
    for (const Vec2 &p : corners(cb)) {
      span0 = std::min(span0, p.dot(d));
      span1 = std::max(span1, p.dot(d));
    }
    // Bidirectional passes are linked at feed where the step over from one
    // pass's end to the next one's start spares the part: `held` is where
    // the tool stays in the cut, and the way it came.
    std::optional<std::pair<Vec2, Vec2>> held;
    auto release = [&] {
      if (held && !leave(held->first, (out - held->second).normalized(), out, lift * std::sqrt(2.0), false))
        return false;
      held.reset();
      return true;
    };
    for (double lv : levels) {
      const Vec2 dd = d * dirSign;
      const Vec2 base = out * lv;
      const Vec2 p0 = base + d * (span0 - 1) - out * out.dot(d * (span0 - 1));
      const Vec2 p1 = base + d * (span1 + 1) - out * out.dot(d * (span1 + 1));
      std::vector<Seg> pieces = geom::clip(centres, dirSign > 0 ? p0 : p1, dirSign > 0 ? p1 : p0);
      for (const Seg &piece : pieces) {
        // Slivers (the nose over a corner the contour pass takes) are left to it.
        if ((piece.b - piece.a).norm() < kMinRoughPass)
          continue;
        if (held && spares(held->first, piece.a)) {
          w_.feed(piece.a, perRev_, "link");
          w_.feed(piece.b, perRev_, "cut");
          removeSwept({Seg::line(held->first, piece.a), Seg::line(piece.a, piece.b)}, out);
        } else {
          if (!release())
            return false;
          const Vec2 entry = piece.a - dd * kLatheClearance;
          if (!cut(entry, {Seg::line(piece.a, piece.b)}))
            return false;
          removeSwept({Seg::line(entry, piece.b)}, out);
        }
        held = {piece.b, dd};
        if (!bidirectional && !release())
          return false;
      }
      if (bidirectional)
        dirSign = -dirSign;
    }
    if (!release())
      return false;
    if (!facing)
      return contourPass(a, "cut");
    return true;
  }

  double liftHeight() const {
    if (const Node *s = strategy())
      if (auto h = s->number("lift_height"); h && *h > 0)
        return *h;
    for (const char *k : {"x_return", "z_return"})
      if (auto h = op_.number(k); h && *h > 0)
        return *h;
    return kDefaultLift;
  }

  /// The nose centre's path along the feature's surface, `a` off it: the
  /// boundary of the region the nose must keep out of, where it runs along
  /// the surface, in the surface's order; trimmed to where there is material.
  std::optional<std::vector<Seg>> contourPath(double a) {
    const Region keep = keepRegion();
    const double off = tool_.rc + a;
    const Region forbidden = grown(keep, off);
    // The pieces of its boundary no farther from the surface than `off`
    // (lines clipped to that band; arcs whole or not at all).
    geom::SegIndex surface(shape_.contour);
    const Region band = geom::sweptDisc(shape_.contour, off + 1e-5);
    // Only on the side of the surface the step removes: the boundary of other material kept
    // (a neighbour's stock) may lie as far from the surface on the part's side.
    auto side = [&](const Vec2 &p) {
      const Seg *nearest = nullptr;
      Vec2 q = Vec2::Zero();
      for (const Seg &sg : shape_.contour)
        if (const Vec2 c = geom::closestPoint(sg, p); !nearest || (c - p).norm() < (q - p).norm()) {
          nearest = &sg;
          q = c;
        }
      Vec2 t = nearest->b - nearest->a;
      if (nearest->isArc()) {
        const Vec2 r = q - nearest->c;
        t = nearest->turn > 0 ? Vec2(-r.y(), r.x()) : Vec2(r.y(), -r.x());
      }
      return geom::cross(t, p - q) > 0;
    };
    bool removalLeft = true;
    for (const Seg &sg : shape_.contour) {
      // The first piece with the removal on one side only says which.
      const Vec2 normal(-sg.tangent(0.5).y(), sg.tangent(0.5).x());
      const bool left = removal_.contains(sg.at(0.5) + normal * 1e-3), right = removal_.contains(sg.at(0.5) - normal * 1e-3);
      if (left != right) {
        removalLeft = left;
        break;
      }
    }
    std::vector<Seg> along;
    for (const Loop &l : forbidden.loops)
      for (const Seg &s : l.segs) {
        if (s.isArc()) {
          if (std::abs(surface.distance(s.at(0.5)) - off) < 1e-5 && std::abs(surface.distance(s.a) - off) < 1e-5 &&
              std::abs(surface.distance(s.b) - off) < 1e-5 && side(s.at(0.5)) == removalLeft)
            along.push_back(s);
          continue;
        }
        for (const Seg &piece : geom::clip(band, s.a, s.b))
          if ((piece.b - piece.a).norm() > 1e-7 && std::abs(surface.distance(piece.at(0.5)) - off) < 1e-5 &&
              side(piece.at(0.5)) == removalLeft)
            along.push_back(piece);
      }
    if (along.empty())
      return std::nullopt;
    // Chain the pieces (a loop's order is counter-clockwise about the
    // forbidden region, which lies left of it; the surface's order may be
    // the other way).
    std::vector<Seg> chain{along.front()};
    along.erase(along.begin());
    for (bool grew = true; grew && !along.empty();) {
      grew = false;
      for (size_t k = 0; k < along.size(); ++k) {
        if ((along[k].a - chain.back().b).norm() < 1e-7) {
          chain.push_back(along[k]);
        } else if ((along[k].b - chain.front().a).norm() < 1e-7) {
          chain.insert(chain.begin(), along[k]);
        } else {
          continue;
        }
        along.erase(along.begin() + static_cast<long>(k));
        grew = true;
        break;
      }
    }
    if (!along.empty()) {
      x_.report(ws_, "the path along " + shape_.symbol + " falls apart in pieces: not supported yet");
      return std::nullopt;
    }
    // The surface's own order: its first point nearest the chain's end?
    const Vec2 first = shape_.contour.front().a;
    if ((chain.back().b - first).norm() < (chain.front().a - first).norm()) {
      std::reverse(chain.begin(), chain.end());
      for (Seg &s : chain)
        s = s.reversed();
    }
    // Pieces shorter than a micrometre (where offsets of two corners nearly
    // meet) joined into their neighbours: a controller may read a tiny
    // arc whose ends print as one point as a whole circle.
    for (size_t k = 0; k < chain.size() && chain.size() > 1;) {
      if (chain[k].length() >= 1e-3) {
        ++k;
        continue;
      }
      const Vec2 from = chain[k].a, to = chain[k].b;
      if ((k + 1 < chain.size() && !chain[k + 1].isArc()) || (k > 0 && !chain[k - 1].isArc())) {
        chain.erase(chain.begin() + static_cast<long>(k));
        if (k < chain.size() && !chain[k].isArc())
          chain[k].a = from;
        else
          chain[k - 1].b = to;
      } else {
        // Between two arcs (or alone at an end): kept, as a line.
        chain[k] = Seg::line(from, to);
        ++k;
      }
    }
    // Trimmed to the pieces that touch material.
    const Region material = geom::intersect(stock_, removal_);
    const Region reach = grown(material, tool_.rc + 1e-3);
    auto touches = [&](const Seg &s) {
      if (reach.contains(s.at(0.5)) || reach.contains(s.a) || reach.contains(s.b))
        return true;
      return !s.isArc() && !geom::clip(reach, s.a, s.b).empty();
    };
    while (!chain.empty() && !touches(chain.front()))
      chain.erase(chain.begin());
    while (!chain.empty() && !touches(chain.back()))
      chain.pop_back();
    // The end lines from where they first reach the material to where they
    // last do, on the near side of the axis.
    const Region near = nearSide(reach);
    if (!chain.empty() && !chain.front().isArc())
      if (std::vector<Seg> in = geom::clip(near, chain.front().a, chain.front().b); !in.empty())
        chain.front().a = in.front().a;
    if (!chain.empty() && !chain.back().isArc())
      if (std::vector<Seg> in = geom::clip(near, chain.back().a, chain.back().b); !in.empty())
        chain.back().b = in.back().b;
    return chain;
  }

  /// One pass along the surface `a` off it, entered and left along its ends' tangents.
  /// `onSurface`: a finishing pass, entered so that a controller's
  /// compensation can make it from the surface (below).
  bool contourPass(double a, const char *role, bool onSurface = false) {
    const std::optional<std::vector<Seg>> path = contourPath(a);
    if (!x_.result.ok)
      return false;
    if (!path || path->empty()) {
      x_.warning(ws_, shape_.symbol + " has no material left along its surface");
      return true;
    }
    // No more than a depth of cut in one pass.
    if (tool_.maxDepth > 0) {
      std::vector<Region> parts;
      for (const Seg &s : *path)
        for (Region &r : geom::sweptDiscParts(s, tool_.rc + tool_.maxDepth))
          parts.push_back(std::move(r));
      // What the pass leaves that it should cut: not the allowance it
      // leaves on purpose (a corner of it lies farther from the pass).
      const Region left = geom::subtract(
          geom::subtract(geom::intersect(stock_, removal_), withMirror(geom::uniteAll(parts))),
          withMirror(grown(keepRegion(), a + 1e-3)));
      if (left.area() > 1e-6) {
        x_.report(ws_, "the pass along " + shape_.symbol + " would cut more than its tool " + toolNode_.symbol +
                           " cuts in one pass (" + formatFixed(tool_.maxDepth, 4) + " mm): rough it first");
        return false;
      }
    }
    const Vec2 t0 = path->front().tangent(0), t1 = path->back().tangent(1);
    // Which side of the pass the nose's centre is on, seen along it from
    // the surface: the side a controller's compensation would put it.
    {
      const Seg &first = path->front();
      const Vec2 mid = first.at(0.5);
      Vec2 onContour = shape_.contour.front().a;
      for (const Seg &sg : shape_.contour)
        if (const Vec2 q = geom::closestPoint(sg, mid); (q - mid).norm() < (onContour - mid).norm())
          onContour = q;
      noseLeft_ = geom::cross(first.tangent(0.5), mid - onContour) > 0;
    }
    Vec2 entry = path->front().a - t0 * kLatheClearance;
    if (onSurface) {
      // The programmed point starts on the tangent of the surface (the
      // allowance's) before the pass, a lead longer than the nose's radius
      // off it: the line a controller compensates on entry (G41/G42) ends
      // with the nose where the pass starts, as without it.
      const Vec2 toNose = Vec2(-t0.y(), t0.x()) * (*noseLeft_ ? tool_.rc : -tool_.rc);
      const Vec2 onPart = path->front().a - toNose;
      entry = onPart - t0 * std::max(kLatheClearance, 2 * tool_.rc) - tool_.tip;
    }
    if (!onSurface && (!clearOfMaterial(entry) || !spares(entry, path->front().a))) {
      // A nose larger than the clearance still touches the stock a
      // clearance back from where the pass meets it: back by its radius more.
      const Vec2 further = path->front().a - t0 * (kLatheClearance + tool_.rc);
      if (clearOfMaterial(further) && spares(further, path->front().a))
        entry = further;
    }
    if (!clearOfMaterial(entry) || !spares(entry, path->front().a)) {
      // Where the surface's tangent runs into the part (a round starting at
      // a face), the nose comes in square to the pass from the tool's side.
      const Vec2 square = path->front().a + Vec2(-t0.y(), t0.x()) * (*noseLeft_ ? 1.0 : -1.0) * kLatheClearance;
      if (!clearOfMaterial(square) || !spares(square, path->front().a)) {
        x_.report(ws_, "the pass along " + shape_.symbol +
                           " starts inside the stock: no way in along its tangent nor square to it");
        return false;
      }
      entry = square;
    }
    if (!cut(entry, *path, role))
      return false;
    // Off the surface along its normal away from the part (the side the
    // nose is on), else on along its tangent. (Not towards the part where
    // that only grazes the stock: it dips into the allowance.)
    const Vec2 end = path->back().b;
    Vec2 normal = Vec2(-t1.y(), t1.x()) * (*noseLeft_ ? 1.0 : -1.0);
    if (!spares(end, end + normal * kLatheClearance))
      normal = -normal;
    if (!leave(end, normal, t1, kLatheClearance, true))
      return false;
    std::vector<Seg> swept = *path;
    swept.insert(swept.begin(), Seg::line(entry, path->front().a));
    swept.push_back(Seg::line(end, w_.position()));
    removeSwept(swept, std::nullopt);
    removeReachable(a);
    return true;
  }

  /// After a pass along the surface `a` off it: all the nose reaches
  /// outside that allowance is gone (the insert's edges cut what lies
  /// beyond the nose circle; corners narrower than the nose stay).
  void removeReachable(double a) {
    const Region keep = keepRegion();
    const geom::Box b = stock_.box();
    const Region window = box(b.lo - Vec2(10, 10), b.hi + Vec2(10, 10));
    const Region centres = geom::subtract(window, grown(keep, tool_.rc + a));
    stock_ = geom::subtract(stock_, geom::intersect(grown(centres, tool_.rc), removal_));
    refreshObstacle();
  }

  bool clearOfMaterial(const Vec2 &p) const { return !obstacle_.contains(p); }

  bool finish(double a) {
    if (tool_.grooving) {
      x_.report(ws_, toolNode_, "finishing a contour with the grooving tool " + toolNode_.symbol + " is not supported");
      return false;
    }
    if (!contourPass(a, "cut", true))
      return false;
    // One pass along the surface: a target may write it as the surface
    // itself with the controller's nose radius compensation on this side.
    if (noseLeft_)
      moves_.set("nose_side", Value::word(*noseLeft_ ? "left" : "right"));
    return true;
  }

  // --- grooves and cutting in ------------------------------------------------------

  bool needsGroove() {
    if (!tool_.grooving) {
      x_.report(ws_, toolNode_, "grooving needs a grooving tool; " + toolNode_.symbol + " is a turning tool");
      return false;
    }
    if (!shape_.grooveSpan) {
      x_.report(ws_, feature_, "grooving operations cut grooves; " + shape_.symbol + " is a " + feature_.kindName());
      return false;
    }
    return true;
  }

  double dwellSeconds() const {
    if (auto t = op_.number("dwell"))
      return *t;
    if (auto revs = op_.number("dwell_revolutions")) {
      const double n = std::abs(movesSpindle());
      return n > 0 ? *revs * 60 / n : 0;
    }
    return 0;
  }

  /// The operation's dwell at the bottom of a plunge; one shorter than a
  /// controller dwells (a dwell in revolutions at a fast spindle) is said
  /// once and not written.
  void dwell() {
    const double s = dwellSeconds();
    if (s > 0 && s < ir::kMinDwellS) {
      if (!saidShortDwell_)
        x_.assumed(ws_, op_,
                   "its dwell of " + formatShortest(s) + " s is shorter than a controller dwells (" +
                       formatShortest(ir::kMinDwellS) + " s): not written");
      saidShortDwell_ = true;
      return;
    }
    w_.dwell(s);
  }

  double movesSpindle() const { return moves_.number("spindle").value_or(0); }

  /// From the part towards where the tool comes from, across the axis: +1
  /// outside, -1 inside a bore.
  double outwards() const { return shape_.inner ? -1 : 1; }

  /// The radius beyond which (outwards, or in towards the axis inside a
  /// bore) the band [z, z + width] of the stock is clear.
  double topOver(double zLeftEdge) const {
    const Region band = nearSide(geom::intersect(stock_, box(Vec2(zLeftEdge, -1), Vec2(zLeftEdge + tool_.width, 1e5))));
    if (shape_.inner)
      return band.empty() ? 0 : band.box().lo.y();
    return maxR(band);
  }

  /// One plunge of the grooving insert with its chuck-side edge at `zEdge`
  /// to `bottom` (the insert's point farthest in), and straight back out.
  bool plunge(double zEdge, double bottom, const char *role) {
    const double out = outwards();
    const double zc = zEdge + tool_.rc;
    const double topR = topOver(zEdge);
    const double top = (out > 0 ? std::max(topR, bottom) : std::min(topR, bottom)) + out * (tool_.rc + kLatheClearance);
    const Vec2 entry(zc, top), end(zc, bottom + out * tool_.rc);
    // Pecking: the strategy's travel_distance at a time into the material,
    // back its retract_distance at rapid to break the chip, in again at feed.
    const Node *st = strategy();
    const double peck = st ? st->number("travel_distance").value_or(0) : 0;
    const double back = st ? st->number("retract_distance").value_or(kDefaultPeckRetract) : kDefaultPeckRetract;
    const double firstCut = topR + out * tool_.rc;  // the centre where the insert meets the stock
    if (peck > 0 && back > 0 && std::abs(end.y() - firstCut) > peck + 1e-9 &&
        std::abs(end.y() - firstCut) / peck <= kMaxLevels) {
      if (!cut(entry, {Seg::line(entry, Vec2(zc, firstCut))}, role))
        return false;
      for (double at = firstCut;;) {
        const double next = out > 0 ? std::max(at - peck, end.y()) : std::min(at + peck, end.y());
        w_.feed(Vec2(zc, next), perRev_, role);
        if (std::abs(next - end.y()) < 1e-9)
          break;
        w_.rapid(Vec2(zc, next + out * back), "retract");
        w_.rapid(Vec2(zc, next + out * std::min(back, 0.1)), "approach");
        at = next;
      }
    } else if (!cut(entry, {Seg::line(entry, end)}, role)) {
      return false;
    }
    dwell();
    w_.rapid(entry, "retract");
    removeSwept({Seg::line(entry, end)}, Vec2(0, out));
    return true;
  }

  /// One plunge of a face grooving insert along -z, its edge nearest the
  /// axis at `rEdge`, to `bottom` (the insert's front), and straight back out.
  bool facePlunge(double rEdge, double bottom, const char *role) {
    const double rc = rEdge + tool_.rc;
    const Region band = geom::intersect(stock_, box(Vec2(-1e5, rEdge), Vec2(1e5, rEdge + tool_.width)));
    const double topZ = band.empty() ? bottom : std::max(band.box().hi.x(), bottom);
    const Vec2 entry(topZ + tool_.rc + kLatheClearance, rc), end(bottom + tool_.rc, rc);
    if (!cut(entry, {Seg::line(entry, end)}, role))
      return false;
    dwell();
    w_.rapid(entry, "retract");
    removeSwept({Seg::line(entry, end)}, Vec2(1, 0));
    return true;
  }

  /// Where the plunges across a groove put the insert's reference edge:
  /// `a` inside the walls, the first and last against them, overlapping by
  /// a fifth of the insert's width; nullopt after an error (the insert wider
  /// than the groove less its allowances).
  std::optional<std::vector<double>> plungeEdges(double a) {
    const auto [lo, hi] = *shape_.grooveSpan;
    const double first = lo + a, last = hi - a - tool_.width;
    if (last < first - 1e-9) {
      x_.report(ws_, toolNode_,
                "its grooving tool " + toolNode_.symbol + " (" + formatFixed(tool_.width, 4) +
                    " mm wide) is wider than " + shape_.symbol + " less its allowances (" +
                    formatFixed(hi - lo - 2 * a, 4) + " mm)");
      return std::nullopt;
    }
    const double step = 0.8 * tool_.width;
    const int n = static_cast<int>(std::ceil((last - first) / step - 1e-9)) + 1;
    std::vector<double> edges;
    for (int k = 0; k < n; ++k)
      edges.push_back(n == 1 ? first : first + (last - first) * k / (n - 1));
    return edges;
  }

  // A groove's own frame: u along its floor (z for a radial groove, r for a
  // face groove), v from the floor towards its open side. The grooving
  // insert's reference corner is at the low-u end of its edge, the far one
  // `width - 2 rc` further along u.

  /// The point (u, v) of the groove's frame in the half plane.
  Vec2 grooveWorld(double u, double v) const {
    if (shape_.faceGroove)
      return Vec2(shape_.grooveFloor + v, u);
    return Vec2(u, shape_.grooveFloor + outwards() * v);
  }

  /// Whether the frame's (u, v) turn the other way round than (z, r): an
  /// arc clockwise in the frame is then counter-clockwise in the half plane.
  bool grooveFlipped() const { return shape_.faceGroove || shape_.inner; }

  /// How close to the floor (v) a corner centre at `u` may come keeping the
  /// allowance `a` off the floor and off a rounded corner: an insert corner
  /// rounder than the groove's stays on the floor's straight part.
  double grooveDepth(double u, double a) const {
    const auto [lo, hi] = *shape_.grooveSpan;
    const auto [rLo, rHi] = shape_.grooveRadii;
    double v = tool_.rc + a;
    auto corner = [&](double cu, double rho) {
      const double reach = rho - tool_.rc - a;
      if (reach <= 0)
        return;
      const double du = std::min(std::abs(u - cu), reach);
      v = std::max(v, rho - std::sqrt(reach * reach - du * du));
    };
    if (u < lo + rLo)
      corner(lo + rLo, rLo);
    if (u > hi - rHi)
      corner(hi - rHi, rHi);
    return v;
  }

  bool grooveRough() {
    if (!needsGroove())
      return false;
    const double a = op_.number("allowance").value_or(0);
    std::optional<std::vector<double>> edges = plungeEdges(a);
    if (!edges)
      return false;
    const double far = tool_.width - 2 * tool_.rc;
    // Corners rounder than the insert's: the plunges next to the walls stop
    // above the rounds, so the floor between them gets plunges of its own
    // (the reference corner where both corners reach the floor's straight
    // part, a fifth of the insert's width overlapping).
    const auto [lo, hi] = *shape_.grooveSpan;
    const auto [rLo, rHi] = shape_.grooveRadii;
    if (rLo > tool_.rc + a || rHi > tool_.rc + a) {
      const double first = lo + std::max(rLo, tool_.rc + a), last = hi - std::max(rHi, tool_.rc + a) - far;
      if (last >= first - 1e-9) {
        const int n = static_cast<int>(std::ceil((last - first) / (0.8 * tool_.width) - 1e-9)) + 1;
        for (int k = 0; k < n; ++k)
          edges->push_back((n == 1 ? first : first + (last - first) * k / (n - 1)) - tool_.rc);
        std::sort(edges->begin(), edges->end());
        edges->erase(std::unique(edges->begin(), edges->end(), [](double x, double y) { return y - x < 1e-6; }),
                     edges->end());
      }
    }
    for (double e : *edges) {
      // The insert's front from the floor: as deep as both corners may go.
      const double u = e + tool_.rc;
      const double front = std::max(grooveDepth(u, a), grooveDepth(u + far, a)) - tool_.rc;
      if (!(shape_.faceGroove ? facePlunge(e, shape_.grooveFloor + front, "cut")
                              : plunge(e, shape_.grooveFloor + outwards() * front, "cut")))
        return false;
    }
    return true;
  }

  /// A groove's finish: down the wall at the high end of its span with the
  /// far corner (round the groove's corner there when it is rounder than
  /// the insert's), along the floor, round the low corner and up the low
  /// wall with the reference corner; entered at its start, the stock then
  /// loses what it swept and all beyond it towards the open side.
  bool grooveFinish() {
    if (!needsGroove())
      return false;
    const auto [lo, hi] = *shape_.grooveSpan;
    const double floor = shape_.grooveFloor, out = outwards();
    if (hi - lo < tool_.width - 1e-9) {
      x_.report(ws_, toolNode_,
                "its grooving tool " + toolNode_.symbol + " is wider than " + shape_.symbol + " (" +
                    formatFixed(hi - lo, 4) + " mm)");
      return false;
    }
    const double rc = tool_.rc, far = tool_.width - 2 * rc;
    const double rLo = std::max(shape_.grooveRadii.first, rc), rHi = std::max(shape_.grooveRadii.second, rc);
    if (hi - rHi - far < lo + rLo - 1e-9) {
      x_.report(ws_, toolNode_,
                "the floor of " + shape_.symbol + " between its rounded corners (" +
                    formatFixed(std::max(0.0, hi - lo - rLo - rHi + 2 * rc), 4) + " mm for the corner centres) is " +
                    "narrower than the edge of its grooving tool " + toolNode_.symbol + " between its corners (" +
                    formatFixed(far, 4) + " mm): a narrower insert finishes it");
      return false;
    }
    // Where the insert comes in from, clear of the stock, as v.
    double top = 0;
    if (shape_.faceGroove) {
      const Region band = geom::intersect(stock_, box(Vec2(-1e5, lo), Vec2(1e5, hi)));
      top = (band.empty() ? floor : band.box().hi.x()) + rc + kLatheClearance - floor;
    } else {
      const double topR = topOver(lo);
      top = ((out > 0 ? std::max(topR, floor) : std::min(topR, floor)) + out * (rc + kLatheClearance) - floor) * out;
    }
    const bool ccw = grooveFlipped();  // clockwise in the frame
    auto at = [&](double u, double v) { return grooveWorld(u, v); };
    std::vector<Seg> path;
    auto line = [&](const Vec2 &p, const Vec2 &q) {
      if ((q - p).norm() >= 1e-9)
        path.push_back(Seg::line(p, q));
    };
    const double uHi = hi - rc - far;
    line(at(uHi, top), at(uHi, rHi));
    if (rHi > rc + 1e-9)
      path.push_back(Seg::arc(at(uHi, rHi), at(hi - rHi - far, rc), at(hi - rHi - far, rHi), ccw));
    line(at(hi - rHi - far, rc), at(lo + rLo, rc));
    if (rLo > rc + 1e-9)
      path.push_back(Seg::arc(at(lo + rLo, rc), at(lo + rc, rLo), at(lo + rLo, rLo), ccw));
    line(at(lo + rc, rLo), at(lo + rc, top));
    if (!cut(path.front().a, path))
      return false;
    removeSwept(path, shape_.faceGroove ? Vec2(1, 0) : Vec2(0, out));
    return true;
  }

  /// Knurling: the wheels pressed in at the knurl's free-end end to its
  /// teeth's depth, fed along it towards the chuck at the feed per
  /// revolution, and lifted straight out at its other end.
  bool knurl() {
    if (!shape_.knurl) {
      x_.report(ws_, feature_, "knurling rolls a knurl; " + shape_.symbol + " is a " + feature_.kindName());
      return false;
    }
    const ir::TurnedShape::KnurlSpan k = *shape_.knurl;
    const double w = tool_.width;
    if (w > k.hi - k.lo + 1e-9) {
      x_.report(ws_, toolNode_,
                "the wheels of its knurling tool " + toolNode_.symbol + " (" + formatFixed(w, 4) +
                    " mm wide) are wider than " + shape_.symbol + " (" + formatFixed(k.hi - k.lo, 4) + " mm)");
      return false;
    }
    // The wheels roll their own pitch and pattern.
    const std::optional<double> toolPitch = toolNode_.number("knurl_pitch"),
                                pitch = feature_.number("diametral_pitch");
    if (toolPitch && pitch && std::abs(*toolPitch - *pitch) > 1e-6)
      x_.assumed(ws_, toolNode_,
                 "its knurling tool " + toolNode_.symbol + " rolls a pitch of " + formatFixed(*toolPitch, 4) +
                     " mm, not the " + formatFixed(*pitch, 4) + " mm of " + shape_.symbol +
                     ": the knurl gets the wheels' pitch");
    const std::optional<std::string> toolPattern = toolNode_.text("knurl_pattern"),
                                     pattern = feature_.text("pattern");
    if (toolPattern && pattern && *pattern != "tool" && *toolPattern != *pattern)
      x_.assumed(ws_, toolNode_,
                 "its knurling tool " + toolNode_.symbol + " rolls a " + *toolPattern + " pattern, not the " +
                     *pattern + " one of " + shape_.symbol + ": the knurl gets the wheels' pattern");
    // The rim presses into the knurl's band and touches the part along its
    // bottom: that is the knurl, so the moves in are not held off the part
    // as a cutting insert's are (cut()).
    const double rim = k.radius - k.depth, clear = k.radius + kLatheClearance;
    const Vec2 start(k.hi - w, rim), end(k.lo, rim);
    if (!travel(Vec2(start.x(), clear)))
      return false;
    w_.feed(start, perRev_, "plunge");
    w_.feed(end, perRev_, "cut");
    dwell();
    w_.feed(Vec2(end.x(), clear), perRev_, "retract");
    removeSwept({Seg::line(Vec2(start.x(), clear), start), Seg::line(start, end)}, Vec2(0, 1));
    return true;
  }

  bool cutIn() {
    if (shape_.inner) {
      x_.report(ws_, op_, "cutting in on the inner surface of " + shape_.symbol + " is not supported");
      return false;
    }
    if (!tool_.grooving) {
      x_.report(ws_, toolNode_, "cutting in needs a grooving (parting) tool; " + toolNode_.symbol + " is a turning tool");
      return false;
    }
    const Vec3 dir = op_.vec("direction").value_or(Vec3(-1, 0, 0));
    if (dir.x() > -1 + 1e-9) {
      x_.report(ws_, op_, "cutting in along " + formatTuple({dir.x(), dir.y(), dir.z()}, 6) +
                              " is not supported: stepnc cuts in towards the axis (-x)");
      return false;
    }
    const double depth = op_.number("depth").value_or(0);
    // The insert's free-end edge at the feature's placement: the part on
    // the free-end side keeps its face.
    const double zEdge = shape_.at.x() - tool_.width;
    const double top = topOver(zEdge);
    if (top <= 0) {
      x_.warning(ws_, "no stock left where " + shape_.symbol + " is cut in");
      return true;
    }
    const double bottom = std::max(top - depth, 0.0);
    if (!plunge(zEdge, bottom, "cut"))
      return false;
    if (bottom <= 1e-9) {
      // Cut off: what lies on the free-end side leaves the lathe.
      stock_ = geom::intersect(stock_, box(Vec2(raw_.z0 - 1, -1), Vec2(zEdge, 1e5)));
      refreshObstacle();
    }
    return true;
  }

  // --- threads ---------------------------------------------------------------------

  /// The cumulative depths of a threading step's passes, the last at `target`:
  /// the strategy's depths per pass, else its infeed law from a first pass
  /// of at most 0.3 mm (constant depth: equal passes; otherwise constant
  /// removal: the depth after pass n is d1 sqrt(n), LinuxCNC's G76 with R 2).
  std::vector<double> threadDepths(double from, double target) {
    std::vector<double> out;
    double at = from;
    const Node *st = strategy();
    if (st)
      if (const ir::Value *v = st->get("cutting_depths"); v && !v->numbers.empty()) {
        for (double d : v->numbers) {
          if (d <= 0) {
            x_.report(ws_, *st, "its strategy's cutting depths must be positive (" + formatShortest(d) + " mm)");
            return {};
          }
          if (at >= target - 1e-9)
            break;
          at = std::min(at + d, target);
          out.push_back(at);
        }
        if (at < target - 1e-9) {
          x_.assumed(ws_, *st,
                     "its cutting depths reach " + formatFixed(at, 4) + " mm of the thread's " +
                         formatFixed(target, 4) + " mm: one more pass to the full depth");
          out.push_back(target);
        }
        return out;
      }
    const double span = target - from;
    if (span <= 1e-9)
      return out;
    const double first = std::min(0.3, span);
    const bool constantDepth = st && st->text("infeed") == "constant_depth";
    for (int n = 1; at < target - 1e-9 && n <= kMaxLevels; ++n) {
      at = std::min(from + (constantDepth ? first * n : first * std::sqrt(static_cast<double>(n))), target);
      out.push_back(at);
    }
    return out;
  }

  /// Threading: passes along the thread from a run-in of two pitches before
  /// its free-end end to its chuck-side end, each deeper (radial infeed),
  /// the spindle and the feed synchronised (`role=thread`, the feed per
  /// revolution the lead); out radially, where nothing is left to cut (a
  /// groove or the part's end), and back. Roughing stops the allowance
  /// short of the full depth; finishing cuts to the full depth (less its
  /// own allowance), then once more there (a spring pass).
  bool threading(bool finishing) {
    if (!shape_.thread) {
      x_.report(ws_, feature_, "threading cuts threads; " + shape_.symbol + " is a " + feature_.kindName());
      return false;
    }
    const ir::TurnedShape::ThreadSpan &t = *shape_.thread;
    if (t.leftHand)
      reverseForLeftHand();
    // The tool's pitch is exact; the one a thread's diameters give is as
    // exact as their decimals (1 % agreement asked).
    const double toolPitch = toolNode_.number("thread_pitch").value_or(0);
    const double pitch = toolPitch > 0 ? toolPitch : t.pitch;
    if (pitch <= 0) {
      x_.report(ws_, feature_, shape_.symbol + " gives no pitch (no pitch diameter) and its tool " + toolNode_.symbol +
                                   " none either");
      return false;
    }
    if (t.pitch > 0 && toolPitch > 0 && std::abs(t.pitch - toolPitch) > 0.01 * toolPitch) {
      x_.report(ws_, toolNode_,
                "its threading tool " + toolNode_.symbol + " cuts a " + formatFixed(toolPitch, 4) + " mm pitch, " +
                    shape_.symbol + " has " + formatFixed(t.pitch, 4) + " mm (from its diameters)");
      return false;
    }
    // A thread of several starts advances by its lead (starts x pitch) a
    // revolution; each start is cut from a run-in a pitch further out.
    const double lead = pitch * t.starts;
    if (perRev_ > 0 && std::abs(perRev_ - lead) > 1e-6)
      x_.assumed(ws_, *op_.child(ir::Kind::Technology),
                 "its feed per revolution " + formatFixed(perRev_, 4) + " mm is not the thread's lead " +
                     formatFixed(lead, 4) + " mm: the passes follow the lead");
    for (const Node &c : moves_.children)
      if (c.kind == ir::Kind::State && c.has("surface_speed")) {
        const Node *tech = op_.child(ir::Kind::Technology);
        x_.report(ws_, tech ? *tech : op_,
                  "threading follows the spindle: it needs a constant spindle speed, not a constant cutting speed");
        return false;
      }
    const double depth = std::abs(t.rootRadius - t.crestRadius);
    const double allowance = op_.number("allowance").value_or(0);
    if (allowance < 0 || allowance >= depth) {
      x_.report(ws_, op_, "its allowance " + formatFixed(allowance, 4) + " mm is not within the thread's depth " +
                              formatFixed(depth, 4) + " mm");
      return false;
    }
    std::vector<double> passes;
    if (finishing) {
      // To the full depth less its own allowance (none, as a rule), then a
      // spring pass there.
      passes = {depth - allowance, depth - allowance};
    } else {
      passes = threadDepths(0, depth - allowance);
      if (!x_.result.ok)
        return false;
    }
    // Out of the thread is away from the axis for an outer thread, towards
    // it inside a bore; the tip circle's centre is a corner radius back
    // from the V's point.
    const double out = shape_.inner ? -1 : 1;
    const double runIn = t.hi + 2 * lead, clearR = t.crestRadius + out * (kLatheClearance + tool_.rc);
    const std::vector<double> shifts = flankShifts(passes, depth);
    for (size_t i = 0; i < passes.size(); ++i)
      for (int k = 0; k < t.starts; ++k) {
        const double r = t.crestRadius - out * (passes[i] - tool_.rc);
        const double z = runIn + k * pitch + shifts[i];
        const Vec2 outAtStart(z, clearR), start(z, r), end(t.lo + shifts[i], r), outAtEnd(t.lo + shifts[i], clearR);
        if (!travel(outAtStart))
          return false;
        if (!clear(outAtStart, start)) {
          x_.report(ws_, feature_,
                    "no room to run in before " + shape_.symbol + ": the stock reaches past its free-end end");
          return false;
        }
        w_.rapid(start, "approach");
        w_.thread(end, lead);
        if (!clear(end, outAtEnd)) {
          x_.report(ws_, feature_,
                    shape_.symbol + " ends in material at z " + formatFixed(end.x(), 4) +
                        " mm: the tool cannot leave the thread there (give it a groove to run out into)");
          return false;
        }
        w_.rapid(outAtEnd, "retract");
      }
    // The thread's band is cut when the step ends (passes do not clear it
    // for one another's way out).
    const double deepest = t.crestRadius - out * (passes.back() - tool_.rc);
    removeSwept({Seg::line(Vec2(runIn + (t.starts - 1) * pitch + shifts.back(), deepest),
                           Vec2(t.lo + shifts.back(), deepest))},
                Vec2(0, out));
    return true;
  }

  /// How far along the axis each pass at cumulative depth `passes[i]` is
  /// moved (docs/turning.md): the strategy's `threading_direction` center
  /// (or none) feeds in radially; right (left) along the flank, the V's
  /// point (D - d) tan(half the thread angle less 0.5 deg) towards the free
  /// end (the chuck) of where it ends, D the full depth, so that the
  /// insert's other flank skims the thread's; the zigzags alternate sides,
  /// starting on the one named. Passes at the full depth are centred.
  std::vector<double> flankShifts(const std::vector<double> &passes, double depth) const {
    std::vector<double> shifts(passes.size(), 0.0);
    const Node *st = strategy();
    const std::string side = st ? st->text("thread_side").value_or("center") : "center";
    if (side == "center")
      return shifts;
    const double half = toolNode_.number("thread_angle").value_or(60) / 2 - 0.5;
    const double slope = std::tan(std::max(half, 0.0) * kPi / 180);
    const double first = side.starts_with("right") ? 1 : -1;
    const bool zigzag = side.ends_with("zigzag");
    for (size_t i = 0; i < passes.size(); ++i) {
      const double sign = zigzag && i % 2 == 1 ? -first : first;
      shifts[i] = sign * std::max(depth - passes[i], 0.0) * slope;
    }
    return shifts;
  }

  /// A left-hand thread is cut as a right-hand one is, towards the chuck,
  /// with the spindle turning the other way (counter-clockwise, M4) and the
  /// insert mounted for it; a step whose spindle turns clockwise is turned
  /// round, and that is said.
  void reverseForLeftHand() {
    const double n = movesSpindle();
    if (n < 0) {
      moves_.set("spindle", Value::spindle(-n));
      x_.assumed(ws_, op_,
                 shape_.symbol + " is a left-hand thread: cut towards the chuck with the spindle reversed "
                                 "(counter-clockwise, M4) and its insert " + toolNode_.symbol +
                     " mounted upside down for it");
    }
  }

  Expander &x_;
  Node &ws_;
  const Node &op_;
  const Node &feature_;
  const Node &toolNode_;
  Region &stock_;
  const ir::TurnStock &raw_;
  const ir::TurnedShape &shape_;
  LatheTool tool_;
  Node &moves_;
  LatheWriter w_;
  Region obstacle_, guard_;
  /// The feature's removal, mirrored across the axis; the chuck (all below
  /// the raw piece's chuck-side end), which no tool may enter.
  Region removal_, chuck_;
  double perRev_ = 0;
  bool saidShortDwell_ = false;
  Vec2 home_ = Vec2::Zero();
  /// The side of the last pass along the surface the nose's centre is on.
  std::optional<bool> noseLeft_;
};

/// A lathe step's explicit toolpaths (AP238 files from CAM systems), in
/// the XZ plane of the feature's frame, as the file gives them: the
/// programmed point is the file's; feeds per revolution and the surface
/// speed of each toolpath's technology (else the operation's).
bool expandLatheToolpaths(Expander &x, Node &ws, const Node &op, const Node &feature, const Node &tool,
                          const std::string &setup) {
  const Vec3 at = feature.vec("at").value_or(Vec3::Zero());
  const Vec3 axis = feature.vec("axis").value_or(Vec3::UnitZ());
  const Vec3 ref = feature.vec("ref").value_or(Vec3::UnitX());
  if ((axis - Vec3::UnitZ()).norm() > 1e-9 || (ref - Vec3::UnitX()).norm() > 1e-9 || std::abs(at.x()) > 1e-9 ||
      std::abs(at.y()) > 1e-9) {
    x.report(ws, feature,
             "its lathe toolpaths are in the frame of " + feature.symbol +
                 ", which is turned or off the turning axis: only a frame moved along the axis is supported");
    return false;
  }
  Node moves = makeMoves(ws, tool.symbol, 0, coolant(op), setup);
  moves.set("x_mode", Value::word("diameter"));
  std::optional<std::pair<double, double>> css;  // surface speed, clamp in force
  const LatheTool asGiven;
  LatheWriter w(moves, asGiven);
  bool spindleSet = false;
  for (const Node *tp : op.childrenOf(ir::Kind::Toolpath)) {
    const Node *tech = tp->child(ir::Kind::Technology);
    if (!tech)
      tech = op.child(ir::Kind::Technology);
    const bool rapid = tp->flag("rapid").value_or(false);
    const Node *curve = tp->childIn(ir::Category::Curve);
    if (!curve)
      continue;
    const double perRev = tech ? tech->number("feed_per_rev").value_or(0) : 0;
    if (!rapid && perRev <= 0) {
      x.report(ws, *tp, "its toolpath gives no feed per revolution: a lathe step is fed in mm/rev");
      return false;
    }
    if (tech && !latheSpeedsInRange(x, ws, *tech))
      return false;
    if (tech) {
      if (auto vc = tech->number("cutting_speed"); vc && *vc > 0) {
        const double clamp = tech->number("spindle_max").value_or(0);
        if (clamp <= 0) {
          x.report(ws, *tech, "its constant cutting speed has no maximum spindle speed");
          return false;
        }
        if (!css || css->first != *vc || css->second != clamp) {
          Node state(ir::Kind::State);
          state.set("surface_speed", Value::feed(*vc));
          state.set("spindle_max", Value::spindle(clamp));
          moves.add(std::move(state));
          css = {*vc, clamp};
        }
        if (!spindleSet)
          moves.set("spindle", Value::spindle(-std::abs(clamp)));
        spindleSet = true;
      } else if (auto n = tech->number("spindle"); n && !spindleSet) {
        moves.set("spindle", Value::spindle(*n));
        spindleSet = true;
      }
    }
    const ir::CurveResult cr = ir::curvePieces(*curve, ir::ArcPlanes::Principal);
    if (!cr.error.empty()) {
      x.report(ws, *curve, cr.error);
      return false;
    }
    for (const ir::CurvePiece &c : cr.pieces) {
      const Vec3 from = c.from + at, to = c.to + at;
      if (c.arc && c.turns > 0) {
        x.report(ws, *curve, "its lathe toolpath turns a whole circle about the y axis: not a lathe's move");
        return false;
      }
      if (std::abs(from.y()) > 1e-9 || std::abs(to.y()) > 1e-9 || (c.arc && c.plane.normal != 1)) {
        x.report(ws, *curve, "its lathe toolpath leaves the XZ plane (y " + formatFixed(to.y(), 4) +
                                 " mm): a lathe's moves lie in the plane of the turning axis");
        return false;
      }
      // Points as the file gives them: the writer's tool has no offset.
      const Vec2 a = halfPlane(from), b = halfPlane(to);
      if (!w.positioned() || (w.position() - a).norm() > 1e-6)
        w.rapid(a, "position");
      if (rapid)
        w.rapid(b, "position");
      else if (c.arc)
        w.seg(Seg::arc(a, b, halfPlane(c.center + at), c.ccw), perRev, "cut");
      else
        w.feed(b, perRev, "cut");
    }
  }
  if (!spindleSet) {
    x.report(ws, op, "its operation gives no spindle speed nor cutting speed");
    return false;
  }
  if (!withinMachine(x, ws, feature, moves))
    return false;
  x.attach(ws, std::move(moves));
  return true;
}

/// The lathe stock of `workpiece` as the steps so far left it (at first its raw piece).
Region &latheStock(Expander &x, const Node &workpiece, const ir::TurnStock &raw) {
  auto [it, fresh] = x.turnedStock.try_emplace(workpiece.symbol, Region());
  if (fresh)
    it->second = withMirror(raw.region());
  return it->second;
}

} // namespace

void noteAxialDrilling(Expander &x, const Node &ws) {
  const Node *feature = ir::findFeature(*x.module, ws.text("feature").value_or(""));
  const Node *moves = ws.child(ir::Kind::Moves);
  const Node *tool = moves ? ir::findTool(*x.module, moves->text("tool").value_or("")) : nullptr;
  const Node *workpiece = feature ? ir::workpieceOf(*x.module, *feature) : nullptr;
  const ir::StockResult raw = ir::turnStock(workpiece);
  if (!tool || !raw.stock)
    return;  // not a lathe's workpiece: nothing to follow
  // The drill's point and body from its deepest point out past the bar's end.
  double tip = 1e300;
  for (const ir::Move &m : ir::walkMoves(*moves))
    if (m.kind != ir::MoveKind::Rapid && m.kind != ir::MoveKind::Dwell)
      tip = std::min(tip, m.to.z());
  const double r = tool->number("diameter").value_or(0) / 2;
  if (tip > raw.stock->z1 || r <= 0)
    return;
  const double point = std::min(ir::pointLength(*tool), raw.stock->z1 + 10 - tip);
  const double out = raw.stock->z1 + 10;
  const std::vector<Vec2> outline =
      point > geom::kEps
          ? std::vector<Vec2>{Vec2(tip, 0), Vec2(tip + point, -r), Vec2(out, -r), Vec2(out, r), Vec2(tip + point, r)}
          : std::vector<Vec2>{Vec2(tip, -r), Vec2(out, -r), Vec2(out, r), Vec2(tip, r)};
  Region &stock = latheStock(x, *workpiece, *raw.stock);
  stock = geom::subtract(stock, Region{{geom::polygon(outline)}});
}

bool expandTurning(Expander &x, Node &ws, const Node &op, const std::string &setup) {
  const Node *feature = ir::findFeature(*x.module, ws.text("feature").value_or(""));
  const Node *tool = ir::findTool(*x.module, op.text("tool").value_or(""));
  if (!feature || !tool)
    return false;  // the IR verifier reports dangling references
  if (!op.childrenOf(ir::Kind::Toolpath).empty())
    return expandLatheToolpaths(x, ws, op, *feature, *tool, setup);
  const Node *workpiece = ir::workpieceOf(*x.module, *feature);
  const ir::StockResult raw = ir::turnStock(workpiece);
  if (!raw.stock) {
    x.report(ws, *feature, raw.error);
    return false;
  }
  const ir::TurnedShapeResult shape = ir::turnedShape(*feature, *raw.stock);
  if (!shape.shape) {
    x.report(ws, *feature, shape.error);
    return false;
  }
  noteUnfollowed(x, ws, op);
  Node moves = makeMoves(ws, tool->symbol, 0, coolant(op), setup);
  TurningStep step(x, ws, op, *feature, *tool, latheStock(x, *workpiece, *raw.stock), *raw.stock, *shape.shape,
                   moves);
  if (!step.run() || !withinMachine(x, ws, *feature, moves))
    return false;
  x.attach(ws, std::move(moves));
  return true;
}

} // namespace stepnc::passes::expand
