#include "ir/geom/FeatureShape.h"

#include "geom/Boolean.h"
#include "ir/Kinds.h"
#include "ir/geom/Curves.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <numbers>

namespace stepnc::ir {

namespace {

using geom::Loop;
using geom::Region;
using geom::Seg;
using geom::Vec2;
using ir::Node;

/// How far past an open side the tool may go: the area beyond is air.
constexpr double kOpenReach = 500.0;

/// Makes outer loops counter-clockwise (a mirrored frame turns them over).
Region outer(Loop l) {
  if (l.area() < 0)
    l.reverse();
  Region r;
  r.loops.push_back(std::move(l));
  return r;
}

/// Maps a loop from a frame's local coordinates to workpiece coordinates.
Loop mapLoop(const Loop &l, const PlaneFrame &f) {
  Loop out;
  for (const Seg &s : l.segs) {
    Seg m = s;
    m.a = f.map(s.a);
    m.b = f.map(s.b);
    m.c = f.map(s.c);
    if (f.mirrored())
      m.turn = static_cast<int8_t>(-m.turn);
    out.segs.push_back(m);
  }
  return out;
}

/// The outline of a slot with vertical walls along the line a -> b (its
/// middle), `width` wide: the straight part with half circles for radiused
/// ends (target), and the width continued into the air past open ends (limit).
/// `united`: the limit as the union of the target and the open ends' strips
/// (how slots have always been outlined); else the same region drawn as one
/// loop, without a Boolean (the outline of every height of a sectioned slot).
void outlineSlot(FeatureShape &s, const Vec2 &a, const Vec2 &b, double width, const std::string &end1,
                 const std::string &end2, bool united = true) {
  const Vec2 along = (b - a).normalized();
  const Vec2 n(-along.y() * width / 2, along.x() * width / 2);
  const Vec2 e = along * kOpenReach;
  auto outline = [&](const Vec2 &from, const Vec2 &to, bool reach) {
    const Vec2 p = reach && end1 == "open" ? from - e : from, q = reach && end2 == "open" ? to + e : to;
    Loop l;
    l.segs.push_back(Seg::line(p - n, q - n));
    if (end2 == "radiused")
      l.segs.push_back(Seg::arc(q - n, q + n, q, true));
    else
      l.segs.push_back(Seg::line(q - n, q + n));
    l.segs.push_back(Seg::line(q + n, p + n));
    if (end1 == "radiused")
      l.segs.push_back(Seg::arc(p + n, p - n, p, true));
    else
      l.segs.push_back(Seg::line(p + n, p - n));
    return outer(l);
  };
  s.target = outline(a, b, false);
  s.slot = FeatureShape::SlotPath{a, b, width, end1, end2, {Seg::line(a, b)}};
  if (!united) {
    s.limit = outline(a, b, true);
    return;
  }
  s.limit = s.target;
  if (end1 == "open")
    s.limit = geom::unite(s.limit, outer(geom::polygon({a - n - e, a - n, a + n, a + n - e})));
  if (end2 == "open")
    s.limit = geom::unite(s.limit, outer(geom::polygon({b - n, b - n + e, b + n + e, b + n})));
}

class ShapeBuilder {
public:
  ShapeBuilder(const ir::Module &m, const Node *workpiece) : module_(m), workpiece_(workpiece) {}

  std::string error;

  /// The first profile child of `owner` (the boundary: an open pocket's wall
  /// boundary comes after it), with the frame of its own placement within the
  /// owner, if it has one.
  const Node *profile(const Node &owner, std::optional<PlaneFrame> &local) {
    const Node *p = nullptr;
    for (const Node &c : owner.children)
      if (c.category() == ir::Category::Profile && !p)
        p = &c;
    if (!p) {
      fail(owner.kindName() + " " + owner.symbol + " has no profile");
      return nullptr;
    }
    if (p->has("at")) {
      FrameResult fr = planeFrame(*p);
      if (!fr.frame) {
        fail(fr.error);
        return nullptr;
      }
      local = *fr.frame;
    }
    return p;
  }

