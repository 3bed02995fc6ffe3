// Flank milling (5-axis): a side finishing operation whose tool direction
// varies (ISO 14649-11 five_axes_var_tilt_yaw) finishes the walls of the
// bosses standing on a planar face in one pass each, the side of a flat end
// mill laid along the wall's rulings instead of levels with the tool along z.
// A boss whose walls lean in (ISO 14649-10 boss.slope) has a ruled wall: the
// foot outline shrunk by (z - foot) tan(slope) at every height, planes on its
// straight sides, a cone on its arcs; a vertical boss is the slope 0 case.
//
// At a foot point p with outward normal n (in the plane) a wall leaning by
// alpha has the outward normal N = (cos(alpha) n, sin(alpha)) and its ruling
// up the wall is a = (-sin(alpha) n, cos(alpha)): the tool axis. The tool's
// side touches the wall along the ruling when its tip stands at
// p + (R + allowance) N, and its bottom face's lowest point is then
// p + allowance N: at the foot, never below it. Round a corner of the outline
// the tool turns about the corner's edge through the planes that hold it
// (N turning from one side's normal to the next, a the steepest line of each),
// touching nothing but the edge. On arcs and round corners the tool's tip
// goes along a polygon outside its circle (the chords touch it), so that the
// tool stands off the wall between its poses by at most the chord tolerance
// and never cuts into it.
//
// Only what this reaches is taken: bosses on a planar face (the face's own
// walls would need finishing too), outlines that turn one way (a corner
// turning into the boss has no ruled tool position), flat end mills whose
// cutting edge covers the wall's slant height.
#include "passes/expand/Expand.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>

namespace stepnc::passes::expand {

namespace {

struct Pose {
  Vec3 tip = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  Vec3 normal = Vec3::UnitX();  ///< the wall's outward normal it stands off along
};

/// The wall's outward normal at a foot point with outward normal `n` in the plane.
Vec3 wallNormal(const Vec2 &n, double cosA, double sinA) { return {cosA * n.x(), cosA * n.y(), sinA}; }

/// The steepest direction up the plane whose normal is N: the tool axis laid along it.
Vec3 ruling(const Vec3 &N) { return (Vec3::UnitZ() - N.z() * N).normalized(); }

/// The outward normal in the plane of a counter-clockwise outline at a point
/// whose direction of travel is `t`.
Vec2 outward(const Vec2 &t) { return {t.y(), -t.x()}; }

/// `n` unit vectors turning evenly from u to w (unit, not opposite) at
/// fractions (j - 1/2)/n, j = 1..n: the middles of n equal steps.
std::vector<Vec3> middles(const Vec3 &u, const Vec3 &w, int n) {
  const double angle = std::acos(std::clamp(u.dot(w), -1.0, 1.0));
  std::vector<Vec3> out;
  const Vec3 perp = (w - u.dot(w) * u).normalized();
  for (int j = 1; j <= n; ++j) {
    const double t = angle * (j - 0.5) / n;
    out.push_back(std::cos(t) * u + std::sin(t) * perp);
  }
  return out;
}

/// Steps of a turn by `angle` (rad) about a point at `radius` whose chords
/// stay within `tolerance` of the circle: at least 1.
int turnSteps(double angle, double radius, double tolerance) {
  const double step = 2 * std::acos(std::clamp(1 - tolerance / std::max(radius, tolerance), -1.0, 1.0));
  return std::max(1, static_cast<int>(std::ceil(angle / std::max(step, 1e-3) - 1e-9)));
}

class Flank {
public:
  Flank(Expander &x, const Step &step) : x_(x), step_(step), p_(step.plan) {}

  bool run() {
    const ir::FeatureShape &s = *step_.shape;
    const Node &ws = step_.ws;
    if (step_.op.kind != ir::Kind::SideFinishMilling) {
      x_.report(ws, step_.op, step_.op.kindName() + " with a tool direction that varies: stepnc flank-mills the "
                                                    "walls of bosses with it, which side finishing asks for");
      return false;
    }
    if (!s.unbounded || s.islands.empty() || s.section) {
      x_.report(ws, "flank milling finishes the walls of the bosses standing on a planar face; " + s.symbol +
                        " is a " + s.kindName() + (s.islands.empty() ? " with no boss" : ", whose own walls it "
                                                                                       "would leave"));
      return false;
    }
    if (!tool())
      return false;
    Emitter e(step_.moves, step_.moves.number("secplane").value_or(0));
    secplane_ = e.secplane();
    std::optional<Vec2> facing;
    for (const ir::IslandShape &isl : s.islands) {
      std::optional<std::vector<Pose>> poses = around(isl, facing);
      if (!poses)
        return false;
      cut(*poses);
      facing = Vec2(poses->front().normal.x(), poses->front().normal.y()).normalized();
    }
    return true;
  }

private:
  /// The tool is a flat end mill whose cutting edge covers every wall.
  bool tool() {
    const Node &t = *p_.tool;
    const std::string type = t.text("type").value_or("");
    if ((type != "endmill" && type != "facemill") || t.number("corner_radius").value_or(0) > 1e-9) {
      x_.report(step_.ws, "flank milling lays the side of a flat end mill along the walls; tool " + t.symbol +
                              " is a " + type +
                              (t.number("corner_radius") ? " with a corner radius of " +
                                                               formatShortest(*t.number("corner_radius")) + " mm"
                                                         : std::string()));
      return false;
    }
    edge_ = t.number("cutting_edge_length");
    return true;
  }

