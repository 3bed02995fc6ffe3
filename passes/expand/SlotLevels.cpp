// Slots whose walls are slanted or curved (vee, partial circular and
// rounded-U cross-sections): z-level passes. The slot is cut level by level
// from the top down; at each level the tool may go as far towards each wall
// as its end fits in the cross-section (ir::SlotSection) kept the side
// allowance away from it, measured normal to the wall. That is the section
// eroded by the tool's corner radius plus the allowance, met by the height of
// the corner's centre, less the flat part of the tool's end. The level is
// then cut as a slot with vertical walls of that width, by the 2.5D machinery
// of Milling2D.cpp (the strategy's rings, strokes or the course of travel).
//
// Roughing steps down by the axial depth of cut; finishing steps down as
// far as keeps the ridge left between two levels on the wall within the
// scallop height, follows the walls with one contour per level and clears
// the bottom at the last level. What the tool cannot reach below its lowest
// level (a wide tool in the bottom of a vee) is left, with a warning.
//
// Assumes what SlotSection promises: a convex section no narrower higher up.
// Then the positions where the tool fits form a convex set in the section's
// plane, so the tool may step down from one level to the next anywhere in
// the lower level's area, straight down.
#include "passes/expand/Expand.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>

namespace stepnc::passes::expand {

namespace {

/// Where the tool centre may be across a sectioned slot, height by height.
class SectionFit {
public:
  SectionFit(const ir::SlotSection &section, double radius, double corner, double allowance)
      : walls_(section.walls), flat_(radius - corner), corner_(corner), allowance_(allowance),
        depth_(section.depth) {
    // The section closed well above its top, its walls continued along
    // their tangents at the top: the tool's corner may stand above the top
    // while its tip cuts below it, and the space there is free (the
    // continued walls keep the section convex and less than that space).
    const double above = section.depth + 4 * radius + 2 * allowance + 10;
    Loop l;
    l.segs = section.walls;
    auto continued = [&](const Vec2 &end, Vec2 up) {
      if (up.y() <= 1e-9)
        up = Vec2::UnitY();
      return end + up * ((above - end.y()) / up.y());
    };
    const Vec2 first = l.segs.front().a, last = l.segs.back().b;
    const Vec2 firstUp = continued(first, -l.segs.front().tangent(0));
    const Vec2 lastUp = continued(last, l.segs.back().tangent(1));
    l.segs.push_back(Seg::line(last, lastUp));
    l.segs.push_back(Seg::line(lastUp, firstUp));
    l.segs.push_back(Seg::line(firstUp, first));
    if (l.area() < 0)
      l.reverse();
    Region r;
    r.loops.push_back(std::move(l));
    reach_ = r.box().grown(1).hi.x() - r.box().grown(1).lo.x() + radius;
    eroded_ = corner + allowance > 0 ? geom::offset(r, -(corner + allowance)) : r;
  }

  /// The tool centre's extent across the slot (u) with its tip at height v
  /// above the floor; none when the tool does not fit there.
  std::optional<std::pair<double, double>> centres(double v) const {
    const double h = v + corner_;
    const std::vector<Seg> inside = geom::clip(eroded_, Vec2(-reach_, h), Vec2(reach_, h));
    if (inside.empty())
      return std::nullopt;
    double lo = 1e300, hi = -1e300;
    for (const Seg &s : inside) {
      lo = std::min({lo, s.a.x(), s.b.x()});
      hi = std::max({hi, s.a.x(), s.b.x()});
    }
    lo += flat_;
    hi -= flat_;
    if (hi < lo - 1e-9)
      return std::nullopt;
    return std::pair(std::min(lo, hi), std::max(lo, hi));
  }

  /// The lowest tip height at or above `from` where the tool fits (bisection:
  /// it fits at every height above one where it fits); none when it fits
  /// nowhere below the top.
  std::optional<double> lowest(double from) const {
    if (centres(from))
      return from;
    double below = from, above = depth_;
    if (!centres(above))
      return std::nullopt;
    for (int i = 0; i < 60 && above - below > 1e-7; ++i) {
      const double mid = (below + above) / 2;
      (centres(mid) ? above : below) = mid;
    }
    return above;
  }

