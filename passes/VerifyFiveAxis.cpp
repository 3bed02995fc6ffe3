#include "passes/VerifyFiveAxis.h"

#include "ir/Plausible.h"
#include "ir/Program.h"
#include "ir/geom/MoveWalk.h"
#include "passes/FeatureWalls.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace stepnc::passes {

namespace {

using ir::Vec3;
using geom::Vec2;

/// mm between the poses sampled along a move, and deg the axis turns between them.
constexpr double kPoseStep = 0.05;
constexpr double kPoseTurn = 0.25;
/// mm between the points sampled on a wall, along it and up it.
constexpr double kWallStep = 0.25;
/// deg: a move at feed that turns the axis this far flips it.
constexpr double kFlip = 90;
/// deg and mm: an axis held, a rapid along it (what the IR's text form
/// rounds: directions to 6 decimals, points to 4).
constexpr double kHeld = 1e-3;
constexpr double kOnAxis = 1e-3;
/// mm: the side of the cells poses are indexed by.
constexpr double kCell = 2.0;

/// The tool as a body: radius, corner radius, the length of its cutting edge.
struct Body {
  double radius = 0, corner = 0, length = 0;

  /// Signed distance from p to the body standing at `tip` along `axis`
  /// (negative inside): in the tool's own (radial, height) half plane, the
  /// union of the core below the corner, the cylinder above it and the
  /// corner's circle.
  double distance(const Vec3 &tip, const Vec3 &axis, const Vec3 &p) const {
    const Vec3 d = p - tip;
    const double h = d.dot(axis);
    const double r = (d - h * axis).norm();
    const double core = box(r, h, radius - corner, 0, length);
    const double above = box(r, h, radius, corner, length);
    const double ring = std::hypot(r - (radius - corner), h - corner) - corner;
    return std::min({core, above, ring});
  }

  /// The height of the body's lowest point: through its corner, the tip
  /// tilted by the axis.
  double lowest(const Vec3 &tip, const Vec3 &axis) const {
    const double az = std::clamp(axis.z(), -1.0, 1.0);
    return tip.z() + corner * az - corner - (radius - corner) * std::sqrt(std::max(0.0, 1 - az * az));
  }

private:
  /// Signed distance to the rectangle |r| <= half, lo <= h <= hi.
  static double box(double r, double h, double half, double lo, double hi) {
    const double qx = std::abs(r) - half;
    const double mid = (lo + hi) / 2, qy = std::abs(h - mid) - (hi - lo) / 2;
    const double outside = std::hypot(std::max(qx, 0.0), std::max(qy, 0.0));
    return outside + std::min(std::max(qx, qy), 0.0);
  }
};

struct Pose {
  Vec3 tip, axis;
};

/// A point of a wall and what it belongs to.
struct WallPoint {
  Vec3 at;
  size_t island;
};

/// The poses of the tool, indexed by the cells of the plane its body spans
/// (below `zTop`, where the walls are).
class PoseIndex {
public:
  PoseIndex(const std::vector<Pose> &poses, const Body &body, double zTop) : poses_(poses) {
    for (uint32_t k = 0; k < poses.size(); ++k) {
      const Pose &p = poses[k];
      // The part of the body's axis below zTop (the whole of it when the
      // tool lies flat or points down).
      double reach = body.length;
      if (p.axis.z() > 1e-9)
        reach = std::clamp((zTop + body.radius - p.tip.z()) / p.axis.z(), 0.0, body.length);
      const Vec3 top = p.tip + reach * p.axis;
      const double lo[2] = {std::min(p.tip.x(), top.x()) - body.radius, std::min(p.tip.y(), top.y()) - body.radius};
      const double hi[2] = {std::max(p.tip.x(), top.x()) + body.radius, std::max(p.tip.y(), top.y()) + body.radius};
      for (int64_t i = cell(lo[0]); i <= cell(hi[0]); ++i)
        for (int64_t j = cell(lo[1]); j <= cell(hi[1]); ++j)
          cells_[key(i, j)].push_back(k);
    }
  }