  /// A closed profile (child of `owner`) as a loop in the owner's local coordinates.
  std::optional<Loop> closedProfile(const Node &owner, double cornerRadius) {
    std::optional<PlaneFrame> local;
    const Node *p = profile(owner, local);
    if (!p)
      return std::nullopt;
    Loop l;
    if (p->kind == ir::Kind::RectangularProfile) {
      // Centred on the profile's origin, its length along x and its width along y.
      const Vec2 half(*p->number("length") / 2, *p->number("width") / 2);
      l = geom::roundedRectangle(-half, half, cornerRadius);
    } else if (p->kind == ir::Kind::CircularProfile) {
      l = geom::circleLoop(Vec2::Zero(), *p->number("diameter") / 2, true);
    } else if (p->kind == ir::Kind::GeneralProfile) {
      if (!p->flag("closed").value_or(false) || p->children.empty()) {
        fail("the general profile of " + owner.symbol + " is not closed");
        return std::nullopt;
      }
      CurveResult cr = curvePieces(p->children.front());
      if (!cr.error.empty()) {
        fail("the profile of " + owner.symbol + ": " + cr.error);
        return std::nullopt;
      }
      l.segs = planarSegs(cr.pieces);
      if (l.segs.empty() || (l.segs.front().a - l.segs.back().b).norm() > 1e-6) {
        fail("the general profile of " + owner.symbol + " does not close on itself");
        return std::nullopt;
      }
      l.segs.back().b = l.segs.front().a;
    } else {
      fail("a " + p->kindName() + " is not a closed profile (" + owner.kindName() + " " + owner.symbol + ")");
      return std::nullopt;
    }
    return local ? mapLoop(l, *local) : l;
  }

  /// An open pocket: the area its open boundary (the walls, an open profile)
  /// closes with the straight line between its ends, which is the open side:
  /// beyond that line is air.
  bool openPocket(const Node &feature, FeatureShape &s) {
    std::optional<PlaneFrame> local;
    const Node *p = profile(feature, local);
    if (!p)
      return false;
    if (p->kind != ir::Kind::GeneralProfile || p->flag("closed").value_or(true) || p->children.empty())
      return fail("the open boundary of pocket " + feature.symbol + " is a " + p->kindName() +
                  ": an open pocket is expanded from an open general profile (its walls)");
    CurveResult cr = curvePieces(p->children.front());
    if (!cr.error.empty())
      return fail("the open boundary of " + feature.symbol + ": " + cr.error);
    Loop walls;
    walls.segs = planarSegs(cr.pieces);
    if (walls.segs.empty())
      return fail("the open boundary of " + feature.symbol + " is empty");
    if (local)
      walls = mapLoop(walls, *local);
    walls = mapLoop(walls, s.frame);
    const Vec2 a = walls.segs.back().b, b = walls.segs.front().a;  // the open side, from the walls' end to their start
    Loop l = walls;
    l.segs.push_back(Seg::line(a, b));
    const double area = l.area();
    if (std::abs(area) < geom::kEps || (a - b).norm() < geom::kEps)
      return fail("the open boundary of pocket " + feature.symbol +
                  " encloses no area with the line between its ends");
    s.target = outer(l);
    // The outward side of the opening: right of a -> b when the loop runs counter-clockwise.
    const Vec2 along = (b - a).normalized();
    const Vec2 out = area > 0 ? Vec2(along.y(), -along.x()) : Vec2(-along.y(), along.x());
    const Vec2 e = along * kOpenReach, o = out * kOpenReach;
    s.limit = geom::unite(s.target, outer(geom::polygon({a - e, a - e + o, b + e + o, b + e})));
    return true;
  }

  /// A general outside profile: the material around its boundary, out to the
  /// raw piece's edges, is removed; the boundary stands as an island to the
  /// feature's top. The tool may pass every outer side.
  bool outsideProfile(const Node &feature, FeatureShape &s) {
    std::optional<Loop> l = closedProfile(feature, 0);
    if (!l)
      return false;
    const geom::Box stock = rawBox();
    if (stock.empty())
      return fail("general outside profile " + feature.symbol +
                  ": its workpiece has no block raw piece to tell how much material surrounds it");
    s.target = outer(geom::polygon(
        {stock.lo, Vec2(stock.hi.x(), stock.lo.y()), stock.hi, Vec2(stock.lo.x(), stock.hi.y())}));
    s.unbounded = true;
    s.islands.push_back({feature.symbol, outer(mapLoop(*l, s.frame)), s.top, s.bottom, 0});
    return true;
  }

