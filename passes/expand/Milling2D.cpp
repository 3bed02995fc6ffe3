// 2.5D milling with an ordinary strategy (ISO 14649-11 two5D_milling_strategy):
// the levels from the feature's top to its floor, at each level the paths of
// the strategy in the area the tool centre may reach (contour rings, zigzag
// or one-way strokes, both, or the course of travel of a slot), each path
// reached by a link at depth or from the security plane by the operation's
// approach (along the axis, a helix or a ramp). The geometry of the rings
// and strokes is in Contour.cpp and Zigzag.cpp; the pattern strategies reuse
// the centre area, the paths and cutPath from here.
#include "passes/expand/Expand.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>

namespace stepnc::passes::expand {

namespace {

/// Whether side milling follows strategy `type` on a feature (face or not):
/// it goes round the walls, which is what the contour strategies do, and
/// strokes on faces.
bool sideMillingFollows(const std::string &type, bool face) {
  if (type == "contour_parallel" || type == "contour_spiral")
    return true;
  return face && (type == "bidirectional" || type == "unidirectional");
}

/// Down to height z at the start of `path`: along the tool axis, or by a
/// helix or a ramp when the operation asks and there is room; `fallbacks`
/// counts a helix or ramp that did not fit.
void approach(Emitter &e, const Path2D &path, double z, const Plan &p, const Node &op, const Region &centres,
              int &fallbacks) {
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
    ++fallbacks;
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
    ++fallbacks;
  }
  // Along the tool axis: asked for, or (reported by the caller) a helix or
  // ramp that does not fit, or an approach type the family does not follow.
  e.travel(start, p.clearanceZ);
  e.linear(at(start, z), p.plungeFeed, "plunge");
}

/// The radius of a tool of `radius` and `corner` at height h (0 .. ) above
/// its tip: R - rc + sqrt(rc^2 - (rc - h)^2) through its corner, R above.
double bodyRadius(double radius, double corner, double h) {
  return h >= corner ? radius : radius - corner + std::sqrt(std::max(0.0, corner * corner - (corner - h) * (corner - h)));
}

/// How a boss whose walls lean in is sampled for the keep-out area of a tool
/// whose corner, grown by the side allowance, is `corner` (slopedKeepOut):
/// heights `step` apart, each section grown by `margin` more than the
/// body's radius there, which bounds what the envelope between two samples
/// stands out: step^2 (1 + slope^2)^1.5 / (8 corner), from the curvature of
/// the corner's circle where it meets a wall. The tool stands off the wall
/// by up to the margin, which finishing counts in its scallop.
struct SliceSampling {
  double step = 0, margin = 0;
};

SliceSampling sliceSampling(const ir::IslandShape &isl, double corner) {
  if (corner <= 0)
    return {};
  const double step = std::min(0.05, corner / 16);
  return {step, step * step * std::pow(1 + isl.slope * isl.slope, 1.5) / (8 * corner)};
}

/// The ridge levels dz apart leave on a long wall leaning `slope` (tan, in
/// from the vertical going up), by a tool of `radius` and `corner`. In a
/// section across the wall each level's silhouette (its diameter wide from
/// its tip up, its lower corners rounded by `corner`) stands as far in as it
/// touches the wall; from points of the wall over one period (the levels
/// repeat) the material left is measured along the wall's normal to the
/// first silhouette it meets (sphere tracing: the silhouettes' signed
/// distance is a safe step), the largest of those being the ridge's height.
double levelRidge(double slope, double radius, double corner, double dz) {
  const double flat = radius - corner;
  // The tool's axis with its tip at height 0, and where it touches the wall
  // (the wall at height v is at u = -v slope, u out from it).
  double axis0 = -1e300, contact = 0;
  constexpr int kBody = 256;
  for (int k = 0; k <= kBody; ++k) {
    const double h = corner * k / kBody;
    const double body = bodyRadius(radius, corner, h);
    if (-h * slope + body > axis0) {
      axis0 = -h * slope + body;
      contact = h;
    }
  }
  // A level k dz higher stands k dz slope further in.
  auto distance = [&](double u, double h, int k) {
    const double tip = k * dz, axis = axis0 - tip * slope;
    const double du = std::abs(u - axis);
    const double dx = std::max(du - flat, 0.0), dy = std::max(tip + corner - h, 0.0);
    if (dx > 0 || dy > 0)
      return std::hypot(dx, dy) - corner;
    return -std::min(flat - du + corner, h - tip);
  };
  const double norm = std::sqrt(1 + slope * slope);
  const double nu = 1 / norm, nh = slope / norm;  // the wall's normal, out and up
  double ridge = 0;
  constexpr int kPoints = 400;
  for (int i = 0; i <= kPoints; ++i) {
    const double h0 = contact + dz * i / kPoints;
    double t = 0;
    for (int step = 0; step < 400; ++step) {
      const double u = -h0 * slope + t * nu, h = h0 + t * nh;
      // Only the levels whose tip is within a corner and two levels below
      // the point, or a level above it, can be nearest.
      double nearest = 1e300;
      const int lo = static_cast<int>(std::floor((h - corner) / dz)) - 2, hi = static_cast<int>(std::ceil(h / dz)) + 1;
      for (int k = lo; k <= hi; ++k)
        nearest = std::min(nearest, distance(u, h, k));
      if (nearest <= 1e-9 * (1 + radius))
        break;
      t += nearest;
    }
    ridge = std::max(ridge, t);
  }
  return ridge;
}

/// The largest step down between two levels that finish the walls of the
/// sloped bosses of `s` within `scallop` (levelRidge, by bisection), less the
/// keep-out area's margin (sliceSampling); none when no boss slopes. On a
/// wall leaning alpha, a flat end mill leaves a step dz sin(alpha); a corner
/// of radius rc, while the ridge stays on its arc, rc - sqrt(rc^2 - s^2 / 4)
/// with s = dz / cos(alpha) along the wall.
std::optional<double> slopedLevelStep(const ir::FeatureShape &s, const Plan &p, double scallop) {
  std::optional<double> out;
  const double rc = ir::cornerRadius(*p.tool), depth = s.top - s.bottom;
  for (const ir::IslandShape &isl : s.islands) {
    if (!isl.sloped())
      continue;
    const double h = std::max(scallop / 2, scallop - sliceSampling(isl, rc + p.allowanceSide).margin);
    double good = 0, bad = depth;
    if (levelRidge(isl.slope, p.radius, rc, depth) <= h) {
      good = depth;
    } else {
      for (int i = 0; i < 50 && bad - good > 1e-6 * depth; ++i) {
        const double mid = (good + bad) / 2;
        (levelRidge(isl.slope, p.radius, rc, mid) <= h ? good : bad) = mid;
      }
    }
    if (good <= 0)
      good = bad;  // cannot happen for a scallop above 0; keeps the levels finite
    out = out ? std::min(*out, good) : good;
  }
  return out;
}

} // namespace

