#include "ir/geom/TurnedShape.h"

#include "ir/geom/Curves.h"
#include "ir/geom/MoveWalk.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace stepnc::ir {

using geom::Loop;
using geom::Region;
using geom::Seg;
using geom::Vec2;

namespace {

constexpr double kDegree = std::numbers::pi / 180;
/// How far off the axis a placement may lie and still be on it (mm).
constexpr double kOnAxis = 1e-6;

std::string named(const Node &n) { return n.kindName() + (n.symbol.empty() ? "" : " " + n.symbol); }

/// The placement of a turned feature in the half plane, or why it has none.
struct Placed {
  Vec2 at = Vec2::Zero();
  double sign = 1;
};

std::optional<Placed> placedOnAxis(const Node &n, std::string &error) {
  const Vec3 at = n.vec("at").value_or(Vec3::Zero());
  const Vec3 axis = n.vec("axis").value_or(Vec3::UnitZ());
  if (std::abs(at.x()) > kOnAxis || std::abs(at.y()) > kOnAxis) {
    error = named(n) + " is placed at " + formatTuple({at.x(), at.y(), at.z()}, 4) +
            " mm, off the turning axis (the workpiece's z axis): only features on it are turned";
    return std::nullopt;
  }
  if (std::abs(std::abs(axis.z()) - 1) > 1e-9) {
    error = named(n) + " has its axis along " + formatTuple({axis.x(), axis.y(), axis.z()}, 6) +
            ": a turned feature's axis is the turning axis (the workpiece's z axis, either way)";
    return std::nullopt;
  }
  return Placed{Vec2(at.z(), 0), axis.z() > 0 ? 1.0 : -1.0};
}

/// Whether a loop's segments meet only where consecutive ones join: a
/// profile that runs back along itself or crosses itself bounds no region.
bool simple(const Loop &l) {
  const size_t n = l.segs.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const bool next = j == i + 1, wrap = i == 0 && j == n - 1;
      for (const Vec2 &x : geom::intersect(l.segs[i], l.segs[j])) {
        const bool atJoint = (next && (x - l.segs[j].a).norm() < 1e-7) || (wrap && (x - l.segs[i].a).norm() < 1e-7);
        if (!atJoint)
          return false;
      }
    }
  return true;
}

/// A loop through the points in order, counter-clockwise whichever way they are given.
Loop ccwPolygon(const std::vector<Vec2> &pts) {
  Loop l = geom::polygon(pts);
  if (l.area() < 0) {
    std::vector<Vec2> back(pts.rbegin(), pts.rend());
    l = geom::polygon(back);
  }
  return l;
}

} // namespace

Region TurnStock::region() const { return Region{{ccwPolygon({{z0, 0}, {z1, 0}, {z1, radius}, {z0, radius}})}}; }

StockResult turnStock(const Node *workpiece) {
  if (!workpiece)
    return {std::nullopt, "the feature belongs to no workpiece"};
  const Node *raw = workpiece->child(ir::Kind::Rawpiece);
  if (!raw)
    return {std::nullopt, "workpiece " + workpiece->symbol +
                              " has no raw piece: turning needs the bar it starts from (a right_circular_cylinder "
                              "as its raw piece's bounding geometry)"};
  if (raw->text("shape") != "cylinder")
    return {std::nullopt, "the raw piece of workpiece " + workpiece->symbol + " is a " +
                              raw->text("shape").value_or("?") + ": turning takes a cylinder about the z axis"};
  std::string error;
  const std::optional<Placed> p = placedOnAxis(*raw, error);
  if (!p)
    return {std::nullopt, "the raw piece of workpiece " + workpiece->symbol + ": " + error};
  const double d = raw->number("diameter").value_or(0), h = raw->number("height").value_or(0);
  if (d <= 0 || h <= 0)
    return {std::nullopt, "the raw piece of workpiece " + workpiece->symbol + " has no diameter or height"};
  TurnStock s;
  s.z0 = std::min(p->at.x(), p->at.x() + p->sign * h);
  s.z1 = std::max(p->at.x(), p->at.x() + p->sign * h);
  s.radius = d / 2;
  return {s, {}};
}

namespace {

class Builder {
public:
  Builder(const Node &f, const TurnStock &stock, double margin)
      : f_(f), reachR_(stock.radius + margin), reachZ_(stock.z1 + margin), lowZ_(stock.z0 - margin) {}