  void islands(const Node &feature, FeatureShape &s) {
    for (const Node *island : feature.childrenOf(ir::Kind::Island)) {
      const Node *boss = findFeature(module_, *island->text("feature"));
      if (!boss)
        continue;  // the IR verifier reports dangling references
      FrameResult fr = planeFrame(*boss);
      if (!fr.frame) {
        fail(fr.error);
        return;
      }
      std::optional<Loop> l = closedProfile(*boss, 0);
      if (!l)
        return;
      IslandShape isl{boss->symbol, outer(mapLoop(*l, *fr.frame)), fr.frame->z, fr.frame->z, 0};
      if (!sloped(*boss, isl))
        return;
      s.islands.push_back(std::move(isl));
    }
  }

  /// A boss's slope (degrees from the vertical, leaning in going up) and foot:
  /// refused when it leans out (an undercut), is 80 deg or more, or shrinks
  /// its outline to nothing below its top.
  bool sloped(const Node &boss, IslandShape &isl) {
    const double depth = boss.number("depth").value_or(0);
    isl.foot = isl.top - depth;
    const double deg = boss.number("slope").value_or(0);
    if (deg == 0)
      return true;
    if (!(deg > 0 && deg < 80))
      return fail("boss " + boss.symbol + ": a slope of " + formatShortest(deg) +
                  " deg is not expanded (walls leaning in going up, from more than 0 up to 80 deg)");
    if (!(depth > 0))
      return fail("boss " + boss.symbol + ": a slope needs a depth (the height of its walls) to stand on");
    isl.slope = std::tan(deg * std::numbers::pi / 180);
    if (isl.sectionAt(isl.top).area() <= 1e-9)
      return fail("boss " + boss.symbol + ": its walls, leaning in by " + formatShortest(deg) + " deg over its " +
                  formatShortest(depth) + " mm depth, close its outline below its top");
    return true;
  }

  /// The feature's `path` when it is one straight piece, mapped to workpiece
  /// coordinates; `what` names the path in messages ("open boundary").
  std::optional<std::pair<Vec2, Vec2>> straightPath(const Node &feature, const FeatureShape &s,
                                                    const std::string &what) {
    const Node *path = feature.child(ir::Kind::Path);
    std::vector<CurvePiece> pieces;
    if (path && !path->children.empty()) {
      CurveResult cr = curvePieces(path->children.front());
      if (!cr.error.empty()) {
        fail("the " + what + " of " + feature.symbol + ": " + cr.error);
        return std::nullopt;
      }
      pieces = std::move(cr.pieces);
    }
    if (pieces.size() != 1 || pieces[0].arc) {
      fail("only " + feature.kindName() + "s along one straight " + what + " are supported (" + feature.symbol + ")");
      return std::nullopt;
    }
    return std::pair(s.frame.map(pieces[0].from.head<2>()), s.frame.map(pieces[0].to.head<2>()));
  }

  /// Material beside a straight open boundary, towards the nearer edge of the raw piece.
  bool step(const Node &feature, FeatureShape &s) {
    const auto path = straightPath(feature, s, "open boundary");
    if (!path)
      return false;
    const auto [a, b] = *path;
    const Vec2 along = (b - a).normalized();
    const Vec2 left(-along.y(), along.x());
    // The step's width: from the boundary to the raw piece's edge on the nearer side.
    const geom::Box stock = rawBox();
    if (stock.empty())
      return fail("step " + feature.symbol + ": its workpiece has no block raw piece to tell which side is removed");
    auto reach = [&](const Vec2 &dir) {
      double best = 0;
      for (const Vec2 &corner : {stock.lo, stock.hi, Vec2(stock.lo.x(), stock.hi.y()), Vec2(stock.hi.x(), stock.lo.y())})
        best = std::max(best, (corner - a).dot(dir));
      return best;
    };
    const double toLeft = reach(left), toRight = reach(-left);
    const Vec2 side = toLeft <= toRight ? left : Vec2(-left);
    const double width = std::min(toLeft, toRight);
    if (width <= geom::kEps)
      return fail("step " + feature.symbol + " lies on the raw piece's edge: nothing to remove");
    s.target = outer(geom::polygon({a, b, b + side * width, a + side * width}));
    // Only the boundary itself is a wall: the ends and the far side are open.
    const Vec2 e = along * kOpenReach;
    s.limit = outer(geom::polygon({a - e, b + e, b + e + side * (width + kOpenReach), a - e + side * (width + kOpenReach)}));
    return true;
  }