  /// The poses whose body may come near p.
  const std::vector<uint32_t> &near(const Vec3 &p) const {
    static const std::vector<uint32_t> none;
    const auto it = cells_.find(key(cell(p.x()), cell(p.y())));
    return it == cells_.end() ? none : it->second;
  }

  const Pose &operator[](uint32_t k) const { return poses_[k]; }

private:
  static int64_t cell(double v) { return static_cast<int64_t>(std::floor(v / kCell)); }
  static uint64_t key(int64_t i, int64_t j) { return (uint64_t(uint32_t(i)) << 32) | uint32_t(j); }

  const std::vector<Pose> &poses_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
};

/// Points along a wall piece every kWallStep, its start included.
void sampleOutline(const Outline &o, double z, size_t island, std::vector<WallPoint> &out) {
  for (const WallPiece &w : o.pieces) {
    const double length = w.arc ? w.radius * std::abs(w.sweep) : (w.b - w.a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(length / kWallStep)));
    for (int k = 0; k < n; ++k) {
      const double t = double(k) / n;
      Vec2 p;
      if (w.arc) {
        const Vec2 u = w.a - w.centre;
        const double a = w.sweep * t;
        p = w.centre + Vec2(u.x() * std::cos(a) - u.y() * std::sin(a), u.x() * std::sin(a) + u.y() * std::cos(a));
      } else {
        p = w.a + t * (w.b - w.a);
      }
      out.push_back({Vec3(p.x(), p.y(), z), island});
    }
  }
}

class Checker {
public:
  Checker(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats, std::optional<double> tolerance,
          std::vector<std::string> *reports)
      : module_(module), diags_(diags), stats_(stats), tolerance_(tolerance), reports_(reports) {}