  TurnedShapeResult build() {
    const std::optional<Placed> p = placedOnAxis(f_, error_);
    if (!p)
      return fail();
    s_.symbol = f_.symbol;
    s_.kind = f_.kind;
    s_.at = p->at;
    s_.axisSign = p->sign;
    switch (f_.kind) {
    case Kind::OuterDiameter: return outerDiameter(*p) ? ok() : fail();
    case Kind::OuterDiameterToShoulder: return toShoulder(*p) ? ok() : fail();
    case Kind::RevolvedFlat: return revolvedFlat(*p) ? ok() : fail();
    case Kind::Groove: return groove(*p) ? ok() : fail();
    case Kind::Thread: return thread(*p) ? ok() : fail();
    case Kind::GeneralRevolution: return generalRevolution() ? ok() : fail();
    case Kind::RoundHole: return roundHole(*p) ? ok() : fail();
    case Kind::RevolvedRound: return revolvedRound(*p) ? ok() : fail();
    case Kind::Knurl: return knurl(*p) ? ok() : fail();
    default:
      error_ = named(f_) + " has no turned shape in stepnc yet (docs/turning.md lists the features turned)";
      return fail();
    }
  }

private:
  TurnedShapeResult ok() { return {std::move(s_), {}}; }
  TurnedShapeResult fail() { return {std::nullopt, error_}; }

  /// The material outside a surface running from the free end towards the
  /// chuck along `wall` (its points from high z to low z), up to the reach.
  /// The surface continues at the chuck end straight out to the reach (a
  /// shoulder or the chuck); at the free end it runs on to the reach along z.
  void outside(const std::vector<Vec2> &wall) {
    std::vector<Vec2> pts;
    pts.emplace_back(reachZ_, wall.front().y());
    for (const Vec2 &q : wall)
      pts.push_back(q);
    pts.emplace_back(wall.back().x(), reachR_);
    pts.emplace_back(reachZ_, reachR_);
    s_.removal = Region{{ccwPolygon(pts)}};
  }

  /// The radii at the two ends of the feature's `diameter` over `length`:
  /// tapering to its `finalAttr` diameter, or by its taper angle (the radius
  /// falls by length x tan(angle)); nullopt, after an error, when one is not
  /// positive. `over` words the length in it ("", "a depth of ").
  std::optional<std::pair<double, double>> taperedRadii(const char *finalAttr, double length, const char *over) {
    const double d = f_.number("diameter").value_or(0);
    double r0 = d / 2, r1 = r0;
    if (auto reduced = f_.number(finalAttr))
      r1 = *reduced / 2;
    else if (auto taper = f_.number("taper_angle"))
      r1 = r0 - length * std::tan(*taper * kDegree);
    if (r0 <= 0 || length <= 0 || r1 <= 0) {
      error_ = named(f_) + ": its diameter " + formatFixed(d, 4) + " mm over " + over + formatFixed(length, 4) +
               " mm tapers to " + formatFixed(2 * r1, 4) + " mm: no turned surface";
      return std::nullopt;
    }
    return std::pair{r0, r1};
  }

  bool outerDiameter(const Placed &p) {
    const double length = f_.number("length").value_or(0);
    const auto radii = taperedRadii("reduced_diameter", length, "");
    if (!radii)
      return false;
    const auto [r0, r1] = *radii;
    // From the placement along its axis; the end nearer the free end (the
    // higher z) is open: what lies beyond it is another feature's.
    Vec2 a(p.at.x(), r0), b(p.at.x() + p.sign * length, r1);
    if (a.x() < b.x())
      std::swap(a, b);
    // Beyond the high end the surface runs on at its radius: conservative
    // (the step cuts nothing inside it there), and open for the tool.
    outside({a, b});
    s_.contour = {Seg::line(Vec2(reachZ_, a.y()), a), Seg::line(a, b), Seg::line(b, Vec2(b.x(), reachR_))};
    return true;
  }

  bool toShoulder(const Placed &p) {
    const double r = f_.number("diameter").value_or(0) / 2;
    if (r <= 0) {
      error_ = named(f_) + " has no diameter";
      return false;
    }
    double fillet = 0;
    if (const Node *vee = f_.child(Kind::VeeProfile)) {
      fillet = vee->number("profile_radius").value_or(0);
      const double angle = vee->number("profile_angle").value_or(90);
      const double tilt = vee->number("tilt_angle").value_or(0);
      if (std::abs(angle - 90) > 1e-9 || std::abs(tilt) > 1e-9) {
        error_ = named(f_) + ": a shoulder at " + formatTrimmed(angle, 4) + " deg tilted " + formatTrimmed(tilt, 4) +
                 " deg is not turned yet (square shoulders only: profile_angle 90, tilt_angle 0)";
        return false;
      }
    }
    if (p.sign < 0) {
      error_ = named(f_) + " runs towards the chuck (its axis along -z): a diameter to a shoulder is turned from "
                           "the free end (+z) towards its shoulder";
      return false;
    }
    // From the free end along the diameter to the shoulder at the placement,
    // round the fillet, up the shoulder face.
    const double z0 = p.at.x();
    const Vec2 start(reachZ_, r), corner(z0, r), up(z0, reachR_);
    if (fillet > 0) {
      const Vec2 c(z0 + fillet, r + fillet), t1(z0 + fillet, r), t2(z0, r + fillet);
      Loop l;
      l.segs = {Seg::line(t1, start), Seg::line(start, Vec2(reachZ_, reachR_)), Seg::line(Vec2(reachZ_, reachR_), up),
                Seg::line(up, t2), Seg::arc(t2, t1, c, true)};
      if (l.area() < 0)
        l.segs = {};
      s_.removal = Region{{l}};
      s_.contour = {Seg::line(start, t1), Seg::arc(t1, t2, c, false), Seg::line(t2, up)};
    } else {
      s_.removal = Region{{ccwPolygon({start, corner, up, Vec2(reachZ_, reachR_)})}};
      s_.contour = {Seg::line(start, corner), Seg::line(corner, up)};
    }
    return true;
  }