  bool slot(const Node &feature, FeatureShape &s) {
    if (const Node *path = feature.child(ir::Kind::Path); path && !path->children.empty()) {
      CurveResult cr = curvePieces(path->children.front());
      if (cr.error.empty() && (cr.pieces.size() > 1 || (cr.pieces.size() == 1 && cr.pieces[0].arc)))
        return curvedSlot(feature, s, cr.pieces);
    }
    const auto path = straightPath(feature, s, "course of travel");
    if (!path)
      return false;
    const auto [a, b] = *path;
    for (const char *end : {"end_1", "end_2"})
      if (auto w = feature.text(end); w == "woodruff" || w == "loop")
        return fail("slot " + feature.symbol + ": " + *w + " slot ends are not supported yet");
    const double depth = s.top - s.bottom;
    double lo = 0, hi = 0;  // the walls at the top, left of the course
    if (const Node *p = feature.child(ir::Kind::SquareUProfile)) {
      hi = *p->number("width") / 2;
      lo = -hi;
    } else {
      std::optional<SlotSection> section;
      if (const Node *q = feature.child(ir::Kind::RoundedUProfile))
        section = circularSection(feature, *q->number("width") / 2, 180, depth);
      else if (const Node *v = feature.child(ir::Kind::VeeProfile))
        section = veeSection(feature, *v, depth);
      else if (const Node *c = feature.child(ir::Kind::PartialCircularProfile))
        section = circularSection(feature, *c->number("radius"), *c->number("sweep_angle"), depth);
      else
        return fail("slot " + feature.symbol + " has no cross-section profile");
      if (!section)
        return false;
      std::tie(lo, hi) = *section->span(depth);
      s.section = std::move(*section);
    }
    if (hi - lo <= geom::kEps)
      return fail("slot " + feature.symbol + " has no width at its top");
    const Vec2 left = Vec2(-(b - a).y(), (b - a).x()).normalized();
    const double mid = (lo + hi) / 2;
    outlineSlot(s, a + left * mid, b + left * mid, hi - lo, std::string(*feature.text("end_1")),
                std::string(*feature.text("end_2")));
    return true;
  }

