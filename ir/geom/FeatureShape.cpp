#include "ir/geom/FeatureShape.h"

#include "geom/Boolean.h"
#include "ir/Kinds.h"
#include "ir/geom/Curves.h"
#include "support/Format.h"

#include <cmath>
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
    s.islands.push_back({feature.symbol, outer(mapLoop(*l, s.frame)), s.top});
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
      s.islands.push_back({boss->symbol, outer(mapLoop(*l, *fr.frame)), fr.frame->z});
    }
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
    const auto path = straightPath(feature, s, "course of travel");
    if (!path)
      return false;
    const auto [a, b] = *path;
    double width = 0;
    if (const Node *p = feature.child(ir::Kind::SquareUProfile))
      width = *p->number("width");
    else if (const Node *q = feature.child(ir::Kind::RoundedUProfile))
      width = *q->number("width");
    else if (feature.child(ir::Kind::VeeProfile) || feature.child(ir::Kind::PartialCircularProfile))
      return fail("slot " + feature.symbol + " has slanted or curved walls; 2.5D strategies cut vertical walls "
                  "only (plan: z-level passes with a form or tapered tool)");
    else
      return fail("slot " + feature.symbol + " has no cross-section profile");
    const Vec2 along = (b - a).normalized();
    const Vec2 n(-along.y() * width / 2, along.x() * width / 2);
    const bool open1 = feature.text("end_1") == "open", open2 = feature.text("end_2") == "open";
    const bool round1 = feature.text("end_1") == "radiused", round2 = feature.text("end_2") == "radiused";
    for (const char *end : {"end_1", "end_2"})
      if (auto w = feature.text(end); w == "woodruff" || w == "loop")
        return fail("slot " + feature.symbol + ": " + *w + " slot ends are not supported yet");
    // The target: the straight part, with half circles for radiused ends.
    Loop l;
    l.segs.push_back(Seg::line(a - n, b - n));
    if (round2)
      l.segs.push_back(Seg::arc(b - n, b + n, b, true));
    else
      l.segs.push_back(Seg::line(b - n, b + n));
    l.segs.push_back(Seg::line(b + n, a + n));
    if (round1)
      l.segs.push_back(Seg::arc(a + n, a - n, a, true));
    else
      l.segs.push_back(Seg::line(a + n, a - n));
    s.target = outer(l);
    s.slot = FeatureShape::SlotPath{a, b, width, std::string(*feature.text("end_1")), std::string(*feature.text("end_2"))};
    // Open ends: the slot's width continued into the air past them.
    const Vec2 e = along * kOpenReach;
    s.limit = s.target;
    if (open1)
      s.limit = geom::unite(s.limit, outer(geom::polygon({a - n - e, a - n, a + n, a + n - e})));
    if (open2)
      s.limit = geom::unite(s.limit, outer(geom::polygon({b - n, b - n + e, b + n + e, b + n})));
    return true;
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

ShapeResult featureShape(const ir::Module &module, const ir::Node &feature) {
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