  /// The ridge two neighbouring levels (tips at heights `upper` > `lower`)
  /// leave on the walls: how far the highest point of the material between
  /// the two tools stands off the wall's offset by the allowance (the larger
  /// of the two walls). The slot's top edge counts as a level at the top. A rounded end's ridge is where the two corners'
  /// circles cross; a sharp one leaves a step whose inner edge is under the
  /// upper tool's end, over the lower tool's side.
  double ridge(double upper, double lower) const {
    const auto up = centres(upper), down = centres(lower);
    if (!up || !down)
      return 1e300;
    double worst = 0;
    for (const double side : {-1.0, 1.0}) {
      // The corners' centres on this side, and which way is out.
      const double u1 = (side < 0 ? up->first - flat_ : up->second + flat_);
      const double u2 = (side < 0 ? down->first - flat_ : down->second + flat_);
      const Vec2 p1(u1, upper + corner_), p2(u2, lower + corner_);
      Vec2 q(u2 + side * corner_, upper);  // the step's inner edge (the top's edge for the first level)
      const double d = (p1 - p2).norm();
      if (corner_ > 0 && d <= 2 * corner_ && d > geom::kEps) {
        const Vec2 mid = (p1 + p2) / 2, along = (p2 - p1) / d;
        Vec2 across(-along.y(), along.x());
        if (across.x() * side < 0)
          across = -across;
        q = mid + across * std::sqrt(corner_ * corner_ - d * d / 4);
      }
      if (q.y() > depth_) {
        // In the air above the top: what is left there is at the slot's
        // edge, outside where the lower tool crosses the top.
        const double dv = std::max(0.0, p2.y() - depth_);
        q = Vec2(u2 + side * std::sqrt(std::max(0.0, corner_ * corner_ - dv * dv)), depth_);
      }
      double off = 1e300;
      for (const Seg &w : walls_)
        off = std::min(off, geom::distance(w, q));
      worst = std::max(worst, off - allowance_);
    }
    return worst;
  }

  /// How far the slot's top edges stand off the tool with its tip at height
  /// v (less the allowance; the larger of the two): the material finishing
  /// leaves at the top above its first level, thickest at the edge.
  double edgeGap(double v) const {
    const auto at = centres(v);
    if (!at)
      return 1e300;
    double worst = 0;
    for (const double side : {-1.0, 1.0}) {
      const Vec2 edge = side < 0 ? walls_.front().a : walls_.back().b;
      const Vec2 p(side < 0 ? at->first - flat_ : at->second + flat_, v + corner_);
      const double gap = edge.y() >= p.y() ? std::abs(edge.x() - (p.x() + side * corner_)) : (edge - p).norm() - corner_;
      worst = std::max(worst, gap - allowance_);
    }
    return worst;
  }

private:
  std::vector<Seg> walls_;
  Region eroded_;
  double flat_, corner_, allowance_, depth_;
  double reach_ = 0;  ///< a half-length across wider than the section
};

/// The tip heights (above the floor, from the top down) of finishing
/// levels: the first as low as leaves the top edges within `scallop` (the
/// gap closes as the tool comes down to the edge, then opens again: its
/// lowest point is found first), each next one as far below as keeps the
/// ridge between the two within it (the ridge grows with the step); steps
/// of at most `maxStep`. Ends above `lowest`, the last level, not included.
std::vector<double> finishLevels(const SectionFit &fit, double depth, double lowest, double maxStep,
                                 double scallop) {
  constexpr double kMinStep = 1e-3;  // mm
  double touch = lowest, high = depth;
  for (int i = 0; i < 80 && high - touch > 1e-6; ++i) {
    const double a = touch + (high - touch) / 3, b = high - (high - touch) / 3;
    if (fit.edgeGap(a) < fit.edgeGap(b))
      high = b;
    else
      touch = a;
  }
  double v = (touch + high) / 2, low = lowest;
  if (fit.edgeGap(low) > scallop) {
    for (int i = 0; i < 60 && v - low > 1e-6; ++i) {
      const double mid = (low + v) / 2;
      (fit.edgeGap(mid) <= scallop ? v : low) = mid;
    }
  } else {
    v = low;
  }
  std::vector<double> levels;
  v = std::max(v, depth - maxStep);
  while (v > lowest + kMinStep) {
    levels.push_back(v);
    const double most = std::min(maxStep, v - lowest);
    double good = kMinStep, bad = most;
    if (fit.ridge(v, v - most) <= scallop) {
      good = most;
    } else {
      for (int i = 0; i < 40 && bad - good > 1e-5; ++i) {
        const double mid = (good + bad) / 2;
        (fit.ridge(v, v - mid) <= scallop ? good : bad) = mid;
      }
    }
    v -= good;
  }
  return levels;
}

} // namespace

bool expandSlotLevels(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  const ir::FeatureShape &s = *step.shape;
  const ir::SlotSection &section = *s.section;
  const Plan &p = step.plan;
  const double corner = ir::cornerRadius(*p.tool);
  const SectionFit fit(section, p.radius, corner, p.allowanceSide);
  const double floorV = p.allowanceBottom;  // heights above the floor
  if (floorV >= section.depth - 1e-9) {
    x.unsupported(ws, "the bottom allowance leaves nothing to cut");
    return false;
  }
  const std::optional<double> lowest = fit.lowest(floorV);
  if (!lowest || *lowest >= section.depth - 1e-6) {
    x.report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                     " mm) does not fit in slot " + s.symbol + " below its top with the side allowance");
    return false;
  }
  const bool finishing = op.is(ir::Trait::Finishing);
  const double axial = op.number("axial_depth").value_or(0);
  const double maxStep = axial > 1e-9 ? axial : p.radius;