  /// A slot along a course of lines and arcs (a general path), its walls
  /// vertical (a square U profile) `width` apart about the course: the area
  /// within width / 2 of it, its ends radiused (half discs), flat (cut square
  /// across the course's end) or open (flat, the width continued into the
  /// air past the end in the limit).
  bool curvedSlot(const Node &feature, FeatureShape &s, const std::vector<CurvePiece> &pieces) {
    const Node *profile = feature.child(ir::Kind::SquareUProfile);
    if (!profile)
      return fail("slot " + feature.symbol + " runs along a curved or polyline course: stepnc makes such slots with "
                  "vertical walls (a square U profile) only");
    for (const char *end : {"end_1", "end_2"})
      if (auto w = feature.text(end); w == "woodruff" || w == "loop")
        return fail("slot " + feature.symbol + ": " + *w + " slot ends are not supported yet");
    const double width = profile->number("width").value_or(0);
    if (!(width > geom::kEps))
      return fail("slot " + feature.symbol + " has no width at its top");
    std::vector<Seg> course;
    for (const CurvePiece &c : pieces) {
      if (c.turns > 0)
        return fail("slot " + feature.symbol + ": its course of travel turns full circles");
      const Vec2 a = s.frame.map(c.from.head<2>()), b = s.frame.map(c.to.head<2>());
      if ((b - a).norm() <= geom::kEps && !c.arc)
        continue;
      course.push_back(c.arc ? Seg::arc(a, b, s.frame.map(c.center.head<2>()), c.ccw != s.frame.mirrored())
                             : Seg::line(a, b));
    }
    if (course.empty())
      return fail("slot " + feature.symbol + ": its course of travel has no length");
    for (size_t i = 1; i < course.size(); ++i)
      if ((course[i].a - course[i - 1].b).norm() > 1e-6)
        return fail("slot " + feature.symbol + ": its course of travel is not one connected path");
    const std::string end1(*feature.text("end_1")), end2(*feature.text("end_2"));
    const double half = width / 2;
    // Past each end, along the course's tangent there: the square cut off a
    // flat or open end (a little wider than the slot), and the strip an open
    // end continues into.
    auto beyond = [&](const Vec2 &p, const Vec2 &out, double length, double across) {
      const Vec2 n(-out.y() * across, out.x() * across);
      return outer(geom::polygon({p - n, p - n + out * length, p + n + out * length, p + n}));
    };
    const Vec2 start = course.front().a, finish = course.back().b;
    const Vec2 out1 = -course.front().tangent(0), out2 = course.back().tangent(1);
    Region target = geom::sweptDisc(course, half);
    std::vector<Region> caps, strips;
    for (const auto &[end, p, out] : {std::tuple(end1, start, out1), std::tuple(end2, finish, out2)}) {
      if (end != "radiused")
        caps.push_back(beyond(p, out, half * 1.5, half * 1.5));
      if (end == "open")
        strips.push_back(beyond(p, out, kOpenReach, half));
    }
    for (const Region &cap : caps)
      target = geom::subtract(target, cap);
    Region limit = target;
    for (const Region &strip : strips)
      limit = geom::unite(limit, strip);
    s.target = std::move(target);
    s.limit = std::move(limit);
    s.slot = FeatureShape::SlotPath{start, finish, width, end1, end2, std::move(course)};
    return true;
  }

  /// A partial circular profile of radius r and sweep (deg) whose lowest
  /// point is the slot's floor, its ends at the same height; above them, to
  /// the slot's top, vertical walls (a rounded-U profile is one of 180 deg
  /// under its straight part). A slot shallower than the arc cuts it there.
  std::optional<SlotSection> circularSection(const Node &feature, double r, double sweepDeg, double depth) {
    if (!(r > geom::kEps) || !(sweepDeg > 0 && sweepDeg <= 180 + 1e-9)) {
      fail("slot " + feature.symbol + ": a circular cross-section of radius " + formatFixed(r, 4) + " mm and sweep " +
           formatFixed(sweepDeg, 4) + " deg is not one a tool from above can cut (a radius above 0, a sweep up to 180 deg)");
      return std::nullopt;
    }
    const double half = std::min(sweepDeg, 180.0) / 2 * std::numbers::pi / 180;
    const Vec2 c(0, r);
    const double endHeight = r * (1 - std::cos(half));
    SlotSection sec;
    sec.depth = depth;
    if (depth <= endHeight + 1e-9) {
      const double u = std::sqrt(std::max(0.0, r * r - (r - depth) * (r - depth)));
      sec.walls.push_back(Seg::arc(Vec2(-u, depth), Vec2(u, depth), c, true));
      return sec;
    }
    const Vec2 e1(-r * std::sin(half), endHeight), e2(r * std::sin(half), endHeight);
    sec.walls.push_back(Seg::line(Vec2(e1.x(), depth), e1));
    sec.walls.push_back(Seg::arc(e1, e2, c, true));
    sec.walls.push_back(Seg::line(e2, Vec2(e2.x(), depth)));
    return sec;
  }