  bool revolvedFlat(const Placed &p) {
    // A face across the axis at the placement, from `radius` out over its
    // linear profile's length; the material is on `material_side` (along z).
    const double inner = f_.number("radius").value_or(0);
    const Node *prof = f_.child(Kind::LinearProfile);
    const double extent = prof ? prof->number("length").value_or(0) : 0;
    const Vec3 side = f_.vec("material_side").value_or(Vec3(0, 0, -p.sign));
    if (std::abs(std::abs(side.z()) - 1) > 1e-9) {
      error_ = named(f_) + ": its material side " + formatTuple({side.x(), side.y(), side.z()}, 6) +
               " is not along the axis: a face across the axis has its material on one side of it";
      return false;
    }
    if (inner < 0 || extent <= 0) {
      error_ = named(f_) + " needs its radius and a linear profile with a length (the face's radial extent)";
      return false;
    }
    if (side.z() > 0) {
      // A face looking towards the chuck (the part on the free end's side):
      // what it removes is the bar between it and the chuck, as parting
      // off does; no tool faces it from the chuck's side.
      const double z0 = p.at.x();
      s_.removal = Region{{ccwPolygon({{lowZ_, inner}, {z0, inner}, {z0, reachR_}, {lowZ_, reachR_}})}};
      s_.contour = {Seg::line(Vec2(z0, reachR_), Vec2(z0, inner))};
      s_.towardsChuck = true;
      return true;
    }
    // Cleared from its inner radius out to the reach, whatever the profile's
    // length: the tool comes in across the face from the outside.
    const double z0 = p.at.x();
    s_.removal = Region{{ccwPolygon({{z0, inner}, {reachZ_, inner}, {reachZ_, reachR_}, {z0, reachR_}})}};
    s_.contour = {Seg::line(Vec2(z0, reachR_), Vec2(z0, inner))};
    if (inner > 0)
      s_.contour.push_back(Seg::line(Vec2(z0, inner), Vec2(reachZ_, inner)));
    return true;
  }

  /// Which side of its surface the feature's material lies on: towards the
  /// axis (absent, -x: an outer surface) or away from it (+x: an inner
  /// one); nullopt, after an error naming `what` ("revolved profiles"), when
  /// it is neither.
  std::optional<bool> innerSide(const char *what) {
    const Vec3 side = f_.vec("material_side").value_or(Vec3(-1, 0, 0));
    if (std::abs(std::abs(side.x()) - 1) < 1e-9 && std::abs(side.z()) < 1e-9)
      return side.x() > 0;
    error_ = named(f_) + ": its material side " + formatTuple({side.x(), side.y(), side.z()}, 6) +
             " is neither towards the axis nor away from it: " + what + " with their material along the axis are "
             "not turned yet";
    return std::nullopt;
  }