double scallopHeight(const Expander &x, const Node &feature) {
  if (x.scallopHeight)
    return *x.scallopHeight;
  if (const Node *wp = ir::workpieceOf(*x.module, feature))
    return wp->number("global_tolerance").value_or(kDefaultScallopHeight);
  return kDefaultScallopHeight;
}

std::vector<double> levelsOf(Expander &x, const Node &ws, const Node &op, const ir::FeatureShape &s, const Plan &p) {
  const double floorZ = s.bottom + p.allowanceBottom;
  if (floorZ >= s.top - 1e-9) {
    x.unsupported(ws, "the bottom allowance leaves nothing to cut");
    return {};
  }
  const double ap = op.number("axial_depth").value_or(0);
  const double depth = s.top - floorZ;
  if (ap < 0 || (ap > 0 && depth / ap > kMaxLevels)) {
    // A depth of cut that makes more levels than any part is cut in (a
    // micrometre on a pocket) would plan for hours: refused, not cut in one.
    x.report(ws, "axial_depth " + formatShortest(ap) + " mm " +
                     (ap < 0 ? std::string("is negative")
                             : "makes " + formatShortest(std::ceil(depth / ap)) + " levels over the " +
                                   formatFixed(depth, 4) + " mm to cut of " + s.symbol + ", more than the " +
                                   std::to_string(kMaxLevels) + " stepnc plans") +
                     ": give a larger depth of cut");
    return {};
  }
  int count = ap > 0 ? std::max(1, static_cast<int>(std::ceil(depth / ap - 1e-9))) : 1;
  // Finishing a boss whose walls lean in: levels close enough that the ridge
  // left on its walls between two stays within the scallop height.
  if (op.is(ir::Trait::WallFinishing))
    if (const std::optional<double> dz = slopedLevelStep(s, p, scallopHeight(x, *p.feature))) {
      const int fine = static_cast<int>(std::ceil(depth / *dz - 1e-9));
      if (fine > kMaxLevels) {
        x.report(ws, "finishing the sloped walls of " + s.symbol + " within the scallop height takes " +
                         std::to_string(fine) + " levels, more than the " + std::to_string(kMaxLevels) +
                         " stepnc plans: give a larger scallop height (the workpiece's global_tolerance, or "
                         "expand-strategies<scallop-height=>) or a tool with a larger corner radius");
        return {};
      }
      count = std::max(count, fine);
    }
  std::vector<double> out;
  for (int i = 1; i <= count; ++i)
    out.push_back(s.top - (s.top - floorZ) * i / count);
  return out;
}