  /// A vee profile: two straight flanks profile_angle apart, the first (on
  /// the right of the course of travel) tilt_angle from the vertical, meeting
  /// on the course of travel, the vee rounded at the bottom to its
  /// profile_radius; its lowest point is the slot's floor.
  std::optional<SlotSection> veeSection(const Node &feature, const Node &vee, double depth) {
    const double deg = std::numbers::pi / 180;
    const double angle = vee.number("profile_angle").value_or(0), tilt = vee.number("tilt_angle").value_or(0);
    const double radius = vee.number("profile_radius").value_or(0);
    const Vec2 d1(-std::sin(tilt * deg), std::cos(tilt * deg));
    const Vec2 d2(std::sin((angle - tilt) * deg), std::cos((angle - tilt) * deg));
    if (!(angle > 0 && angle < 180) || tilt < 0 || tilt > angle || d1.y() <= geom::kEps || d2.y() <= geom::kEps ||
        radius < 0) {
      fail("slot " + feature.symbol + ": a vee of " + formatFixed(angle, 4) + " deg tilted " + formatFixed(tilt, 4) +
           " deg has a flank that does not rise from its bottom: a tool from above cannot cut it");
      return std::nullopt;
    }
    // The flanks from the apex (origin), the rounding tangent to both.
    const double half = angle / 2 * deg;
    const Vec2 centre = (d1 + d2).normalized() * (radius / std::sin(half));
    const double along = radius / std::tan(half);
    Vec2 t1 = d1 * along, t2 = d2 * along;
    const Vec2 shift(0, -(radius > 0 ? centre.y() - radius : 0.0));  // the lowest point to v = 0
    const Vec2 c = centre + shift;
    t1 += shift;
    t2 += shift;
    SlotSection sec;
    sec.depth = depth;
    if (radius > 0 && depth < std::max(t1.y(), t2.y()) - 1e-9) {
      if (depth > std::min(t1.y(), t2.y()) + 1e-9) {
        fail("slot " + feature.symbol + " is shallower than the rounding of its vee on one side");
        return std::nullopt;
      }
      const double u = std::sqrt(std::max(0.0, radius * radius - (depth - c.y()) * (depth - c.y())));
      sec.walls.push_back(Seg::arc(Vec2(c.x() - u, depth), Vec2(c.x() + u, depth), c, true));
      return sec;
    }
    auto topOf = [&](const Vec2 &from, const Vec2 &dir) { return from + dir * ((depth - from.y()) / dir.y()); };
    sec.walls.push_back(Seg::line(topOf(t1, d1), t1));
    if (radius > 0)
      sec.walls.push_back(Seg::arc(t1, t2, c, true));
    sec.walls.push_back(Seg::line(t2, topOf(t2, d2)));
    std::erase_if(sec.walls, [](const Seg &sg) { return (sg.b - sg.a).norm() <= geom::kEps; });
    return sec;
  }

  bool fail(std::string message) {
    if (error.empty())
      error = std::move(message);
    return false;
  }

private:
  geom::Box rawBox() const {
    const std::optional<RawBlock> raw = rawBlock(workpiece_);
    return raw ? raw->box : geom::Box{};
  }