  bool groove(const Placed &p) {
    // A groove: its floor at `radius`, its square-U profile's width centred
    // on the placement along the axis, open outwards (an outer groove) or
    // in towards the axis (an inner one, in a bore).
    const double floor = f_.number("radius").value_or(0);
    if (const Vec3 side = f_.vec("material_side").value_or(Vec3(-1, 0, 0));
        std::abs(std::abs(side.z()) - 1) < 1e-9)
      return faceGroove(p, side.z());
    const std::optional<bool> inner = innerSide("grooves");
    if (!inner)
      return false;
    const Node *u = f_.child(Kind::SquareUProfile);
    if (!u) {
      error_ = named(f_) + ": only grooves with a square_u_profile are turned yet";
      return false;
    }
    const double w = u->number("width").value_or(0);
    const double r1 = u->number("first_radius").value_or(0), r2 = u->number("second_radius").value_or(0);
    if (!squareWalls(*u))
      return false;
    if (floor <= 0 || w <= 0 || r1 < 0 || r2 < 0 || r1 + r2 > w + 1e-9) {
      error_ = named(f_) + ": its floor radius " + formatFixed(floor, 4) + " mm and width " + formatFixed(w, 4) +
               " mm (corner radii " + formatFixed(r1, 4) + " and " + formatFixed(r2, 4) + " mm) make no groove";
      return false;
    }
    const double lo = p.at.x() - w / 2, hi = p.at.x() + w / 2;
    // Walls from the open side (the reach, or the axis) to the floor,
    // round the corners (r1 at the low z wall, r2 at the high), along the
    // floor; `in` points from the floor towards the open side.
    const double in = *inner ? -1 : 1, open = *inner ? 0.0 : reachR_;
    const Vec2 topLo(lo, open), topHi(hi, open);
    std::vector<Seg> path;
    path.push_back(Seg::line(topLo, Vec2(lo, floor + in * r1)));
    if (r1 > 0)
      path.push_back(Seg::arc(Vec2(lo, floor + in * r1), Vec2(lo + r1, floor), Vec2(lo + r1, floor + in * r1), !*inner));
    path.push_back(Seg::line(Vec2(lo + r1, floor), Vec2(hi - r2, floor)));
    if (r2 > 0)
      path.push_back(Seg::arc(Vec2(hi - r2, floor), Vec2(hi, floor + in * r2), Vec2(hi - r2, floor + in * r2), !*inner));
    path.push_back(Seg::line(Vec2(hi, floor + in * r2), topHi));
    std::erase_if(path, [](const Seg &s) { return (s.b - s.a).norm() <= geom::kEps && !s.isArc(); });
    Loop l;
    l.segs = path;
    l.segs.push_back(Seg::line(topHi, topLo));
    if (*inner) {
      // Walked clockwise round the material inside: reversed.
      Loop ccw;
      for (auto it = l.segs.rbegin(); it != l.segs.rend(); ++it)
        ccw.segs.push_back(it->reversed());
      l = ccw;
    }
    s_.removal = Region{{l}};
    s_.contour = path;  // from the low z wall's open end round to the high one's
    s_.grooveSpan = {lo, hi};
    s_.grooveFloor = floor;
    s_.grooveRadii = {r1, r2};
    s_.inner = *inner;
    return true;
  }

  /// Whether a square-U profile's walls stand at 90 degrees (the only ones
  /// turned); else an error naming the first that does not.
  bool squareWalls(const Node &u) {
    for (const char *a : {"first_angle", "second_angle"})
      if (auto angle = u.number(a); angle && std::abs(*angle - 90) > 1e-9) {
        error_ = named(f_) + ": a groove wall at " + formatTrimmed(*angle, 4) +
                 " deg is not turned yet (square walls only)";
        return false;
      }
    return true;
  }

  /// A face groove: in a face looking towards the free end (its material
  /// side -z), its floor at the placement's z, its square-U profile's width
  /// centred on `radius` across the axis, open towards the free end; its
  /// corner radii first_radius at the wall nearer the axis, second_radius at
  /// the outer one.
  bool faceGroove(const Placed &p, double side) {
    if (side > 0) {
      error_ = named(f_) + ": a face groove in a face looking towards the chuck (its material side +z) is not "
                           "turned (no tool reaches it from the free end)";
      return false;
    }
    const Node *u = f_.child(Kind::SquareUProfile);
    if (!u) {
      error_ = named(f_) + ": only grooves with a square_u_profile are turned yet";
      return false;
    }
    if (!squareWalls(*u))
      return false;
    const double mid = f_.number("radius").value_or(0), w = u->number("width").value_or(0);
    const double r1 = u->number("first_radius").value_or(0), r2 = u->number("second_radius").value_or(0);
    const double lo = mid - w / 2, hi = mid + w / 2, z0 = p.at.x();
    if (w <= 0 || lo < 0 || r1 < 0 || r2 < 0 || r1 + r2 > w + 1e-9) {
      error_ = named(f_) + ": its width " + formatFixed(w, 4) + " mm about a radius of " + formatFixed(mid, 4) +
               " mm (corner radii " + formatFixed(r1, 4) + " and " + formatFixed(r2, 4) + " mm) makes no face groove";
      return false;
    }
    // From the outer wall's open end, down it, round its corner, across the
    // floor, round the inner corner, up the inner wall.
    std::vector<Seg> path;
    path.push_back(Seg::line(Vec2(reachZ_, hi), Vec2(z0 + r2, hi)));
    if (r2 > 0)
      path.push_back(Seg::arc(Vec2(z0 + r2, hi), Vec2(z0, hi - r2), Vec2(z0 + r2, hi - r2), true));
    path.push_back(Seg::line(Vec2(z0, hi - r2), Vec2(z0, lo + r1)));
    if (r1 > 0)
      path.push_back(Seg::arc(Vec2(z0, lo + r1), Vec2(z0 + r1, lo), Vec2(z0 + r1, lo + r1), true));
    path.push_back(Seg::line(Vec2(z0 + r1, lo), Vec2(reachZ_, lo)));
    std::erase_if(path, [](const Seg &s) { return (s.b - s.a).norm() <= geom::kEps && !s.isArc(); });
    Loop l;
    l.segs = path;
    l.segs.push_back(Seg::line(Vec2(reachZ_, lo), Vec2(reachZ_, hi)));
    s_.removal = Region{{l}};
    s_.contour = path;
    s_.grooveSpan = {lo, hi};
    s_.grooveFloor = z0;
    s_.grooveRadii = {r1, r2};
    s_.faceGroove = true;
    return true;
  }