LevelStrategy levelStrategy(const Step &step, const ir::FeatureShape &s, const Plan &p) {
  const Node &op = step.op;
  const Node *strategy = step.strategy;
  LevelStrategy ls;
  ls.type = strategy ? strategy->text("type").value_or("") : "";
  ls.face = op.is(ir::Trait::FaceOperation) || ir::hasTraits(s.kind, ir::Trait::FaceFeature);
  if (ls.type.empty())
    ls.type = ls.face ? "bidirectional" : "contour_parallel";
  ls.sideOnly = op.is(ir::Trait::SideOnly);
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
  ls.stepover =
      std::min(stepover, ls.type == "bidirectional" || ls.type == "unidirectional" ? limitBidir : coverLimit);
  ls.followOrientation = counterClockwise(strategy, p.spindle);
  ls.strokeDir = strokeDirection(*p.feature, s, strategy);
  ls.linkAtDepth = ls.type == "contour_spiral" || ls.type == "contour_parallel" || ls.type == "bidirectional" ||
                   ls.type == "contour_bidirectional" || ls.type == "bidirectional_contour";
  return ls;
}

bool planLevel(Expander &x, const Step &step, const ir::FeatureShape &s, const Plan &p,
               const std::vector<Region> &keepOut, LevelStrategy &ls, LevelPaths &out) {
  const Node &ws = step.ws, &op = step.op;
  const Node *strategy = step.strategy;
  const std::string &type = ls.type;
  out.centres = centreArea(s, s.unbounded ? s.target : s.limit, keepOut, p);
  out.paths.clear();
  if (!out.centres.empty()) {
    const geom::Box box = out.centres.box();
    const double across = std::max(box.hi.x() - box.lo.x(), box.hi.y() - box.lo.y());
    if (across / ls.stepover > kMaxRadialPasses) {
      x.report(ws, "a stepover of " + formatShortest(ls.stepover) + " mm makes about " +
                       formatShortest(std::ceil(across / ls.stepover)) + " passes across the " +
                       formatFixed(across, 4) + " mm of " + s.symbol + " the tool's centre covers, more than the " +
                       std::to_string(kMaxRadialPasses) + " stepnc plans: give a larger radial depth of cut");
      return false;
    }
  }
  // Center milling, and slots exactly as wide as the tool: along the course of travel.
  if (s.slot && (type == "center_milling" || out.centres.empty())) {
    std::optional<Path2D> line = slotCentreline(*s.slot, p);
    if (!line) {
      x.report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                       " mm) does not fit in slot " + s.symbol + " (width " + formatFixed(s.slot->width, 3) +
                       " mm) with the side allowance");
      return false;
    }
    if (strategy && type != "center_milling" && !ls.saidSlotLine) {
      x.assumed(ws, *strategy,
                "strategy " + type + " is not supported in slot " + s.symbol + ", no wider than tool " +
                    p.tool->symbol + " with the side allowance: center milling along its course of travel");
      ls.saidSlotLine = true;
    }
    out.centres = geom::offset(s.target, -geom::kEps);  // links stay in the slot
    out.paths.push_back(std::move(*line));
  } else if (type == "center_milling") {
    x.unsupported(ws, "center milling follows the course of travel of a slot; " + s.symbol + " is a " +
                          s.kindName());
    return false;
  } else if (!out.centres.empty()) {
    auto made = strategyPaths(type, ls.face, s.unbounded, ls.sideOnly, out.centres, ls.strokeDir, ls.stepover,
                              ls.followOrientation, p.radius);
    if (!made) {
      x.unsupported(ws, "strategy '" + type + "' is not expanded yet");
      return false;
    }
    if (ls.sideOnly && strategy && !sideMillingFollows(type, ls.face) && !ls.saidSideMilling) {
      x.assumed(ws, *strategy,
                "strategy " + type + " is not supported by " + op.kindName() + ": one contour along " +
                    (ls.face || s.unbounded ? "each island" : "the walls"));
      ls.saidSideMilling = true;
    }
    out.paths = std::move(*made);
  } else if (!(s.holeCentre && 2 * p.radius <= s.holeDiameter + 1e-6)) {
    x.report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                     " mm) does not fit in " + s.symbol + " with the side allowance");
    return false;
  }
  return true;
}

