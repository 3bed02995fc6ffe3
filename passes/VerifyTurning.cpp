// The lathe half of verify-toolpaths (see VerifyTurning.h).
//
// Everything happens in the half plane of the turning axis, points (z, r).
// The part is the raw piece less what every turned feature of its workpiece
// removes; the stock starts as the raw piece and loses what each feed move's
// insert sweeps. The insert is a convex skeleton grown by its corner
// radius: a turning insert's nose circle with its two cutting edges (the
// side edge leaning from the radial direction by the side edge angle, the
// end edge rising from the axis direction by the end edge angle, both as
// long as the cutting edge); a grooving insert's two corners a cutting
// width apart and its sides. The holder is not modelled. A tool past the
// axis (r < 0) meets what lies at -r: the section of a body of revolution
// is symmetric, so sweeps are mirrored before they meet the stock.
//
// Moves are read as written: their points are the chuck-side corner's
// imaginary tip (docs/turning.md), the corner's centre a corner radius
// further out in z and r; inside a bore (an inner turned shape) further out
// in z and in towards the axis in r, the insert's edges reaching in too.
#include "passes/VerifyTurning.h"

#include "geom/Boolean.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "ir/geom/TurnedShape.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace stepnc::passes {

namespace {

using geom::Loop;
using geom::Region;
using geom::Seg;
using geom::Vec2;
using ir::Node;

constexpr double kDegree = std::numbers::pi / 180;
/// Edge length of an insert whose tool gives none (mm).
constexpr double kDefaultEdge = 5.0;

Vec2 halfPlane(const ir::Vec3 &p) { return {p.z(), p.x()}; }

/// What a region swept in the half plane takes from material on both sides of the axis.
Region folded(const Region &r) {
  if (r.empty() || r.box().lo.y() >= 0)
    return r;  // nothing past the axis
  return geom::unite(r, geom::mirroredAcrossX(r));
}

/// Material thicker than `t` somewhere in `r`: a loop whose mean width
/// (twice its area over its perimeter) is more than a quarter of `t` (the
/// slivers Booleans leave along a shared edge are far thinner), and that
/// keeps something when shrunk by t/2.
bool thick(const Region &r, double t) {
  bool wide = false;
  for (const Loop &l : r.loops) {
    double perimeter = 0;
    for (const Seg &s : l.segs)
      perimeter += s.length();
    wide = wide || (perimeter > 0 && 2 * std::abs(l.area()) / perimeter > t / 4);
  }
  return wide && !geom::offset(r, -t / 2).empty();
}

/// Where a region lies, as a programmer finds it: each of its separate
/// pieces as its extent in z and r (the first three along the axis, then
/// how many more), not one box over all of them.
std::string where(const Region &r) {
  auto extent = [](const geom::Box &b) {
    return "z " + formatFixed(b.lo.x(), 3) + ".." + formatFixed(b.hi.x(), 3) + ", r " +
           formatFixed(std::max(b.lo.y(), 0.0), 3) + ".." + formatFixed(b.hi.y(), 3) + " mm";
  };
  std::vector<geom::Box> pieces;
  for (const geom::Loop &l : r.loops)
    if (l.area() > 1e-9)  // an outer boundary (holes run the other way)
      pieces.push_back(Region{{l}}.box());
  if (pieces.size() <= 1)
    return extent(r.box());
  std::sort(pieces.begin(), pieces.end(), [](const geom::Box &a, const geom::Box &b) {
    return a.lo.x() != b.lo.x() ? a.lo.x() < b.lo.x() : a.lo.y() < b.lo.y();
  });
  constexpr size_t kShown = 3;
  std::string out;
  for (size_t i = 0; i < pieces.size() && i < kShown; ++i)
    out += (i == 0 ? "" : i + 1 == std::min(pieces.size(), kShown) && pieces.size() <= kShown ? " and " : "; ") +
           extent(pieces[i]);
  if (pieces.size() > kShown)
    out += " and " + std::to_string(pieces.size() - kShown) + " more places";
  return out;
}

struct Insert {
  std::vector<Vec2> skeleton;  ///< relative to the chuck-side corner's centre
  double rc = 0;
  /// From the point moves program to that centre: the corner's imaginary
  /// tip (turning, grooving) or the point of a threading insert's V.
  Vec2 tipToCentre = Vec2::Zero();