  bool run() {
    const unsigned before = diags_.errorCount();
    for (const ir::Node *e : ir::programOrder(module_))
      if (ir::tiltsTool(*e))
        check(*e);
    return diags_.errorCount() == before;
  }

private:
  void check(const ir::Node &exec) {
    const ir::Node &moves = *exec.child(ir::Kind::Moves);
    const std::string name = exec.kindName() + " " + exec.symbol;
    const ir::Node *tool = ir::findTool(module_, moves.text("tool").value_or(""));
    const ir::Node *feature = exec.has("feature") ? ir::findFeature(module_, *exec.text("feature")) : nullptr;
    const ir::Node *op = ir::operationOf(exec);
    double tol = tolerance_.value_or(ir::kDefaultTolerance);
    if (!tolerance_ && feature)
      if (const ir::Node *wp = ir::workpieceOf(module_, *feature))
        tol = wp->number("global_tolerance").value_or(tol);
    if (!tool || !(tool->number("diameter").value_or(0) > 0)) {
      notVerified(exec, name + ": not verified: its tool has no diameter");
      return;
    }
    Body body;
    body.radius = *tool->number("diameter") / 2;
    body.corner = std::clamp(tool->number("corner_radius").value_or(tool->text("type") == "ball_endmill" ? body.radius
                                                                                                         : 0.0),
                             0.0, body.radius);
    body.length = tool->number("cutting_edge_length").value_or(tool->number("overall_length").value_or(100.0));

    // The moves, their safety and the axis's turns; the poses along them.
    const double secplane = moves.number("secplane").value_or(0);
    std::optional<FeatureWalls> walls;
    std::string why;
    if (feature)
      walls = FeatureWalls::read(module_, *feature, why);
    // The feature's top: as the walls read it, else its placement's height
    // (a toolpath feature), else the security plane.
    const double top = walls ? walls->top()
                             : feature && feature->vec("at") ? feature->vec("at")->z() : secplane;
    std::vector<Pose> poses;
    double turned = 0;
    for (const ir::Move &m : ir::walkMoves(moves, std::nullopt, ir::PathKind::Predicted)) {
      if (!m.from || m.kind == ir::MoveKind::Dwell)
        continue;
      const double turn = ir::angleBetween(m.fromAxis, m.axis);
      if (m.isFeed())
        turned = std::max(turned, turn);
      if (m.kind == ir::MoveKind::Rapid)
        checkRapid(exec, name, m, secplane, top, tol);
      else if (turn >= kFlip)
        error(exec, m, name + ": the tool axis turns " + formatFixed(turn, 4) +
                           " deg in one move at feed, from " + axisText(m.fromAxis) + " to " + axisText(m.axis) +
                           ": a flip, not a cut");
      sample(m, poses);
    }

    std::string figures = name + ": " + std::to_string(poses.size()) + " poses, the axis turned up to " +
                          formatFixed(turned, 4) + " deg per move at feed";
    if (!walls) {
      notVerified(exec, name + ": walls and floor not verified: " + (feature ? why : "it names no feature"));
      report(figures);
      return;
    }
    if (walls->hasOwnWalls())
      notVerified(exec, name + ": the walls of " + feature->symbol +
                            " itself not verified against a tool that leans (its islands' walls are)");

    // The floor.
    const double floorZ = walls->top() - feature->number("depth").value_or(0) +
                          (op ? op->number("allowance_bottom").value_or(0) : 0);
    double lowest = 1e300;
    const Pose *lowestPose = nullptr;
    for (const Pose &p : poses) {
      const double z = body.lowest(p.tip, p.axis);
      if (z < lowest) {
        lowest = z;
        lowestPose = &p;
      }
    }
    if (lowestPose && lowest < floorZ - tol)
      error(exec, name + ": the tool goes " + formatFixed(floorZ - lowest, 4) + " mm below the floor of " +
                      feature->symbol + " (z=" + formatFixed(floorZ, 4) + " mm with the bottom allowance) with its tip at " +
                      pointText(lowestPose->tip) + " and its axis " + axisText(lowestPose->axis));

    // The walls.
    const std::vector<FeatureWalls::Island> &islands = walls->islands();
    std::vector<WallPoint> points;
    double zTop = -1e300;
    for (size_t i = 0; i < islands.size(); ++i) {
      const FeatureWalls::Island &isl = islands[i];
      zTop = std::max(zTop, isl.top);
      const int n = std::max(2, static_cast<int>(std::ceil((isl.top - isl.foot) / kWallStep)));
      for (int k = 0; k <= n; ++k) {
        const double z = isl.foot + (isl.top - isl.foot) * k / n;
        sampleOutline(isl.sectionAt(z), z, i, points);
      }
    }
    const double allowance = op ? op->number("allowance_side").value_or(0) : 0;
    const bool finishes = op && op->is(ir::Trait::WallFinishing);
    const PoseIndex index(poses, body, zTop);
    double deepest = -1e300, widest = -1e300;
    const WallPoint *deepAt = nullptr, *wideAt = nullptr;
    size_t uncut = 0;
    for (const WallPoint &w : points) {
      double d = 1e300;
      for (const uint32_t k : index.near(w.at))
        d = std::min(d, body.distance(index[k].tip, index[k].axis, w.at));
      // How far the tool reaches past the allowance (a gouge), and how far
      // short of it it stays (uncut wall).
      if (allowance - d > deepest) {
        deepest = allowance - d;
        deepAt = &w;
      }
      if (d - allowance > widest) {
        widest = d - allowance;
        wideAt = &w;
      }
      uncut += d - allowance > tol;
    }
    if (deepAt && deepest > tol)
      error(exec, name + ": the tool reaches " + formatFixed(deepest, 4) + " mm into the wall of island " +
                      islands[deepAt->island].symbol + (allowance > 0 ? " past its allowance" : "") + " at " +
                      pointText(deepAt->at));
    if (finishes && wideAt && uncut > 0)
      error(exec, name + ": " + std::to_string(uncut) + " of " + std::to_string(points.size()) +
                      " points on the walls left uncut, up to " + formatFixed(widest, 4) + " mm beyond the allowance, at " +
                      pointText(wideAt->at) + " on island " + islands[wideAt->island].symbol);
    figures += "; walls of " + std::to_string(islands.size()) + " islands at " + std::to_string(points.size()) +
               " points: deepest " + formatFixed(std::max(deepest, 0.0), 4) + " mm, largest uncut " +
               (finishes ? formatFixed(std::max(widest, 0.0), 4) + " mm" : std::string("not checked (roughing)")) +
               "; lowest point " + formatFixed(lowest - floorZ, 4) + " mm above the floor";
    ++stats_["tilted workingsteps verified"];
    report(figures);
  }