void cutLevel(Emitter &e, const Step &step, const ir::FeatureShape &s, const Plan &p, LevelPaths &level, double z,
              const LevelStrategy &ls, int &fallbacks) {
  if (level.centres.empty()) {
    // A cutter as wide as the hole: straight down its axis.
    e.travel(*s.holeCentre, p.clearanceZ);
    e.linear(at(*s.holeCentre, z), p.plungeFeed, "plunge");
    e.retract();
    return;
  }
  if (s.slot && level.paths.size() == 1 && !geom::Chain{level.paths[0]}.closed()) {
    // One open path per level (center milling): down at the end where the
    // level before finished, and back along it.
    Path2D &line = level.paths[0];
    if (e.positioned() && (e.position().head<2>() - line.back().b).norm() <
                              (e.position().head<2>() - line.front().a).norm()) {
      Loop back{line};
      back.reverse();
      line = std::move(back.segs);
    }
    cutPath(e, line, z, p, step.op, level.centres, false, false, fallbacks);
    return;
  }
  for (size_t k = 0; k < level.paths.size(); ++k)
    cutPath(e, level.paths[k], z, p, step.op, level.centres, ls.linkAtDepth && k > 0, linkAnywhere(s), fallbacks);
}

bool expandMilling2D(Expander &x, const Step &step) {
  if (step.op.has("tool_direction"))
    return expandFlankMilling(x, step);
  const ir::FeatureShape &s = *step.shape;
  if (s.section)
    return expandSlotLevels(x, step);
  const Plan &p = step.plan;
  const std::vector<double> levels = levelsOf(x, step.ws, step.op, s, p);
  if (levels.empty())
    return false;
  LevelStrategy ls = levelStrategy(step, s, p);
  int fallbacks = 0;
  Emitter e(step.moves, step.moves.number("secplane").value_or(0));
  // The centre area and the paths depend on the level only through the
  // islands standing at it: they are made again only when that set changes.
  // A boss whose walls lean in changes them at every level.
  std::optional<std::vector<bool>> standing;
  LevelPaths level;
  for (const double z : levels) {
    std::vector<bool> here;
    bool sloped = false;
    for (const ir::IslandShape &isl : s.islands) {
      here.push_back(isl.top > z + 1e-9);
      sloped = sloped || (here.back() && isl.sloped());
    }
    if (standing != here || sloped) {
      standing = here;
      if (!planLevel(x, step, s, p, keepOutAt(s, z, p), ls, level))
        return false;
    }
    cutLevel(e, step, s, p, level, z, ls, fallbacks);
  }
  e.retract();
  reportApproachFallbacks(x, step, fallbacks);
  return true;
}