  /// A knurl rolled on an outer diameter: from its placement along its axis
  /// over its length, at its major diameter (else its nominal one), its
  /// teeth tooth_depth deep.
  bool knurl(const Placed &p) {
    const double d = f_.number("major_diameter").value_or(f_.number("nominal_diameter").value_or(0));
    const double length = f_.number("length").value_or(0), depth = f_.number("tooth_depth").value_or(0);
    if (d <= 0) {
      error_ = named(f_) + " needs the diameter it is rolled on (its major_diameter or nominal_diameter)";
      return false;
    }
    if (length <= 0) {
      error_ = named(f_) + " needs its length (its partial area's)";
      return false;
    }
    if (depth <= 0 || depth >= d / 2) {
      error_ = named(f_) + " needs a tooth_depth between 0 and its radius " + formatFixed(d / 2, 4) + " mm, not " +
               formatFixed(depth, 4) + " mm";
      return false;
    }
    const double r = d / 2, z0 = p.at.x(), z1 = p.at.x() + p.sign * length;
    const double lo = std::min(z0, z1), hi = std::max(z0, z1);
    s_.removal = Region{{ccwPolygon({{lo, r - depth}, {hi, r - depth}, {hi, r}, {lo, r}})}};
    s_.contour = {Seg::line(Vec2(hi, r), Vec2(lo, r))};
    s_.knurl = TurnedShape::KnurlSpan{lo, hi, r, depth};
    return true;
  }

  bool generalRevolution() {
    // Its general profile's curve, in the profile's placement within the
    // feature's: the points' x is the distance from the axis less the
    // feature's `radius`, z along it; y must be 0 (the half plane), arcs
    // turn about y (docs/turning.md).
    const std::optional<bool> inner = innerSide("revolved profiles");
    if (!inner)
      return false;
    const Node *profile = f_.child(Kind::GeneralProfile);
    if (!profile || profile->children.empty()) {
      error_ = named(f_) + " needs a general profile with its curve";
      return false;
    }
    if (profile->flag("closed").value_or(false)) {
      error_ = named(f_) + ": its profile is closed: a revolved profile is an open curve from one end of the "
                           "surface to the other";
      return false;
    }
    const CurveResult cr = curvePieces(profile->children.front(), ArcPlanes::Principal);
    if (!cr.error.empty()) {
      error_ = named(f_) + ": " + cr.error;
      return false;
    }
    auto frameOf = [](const Node &n) {
      const Vec3 at = n.vec("at").value_or(Vec3::Zero()), axis = n.vec("axis").value_or(Vec3::UnitZ());
      const Vec3 ref = n.vec("ref").value_or(Vec3::UnitX());
      return std::array<Vec3, 4>{at, ref, axis.cross(ref), axis};
    };
    auto place = [](const std::array<Vec3, 4> &f, const Vec3 &p) { return Vec3(f[0] + p.x() * f[1] + p.y() * f[2] + p.z() * f[3]); };
    auto turn = [](const std::array<Vec3, 4> &f, const Vec3 &v) { return Vec3(v.x() * f[1] + v.y() * f[2] + v.z() * f[3]); };
    const std::array<Vec3, 4> feature = frameOf(f_);
    const std::optional<std::array<Vec3, 4>> local =
        profile->has("at") ? std::optional(frameOf(*profile)) : std::nullopt;
    const double radius = f_.number("radius").value_or(0);
    auto toHalfPlane = [&](const Vec3 &p, bool &off) {
      Vec3 w = place(feature, local ? place(*local, p) : p);
      off = off || std::abs(w.y()) > 1e-6;
      return Vec2(w.z(), w.x() + radius);
    };
    std::vector<Seg> chain;
    bool off = false;
    for (const CurvePiece &c : cr.pieces) {
      const Vec2 a = toHalfPlane(c.from, off), b = toHalfPlane(c.to, off);
      if (!c.arc) {
        if ((b - a).norm() > geom::kEps)
          chain.push_back(Seg::line(a, b));
        continue;
      }
      // The arc's axis in the workpiece: along y for a turned profile; seen
      // from +y, counter-clockwise in (z, x) is counter-clockwise in (z, r).
      const Vec3 normal = turn(feature, local ? turn(*local, c.plane.normalVector()) : c.plane.normalVector());
      if (std::abs(std::abs(normal.y()) - 1) > 1e-9 || c.turns > 0) {
        error_ = named(f_) + ": its profile has an arc about an axis other than the half plane's normal (y)";
        return false;
      }
      const bool ccw = normal.y() > 0 ? c.ccw : !c.ccw;
      chain.push_back(Seg::arc(a, b, toHalfPlane(c.center, off), ccw));
    }
    if (off || chain.empty()) {
      error_ = named(f_) + ": its profile " + (off ? "leaves the half plane of the axis (y is not 0)" : "is empty");
      return false;
    }
    // From the free end towards the chuck.
    if (chain.front().a.x() < chain.back().b.x()) {
      std::reverse(chain.begin(), chain.end());
      for (Seg &sg : chain)
        sg = sg.reversed();
    }
    return surface(std::move(chain), *inner);
  }