  /// The area the insert covers moving from `a` to `b` (corner centres).
  Region sweep(const Vec2 &a, const Vec2 &b) const {
    std::vector<Vec2> pts;
    for (const Vec2 &s : skeleton) {
      pts.push_back(a + s);
      pts.push_back(b + s);
    }
    const std::vector<Vec2> h = geom::convexHull(pts);
    std::vector<Seg> edges;
    Region body;
    if (h.size() >= 3) {
      body = Region{{geom::polygon(h)}};
      for (size_t i = 0; i < h.size(); ++i)
        edges.push_back(Seg::line(h[i], h[(i + 1) % h.size()]));
    } else if (h.size() == 2) {
      edges.push_back(Seg::line(h[0], h[1]));
    } else if (!h.empty()) {
      edges.push_back(Seg::line(h[0], h[0] + Vec2(1e-9, 0)));
    }
    if (rc <= 0)
      return body;
    const Region rounded = geom::sweptDisc(edges, rc);
    return body.empty() ? rounded : geom::unite(body, rounded);
  }
};

/// The insert of `tool`; `inner`: working an inner surface (a boring bar),
/// its edges reaching in towards the axis from the corner and its imaginary
/// tip on the corner's side away from it.
Insert insertOf(const Node &tool, bool inner, bool face) {
  Insert in;
  const std::string type = tool.text("type").value_or("");
  if (type == "knurling_tool") {
    // Its wheels' rim, as wide as its cutting length along the axis,
    // programmed at its chuck-side end; the wheels outwards from it.
    const double w = tool.number("cutting_width").value_or(0);
    in.skeleton = {Vec2(0, 0), Vec2(w, 0), Vec2(w, 2 * kDefaultEdge), Vec2(0, 2 * kDefaultEdge)};
    return in;
  }
  if (type != "turning_tool" && type != "grooving_tool" && type != "threading_tool") {
    // A drill (any axial tool) on the spindle axis, its tip the programmed
    // point: its point cone, then its body as long as its flutes.
    const double r = tool.number("diameter").value_or(0) / 2;
    const double point = ir::pointLength(tool);
    const double body = tool.number("cutting_edge_length").value_or(std::max(3 * 2 * r, point + 1));
    in.skeleton = {Vec2(0, 0), Vec2(point, -r), Vec2(body, -r), Vec2(body, r), Vec2(point, r)};
    return in;
  }
  in.rc = tool.number("corner_radius").value_or(0);
  const double edge =
      tool.number("cutting_edge_length").value_or(tool.number("max_cutting_depth").value_or(kDefaultEdge));
  in.tipToCentre = Vec2(in.rc, in.rc);
  if (tool.text("type") == "threading_tool") {
    // A V of the thread's angle pointing at the axis, as deep as the tool cuts.
    const double half = tool.number("thread_angle").value_or(60) * kDegree / 2;
    const double depth = tool.number("max_cutting_depth").value_or(kDefaultEdge);
    in.skeleton = {Vec2(0, 0), Vec2(-std::tan(half), 1) * depth, Vec2(std::tan(half), 1) * depth};
    in.tipToCentre = Vec2(0, in.rc);
  } else if (tool.text("type") == "grooving_tool") {
    const double w = std::max(tool.number("cutting_width").value_or(2 * in.rc) - 2 * in.rc, 0.0);
    const double depth = tool.number("max_cutting_depth").value_or(kDefaultEdge * 2);
    // Its cutting corners along the axis, its body outwards; a face
    // grooving insert's corners across the axis, its body towards the free end.
    in.skeleton = face ? std::vector<Vec2>{Vec2(0, 0), Vec2(0, w), Vec2(depth, w), Vec2(depth, 0)}
                       : std::vector<Vec2>{Vec2(0, 0), Vec2(w, 0), Vec2(w, depth), Vec2(0, depth)};
  } else {
    const double side = tool.number("side_edge_angle").value_or(0) * kDegree;
    const double end = tool.number("end_edge_angle").value_or(0) * kDegree;
    in.skeleton = {Vec2(0, 0), Vec2(-std::sin(side), std::cos(side)) * edge, Vec2(std::cos(end), std::sin(end)) * edge};
  }
  if (inner) {
    for (Vec2 &p : in.skeleton)
      p.y() = -p.y();
    in.tipToCentre.y() = -in.tipToCentre.y();
  }
  return in;
}

struct Workpiece {
  ir::TurnStock raw;
  Region stock;
  Region part;
  Region chuck;
};

class Checker {
public:
  Checker(const ir::Module &m, DiagnosticEngine &d, PassStats &s, std::optional<double> t)
      : module_(m), diags_(d), stats_(s), tolerance_(t) {}