std::optional<Path2D> slotCentreline(const ir::FeatureShape::SlotPath &slot, const Plan &p) {
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
  const double in1 = inset(slot.end1), in2 = inset(slot.end2);
  if (slot.straight()) {
    const Vec2 along = (slot.to - slot.from).normalized();
    const double length = (slot.to - slot.from).norm();
    if (length - in1 - in2 < -1e-9)
      return std::nullopt;
    const Vec2 a = slot.from + along * in1;
    const Vec2 b = slot.from + along * std::max(in1, length - in2);
    return Path2D{Seg::line(a, b)};
  }
  // A course of lines and arcs: cut back along its length until the tool's
  // edge is `inset` from the end (square across the course there: on an end
  // arc of radius R the angle asin(inset / R) back), or continued along its
  // end tangents past open ends.
  auto back = [](double by, const Seg &end) {
    if (by <= 0 || !end.isArc())
      return std::max(by, 0.0);
    const double r = end.radius();
    return r * std::asin(std::min(1.0, by / r));
  };
  double length = 0;
  for (const Seg &sg : slot.course)
    length += sg.length();
  const double from = back(in1, slot.course.front()), to = length - back(in2, slot.course.back());
  if (to - from < -1e-9)
    return std::nullopt;
  Path2D path;
  if (in1 < 0) {
    const Vec2 a = slot.course.front().a;
    path.push_back(Seg::line(a + slot.course.front().tangent(0) * in1, a));
  }
  double run = 0;
  for (const Seg &sg : slot.course) {
    const double len = sg.length(), lo = std::max(from, run), hi = std::min(to, run + len);
    if (hi - lo > geom::kEps) {
      const Vec2 a = sg.at((lo - run) / len), b = sg.at((hi - run) / len);
      path.push_back(sg.isArc() ? Seg::arc(a, b, sg.c, sg.turn > 0) : Seg::line(a, b));
    }
    run += len;
  }
  if (in2 < 0) {
    const Vec2 b = slot.course.back().b;
    path.push_back(Seg::line(b, b - slot.course.back().tangent(1) * in2));
  }
  if (path.empty())
    return std::nullopt;
  return path;
}

std::optional<std::vector<Path2D>> strategyPaths(const std::string &type, bool face, bool unbounded, bool sideOnly,
                                                 const Region &centres, const Vec2 &strokeDir, double stepover,
                                                 bool followOrientation, double radius) {
  const bool strokesOnly = type == "bidirectional" || type == "unidirectional";
  if (face && strokesOnly)
    return strokes(centres, strokeDir, stepover, type == "bidirectional", radius);
  if (sideOnly) {
    // Side milling follows the walls; with no walls around (outside
    // profiles, faces) only the rings round what stands.
    std::vector<Path2D> out = rings(centres, stepover, followOrientation, /*all=*/false, radius);
    if (face || unbounded)
      std::erase_if(out, [&](const Path2D &ring) { return (Loop{ring}.area() > 0) == followOrientation; });
    return out;
  }
  if (type == "contour_parallel" || type == "contour_spiral")
    return rings(centres, stepover, followOrientation, /*all=*/true, radius);
  if (strokesOnly)
    return strokes(centres, strokeDir, stepover, type == "bidirectional", 0);
  if (type == "contour_bidirectional" || type == "bidirectional_contour") {
    // Zigzag inside the first ring, and the ring: before or after.
    std::vector<Path2D> ring = rings(centres, stepover, followOrientation, false, radius);
    std::vector<Path2D> zig = strokes(geom::offset(centres, -stepover), strokeDir, stepover, true, 0);
    std::vector<Path2D> paths = type == "contour_bidirectional" ? ring : zig;
    const auto &rest = type == "contour_bidirectional" ? zig : ring;
    paths.insert(paths.end(), rest.begin(), rest.end());
    return paths;
  }
  return std::nullopt;
}

Region centreArea(const ir::FeatureShape &s, const Region &area, const std::vector<Region> &keepOut, const Plan &p) {
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
  for (const Region &k : keepOut)
    centres = geom::subtract(centres, k);
  return centres;
}