  /// The removal and contour of a surface of revolution given by `chain`,
  /// its section from the free end towards the chuck without turning back.
  /// An outer surface continues at its first radius past the free end and,
  /// at its chuck-side end, out to the reach (a shoulder); its removal lies
  /// outwards of it. An inner one (a bore) continues at its first radius
  /// past the free end and, at its deep end, in to the axis (its bottom);
  /// its removal lies between it and the axis.
  bool surface(std::vector<Seg> chain, bool inner) {
    for (const Seg &sg : chain) {
      if (sg.box().lo.y() < -1e-9) {
        error_ = named(f_) + ": its profile crosses the axis (a radius below 0)";
        return false;
      }
      // From the free end towards the chuck without turning back: an
      // undercut is no surface a turning tool reaches from the end.
      const geom::Box b = sg.box();
      if (b.hi.x() > sg.a.x() + 1e-9 || b.lo.x() < sg.b.x() - 1e-9) {
        error_ = named(f_) + ": its profile turns back towards the free end near (z " + formatFixed(sg.a.x(), 4) +
                 ", r " + formatFixed(sg.a.y(), 4) + ") mm (an undercut): not turned yet";
        return false;
      }
    }
    const Vec2 first = chain.front().a, last = chain.back().b;
    const double end = inner ? 0.0 : reachR_;  // where the surface's chuck-side end runs to
    Loop l;
    l.segs.push_back(Seg::line(Vec2(reachZ_, first.y()), first));
    for (const Seg &sg : chain)
      l.segs.push_back(sg);
    if (std::abs(last.y() - end) > geom::kEps)
      l.segs.push_back(Seg::line(last, Vec2(last.x(), end)));
    s_.contour = l.segs;
    l.segs.push_back(Seg::line(Vec2(last.x(), end), Vec2(reachZ_, end)));
    l.segs.push_back(Seg::line(Vec2(reachZ_, end), Vec2(reachZ_, first.y())));
    s_.inner = inner;
    // The loop runs along the surface towards the chuck and back along the
    // reach: clockwise round an outer removal (reversed, counter-clockwise
    // as regions are), counter-clockwise round an inner one.
    if ((inner ? l.area() <= 0 : l.area() >= 0) || !simple(l)) {
      error_ = named(f_) + ": its profile does not bound material " + (inner ? "away from" : "towards") +
               " the axis (it turns back on itself)";
      return false;
    }
    if (inner) {
      s_.removal = Region{{l}};
      return true;
    }
    Loop ccw;
    for (auto it = l.segs.rbegin(); it != l.segs.rend(); ++it)
      ccw.segs.push_back(it->reversed());
    s_.removal = Region{{ccw}};
    return true;
  }