  const ir::Module &module_;
  const Node *workpiece_;
};

} // namespace

FrameResult planeFrame(const ir::Node &placed) {
  const ir::Vec3 at = placed.vec("at").value_or(ir::Vec3::Zero());
  const ir::Vec3 axis = placed.vec("axis").value_or(ir::Vec3::UnitZ());
  const ir::Vec3 ref = placed.vec("ref").value_or(ir::Vec3::UnitX());
  if (std::abs(axis.z() - 1) > 1e-9)
    return {std::nullopt, placed.kindName() + (placed.symbol.empty() ? "" : " " + placed.symbol) + " has its axis along " +
                              formatTuple({axis.x(), axis.y(), axis.z()}, 6) + ": only features facing the tool axis +z are expanded (plan: "
                              "setups per face orientation)"};
  PlaneFrame f;
  f.origin = at.head<2>();
  f.x = ref.head<2>().normalized();
  f.y = Vec2(-f.x.y(), f.x.x());
  f.z = at.z();
  return {f, {}};
}

double pointLength(const ir::Node &tool) {
  const double half = tool.number("tip_half_angle").value_or(0);
  if (!(half > 0 && half < 90))
    return 0;
  return tool.number("diameter").value_or(0) / 2 * std::tan(half * std::numbers::pi / 180);
}

std::optional<RawBlock> rawBlock(const ir::Node *workpiece) {
  const Node *raw = workpiece ? workpiece->child(ir::Kind::Rawpiece) : nullptr;
  if (!raw || raw->text("shape") != "block" || !raw->has("size"))
    return std::nullopt;
  FrameResult fr = planeFrame(*raw);
  if (!fr.frame)
    return std::nullopt;
  const ir::Vec3 size = *raw->vec("size");
  RawBlock block;
  for (const Vec2 &c : {Vec2(0, 0), Vec2(size.x(), 0), Vec2(size.x(), size.y()), Vec2(0, size.y())})
    block.box.add(fr.frame->map(c));
  block.bottom = fr.frame->z;
  block.top = fr.frame->z + size.z();
  return block;
}

namespace {

/// ISO 14649-10: a pocket's orthogonal_radius is the radius between its
/// walls, whatever its profile. A rectangle is built with it; a general
/// profile's every corner that turns into the pocket is rounded here: the
/// opening of the area by the radius (shrunk, then grown back), which rounds
/// exactly the corners sharper than the radius and leaves the rest.
void roundCorners(const ir::Node &feature, FeatureShape &s) {
  const double radius = feature.number("orthogonal_radius").value_or(0);
  const ir::Node *profile = feature.child(ir::Kind::GeneralProfile);
  if (radius <= 0 || !profile)
    return;
  s.target = geom::growExact(geom::shrinkExact(s.target, radius), radius);
  s.limit = s.target;
}

} // namespace

std::optional<std::pair<double, double>> SlotSection::span(double v) const {
  if (v < -1e-9 || walls.empty())
    return std::nullopt;
  v = std::clamp(v, 0.0, depth);
  double lo = 1e300, hi = -1e300;
  auto take = [&](double u) {
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  };
  for (const Seg &sg : walls) {
    if (!sg.isArc()) {
      const double v0 = std::min(sg.a.y(), sg.b.y()), v1 = std::max(sg.a.y(), sg.b.y());
      if (v < v0 - 1e-12 || v > v1 + 1e-12)
        continue;
      if (v1 - v0 <= 1e-12) {
        take(sg.a.x());
        take(sg.b.x());
      } else {
        take(sg.a.x() + (sg.b.x() - sg.a.x()) * (v - sg.a.y()) / (sg.b.y() - sg.a.y()));
      }
      continue;
    }
    // The circle's points at height v that lie on the arc.
    const double r = sg.radius(), dv = v - sg.c.y();
    if (std::abs(dv) > r + 1e-12)
      continue;
    const double du = std::sqrt(std::max(0.0, r * r - dv * dv));
    for (double u : {sg.c.x() - du, sg.c.x() + du}) {
      const Vec2 p(u, v);
      const double start = std::atan2((sg.a - sg.c).y(), (sg.a - sg.c).x());
      double turn = std::atan2((p - sg.c).y(), (p - sg.c).x()) - start;
      if (sg.turn < 0)
        turn = -turn;
      turn = std::fmod(turn + 4 * std::numbers::pi, 2 * std::numbers::pi);
      if (turn <= std::abs(sg.sweep()) + 1e-9 || turn >= 2 * std::numbers::pi - 1e-9)
        take(u);
    }
  }
  if (lo > hi)
    return std::nullopt;
  return std::pair(lo, hi);
}

std::vector<double> SlotSection::breaks() const {
  std::vector<double> out;
  for (const Seg &sg : walls) {
    out.push_back(sg.a.y());
    out.push_back(sg.b.y());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end(), [](double x, double y) { return std::abs(x - y) <= 1e-9; }),
            out.end());
  return out;
}

FeatureShape slotBetween(const FeatureShape &slot, double lo, double hi) {
  FeatureShape s = slot;
  const FeatureShape::SlotPath &p = *slot.slot;
  const Vec2 left = Vec2(-(p.to - p.from).y(), (p.to - p.from).x()).normalized();
  // The slot path runs along the middle of the top; the course of travel is
  // where the section puts u = 0.
  double topMid = 0;
  if (slot.section)
    if (auto top = slot.section->span(slot.section->depth))
      topMid = (top->first + top->second) / 2;
  const double shift = (lo + hi) / 2 - topMid;
  outlineSlot(s, p.from + left * shift, p.to + left * shift, hi - lo, p.end1, p.end2, /*united=*/false);
  return s;
}