namespace {

/// Where the centre of the tool, its tip at z, may not be for a boss whose
/// walls lean in (ir::IslandShape::sectionAt). The tool is a body: at height
/// h above its tip a disc of radius R - rc + sqrt(rc^2 - (rc - h)^2) through
/// its corner (rc), R above; grown all round by the side allowance a (R + a,
/// rc + a, its tip a lower), it must keep out of the boss's section at every
/// height. The sections shrink going up, so only the heights through the
/// grown corner count (above it the body is a cylinder meeting less): those
/// heights are sampled (sliceSampling) and each section grown by the body's
/// radius there plus the margin; the union is the keep-out area.
Region slopedKeepOut(const ir::IslandShape &isl, double z, const Plan &p) {
  const double a = p.allowanceSide, radius = p.radius + a, corner = ir::cornerRadius(*p.tool) + a, tip = z - a;
  auto body = [&](double v) { return bodyRadius(radius, corner, v - tip); };
  const double lo = std::max(tip, isl.foot), hi = std::min(tip + corner, isl.top);
  if (hi <= lo + 1e-9)
    return geom::offset(isl.sectionAt(lo), body(lo));
  const auto [step, margin] = sliceSampling(isl, corner);
  const int count = static_cast<int>(std::ceil((hi - lo) / step - 1e-9));
  std::vector<Region> slices;
  for (int k = 0; k <= count; ++k) {
    const double v = lo + (hi - lo) * k / count;
    slices.push_back(geom::offset(isl.sectionAt(v), body(v) + margin));
  }
  return geom::uniteAll(slices);
}

} // namespace

std::vector<Region> keepOutAt(const ir::FeatureShape &s, double z, const Plan &p) {
  std::vector<Region> out;
  for (const ir::IslandShape &isl : s.islands)
    if (isl.top > z + 1e-9)
      out.push_back(isl.sloped() ? slopedKeepOut(isl, z, p)
                                 : geom::offset(geom::offset(isl.region, p.allowanceSide), p.radius));
  return out;
}

bool counterClockwise(const Node *strategy, double spindle) {
  const std::string cutmode = strategy ? strategy->text("cutmode").value_or("") : "";
  const std::string rotation = strategy ? strategy->text("rotation").value_or("") : "";
  if (!cutmode.empty())
    return (cutmode == "climb") == (spindle <= 0);
  return rotation.empty() || rotation == "ccw";
}

bool linkAnywhere(const ir::FeatureShape &s) { return s.unbounded && s.islands.empty(); }

void cutPath(Emitter &e, const Path2D &given, double z, const Plan &p, const Node &op, const Region &centres,
             bool mayLink, bool anywhere, int &fallbacks) {
  if (given.empty())
    return;
  // A closed ring starts where it is nearest to the tool.
  Path2D nearest;
  if (e.positioned() && given.size() > 1 && (given.front().a - given.back().b).norm() < 1e-7) {
    Loop ring;
    ring.segs = given;
    nearest = startNearest(ring, e.position().head<2>()).segs;
  }
  const Path2D &path = nearest.empty() ? given : nearest;
  const Vec2 start = path.front().a;
  bool linked = false;
  if (mayLink && e.positioned() && std::abs(e.position().z() - z) < 1e-9) {
    const Vec2 here = e.position().head<2>();
    std::vector<Seg> inside = geom::clip(centres, here, start);
    double len = 0;
    for (const Seg &sg : inside)
      len += sg.length();
    if (anywhere || std::abs(len - (start - here).norm()) < 1e-6) {
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
    approach(e, path, z, p, op, centres, fallbacks);
  for (const Seg &sg : path)
    e.seg(sg, z, p.feed);
}

void reportApproachFallbacks(Expander &x, const Step &step, int fallbacks) {
  const Node *a = step.op.child(ir::Kind::Approach);
  if (fallbacks == 0 || !a)
    return;
  const std::string type = a->text("type").value_or("");
  x.assumed(step.ws, *a,
            "approach " + type + " does not fit at " + std::to_string(fallbacks) + " path start" +
                (fallbacks == 1 ? "" : "s") +
                (type == "plunge_helix" ? " (the helix leaves the area the tool centre may reach)"
                                        : " (no straight first segment longer than the tool's diameter)") +
                ": plunging along the tool axis there");
}

} // namespace stepnc::passes::expand