  /// A round on the part's outer edge: the corner at the placement, `radius`
  /// from the axis, between the face there (the part behind it, towards the
  /// chuck) and the diameter (the part inside it, its material side towards
  /// the axis), rounded by its partial circular profile's radius over a
  /// quarter turn. Everything outside the round, out to the reach, is the
  /// round's to remove, as an outer diameter's is (the steps before took
  /// what belongs to the face and the diameter).
  bool revolvedRound(const Placed &p) {
    const double corner = f_.number("radius").value_or(0);
    const std::optional<bool> inner = innerSide("rounds");
    if (!inner)
      return false;
    const Node *prof = f_.child(Kind::PartialCircularProfile);
    const double r = prof ? prof->number("radius").value_or(0) : 0;
    const double sweep = prof ? prof->number("sweep_angle").value_or(90) : 90;
    if (!prof || r <= 0 || corner <= r) {
      error_ = named(f_) + " needs a partial circular profile with a radius below its own radius " +
               formatFixed(corner, 4) + " mm (the edge it rounds)";
      return false;
    }
    if (std::abs(sweep - 90) > 1e-9) {
      error_ = named(f_) + ": a round over " + formatTrimmed(sweep, 4) +
               " deg is not turned yet (rounds of a square edge, 90 deg)";
      return false;
    }
    if (p.sign < 0) {
      error_ = named(f_) + " has its axis towards the chuck: a round on an edge looking towards the chuck is not "
                           "turned (no tool reaches it from the free end)";
      return false;
    }
    const double z0 = p.at.x();
    if (*inner) {
      // An edge of a bore (its material away from the axis): the face's
      // edge at the bore's mouth, or a shoulder's inside it. From the face
      // round the arc into the bore, the round's centre out from the edge.
      const Vec2 onFace(z0, corner + r), onBore(z0 - r, corner), c(z0 - r, corner + r);
      Loop l;
      l.segs = {Seg::arc(onFace, onBore, c, false), Seg::line(onBore, Vec2(z0 - r, 0)),
                Seg::line(Vec2(z0 - r, 0), Vec2(reachZ_, 0)), Seg::line(Vec2(reachZ_, 0), Vec2(reachZ_, corner + r)),
                Seg::line(Vec2(reachZ_, corner + r), onFace)};
      if (l.area() <= 0) {
        error_ = named(f_) + ": its round bounds no material";
        return false;
      }
      s_.removal = Region{{l}};
      // The surface: in along the face onto the round, round it, on into
      // the bore (a radius of each, tangent to the round).
      s_.contour = {Seg::line(Vec2(z0, corner + 2 * r), onFace), Seg::arc(onFace, onBore, c, false),
                    Seg::line(onBore, Vec2(z0 - 2 * r, corner))};
      s_.inner = true;
      return true;
    }
    // From the face (the free end's side) round the arc onto the diameter.
    const Vec2 onFace(z0, corner - r), onDiameter(z0 - r, corner), c(z0 - r, corner - r);
    Loop l;
    l.segs = {Seg::arc(onDiameter, onFace, c, false), Seg::line(onFace, Vec2(reachZ_, corner - r)),
              Seg::line(Vec2(reachZ_, corner - r), Vec2(reachZ_, reachR_)),
              Seg::line(Vec2(reachZ_, reachR_), Vec2(z0 - r, reachR_)), Seg::line(Vec2(z0 - r, reachR_), onDiameter)};
    if (l.area() <= 0) {
      error_ = named(f_) + ": its round bounds no material";
      return false;
    }
    s_.removal = Region{{l}};
    // The surface: up the face onto the round, round it, on along the
    // diameter (a radius of each, tangent to the round).
    s_.contour = {Seg::line(Vec2(z0, corner - 2 * r), onFace), Seg::arc(onFace, onDiameter, c, true),
                  Seg::line(onDiameter, Vec2(z0 - 2 * r, corner))};
    return true;
  }

  /// A round hole on the axis, turned as an inner diameter (a bore): from
  /// its placement down its depth along -axis at its diameter (tapering to
  /// its final diameter, or by its taper angle), with its bottom: through
  /// (on to the chuck side), flat, or conical (the point at its depth).
  bool roundHole(const Placed &p) {
    const double depth = f_.number("depth").value_or(0);
    if (p.sign < 0) {
      error_ = named(f_) + " points towards the chuck (its axis along -z): a hole on the axis is bored from the "
                           "free end (+z)";
      return false;
    }
    const auto radii = taperedRadii("final_diameter", depth, "a depth of ");
    if (!radii)
      return false;
    const auto [r0, r1] = *radii;
    const double top = p.at.x(), bottom = top - depth;
    const std::string kind = f_.text("bottom").value_or("flat");
    std::vector<Seg> chain;
    if (kind == "through") {
      // Through the bar: the wall runs on to the chuck side at its last radius.
      chain = {Seg::line(Vec2(top, r0), Vec2(bottom, r1))};
      if (bottom > lowZ_)
        chain.push_back(Seg::line(Vec2(bottom, r1), Vec2(lowZ_, r1)));
    } else if (kind == "flat") {
      chain = {Seg::line(Vec2(top, r0), Vec2(bottom, r1))};
    } else if (kind == "conical") {
      const double tip = f_.number("tip_angle").value_or(118);
      if (tip <= 0 || tip >= 180) {
        error_ = named(f_) + ": its conical bottom's tip angle " + formatTrimmed(tip, 4) + " deg makes no cone";
        return false;
      }
      // The cone's length L from its point up to the wall, where the
      // (tapering) wall's radius is r1 + (r0 - r1) L / depth.
      const double slope = std::tan(tip * kDegree / 2) - (r0 - r1) / depth;
      const double coneLength = slope > 0 ? r1 / slope : depth;
      if (coneLength >= depth) {
        error_ = named(f_) + ": its conical bottom is longer than the hole is deep";
        return false;
      }
      const double shoulder = bottom + coneLength;
      const double rs = r0 + (r1 - r0) * (top - shoulder) / depth;
      chain = {Seg::line(Vec2(top, r0), Vec2(shoulder, rs)), Seg::line(Vec2(shoulder, rs), Vec2(bottom, 0))};
    } else {
      error_ = named(f_) + ": a hole with a " + kind +
               " bottom is not turned yet (through, flat and conical bottoms are)";
      return false;
    }
    return surface(std::move(chain), true);
  }