  bool run() {
    for (const Node *e : ir::programOrder(module_))
      if (ir::isTurningStep(*e) || ir::drillsOnTurningAxis(*e))
        if (const Node *moves = e->child(ir::Kind::Moves))
          step(*e, *moves);
    return ok_;
  }

private:
  void error(const Node &ws, const std::string &message) {
    diags_.error(ws.origin.loc, "workingstep " + ws.symbol + ": " + message).entity(ws.origin.entityId);
    ok_ = false;
  }

  Workpiece *workpiece(const Node &ws, const Node &wp) {
    if (auto it = pieces_.find(wp.symbol); it != pieces_.end())
      return &it->second;
    const ir::StockResult raw = ir::turnStock(&wp);
    if (!raw.stock) {
      // Nothing to check the moves against (an AP238 file that describes
      // its bar in words): said once per workpiece.
      if (unverified_.insert(wp.symbol).second)
        diags_.warning(ws.origin.loc, "workingstep " + ws.symbol + ": lathe moves not verified: " + raw.error)
            .entity(ws.origin.entityId);
      return nullptr;
    }
    Workpiece w;
    w.raw = *raw.stock;
    w.stock = raw.stock->region();
    std::vector<Region> removals;
    for (const Node &f : wp.children) {
      // Turned features, and holes on the axis (drilled or bored on the lathe).
      if (f.category() == ir::Category::Feature && (f.is(ir::Trait::Turning) || f.kind == ir::Kind::RoundHole))
        if (ir::TurnedShapeResult s = ir::turnedShape(f, w.raw); s.shape)
          removals.push_back(s.shape->removal);
    }
    w.part = geom::subtract(w.stock, geom::uniteAll(removals));
    w.chuck = Region{{geom::polygon({Vec2(w.raw.z0 - 1e4, -1e4), Vec2(w.raw.z0, -1e4), Vec2(w.raw.z0, 1e4),
                                     Vec2(w.raw.z0 - 1e4, 1e4)})}};
    return &pieces_.emplace(wp.symbol, std::move(w)).first->second;
  }

