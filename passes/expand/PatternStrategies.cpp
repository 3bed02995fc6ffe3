// Pattern strategies (stepnc's extension schema, docs/pattern-strategies.md):
// a motif repeated along the paths of a guide strategy, then one contour
// along the walls per level to take what the motif leaves there.
// trochoidal_strategy makes the motif a continuous trochoid whose step is
// lowered to keep the tool's engagement under the pass's max-engagement;
// plunge_strategy makes it plunges along the tool axis, linked above the
// material by rounded moves. The geometry of the motifs (the smoothed guide,
// the trochoid, its engagement, plunge places) is in passes/PatternPaths.
#include "passes/expand/Expand.h"

#include "passes/PatternPaths.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>

namespace stepnc::passes::expand {

namespace {

/// The guide of a pattern strategy and the levels, or none after a
/// diagnostic (a guide that is no ordinary strategy, nothing to cut).
struct Guided {
  const Node *guide = nullptr;
  std::vector<double> levels;
};

std::optional<Guided> guided(Expander &x, const Step &step) {
  const Node &pattern = *step.strategy;
  const Node *guide = pattern.child(ir::Kind::Strategy);
  const std::string type = guide ? guide->text("type").value_or("") : "";
  if (type.empty() || type == "explicit") {
    x.report(step.ws, "its " + pattern.kindName() +
                          " needs an ordinary strategy as its guide (contour parallel, "
                          "bidirectional, center milling, ...), found " +
                          (type.empty() ? "none" : "'" + type + "'"));
    return std::nullopt;
  }
  std::vector<double> levels = levelsOf(x, step.ws, step.op, *step.shape, step.plan);
  if (levels.empty())
    return std::nullopt;
  return Guided{guide, std::move(levels)};
}

/// A pattern that would sample more than kMaxPatternPoints points for one
/// step: `what` names the step that makes them.
void tooManyPoints(Expander &x, const Node &ws, const Node &pattern, const std::string &what) {
  x.report(ws, pattern,
           "its " + what + " would take more than " + formatFixed(kMaxPatternPoints, 0) +
               " points for this step, the most stepnc plans: it is far too small for the feature");
}

/// The guide's paths at height z for a motif that reaches `reach.radius`
/// from the guide (the tool's radius plus the motif's), `spacing` apart,
/// kept `margin` further from the walls; `area` receives where the guide
/// may run. None after a diagnostic when the motif does not fit.
std::optional<std::vector<Path2D>> guidePaths(Expander &x, const Node &ws, const Node &op, const Node &guide,
                                              const ir::FeatureShape &s, const Plan &reach, double z, double spacing,
                                              double margin, Region &area) {
  const std::string type = guide.text("type").value_or("");
  area = centreArea(s, s.unbounded ? s.target : s.limit, keepOutAt(s, z, reach), reach);
  if (margin > 0 && !area.empty())
    area = geom::offset(area, -margin);
  auto tooWide = [&](const std::string &what) {
    x.report(ws, "its tool " + reach.tool->symbol + " with the motif of its pattern strategy reaches " +
                     formatFixed(reach.radius, 3) + " mm from the guide and does not fit in " + what +
                     " with the side allowance");
  };
  if (s.slot && (type == "center_milling" || area.empty())) {
    std::optional<Path2D> line = slotCentreline(*s.slot, reach);
    if (!line) {
      tooWide("slot " + s.symbol + " (width " + formatFixed(s.slot->width, 3) + " mm)");
      return std::nullopt;
    }
    area = geom::offset(s.target, -geom::kEps);
    return std::vector<Path2D>{std::move(*line)};
  }
  if (type == "center_milling") {
    x.unsupported(ws, "center milling follows the course of travel of a slot; " + s.symbol + " is a " + s.kindName());
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
    x.unsupported(ws, "strategy '" + type + "' is not expanded yet");
    return std::nullopt;
  }
  return made;
}

/// After a motif at height z: one contour of the tool along every wall,
/// climb, taking what the motif leaves there (its scallops or cusps
/// between loops or plunges, and corners tighter than its reach).
void wallPass(Emitter &e, const Node &op, const ir::FeatureShape &s, const Plan &p, double z, bool ccw,
              int &fallbacks) {
  const Region centres = centreArea(s, s.unbounded ? s.target : s.limit, keepOutAt(s, z, p), p);
  if (centres.empty())
    return;
  for (const Path2D &ring : rings(centres, p.radius, ccw, /*all=*/false, p.radius))
    cutPath(e, ring, z, p, op, centres, /*mayLink=*/true, linkAnywhere(s), fallbacks);
}

/// Paths joined into chains: each path goes on from the end of the one
/// before by a straight link when the link stays inside `area`; a closed
/// path starts where it is nearest to that end.
std::vector<Path2D> chains(const std::vector<Path2D> &paths, const Region &area) {
  std::vector<Path2D> out;
  for (const Path2D &path : paths) {
    if (path.empty())
      continue;
    Path2D next = path;
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
double guideSpacing(const Node &pattern, const ir::FeatureShape &s, double radius) {
  double overlap = pattern.number("overlap").value_or(kPatternOverlap);
  if (overlap <= 0 || overlap >= 1)
    overlap = kPatternOverlap;
  return std::min(2 * radius * (1 - overlap), ringCoverLimit(s, radius));
}

/// From `from`, `corner` below the height `above`, to over `to` at `corner`
/// below it: up, across and down in the vertical plane through both, the
/// two bends rounded to radius `corner` (shortened to half the way
/// across), as feed moves within the chord tolerance.
void link(Emitter &e, double chordTolerance, const Vec2 &from, const Vec2 &to, double above, double corner,
          double feed) {
  const double across = (to - from).norm();
  if (across <= geom::kEps)
    return;
  const Vec2 u = (to - from) / across;
  const double r = std::min(corner, across / 2);
  // The bends start `corner` below `above`: lower them when r is shorter.
  if (r < corner)
    e.rapid(at(from, above - r), "retract");
  const int n =
      r > chordTolerance ? std::max(2, int(std::ceil(kPi / 2 / (2 * std::acos(1 - chordTolerance / r))))) : 1;
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

} // namespace

bool expandTrochoidal(Expander &x, const Step &step) {
  std::optional<Guided> g0 = guided(x, step);
  if (!g0)
    return false;
  const Node &ws = step.ws, &op = step.op, &pattern = *step.strategy, &guide = *g0->guide;
  const ir::FeatureShape &s = *step.shape;
  const Plan &p = step.plan;
  const double loop = pattern.number("radius").value_or(0);
  const double stepLength = pattern.number("step").value_or(0);
  if (loop <= 0 || stepLength <= 0) {
    x.report(ws, pattern, "its trochoidal strategy needs a positive trochoid radius and step per revolution");
    return false;
  }
  if (stepLength >= 2 * kPi * loop) {
    x.report(ws, pattern,
             "its trochoidal step per revolution " + formatFixed(stepLength, 3) +
                 " mm is not less than 2 pi times the trochoid radius (" + formatFixed(2 * kPi * loop, 3) +
                 " mm): the tool would stop on every loop");
    return false;
  }
  // The step the engagement allows, on a straight guide in full material.
  const double used = largestTrochoidStep(p.radius, loop, x.maxEngagement * kPi / 180, stepLength);
  if (used <= 0) {
    x.report(ws, pattern,
             "no trochoid of radius " + formatFixed(loop, 3) + " mm keeps the engagement of its tool under " +
                 formatFixed(x.maxEngagement, 1) + " deg");
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
  Emitter e(step.moves, step.moves.number("secplane").value_or(0));
  long loops = 0;
  size_t planned = 0;  // points, against kMaxPatternPoints
  int fallbacks = 0;
  for (double z : g0->levels) {
    Region area;
    auto paths = guidePaths(x, ws, op, guide, s, reach, z, spacing, SmoothGuide::arcShrink(w, reach.radius), area);
    if (!paths)
      return false;
    for (Path2D &chain : chains(*paths, area)) {
      const SmoothGuide g(std::move(chain), w);
      const std::optional<std::vector<Vec2>> sampled =
          trochoidPoints(g, motif, x.chordTolerance, kMaxPatternPoints - double(planned));
      if (!sampled) {
        tooManyPoints(x, ws, pattern, "trochoid step " + formatShortest(used) + " mm");
        return false;
      }
      const std::vector<Vec2> &points = *sampled;
      planned += points.size();
      loops += long(trochoidLoops(g, used));
      // Down about the guide's start on the first loop: a helix, unless
      // the operation asks for a plunge along the tool axis (any other
      // approach is reported by the pass).
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
    wallPass(e, op, s, p, z, motif.ccw, fallbacks);
  }
  e.retract();
  std::string note = "trochoid radius " + formatFixed(loop, 3) + " mm, step " + formatFixed(used, 3) + " mm";
  if (used < stepLength)
    note += " (" + formatFixed(stepLength, 3) + " lowered: engagement at most " + formatFixed(x.maxEngagement, 1) +
            " deg)";
  ir::replaceCommentPart(step.moves, {"trochoid "}, note + ", " + std::to_string(loops) + " loops");
  (*x.stats)["trochoid loops"] += loops;
  reportApproachFallbacks(x, step, fallbacks);
  return true;
}

bool expandPlunging(Expander &x, const Step &step) {
  std::optional<Guided> g0 = guided(x, step);
  if (!g0)
    return false;
  const Node &ws = step.ws, &op = step.op, &pattern = *step.strategy, &guide = *g0->guide;
  const ir::FeatureShape &s = *step.shape;
  const Plan &p = step.plan;
  const double clearance = pattern.number("clearance").value_or(0);
  const double backOff = std::max(0.0, pattern.number("retract_offset").value_or(0));
  const double bottom = pattern.number("bottom_radius").value_or(0);
  const double pitch = pattern.number("radial_step").value_or(0);
  const double linkRadius = std::max(0.0, pattern.number("link_radius").value_or(0));
  if (bottom <= 0 || bottom > p.radius + 1e-9) {
    x.report(ws, pattern,
             "its plunge bottom radius " + formatFixed(bottom, 3) + " mm is not within the radius of its tool " +
                 p.tool->symbol + " (" + formatFixed(p.radius, 3) + " mm)");
    return false;
  }
  // Plunges on a square grid of pitch p cover the area when p <= sqrt(2) R.
  if (pitch <= 0 || pitch > std::sqrt(2.0) * bottom * (1 + 1e-9)) {
    x.report(ws, pattern,
             "its plunge radial step " + formatFixed(pitch, 3) + " mm leaves material between plunges: at most " +
                 "sqrt(2) times the plunge bottom radius, " + formatFixed(std::sqrt(2.0) * bottom, 3) + " mm");
    return false;
  }
  if (clearance <= 0) {
    x.report(ws, pattern,
             "its plunge clearance height " + formatFixed(clearance, 3) +
                 " mm does not take the tool out of the material between plunges");
    return false;
  }
  const double secplane = step.moves.number("secplane").value_or(0);
  const double above = std::min(s.top + clearance, secplane);
  // Rounded corners stay above the material: the way down is a plunge.
  const double corner = std::min(linkRadius, above - s.top);
  Emitter e(step.moves, secplane);
  long plunges = 0;
  size_t planned = 0;  // plunges, against kMaxPatternPoints
  int fallbacks = 0;
  for (double z : g0->levels) {
    Region area;
    auto paths = guidePaths(x, ws, op, guide, s, p, z, pitch, 0, area);
    if (!paths)
      return false;
    const geom::SegIndex areaEdges = geom::SegIndex::of(area);
    for (Path2D path : *paths) {
      const bool closed = path.size() > 1 && (path.front().a - path.back().b).norm() < 1e-7;
      if (closed && e.positioned())
        path = startNearest(Loop{path}, e.position().head<2>()).segs;
      const std::optional<std::vector<Vec2>> placed =
          plungeCentres(path, pitch, bottom, kMaxPatternPoints - double(planned));
      if (!placed) {
        tooManyPoints(x, ws, pattern, "plunge radial step " + formatShortest(pitch) + " mm");
        return false;
      }
      const std::vector<Vec2> &centres = *placed;
      planned += centres.size();
      for (size_t k = 0; k < centres.size(); ++k) {
        const Vec2 c = centres[k];
        if (k == 0)
          e.travel(c, above);
        else
          link(e, x.chordTolerance, e.position().head<2>(), c, above, corner, p.feed);
        e.linear(at(c, z), p.plungeFeed, "plunge");
        ++plunges;
        // Away from the wall just cut, into the hole of the plunge before,
        // then straight up. Where the guide turns round a corner of the
        // material, the chord to the plunge before passes closer to it than
        // the tool may go: there the tool goes straight up.
        Vec2 out = c;
        if (k > 0 && backOff > 0) {
          const Vec2 back = centres[k - 1] - c;
          const Vec2 to = c + back * std::min(1.0, backOff / back.norm());
          auto allowed = [&](const Vec2 &q) {
            return area.contains(q) || areaEdges.distance(q) <= 1e-6;
          };
          if (allowed(to) && allowed((c + to) / 2)) {
            out = to;
            e.linear(at(out, z), p.feed, "retract");
          }
        }
        e.rapid(at(out, k + 1 < centres.size() ? above - corner : secplane), "retract");
      }
    }
    wallPass(e, op, s, p, z, counterClockwise(&pattern, p.spindle), fallbacks);
  }
  e.retract();
  const double cusp = bottom - std::sqrt(bottom * bottom - pitch * pitch / 4);
  ir::replaceCommentPart(step.moves, {"plunges "},
                         "plunges " + std::to_string(plunges) + " on a " + formatFixed(pitch, 3) +
                             " mm pitch, wall cusp " + formatFixed(cusp, 3) + " mm");
  (*x.stats)["plunges"] += plunges;
  reportApproachFallbacks(x, step, fallbacks);
  return true;
}

} // namespace stepnc::passes::expand