  /// The tool's poses once round island `isl` in the direction that climbs
  /// (or as the strategy's cut mode says), from the middle of a side back to
  /// it: the side whose wall faces most nearly `facing` (the way the boss
  /// before ended: the tool between them then turns least, and never
  /// through upright, where a machine's table or fork would have to swing
  /// half a turn), else the longest; nullopt after reporting.
  std::optional<std::vector<Pose>> around(const ir::IslandShape &isl, const std::optional<Vec2> &facing) {
    const Node &ws = step_.ws;
    if (isl.region.loops.size() != 1) {
      x_.report(ws, "flank milling takes a boss whose outline is one loop; " + isl.symbol + " has " +
                        std::to_string(isl.region.loops.size()));
      return std::nullopt;
    }
    geom::Loop loop = isl.region.loops.front();
    if (loop.area() < 0)
      loop.reverse();
    const double alpha = std::atan(isl.slope);
    cos_ = std::cos(alpha);
    sin_ = std::sin(alpha);
    const double height = isl.top - isl.foot;
    const double slant = height / cos_;
    if (edge_ && *edge_ < slant - 1e-9) {
      x_.report(ws, "the walls of " + isl.symbol + " are " + formatFixed(slant, 4) +
                        " mm from foot to top along the tool, longer than the cutting edge of " + p_.tool->symbol +
                        " (" + formatShortest(*edge_) + " mm): flank milling cuts them in one pass");
      return std::nullopt;
    }
    if (!edge_ && !warnedEdge_) {
      warnedEdge_ = true;
      x_.assumed(ws, *p_.tool,
                 "tool " + p_.tool->symbol + " gives no cutting_edge_length: assumed to cover the walls it "
                 "flank-mills (" + formatFixed(slant, 4) + " mm along the tool on " + isl.symbol + ")");
    }
    reach_ = p_.radius + p_.allowanceSide;
    foot_ = isl.foot;
    // Start in the middle of the side facing the way the boss before ended,
    // else of the longest.
    size_t first = 0;
    auto facingOf = [&](size_t k) { return facing ? outward(loop.segs[k].tangent(0.5)).dot(*facing) : 0.0; };
    for (size_t k = 1; k < loop.segs.size(); ++k) {
      const double better = facingOf(k) - facingOf(first);
      if (better > 1e-9 || (better > -1e-9 && loop.segs[k].length() > loop.segs[first].length() + 1e-9))
        first = k;
    }
    std::vector<Pose> poses;
    const size_t count = loop.segs.size();
    for (size_t k = 0; k <= count; ++k) {
      const Seg &seg = loop.segs[(first + k) % count];
      const bool head = k == 0, tail = k == count;
      const Seg part = head ? Seg{seg.at(0.5), seg.b, seg.c, seg.turn} : tail ? Seg{seg.a, seg.at(0.5), seg.c, seg.turn}
                                                                         : seg;
      if (!head && !corner(loop.segs[(first + k + count - 1) % count], seg, isl, poses))
        return std::nullopt;
      if (!along(part, isl, poses))
        return std::nullopt;
    }
    const Node *strategy = step_.strategy;
    const std::string cutmode = strategy ? strategy->text("cutmode").value_or("climb") : "climb";
    // Round a boss with the spindle clockwise (M3) the tool climbs going
    // clockwise: the wall on its right.
    const bool ccw = (cutmode == "conventional") == (p_.spindle <= 0);
    if (!ccw)
      std::reverse(poses.begin(), poses.end());
    return poses;
  }

  Pose at(const Vec2 &foot, const Vec3 &N, double reach) const {
    return {Vec3(foot.x(), foot.y(), foot_) + reach * N, ruling(N), N};
  }

  /// Adds a pose unless it is the last one again (where sides meet smoothly).
  static void push(std::vector<Pose> &poses, const Pose &p) {
    if (poses.empty() || (poses.back().tip - p.tip).norm() > 1e-9 || (poses.back().axis - p.axis).norm() > 1e-12)
      poses.push_back(p);
  }