double cornerRadius(const ir::Node &tool) {
  const double radius = tool.number("diameter").value_or(0) / 2;
  if (tool.text("type") == "ball_endmill")
    return radius;
  return std::clamp(tool.number("corner_radius").value_or(0), 0.0, radius);
}

geom::Region IslandShape::sectionAt(double z) const {
  const double inset = (std::clamp(z, foot, top) - foot) * slope;
  return inset > 0 ? geom::offset(region, -inset) : region;
}

std::optional<geom::Loop> closedProfileLoop(const ir::Module &module, const ir::Node &owner, std::string &error) {
  ShapeBuilder b(module, nullptr);
  std::optional<Loop> l = b.closedProfile(owner, 0);
  if (!l)
    error = b.error;
  return l;
}

ShapeResult featureShape(const ir::Module &module, const ir::Node &feature) {
  if (feature.kind == ir::Kind::ToolpathFeature)
    return {std::nullopt, "toolpath_feature " + feature.symbol +
                              " has no shape (the file gives only its toolpaths): its moves are checked for the "
                              "safety rules only"};
  const Node *workpiece = workpieceOf(module, feature);
  FrameResult fr = planeFrame(feature);
  if (!fr.frame)
    return {std::nullopt, fr.error};
  FeatureShape s;
  s.symbol = feature.symbol;
  s.kind = feature.kind;
  s.frame = *fr.frame;
  s.top = s.frame.z;
  s.bottom = s.top - feature.number("depth").value_or(0);
  ShapeBuilder b(module, workpiece);
  bool ok = true;
  if (feature.kind == ir::Kind::ClosedPocket || feature.kind == ir::Kind::OpenPocket) {
    if (const double slope = feature.number("slope").value_or(0); slope != 0)
      return {std::nullopt, "pocket " + feature.symbol + " has walls with a slope of " + formatShortest(slope) +
                                " deg; pockets are expanded with vertical walls only (bosses may slope)"};
    if (feature.text("bottom") != "planar" && feature.text("bottom") != "through")
      return {std::nullopt, "pocket " + feature.symbol + " has a " + feature.text("bottom").value_or("") +
                                " bottom; only planar and through bottoms are expanded (plan: ball-end finishing)"};
    if (feature.kind == ir::Kind::OpenPocket) {
      ok = b.openPocket(feature, s);
    } else if (auto l = b.closedProfile(feature, feature.number("orthogonal_radius").value_or(0))) {
      s.target = outer(mapLoop(*l, s.frame));
      s.limit = s.target;
      roundCorners(feature, s);
    }
    b.islands(feature, s);
  } else if (feature.kind == ir::Kind::PlanarFace) {
    const Vec2 travel = s.frame.mapDir(feature.vec("travel_dir")->head<2>()).normalized();
    const Vec2 across = s.frame.mapDir(feature.vec("width_dir")->head<2>()).normalized();
    const Vec2 o = s.frame.origin;
    const Vec2 t = travel * *feature.number("travel"), w = across * *feature.number("width");
    s.target = outer(geom::polygon({o, o + w, o + w + t, o + t}));
    s.unbounded = true;
    b.islands(feature, s);
  } else if (feature.kind == ir::Kind::RoundHole) {
    s.holeCentre = s.frame.origin;
    s.holeDiameter = *feature.number("diameter");
    s.target = outer(geom::circleLoop(s.frame.origin, s.holeDiameter / 2, true));
    s.limit = s.target;
  } else if (feature.kind == ir::Kind::Slot) {
    ok = b.slot(feature, s);
  } else if (feature.kind == ir::Kind::Step) {
    ok = b.step(feature, s);
    b.islands(feature, s);
  } else if (feature.kind == ir::Kind::GeneralOutsideProfile) {
    ok = b.outsideProfile(feature, s);
  } else {
    return {std::nullopt, feature.kindName() + " " + feature.symbol + " is not a feature strategy expansion can cut"};
  }
  if (!ok || !b.error.empty() || s.target.empty())
    return {std::nullopt, b.error.empty() ? feature.kindName() + " " + feature.symbol + " has no usable outline" : b.error};
  return {std::move(s), {}};
}

} // namespace stepnc::ir