  // The levels, heights above the floor from the top down.
  std::vector<double> levels;
  if (finishing) {
    levels = finishLevels(fit, section.depth, *lowest, maxStep, scallopHeight(x, *p.feature));
    levels.push_back(*lowest);
  } else {
    if (axial <= 1e-9)
      x.assumed(ws, op,
                "no axial_depth for slot " + s.symbol + ", whose walls are slanted or curved: levels at most " +
                    formatFixed(maxStep, 3) + " mm apart (the tool's radius)");
    const double height = section.depth - *lowest;
    const int count = std::max(1, static_cast<int>(std::ceil(height / maxStep - 1e-9)));
    for (int i = 1; i <= count; ++i)
      levels.push_back(section.depth - height * i / count);
  }
  if (*lowest > floorV + 1e-4)
    x.warning(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                      " mm) does not fit in slot " + s.symbol + " below z=" + formatFixed(s.bottom + *lowest, 4) +
                      " mm: the lowest " + formatFixed(*lowest - floorV, 4) + " mm of its profile (down to z=" +
                      formatFixed(s.bottom + floorV, 4) + " mm) are left uncut");

  // Each level is a slot with vertical walls, as wide as the tool centre's
  // extent plus the tool, cut with no further allowance.
  Plan flat = p;
  flat.allowanceSide = 0;
  LevelStrategy ls = levelStrategy(step, s, flat);
  ls.saidSlotLine = true;  // the narrow levels of a slanted slot are no choice of the strategy
  const Node *approach = op.child(ir::Kind::Approach);
  const bool alongAxis = !approach || approach->text("type").value_or("plunge_toolaxis") == "plunge_toolaxis";
  int fallbacks = 0;
  Emitter e(step.moves, step.moves.number("secplane").value_or(0));
  for (size_t i = 0; i < levels.size(); ++i) {
    auto [lo, hi] = *fit.centres(levels[i]);
    if (hi - lo < 1e-3)
      lo = hi = (lo + hi) / 2;  // along the course of travel
    const ir::FeatureShape level = ir::slotBetween(s, lo - p.radius, hi + p.radius);
    // Finishing follows the walls at every level but the last, which
    // clears the bottom as the operation asks.
    LevelStrategy here = ls;
    here.sideOnly = ls.sideOnly || (finishing && i + 1 < levels.size());
    LevelPaths paths;
    if (!planLevel(x, step, level, flat, {}, here, paths))
      return false;
    ls.saidSideMilling = here.saidSideMilling;
    if (paths.paths.empty())
      continue;
    const double z = s.bottom + levels[i];
    if (alongAxis && e.positioned() && e.position().z() < e.secplane()) {
      // Down from the level above: across it to over where this level
      // starts, then straight down. The tool fits wherever it fits one
      // level lower, and the places it fits at a height are convex.
      const Vec2 from = e.position().head<2>();
      const Path2D &first = paths.paths.front();
      Vec2 start = first.front().a;
      if (geom::Chain{first}.closed())
        start = startNearest(Loop{first}, from).segs.front().a;
      else if ((first.back().b - from).norm() < (start - from).norm())
        start = first.back().b;
      e.linear(at(start, e.position().z()), p.feed, "link");
    }
    cutLevel(e, step, level, flat, paths, z, here, fallbacks);
  }
  e.retract();
  reportApproachFallbacks(x, step, fallbacks);
  return true;
}

} // namespace stepnc::passes::expand