  void step(const Node &ws, const Node &moves) {
    const Node *op = ir::operationOf(ws);
    const Node *feature = ir::findFeature(module_, ws.text("feature").value_or(""));
    const Node *tool = ir::findTool(module_, moves.text("tool").value_or(""));
    const Node *wp = feature ? ir::workpieceOf(module_, *feature) : nullptr;
    if (!op || !feature || !tool || !wp)
      return;  // the IR verifier reports what is missing
    Workpiece *w = workpiece(ws, *wp);
    if (!w)
      return;
    const ir::TurnedShapeResult shape = ir::turnedShape(*feature, w->raw);
    // A drill on the axis: its hole is in the part's reading; its moves are
    // checked as any lathe tool's.
    const bool drilling = ir::drillsOnTurningAxis(ws);
    const bool pathsOnly = feature->kind == ir::Kind::ToolpathFeature || drilling;
    if (!shape.shape && !pathsOnly) {
      error(ws, shape.error);
      return;
    }
    if (pathsOnly && !drilling)
      diags_.warning(ws.origin.loc, "workingstep " + ws.symbol + ": " + feature->symbol +
                                        " gives only its toolpaths: its moves are checked against the stock only")
          .entity(ws.origin.entityId);
    const double t = tolerance_.value_or(wp->number("global_tolerance").value_or(0.01));
    const double allowance = op->number("allowance").value_or(0);
    const Insert insert =
        insertOf(*tool, shape.shape && shape.shape->inner, shape.shape && shape.shape->faceGroove);
    const Vec2 tipToCentre = insert.tipToCentre;
    // What the step may not cut: the part grown by its allowance, and the chuck.
    const Region guard = geom::unite(allowance > 0 ? geom::growExact(w->part, allowance) : w->part, w->chuck);
    std::vector<Region> pending;
    auto flush = [&] {
      if (!pending.empty())
        w->stock = geom::subtract(w->stock, folded(geom::uniteAll(pending)));
      pending.clear();
    };
    bool gouged = false, crashed = false;
    long long checked = 0;
    for (const ir::Move &m : ir::walkMoves(moves)) {
      if (m.kind == ir::MoveKind::Dwell || !m.from)
        continue;
      if (std::abs(m.to.y()) > 1e-9 || std::abs(m.from->y()) > 1e-9) {
        error(ws, "a lathe move leaves the XZ plane (y " + formatFixed(m.to.y(), 4) + " mm)");
        return;
      }
      const Vec2 a = halfPlane(*m.from) + tipToCentre, b = halfPlane(m.to) + tipToCentre;
      if ((a - b).norm() < 1e-12)
        continue;
      const Region swept = insert.sweep(a, b);
      ++checked;
      if (m.kind == ir::MoveKind::Rapid) {
        flush();
        const Region f = folded(swept);
        const Region hit = f.box().overlaps(w->stock.box().grown(1e-6)) || f.box().lo.x() < w->raw.z0
                               ? geom::intersect(f, geom::unite(w->stock, w->chuck))
                               : Region();
        if (!crashed && thick(hit, std::min(t, 0.001) * 2)) {
          crashed = true;
          error(ws, "a rapid to (x " + formatFixed(m.to.x(), 4) + ", z " + formatFixed(m.to.z(), 4) +
                        ") mm meets the stock at " + where(hit));
        }
        continue;
      }
      pending.push_back(swept);
      if (!gouged && (!pathsOnly || drilling)) {
        const Region cut = geom::intersect(folded(swept), guard);
        if (thick(cut, t)) {
          gouged = true;
          error(ws, "a cut to (x " + formatFixed(m.to.x(), 4) + ", z " + formatFixed(m.to.z(), 4) +
                        ") mm reaches into the part" + (allowance > 0 ? " or its allowance" : std::string()) +
                        " by more than " + formatFixed(t, 4) + " mm at " + where(cut));
        }
      }
    }
    flush();
    stats_["turning moves checked"] += checked;
    stats_["turning steps verified"]++;
    // A thread's flanks are not a body of revolution: its band is the part's
    // by the features' reading, and nothing is asked of what a pass leaves.
    if (op->is(ir::Trait::Finishing) && shape.shape && !shape.shape->thread)
      finished(ws, *w, *shape.shape, insert, allowance, t);
  }

  /// After a finishing step: the material left in the feature's removal
  /// beyond its allowance is an error where the insert could have reached
  /// it, a warning in corners narrower than its nose (corners of the part,
  /// or of the part and another feature's material still there).
  void finished(const Node &ws, const Workpiece &w, const ir::TurnedShape &s, const Insert &insert, double allowance,
                double t) {
    const Region left = geom::subtract(geom::intersect(w.stock, s.removal), geom::growExact(w.part, allowance + t));
    if (!thick(left, t))
      return;
    // What the step had to leave: the part, and the stock outside its
    // feature's removal (another feature's material, not cut yet, which the
    // strategies do not touch): a corner it makes with the surface is as
    // much out of the nose's reach as one the part makes.
    const double reach = insert.rc + allowance;
    const Region kept = geom::unite(w.part, geom::subtract(w.stock, s.removal));
    const Region corners = reach > 0 ? geom::shrinkExact(geom::growExact(kept, reach), reach) : kept;
    const Region missed = geom::subtract(left, corners);
    if (thick(missed, t)) {
      error(ws, s.symbol + " is left uncut beyond its allowance at " + where(missed));
      return;
    }
    diags_.warning(ws.origin.loc, "workingstep " + ws.symbol + ": " + s.symbol + " keeps material at " + where(left) +
                                      ": a corner narrower than the insert's nose radius " +
                                      formatFixed(insert.rc, 4) + " mm")
        .entity(ws.origin.entityId);
  }

  const ir::Module &module_;
  DiagnosticEngine &diags_;
  PassStats &stats_;
  std::optional<double> tolerance_;
  std::map<std::string, Workpiece> pieces_;
  std::set<std::string> unverified_;  ///< workpieces said to have no raw piece to check against
  bool ok_ = true;
};

} // namespace

bool verifyTurning(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                   std::optional<double> tolerance) {
  return Checker(module, diags, stats, tolerance).run();
}

} // namespace stepnc::passes