  /// Poses along side `s` of the outline, from its start to its end.
  bool along(const Seg &s, const ir::IslandShape &isl, std::vector<Pose> &poses) {
    if (!s.isArc()) {
      const Vec3 N = wallNormal(outward(s.tangent(0)), cos_, sin_);
      push(poses, at(s.a, N, reach_));
      push(poses, at(s.b, N, reach_));
      return true;
    }
    if (s.turn < 0) {
      x_.report(step_.ws, "flank milling takes a boss whose outline turns one way; " + isl.symbol +
                              " has an arc turning into it about " +
                              formatTuple({s.c.x(), s.c.y()}, 4) + " mm, where no ruled tool position fits");
      return false;
    }
    const double r = s.radius();
    const Vec3 u = wallNormal((s.a - s.c) / r, cos_, sin_), w = wallNormal((s.b - s.c) / r, cos_, sin_);
    push(poses, at(s.a, u, reach_));
    // The tip goes round a circle of r + reach cos(alpha) about the centre.
    const int n = turnSteps(std::abs(s.sweep()), r + reach_ * cos_, x_.chordTolerance);
    const double out = 1 / std::cos(std::abs(s.sweep()) / n / 2);
    const double sweep = s.sweep();
    for (int j = 1; j <= n; ++j) {
      const double t = sweep * (j - 0.5) / n;
      const Vec2 from = (s.a - s.c) / r;
      const Vec2 radial(std::cos(t) * from.x() - std::sin(t) * from.y(), std::sin(t) * from.x() + std::cos(t) * from.y());
      const Vec3 N = wallNormal(radial, cos_, sin_);
      // Out along the plane's radial, so that the chords touch the tip's circle.
      const Vec2 tipXY = s.c + (r + reach_ * cos_) * out * radial;
      poses.push_back({Vec3(tipXY.x(), tipXY.y(), foot_ + reach_ * sin_), ruling(N), N});
    }
    push(poses, at(s.b, w, reach_));
    return true;
  }

  /// The turn about the corner where `before` ends and `after` starts.
  bool corner(const Seg &before, const Seg &after, const ir::IslandShape &isl, std::vector<Pose> &poses) {
    const Vec2 t1 = before.tangent(1), t2 = after.tangent(0);
    const double cross = t1.x() * t2.y() - t1.y() * t2.x();
    if (t1.dot(t2) > 1 - 1e-12)
      return true;  // tangent: no corner
    if (cross < 0) {
      x_.report(step_.ws, "flank milling takes a boss whose outline turns one way; " + isl.symbol +
                              " has a corner turning into it at " +
                              formatTuple({after.a.x(), after.a.y()}, 4) + " mm, where no ruled tool position fits");
      return false;
    }
    const Vec3 u = wallNormal(outward(t1), cos_, sin_), w = wallNormal(outward(t2), cos_, sin_);
    const double angle = std::acos(std::clamp(u.dot(w), -1.0, 1.0));
    const int n = turnSteps(angle, reach_, x_.chordTolerance);
    const double out = 1 / std::cos(angle / n / 2);
    for (const Vec3 &N : middles(u, w, n))
      poses.push_back(at(after.a, N, reach_ * out));
    return true;
  }

  Node move(ir::Kind kind, const Vec3 &to, const Vec3 &axis, const char *role, double feed = 0) {
    return Emitter::tilted(kind == ir::Kind::Rapid ? Emitter::rapidNode(to, role) : Emitter::linearNode(to, feed, role),
                           axis);
  }

  /// Down to the first pose from off the wall, round, and back out and up.
  void cut(const std::vector<Pose> &poses) {
    Node &moves = step_.moves;
    const Pose &start = poses.front(), &end = poses.back();
    // Off the wall along its normal by a lead, where the tool stands clear.
    const Vec3 in = start.tip + kLead * start.normal, out = end.tip + kLead * end.normal;
    moves.add(move(ir::Kind::Rapid, Emitter::alongAxisTo(in, start.axis, secplane_), start.axis, "position"));
    if (p_.clearanceZ > in.z())
      moves.add(move(ir::Kind::Rapid, Emitter::alongAxisTo(in, start.axis, p_.clearanceZ), start.axis, "approach"));
    moves.add(move(ir::Kind::Linear, in, start.axis, "plunge", p_.plungeFeed));
    moves.add(move(ir::Kind::Linear, start.tip, start.axis, "approach", p_.feed));
    for (size_t k = 1; k < poses.size(); ++k)
      moves.add(move(ir::Kind::Linear, poses[k].tip, poses[k].axis, "cut", p_.feed));
    moves.add(move(ir::Kind::Linear, out, end.axis, "retract", p_.feed));
    moves.add(move(ir::Kind::Rapid, Emitter::alongAxisTo(out, end.axis, secplane_), end.axis, "retract"));
  }

  /// mm the tool starts and ends off the wall, along its normal.
  static constexpr double kLead = 2.0;

  Expander &x_;
  const Step &step_;
  const Plan &p_;
  double secplane_ = 0;
  std::optional<double> edge_;
  bool warnedEdge_ = false;
  double cos_ = 1, sin_ = 0, reach_ = 0, foot_ = 0;
};

} // namespace

bool expandFlankMilling(Expander &x, const Step &step) {
  const std::string direction = step.op.text("tool_direction").value_or("");
  if (direction != "varying") {
    x.report(step.ws, step.op,
             "tool direction " + direction + " (ISO 14649-11 " +
                 (direction == "tilted" ? "three_axes_tilted_tool" : "five_axes_const_tilt_yaw") +
                 ") is not supported: stepnc tilts the tool for flank milling (five_axes_var_tilt_yaw)");
    return false;
  }
  return Flank(x, step).run();
}

} // namespace stepnc::passes::expand