  bool thread(const Placed &p) {
    // ISO 68-1's basic profile of a 60 degree thread: the pitch diameter is
    // d - 0.649519 P. An outer thread's root (minor) diameter is
    // d - 1.226869 P, the depth 0.613435 P (ISO 965-1's d3); an inner
    // thread's crest (minor) diameter D1 = D - 1.082532 P, cut out to its
    // major diameter D, the depth 0.541266 P.
    const bool inner = f_.flag("inner").value_or(false);
    const double major = f_.number("major_diameter").value_or(0), length = f_.number("length").value_or(0);
    const std::optional<double> pitchD = f_.number("pitch_diameter"), minor = f_.number("minor_diameter");
    if (major <= 0 || length <= 0) {
      error_ = named(f_) + " needs its major diameter and its length";
      return false;
    }
    TurnedShape::ThreadSpan t;
    if (pitchD) {
      t.pitch = (major - *pitchD) / 0.649519;
      if (!(t.pitch > 0) || *pitchD <= 0) {
        error_ = named(f_) + ": its pitch diameter " + formatFixed(*pitchD, 4) + " mm is not below its major diameter " +
                 formatFixed(major, 4) + " mm";
        return false;
      }
    }
    const double minorRadius =
        minor ? *minor / 2 : (t.pitch > 0 ? (major - (inner ? 1.082532 : 1.226869) * t.pitch) / 2 : 0);
    if (minorRadius <= 0 || minorRadius >= major / 2) {
      error_ = named(f_) + " needs a minor diameter below its major one, or its pitch diameter (to derive the pitch "
                           "and root of its 60 degree profile)";
      return false;
    }
    t.lo = std::min(p.at.x(), p.at.x() + p.sign * length);
    t.hi = std::max(p.at.x(), p.at.x() + p.sign * length);
    t.crestRadius = inner ? minorRadius : major / 2;
    t.rootRadius = inner ? major / 2 : minorRadius;
    t.starts = static_cast<int>(f_.count("starts").value_or(1));
    t.leftHand = f_.text("hand") == "left";
    if (t.starts < 1) {
      error_ = named(f_) + " has " + std::to_string(t.starts) + " starts";
      return false;
    }
    // What the thread removes: its band from the root out (an outer
    // thread) or in to the axis (an inner one, the hole it is cut in).
    const double from = inner ? 0.0 : t.rootRadius, to = inner ? t.rootRadius : reachR_;
    s_.removal = Region{{ccwPolygon({{t.lo, from}, {t.hi, from}, {t.hi, to}, {t.lo, to}})}};
    s_.contour = {Seg::line(Vec2(t.hi, t.rootRadius), Vec2(t.lo, t.rootRadius))};
    s_.thread = t;
    s_.inner = inner;
    return true;
  }

  const Node &f_;
  double reachR_, reachZ_, lowZ_;
  TurnedShape s_;
  std::string error_;
};

} // namespace

bool drillsOnTurningAxis(const Node &exec) {
  const Node *op = operationOf(exec);
  const Node *moves = exec.child(Kind::Moves);
  if (exec.kind != Kind::Workingstep || !op || !op->is(Trait::HoleMaking) || !moves)
    return false;
  bool any = false;
  for (const Move &m : walkMoves(*moves)) {
    if (std::abs(m.to.x()) > kOnAxis || std::abs(m.to.y()) > kOnAxis)
      return false;
    any = true;
  }
  return any;
}

TurnedShapeResult turnedShape(const Node &feature, const TurnStock &stock, double margin) {
  return Builder(feature, stock, margin).build();
}

} // namespace stepnc::ir