  /// A rapid runs at or above the security plane, or along the held axis
  /// (down no lower than the feature's top); it turns the tool only above.
  void checkRapid(const ir::Node &exec, const std::string &name, const ir::Move &m, double secplane, double top,
                  double tol) {
    const Vec3 from = *m.from;
    const bool above = std::min(from.z(), m.to.z()) >= secplane - tol;
    const bool held = ir::angleBetween(m.fromAxis, m.axis) <= kHeld;
    if (!held && !above) {
      error(exec, m, name + ": a rapid turns the tool from " + axisText(m.fromAxis) + " to " + axisText(m.axis) +
                         " below the security plane z=" + formatFixed(secplane, 4) + " mm");
      return;
    }
    if (above)
      return;
    const Vec3 d = m.to - from;
    const bool alongAxis = d.cross(m.axis).norm() <= kOnAxis;
    if (!alongAxis) {
      error(exec, m, name + ": a rapid to " + pointText(m.to) + " below the security plane z=" +
                         formatFixed(secplane, 4) + " mm and not along the tool axis " + axisText(m.axis));
      return;
    }
    if (d.dot(m.axis) < 0 && m.to.z() < top - tol)
      error(exec, m, name + ": a rapid down the tool axis to " + pointText(m.to) + ", below the feature's top z=" +
                         formatFixed(top, 4) + " mm");
  }

  /// Poses along a move, the tip along its path and the axis turning evenly.
  static void sample(const ir::Move &m, std::vector<Pose> &poses) {
    const std::vector<Vec3> points = m.kind == ir::MoveKind::Arc ? m.chordPoints(kPoseStep / 10) : std::vector<Vec3>{*m.from, m.to};
    double total = 0;
    for (size_t k = 1; k < points.size(); ++k)
      total += (points[k] - points[k - 1]).norm();
    const double turn = ir::angleBetween(m.fromAxis, m.axis);
    double done = 0;
    for (size_t k = 1; k < points.size(); ++k) {
      const double length = (points[k] - points[k - 1]).norm();
      const int n = std::max({1, static_cast<int>(std::ceil(length / kPoseStep)),
                              static_cast<int>(std::ceil(turn / kPoseTurn))});
      for (int j = poses.empty() ? 0 : 1; j <= n; ++j) {
        const double s = done + length * j / n;
        const double t = total > 0 ? s / total : double(j) / n;
        poses.push_back({points[k - 1] + (points[k] - points[k - 1]) * (double(j) / n), ir::turnAxis(m.fromAxis, m.axis, t)});
      }
      done += length;
    }
  }

  static std::string pointText(const Vec3 &p) { return formatTuple({p.x(), p.y(), p.z()}, 4) + " mm"; }
  static std::string axisText(const Vec3 &a) { return formatTuple({a.x(), a.y(), a.z()}, 6); }

  void error(const ir::Node &exec, const std::string &message) {
    diags_.error(exec.origin.loc, message).entity(exec.origin.entityId);
  }
  void error(const ir::Node &exec, const ir::Move &m, const std::string &message) {
    const ir::Origin &o = m.node && m.node->origin.loc.valid() ? m.node->origin : exec.origin;
    diags_.error(o.loc, message).entity(o.entityId ? o.entityId : exec.origin.entityId);
  }
  void notVerified(const ir::Node &exec, const std::string &message) {
    diags_.warning(exec.origin.loc, message).entity(exec.origin.entityId);
    ++stats_["tilted workingsteps not verified"];
  }
  void report(const std::string &line) {
    if (reports_)
      reports_->push_back(line);
  }

  const ir::Module &module_;
  DiagnosticEngine &diags_;
  PassStats &stats_;
  std::optional<double> tolerance_;
  std::vector<std::string> *reports_;
};

} // namespace

bool verifyFiveAxis(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                    std::optional<double> tolerance, std::vector<std::string> *reports) {
  return Checker(module, diags, stats, tolerance, reports).run();
}

} // namespace stepnc::passes
