#include "passes/FeatureWalls.h"

#include "ir/Kinds.h"
#include "ir/geom/Curves.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

namespace stepnc::passes {

namespace {

using geom::Vec2;
using ir::Node;

constexpr double kTwoPi = 2 * std::numbers::pi;
/// How far open sides and open slot ends reach into the air: past any machine.
constexpr double kAir = 1e6;

Vec2 left(const Vec2 &v) { return Vec2(-v.y(), v.x()); }
double angleOf(const Vec2 &v) { return std::atan2(v.y(), v.x()); }
Vec2 unitAt(double angle) { return Vec2(std::cos(angle), std::sin(angle)); }

/// The angle turned from `from` to `to` going the way of `sign`, in [0, 2 pi).
double turnBetween(double from, double to, double sign) {
  const double t = std::fmod(sign * (to - from), kTwoPi);
  return t < 0 ? t + kTwoPi : t;
}

/// A placement in the plane: `at`, with x along `ref` (axis +z only).
struct Frame {
  Vec2 origin = Vec2::Zero(), x = Vec2::UnitX();
  double z = 0;
  Vec2 map(const Vec2 &local) const { return origin + local.x() * x + local.y() * left(x); }
  Vec2 mapDir(const Vec2 &local) const { return local.x() * x + local.y() * left(x); }
  WallPiece map(const WallPiece &w) const {
    if (!w.arc)
      return WallPiece::line(map(w.a), map(w.b));
    return WallPiece::arcFrom(map(w.centre), map(w.a), w.sweep);
  }
};

std::optional<Frame> frameOf(const Node &n, std::string &error) {
  const ir::Vec3 at = n.vec("at").value_or(ir::Vec3::Zero());
  const ir::Vec3 axis = n.vec("axis").value_or(ir::Vec3::UnitZ());
  const ir::Vec3 ref = n.vec("ref").value_or(ir::Vec3::UnitX());
  if (std::abs(axis.x()) > 1e-9 || std::abs(axis.y()) > 1e-9 || axis.z() <= 0) {
    error = n.kindName() + " " + n.symbol + " does not face +z";
    return std::nullopt;
  }
  const Vec2 x(ref.x(), ref.y());
  if (x.norm() < 1e-12) {
    error = n.kindName() + " " + n.symbol + " has its reference direction along z";
    return std::nullopt;
  }
  return Frame{Vec2(at.x(), at.y()), x.normalized(), at.z()};
}

} // namespace

// --- Pieces --------------------------------------------------------------------------

WallPiece WallPiece::line(const Vec2 &a, const Vec2 &b) {
  WallPiece w;
  w.a = a;
  w.b = b;
  return w;
}

WallPiece WallPiece::arcFrom(const Vec2 &centre, const Vec2 &a, double sweep) {
  WallPiece w;
  w.arc = true;
  w.centre = centre;
  w.a = a;
  w.radius = (a - centre).norm();
  w.sweep = sweep;
  w.b = centre + w.radius * unitAt(angleOf(a - centre) + sweep);
  return w;
}

Vec2 WallPiece::nearest(const Vec2 &p) const {
  if (!arc) {
    const Vec2 d = b - a;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    return a + t * d;
  }
  const Vec2 v = p - centre;
  if (v.norm() < 1e-15)
    return a;
  // Whether v points into the arc's span, by the sides it lies on of the
  // radii to its ends (no angles: this runs for every sample of every move).
  const double sign = sweep < 0 ? -1 : 1;
  const Vec2 ra = a - centre, rb = b - centre;
  bool within;
  if (std::abs(sweep) >= kTwoPi - 1e-12)
    within = true;
  else if (std::abs(sweep) <= std::numbers::pi)
    within = sign * geom::cross(ra, v) >= 0 && sign * geom::cross(v, rb) >= 0;
  else  // more than half a turn: anywhere but strictly within the rest of the circle
    within = !(sign * geom::cross(rb, v) > 0 && sign * geom::cross(v, ra) > 0);
  if (within)
    return centre + radius * v.normalized();
  return (p - a).norm() <= (p - b).norm() ? a : b;
}

Vec2 WallPiece::tangent(int end) const {
  if (!arc)
    return (b - a).normalized();
  const Vec2 radial = ((end == 0 ? a : b) - centre).normalized();
  return sweep < 0 ? Vec2(-left(radial)) : left(radial);
}

// --- Outlines --------------------------------------------------------------------

bool Outline::contains(const Vec2 &p) const {
  // The outline with every arc replaced by its chord, plus or minus the
  // circular segment between each chord and its arc: p is enclosed when it
  // crosses the chord polygon an odd number of times, flipped by each
  // segment it lies in.
  bool in = false;
  for (const WallPiece &w : pieces) {
    const bool fullCircle = w.arc && std::abs(w.sweep) >= kTwoPi - 1e-12;
    if (!fullCircle && (w.a.y() > p.y()) != (w.b.y() > p.y())) {
      const double x = w.a.x() + (p.y() - w.a.y()) * (w.b.x() - w.a.x()) / (w.b.y() - w.a.y());
      if (x > p.x())
        in = !in;
    }
    if (!w.arc || (p - w.centre).norm() >= w.radius)
      continue;
    if (fullCircle) {
      in = !in;
      continue;
    }
    const Vec2 mid = w.centre + w.radius * unitAt(angleOf(w.a - w.centre) + w.sweep / 2);
    const double side = geom::cross(w.b - w.a, p - w.a), arcSide = geom::cross(w.b - w.a, mid - w.a);
    if (side * arcSide > 0)
      in = !in;
  }
  return in;
}

double Outline::clearance(const Vec2 &p) const {
  double d = std::numeric_limits<double>::infinity();
  for (const WallPiece &w : pieces)
    d = std::min(d, w.distance(p));
  return contains(p) ? d : -d;
}

namespace {

/// Twice the signed area the outline encloses (counter-clockwise positive).
double doubleArea(const Outline &o) {
  double a = 0;
  for (const WallPiece &w : o.pieces) {
    a += geom::cross(w.a, w.b);
    if (w.arc)  // the circular segment between the chord and the arc
      a += w.radius * w.radius * (w.sweep - std::sin(w.sweep));
  }
  return a;
}

/// Where the moved pieces `p` (ending) and `q` (starting) cross nearest to
/// `near`; none when they do not.
std::optional<Vec2> crossing(const WallPiece &p, const WallPiece &q, const Vec2 &near) {
  std::vector<Vec2> found;
  auto lineCircle = [&](const Vec2 &a, const Vec2 &d, const Vec2 &c, double r) {
    // |a + t d - c| = r
    const Vec2 f = a - c;
    const double A = d.dot(d), B = 2 * f.dot(d), C = f.dot(f) - r * r;
    const double disc = B * B - 4 * A * C;
    if (disc < 0 || A <= 0)
      return;
    for (double sign : {-1.0, 1.0})
      found.push_back(a + d * ((-B + sign * std::sqrt(disc)) / (2 * A)));
  };
  if (!p.arc && !q.arc) {
    const Vec2 d1 = p.b - p.a, d2 = q.b - q.a;
    const double den = geom::cross(d1, d2);
    if (std::abs(den) < 1e-15)
      return std::nullopt;
    found.push_back(p.a + d1 * (geom::cross(q.a - p.a, d2) / den));
  } else if (!p.arc || !q.arc) {
    const WallPiece &line = p.arc ? q : p, &arc = p.arc ? p : q;
    lineCircle(line.a, line.b - line.a, arc.centre, arc.radius);
  } else {
    const Vec2 d = q.centre - p.centre;
    const double l = d.norm();
    if (l < 1e-15 || l > p.radius + q.radius || l < std::abs(p.radius - q.radius))
      return std::nullopt;
    const double x = (l * l + p.radius * p.radius - q.radius * q.radius) / (2 * l);
    const double y = std::sqrt(std::max(0.0, p.radius * p.radius - x * x));
    const Vec2 u = d / l;
    for (double sign : {-1.0, 1.0})
      found.push_back(p.centre + u * x + left(u) * (sign * y));
  }
  if (found.empty())
    return std::nullopt;
  return *std::min_element(found.begin(), found.end(),
                           [&](const Vec2 &a, const Vec2 &b) { return (a - near).norm() < (b - near).norm(); });
}

} // namespace

std::optional<Outline> Outline::inset(double e) const {
  const size_t n = pieces.size();
  if (n == 0)
    return std::nullopt;
  const double inward = doubleArea(*this) >= 0 ? 1 : -1;  // the inside is left (+1) or right (-1)
  // Each piece moved; for an arc, its centre stays and its radius changes.
  std::vector<WallPiece> moved(pieces);
  for (WallPiece &w : moved) {
    if (w.arc) {
      const bool centreInside = (w.sweep > 0) == (inward > 0);
      const double r = w.radius + (centreInside ? -e : e);
      if (r <= 1e-9)
        return std::nullopt;
      w.a = w.centre + (w.a - w.centre).normalized() * r;
      w.b = w.centre + (w.b - w.centre).normalized() * r;
      w.radius = r;
    } else {
      const Vec2 shift = inward * left((w.b - w.a).normalized()) * e;
      w.a += shift;
      w.b += shift;
    }
  }
  if (n == 1) {
    if (!moved[0].arc)
      return std::nullopt;
    return Outline{moved};
  }
  Outline out;
  for (size_t i = 0; i < n; ++i) {
    const WallPiece &p = pieces[i], &q = pieces[(i + 1) % n];
    const Vec2 t1 = p.tangent(1), t2 = q.tangent(0);
    const double turn = inward * geom::cross(t1, t2);
    WallPiece &mp = moved[i], &mq = moved[(i + 1) % n];
    if (std::abs(geom::cross(t1, t2)) < 1e-9 && t1.dot(t2) > 0) {
      const Vec2 mid = (mp.b + mq.a) / 2;  // a smooth join: the moved ends meet
      mp.b = mid;
      mq.a = mid;
    } else if (turn > 0) {
      const std::optional<Vec2> x = crossing(mp, mq, (mp.b + mq.a) / 2);
      if (!x)
        return std::nullopt;
      mp.b = *x;
      mq.a = *x;
    }
    // A concave corner keeps the moved ends apart: an arc about it joins them
    // (added after the piece, below).
  }
  for (size_t i = 0; i < n; ++i) {
    const WallPiece &orig = pieces[i];
    WallPiece w = moved[i];
    if (w.arc) {
      const double sign = orig.sweep < 0 ? -1 : 1;
      double sweep = turnBetween(angleOf(w.a - w.centre), angleOf(w.b - w.centre), sign);
      if (std::abs(orig.sweep) >= kTwoPi - 1e-12 && sweep < 1e-12)
        sweep = kTwoPi;
      if (sweep <= 1e-12 || sweep > std::abs(orig.sweep) + std::numbers::pi / 2)
        return std::nullopt;  // turned round
      w = WallPiece::arcFrom(w.centre, w.a, sign * sweep);
    } else if ((w.b - w.a).dot(orig.b - orig.a) <= 1e-12) {
      return std::nullopt;  // vanished or turned round
    }
    out.pieces.push_back(w);
    const WallPiece &next = moved[(i + 1) % n];
    if ((next.a - w.b).norm() > 1e-12) {
      const Vec2 corner = orig.b;
      const double sweep = -inward * turnBetween(angleOf(w.b - corner), angleOf(next.a - corner), -inward);
      out.pieces.push_back(WallPiece::arcFrom(corner, w.b, sweep));
    }
  }
  return out;
}

double bodyRadius(double radius, double corner, double h) {
  if (h < 0)
    return -1;
  if (h >= corner)
    return radius;
  return radius - corner + std::sqrt(std::max(0.0, corner * corner - (corner - h) * (corner - h)));
}

Outline FeatureWalls::Island::sectionAt(double v) const {
  const double e = (v - foot) * slope;
  // The reader made sure the outline shrinks to the island's top; a height
  // between keeps its shape.
  std::optional<Outline> o = e > 0 ? outline.inset(e) : std::nullopt;
  return o ? std::move(*o) : outline;
}

// --- Reading the feature ----------------------------------------------------------

class WallsReader {
public:
  WallsReader(const ir::Module &module, std::string &error) : module_(module), error_(error) {}

  std::optional<FeatureWalls> read(const Node &feature) {
    std::optional<Frame> f = frameOf(feature, error_);
    if (!f)
      return std::nullopt;
    FeatureWalls w;
    w.symbol_ = feature.symbol;
    w.top_ = f->z;
    bool ok = false;
    switch (feature.kind) {
    case ir::Kind::ClosedPocket: ok = closedPocket(feature, *f, w); break;
    case ir::Kind::OpenPocket: ok = openPocket(feature, *f, w); break;
    case ir::Kind::RoundHole: ok = roundHole(feature, *f, w); break;
    case ir::Kind::Slot: ok = slot(feature, *f, w); break;
    case ir::Kind::Step: ok = step(feature, *f, w); break;
    case ir::Kind::PlanarFace: ok = islands(feature, w); break;
    case ir::Kind::GeneralOutsideProfile: ok = outsideProfile(feature, *f, w); break;
    default: return fail("a " + feature.kindName() + " has no walls this check reads");
    }
    if (!ok)
      return std::nullopt;
    return w;
  }

private:
  std::nullopt_t fail(std::string why) {
    if (error_.empty())
      error_ = std::move(why);
    return std::nullopt;
  }
  bool failed(std::string why) {
    fail(std::move(why));
    return false;
  }

  /// The pieces of a curve node, mapped by `frames` (innermost first).
  std::optional<std::vector<WallPiece>> curve(const Node &c, const std::vector<Frame> &frames) {
    ir::CurveResult cr = ir::curvePieces(c);
    if (!cr.error.empty())
      return fail(cr.error);
    std::vector<WallPiece> out;
    for (const ir::CurvePiece &cp : cr.pieces) {
      const Vec2 a(cp.from.x(), cp.from.y()), b(cp.to.x(), cp.to.y());
      WallPiece w;
      if (!cp.arc) {
        if ((b - a).norm() < 1e-12)
          continue;
        w = WallPiece::line(a, b);
      } else {
        const Vec2 c2(cp.center.x(), cp.center.y());
        const double sign = cp.ccw ? 1 : -1;
        double sweep = turnBetween(angleOf(a - c2), angleOf(b - c2), sign);
        if (cp.turns > 0 || (b - a).norm() < 1e-9)
          sweep = kTwoPi;
        w = WallPiece::arcFrom(c2, a, sign * sweep);
      }
      for (const Frame &f : frames)
        w = f.map(w);
      out.push_back(w);
    }
    return out;
  }

  /// The pieces of the feature's `path` (a slot's course of travel, a
  /// step's boundary), mapped by its frame; `what` names it in messages.
  std::optional<std::vector<WallPiece>> pathOf(const Node &feature, const Frame &f, const std::string &what) {
    const Node *path = feature.child(ir::Kind::Path);
    if (!path || path->children.empty())
      return fail(feature.kindName() + " " + feature.symbol + " has no " + what);
    return curve(path->children.front(), {f});
  }

  /// The profile child of `owner` as a closed outline in workpiece
  /// coordinates; `sharp` tells whether it has corners (a rectangle or a
  /// general profile) for a corner radius to round.
  std::optional<Outline> closedProfile(const Node &owner, const Frame &ownerFrame, bool *sharp = nullptr) {
    const Node *p = nullptr;
    for (const Node &c : owner.children)
      if (c.category() == ir::Category::Profile) {
        p = &c;
        break;
      }
    if (!p)
      return fail(owner.kindName() + " " + owner.symbol + " has no profile");
    std::vector<Frame> frames;
    if (p->has("at")) {
      std::optional<Frame> local = frameOf(*p, error_);
      if (!local)
        return std::nullopt;
      frames.push_back(*local);
    }
    frames.push_back(ownerFrame);
    auto mapped = [&](const Vec2 &v) {
      Vec2 out = v;
      for (const Frame &f : frames)
        out = f.map(out);
      return out;
    };
    Outline o;
    if (sharp)
      *sharp = p->kind != ir::Kind::CircularProfile;
    if (p->kind == ir::Kind::RectangularProfile) {
      const double hx = p->number("length").value_or(0) / 2, hy = p->number("width").value_or(0) / 2;
      const Vec2 c[4] = {mapped(Vec2(-hx, -hy)), mapped(Vec2(hx, -hy)), mapped(Vec2(hx, hy)), mapped(Vec2(-hx, hy))};
      for (int i = 0; i < 4; ++i)
        o.pieces.push_back(WallPiece::line(c[i], c[(i + 1) % 4]));
    } else if (p->kind == ir::Kind::CircularProfile) {
      const Vec2 c = mapped(Vec2::Zero());
      o.pieces.push_back(WallPiece::arcFrom(c, c + Vec2(p->number("diameter").value_or(0) / 2, 0), kTwoPi));
    } else if (p->kind == ir::Kind::GeneralProfile && !p->children.empty()) {
      std::optional<std::vector<WallPiece>> pieces = curve(p->children.front(), frames);
      if (!pieces)
        return std::nullopt;
      if (pieces->empty())
        return fail("the profile of " + owner.symbol + " is empty");
      // Closed as the generator would close it: end to start.
      if ((pieces->back().b - pieces->front().a).norm() > 1e-6)
        pieces->push_back(WallPiece::line(pieces->back().b, pieces->front().a));
      o.pieces = std::move(*pieces);
    } else {
      return fail("a " + p->kindName() + " outline of " + owner.symbol + " is not read by this check");
    }
    return o;
  }

  bool islands(const Node &feature, FeatureWalls &w) {
    for (const Node *island : feature.childrenOf(ir::Kind::Island)) {
      const Node *boss = ir::findFeature(module_, island->text("feature").value_or(""));
      if (!boss)
        continue;  // the IR verifier reports dangling references
      std::optional<Frame> f = frameOf(*boss, error_);
      if (!f)
        return false;
      std::optional<Outline> o = closedProfile(*boss, *f);
      if (!o)
        return false;
      FeatureWalls::Island isl{boss->symbol, std::move(*o), f->z, f->z - boss->number("depth").value_or(0), 0, {}};
      // A slope leans the walls in going up, the outline at the foot
      // (docs/toolpaths.md, "Bosses with a slope").
      if (const double deg = boss->number("slope").value_or(0); deg != 0) {
        if (!(deg > 0 && deg < 90))
          return failed("boss " + boss->symbol + " has a slope of " + formatShortest(deg) + " deg");
        isl.slope = std::tan(deg * std::numbers::pi / 180);
        if (!isl.outline.inset((isl.top - isl.foot) * isl.slope))
          return failed("boss " + boss->symbol + ": its outline, shrunk by its slope to its top, changes shape");
      }
      w.islands_.push_back(std::move(isl));
    }
    return true;
  }

  bool closedPocket(const Node &feature, const Frame &f, FeatureWalls &w) {
    bool sharp = false;
    std::optional<Outline> o = closedProfile(feature, f, &sharp);
    if (!o)
      return false;
    w.bound_ = FeatureWalls::Bound::Outline;
    w.outline_ = std::move(*o);
    // ISO 14649-10: the radius between a pocket's walls, whatever its profile.
    if (sharp)
      w.fillet_ = std::max(0.0, feature.number("orthogonal_radius").value_or(0));
    return islands(feature, w);
  }

  /// An open pocket's walls are an open profile; the straight line between
  /// its ends is the open side, and the air past it reaches as far as the
  /// line goes on: the outline runs out along that line from one end, round
  /// the air, and back along it to the other end.
  bool openPocket(const Node &feature, const Frame &f, FeatureWalls &w) {
    const Node *p = feature.child(ir::Kind::GeneralProfile);
    if (!p || p->children.empty())
      return failed("the walls of open pocket " + feature.symbol + " are not an open general profile");
    std::vector<Frame> frames;
    if (p->has("at")) {
      std::optional<Frame> local = frameOf(*p, error_);
      if (!local)
        return false;
      frames.push_back(*local);
    }
    frames.push_back(f);
    std::optional<std::vector<WallPiece>> walls = curve(p->children.front(), frames);
    if (!walls)
      return false;
    if (walls->empty())
      return failed("the walls of open pocket " + feature.symbol + " are empty");
    const Vec2 first = walls->front().a, last = walls->back().b;
    if ((first - last).norm() < 1e-9)
      return failed("the walls of open pocket " + feature.symbol + " close on themselves: no open side");
    // Which side of the open side the pocket lies on: the sign of the area
    // the walls enclose with it (arcs by their chords and midpoints).
    double area = 0;
    auto add = [&](const Vec2 &u, const Vec2 &v) { area += geom::cross(u, v); };
    for (const WallPiece &piece : *walls) {
      if (piece.arc) {
        const Vec2 mid = piece.centre + piece.radius * unitAt(angleOf(piece.a - piece.centre) + piece.sweep / 2);
        add(piece.a, mid);
        add(mid, piece.b);
      } else {
        add(piece.a, piece.b);
      }
    }
    add(last, first);
    const Vec2 along = (first - last).normalized();  // the open side, from the walls' end to their start
    const Vec2 out = area > 0 ? Vec2(-left(along)) : left(along);
    Outline o;
    o.pieces = std::move(*walls);
    const Vec2 p1 = last - along * kAir, p2 = p1 + out * kAir, p4 = first + along * kAir, p3 = p4 + out * kAir;
    for (const auto &[a, b] : {std::pair(last, p1), std::pair(p1, p2), std::pair(p2, p3), std::pair(p3, p4),
                               std::pair(p4, first)})
      o.pieces.push_back(WallPiece::line(a, b));
    w.bound_ = FeatureWalls::Bound::Outline;
    w.outline_ = std::move(o);
    return islands(feature, w);
  }

  bool roundHole(const Node &feature, const Frame &f, FeatureWalls &w) {
    const double d = feature.number("diameter").value_or(0);
    w.bound_ = FeatureWalls::Bound::Outline;
    w.outline_.pieces.push_back(WallPiece::arcFrom(f.origin, f.origin + Vec2(d / 2, 0), kTwoPi));
    return true;
  }

  /// A slot with vertical walls: the points within half its width of its
  /// course of travel; an open end continues the course straight on into
  /// the air, a flat end cuts it square at the end, a radiused end is the
  /// half disc the width makes there.
  bool slot(const Node &feature, const Frame &f, FeatureWalls &w) {
    const Node *profile = feature.child(ir::Kind::SquareUProfile);
    if (!profile)
      return failed("slot " + feature.symbol + " has walls that are not vertical (checked by its cross-section)");
    std::optional<std::vector<WallPiece>> course = pathOf(feature, f, "course of travel");
    if (!course)
      return false;
    if (course->empty())
      return failed("the course of travel of slot " + feature.symbol + " has no length");
    w.halfWidth_ = profile->number("width").value_or(0) / 2;
    const std::string end1(feature.text("end_1").value_or("")), end2(feature.text("end_2").value_or(""));
    const Vec2 start = course->front().a, finish = course->back().b;
    const Vec2 out1 = -course->front().tangent(0), out2 = course->back().tangent(1);
    for (const auto &[end, at, out] : {std::tuple(end1, start, out1), std::tuple(end2, finish, out2)}) {
      if (end == "open")
        course->push_back(WallPiece::line(at, at + out * kAir));
      else if (end == "flat")
        w.flatEnds_.push_back({at, out, w.halfWidth_});
      else if (end != "radiused")
        return failed("slot " + feature.symbol + ": " + end + " ends are not read by this check");
    }
    w.bound_ = FeatureWalls::Bound::Tube;
    w.course_ = std::move(*course);
    return true;
  }

  /// A step's only wall is its straight boundary; the material it removes
  /// lies on the side of it nearer the raw block's edge.
  bool step(const Node &feature, const Frame &f, FeatureWalls &w) {
    std::optional<std::vector<WallPiece>> pieces = pathOf(feature, f, "boundary");
    if (!pieces)
      return false;
    if (pieces->size() != 1 || pieces->front().arc)
      return failed("step " + feature.symbol + " has a boundary that is not one straight line");
    const Vec2 a = pieces->front().a, normal = left(pieces->front().tangent(0));
    const std::optional<std::vector<Vec2>> corners = rawCorners(feature);
    if (!corners)
      return failed("step " + feature.symbol + " has no block raw piece to tell its side by");
    double toLeft = 0, toRight = 0;
    for (const Vec2 &c : *corners) {
      toLeft = std::max(toLeft, (c - a).dot(normal));
      toRight = std::max(toRight, -(c - a).dot(normal));
    }
    w.bound_ = FeatureWalls::Bound::HalfPlane;
    w.planeAt_ = a;
    w.planeIn_ = toLeft <= toRight ? normal : Vec2(-normal);
    return islands(feature, w);
  }

  /// An outside profile stands as an island up to the feature's top; the
  /// tool passes every other side.
  bool outsideProfile(const Node &feature, const Frame &f, FeatureWalls &w) {
    std::optional<Outline> o = closedProfile(feature, f);
    if (!o)
      return false;
    w.islands_.push_back({feature.symbol, std::move(*o), f.z, f.z - feature.number("depth").value_or(0), 0, {}});
    return true;
  }

  /// The corners of the feature's workpiece's block raw piece in the plane.
  std::optional<std::vector<Vec2>> rawCorners(const Node &feature) {
    const Node *wp = ir::workpieceOf(module_, feature);
    const Node *raw = wp ? wp->child(ir::Kind::Rawpiece) : nullptr;
    if (!raw || raw->text("shape") != "block" || !raw->has("size"))
      return std::nullopt;
    std::string ignored;
    std::optional<Frame> f = frameOf(*raw, ignored);
    if (!f)
      return std::nullopt;
    const ir::Vec3 size = *raw->vec("size");
    return std::vector<Vec2>{f->map(Vec2(0, 0)), f->map(Vec2(size.x(), 0)), f->map(Vec2(size.x(), size.y())),
                             f->map(Vec2(0, size.y()))};
  }

  const ir::Module &module_;
  std::string &error_;
};

std::optional<FeatureWalls> FeatureWalls::read(const ir::Module &module, const ir::Node &feature, std::string &error) {
  error.clear();
  WallsReader r(module, error);
  return r.read(feature);
}

// --- Contact ---------------------------------------------------------------------

namespace {

/// A curve the centre of a disc of radius rho touching one wall piece
/// moves on: a line (through `p` along `d`) or a circle.
struct Offset {
  bool circle = false;
  Vec2 p = Vec2::Zero(), d = Vec2::UnitX();
  double r = 0;
};

void offsetsOf(const WallPiece &w, double rho, std::vector<Offset> &out) {
  if (!w.arc) {
    const Vec2 d = (w.b - w.a).normalized(), n = left(d);
    out.push_back({false, w.a + n * rho, d, 0});
    out.push_back({false, w.a - n * rho, d, 0});
  } else {
    out.push_back({true, w.centre, Vec2::UnitX(), w.radius + rho});
    if (w.radius > rho)
      out.push_back({true, w.centre, Vec2::UnitX(), w.radius - rho});
  }
  out.push_back({true, w.a, Vec2::UnitX(), rho});  // round its end
  out.push_back({true, w.b, Vec2::UnitX(), rho});
}

void intersect(const Offset &u, const Offset &v, std::vector<Vec2> &out) {
  if (!u.circle && !v.circle) {
    const double den = geom::cross(u.d, v.d);
    if (std::abs(den) < 1e-12)
      return;
    out.push_back(u.p + u.d * (geom::cross(v.p - u.p, v.d) / den));
    return;
  }
  if (u.circle && v.circle) {
    const Vec2 d = v.p - u.p;
    const double dist = d.norm();
    if (dist < 1e-12 || dist > u.r + v.r || dist < std::abs(u.r - v.r))
      return;
    const double a = (u.r * u.r - v.r * v.r + dist * dist) / (2 * dist);
    const double h = std::sqrt(std::max(0.0, u.r * u.r - a * a));
    const Vec2 m = u.p + d * (a / dist), n = left(d / dist);
    out.push_back(m + n * h);
    out.push_back(m - n * h);
    return;
  }
  const Offset &l = u.circle ? v : u, &c = u.circle ? u : v;
  const double t0 = (c.p - l.p).dot(l.d);
  const Vec2 foot = l.p + l.d * t0;
  const double off = (c.p - foot).norm();
  if (off > c.r)
    return;
  const double h = std::sqrt(std::max(0.0, c.r * c.r - off * off));
  out.push_back(foot + l.d * h);
  out.push_back(foot - l.d * h);
}

} // namespace

/// The distance from p to the nearest centre of a disc of radius fillet_
/// inside the outline: the disc p's tool must stay within to leave the
/// corners rounded. Such centres are found where one piece's nearest point
/// is pushed fillet_ along its normal, or where the centre curves of two
/// pieces cross; the nearest that truly has fillet_ of room is the answer.
double FeatureWalls::distanceToCentres(const Vec2 &p, double clearance) const {
  const double rho = fillet_;
  // Along a wall, away from corners: the disc touching the wall at p's
  // nearest point, pushed rho from it, has its room. No centre is nearer
  // than rho - clearance (the clearance changes no faster than the point
  // moves), so that one is the nearest.
  if (clearance >= 0) {
    Vec2 foot = p;
    double nearest = std::numeric_limits<double>::infinity();
    for (const WallPiece &w : outline_.pieces)
      if (const Vec2 q = w.nearest(p); (q - p).norm() < nearest) {
        nearest = (q - p).norm();
        foot = q;
      }
    if (nearest > 1e-12 && outline_.clearance(foot + (p - foot) * (rho / nearest)) >= rho - 1e-9)
      return rho - clearance;
  }
  std::vector<const WallPiece *> near;
  for (const WallPiece &w : outline_.pieces)
    if (w.distance(p) <= 3 * rho + std::max(0.0, -clearance))
      near.push_back(&w);
  std::vector<Vec2> candidates;
  std::vector<Offset> offsets;
  for (const WallPiece *w : near) {
    const Vec2 q = w->nearest(p);
    const double d = (p - q).norm();
    if (d > 1e-12)
      candidates.push_back(q + (p - q) * ((clearance >= 0 ? rho : -rho) / d));
    offsetsOf(*w, rho, offsets);
  }
  for (size_t i = 0; i < offsets.size(); ++i)
    for (size_t j = i + 1; j < offsets.size(); ++j)
      intersect(offsets[i], offsets[j], candidates);
  std::sort(candidates.begin(), candidates.end(),
            [&](const Vec2 &a, const Vec2 &b) { return (a - p).squaredNorm() < (b - p).squaredNorm(); });
  for (const Vec2 &q : candidates)
    if (outline_.clearance(q) >= rho - 1e-9)
      return (q - p).norm();
  // No centre nearby: the outline is narrower than the corner radius here.
  return rho - clearance;
}

WallContact FeatureWalls::outlineContact(const Vec2 &p, double radius) const {
  const double c = outline_.clearance(p);
  if (fillet_ <= radius || c >= fillet_)
    return {radius - c, WallContact::Where::Wall};
  // A tool smaller than the corner radius stays within a disc of that radius
  // inside the walls: it leaves the corners rounded.
  const double depth = distanceToCentres(p, c) - (fillet_ - radius);
  if (radius - c >= depth - 1e-12)
    return {radius - c, WallContact::Where::Wall};
  return {depth, WallContact::Where::Corner};
}

WallContact FeatureWalls::tubeContact(const Vec2 &p, double radius) const {
  double d = std::numeric_limits<double>::infinity();
  for (const WallPiece &w : course_)
    d = std::min(d, w.distance(p));
  WallContact out{radius - (halfWidth_ - d), WallContact::Where::Wall};
  for (const FlatEnd &e : flatEnds_) {
    // The square past the end: along `out` from 0 to 1.5 half widths, across
    // 1.5 half widths either way; its signed distance (positive outside).
    const double s = (p - e.at).dot(e.out), t = (p - e.at).dot(left(e.out));
    const double qx = std::abs(s - 0.75 * e.half) - 0.75 * e.half, qy = std::abs(t) - 1.5 * e.half;
    const double outside = Vec2(std::max(qx, 0.0), std::max(qy, 0.0)).norm() + std::min(std::max(qx, qy), 0.0);
    if (radius - outside > out.depth)
      out = {radius - outside, WallContact::Where::FlatEnd};
  }
  return out;
}

double FeatureWalls::slopedDepth(const Island &i, const Vec2 &p, double radius, const ToolBody &body) const {
  // The body's disc at each sampled height against the section there; the
  // sections shrink going up, so heights above the corner meet no more than
  // the corner's top does. The heights and their sections are made once per
  // tip height.
  constexpr int kSamples = 48;
  Island::Heights &hs = i.heights;
  if (!(hs.tip == body.tip && hs.lowered == body.lowered && hs.radius == radius && hs.corner == body.corner) ||
      hs.at.empty()) {
    hs = {body.tip, body.lowered, radius, body.corner, {}};
    const double tip = body.tip - body.lowered, corner = body.corner;
    const double lo = std::max(tip, i.foot), hi = std::min(tip + corner, i.top);
    const int count = hi > lo ? std::clamp(static_cast<int>(std::ceil((hi - lo) / 0.01)), 1, kSamples) : 0;
    for (int k = 0; k <= count; ++k) {
      const double v = count > 0 ? lo + (hi - lo) * k / count : lo;
      hs.at.emplace_back(bodyRadius(radius, corner, v - tip), i.sectionAt(v));
    }
  }
  // Coarsely, then every height about the deepest: the depth over the
  // heights is a disc's radius (concave in the height) less its distance to
  // a section moving in at a constant rate (convex), so it has one peak on
  // a wall or at a corner.
  auto depthAt = [&](size_t k) { return hs.at[k].first + hs.at[k].second.clearance(p); };
  constexpr size_t kCoarse = 4;
  size_t best = 0;
  double depth = -1e300;
  for (size_t k = 0; k < hs.at.size(); k += kCoarse)
    if (const double d = depthAt(k); d > depth) {
      depth = d;
      best = k;
    }
  const size_t from = best >= kCoarse ? best - kCoarse + 1 : 0, to = std::min(hs.at.size(), best + kCoarse);
  for (size_t k = from; k < to; ++k)
    if (k != best)
      depth = std::max(depth, depthAt(k));
  if (hs.at.size() > 1)
    depth = std::max(depth, depthAt(hs.at.size() - 1));
  return depth;
}

WallContact FeatureWalls::contact(const Vec2 &p, double z, double radius, double tol, const ToolBody &body) const {
  WallContact out;
  if (z < top_ - tol) {
    switch (bound_) {
    case Bound::None: break;
    case Bound::Outline: out = outlineContact(p, radius); break;
    case Bound::Tube: out = tubeContact(p, radius); break;
    case Bound::HalfPlane: out = {radius - (p - planeAt_).dot(planeIn_), WallContact::Where::Wall}; break;
    }
  }
  for (size_t k = 0; k < islands_.size(); ++k) {
    const Island &i = islands_[k];
    if (z >= i.top - tol)
      continue;
    const double depth = i.slope > 0 ? slopedDepth(i, p, radius, body) : radius + i.outline.clearance(p);
    if (depth > out.depth)
      out = {depth, WallContact::Where::Island, k};
  }
  return out;
}

std::string FeatureWalls::describe(const WallContact &c) const {
  switch (c.where) {
  case WallContact::Where::Wall: return (bound_ == Bound::HalfPlane ? "the wall of " : "a wall of ") + symbol_;
  case WallContact::Where::Corner: return "a corner of radius " + formatFixed(fillet_, 4) + " mm of " + symbol_;
  case WallContact::Where::FlatEnd: return "the flat end of " + symbol_;
  case WallContact::Where::Island: return "island " + islands_.at(c.island).symbol;
  }
  return symbol_;
}

std::vector<double> FeatureWalls::levels(double tol) const {
  std::vector<double> out{top_ - tol};
  for (const Island &i : islands_)
    out.push_back(i.top - tol);
  return out;
}

// --- Moves -------------------------------------------------------------------------

MoveContact deepestContact(const FeatureWalls &walls, const ir::Move &m, double radius, double tol, double corner,
                           double lowered) {
  MoveContact best;
  const ir::Vec3 from = *m.from;
  const Vec2 a(from.x(), from.y()), b(m.to.x(), m.to.y());
  // The move as a function of the distance s travelled in the plane.
  double length = 0, start = 0, sweep = 0, arcRadius = 0;
  Vec2 centre = Vec2::Zero();
  if (m.kind == ir::MoveKind::Arc) {
    centre = Vec2(m.center.x(), m.center.y());
    arcRadius = (a - centre).norm();
    start = angleOf(a - centre);
    const double sign = m.ccw ? 1 : -1;
    double partial = turnBetween(start, angleOf(b - centre), sign);
    if ((b - a).norm() < 1e-9)
      partial = kTwoPi;
    sweep = sign * (static_cast<double>(m.turns) * kTwoPi + partial);
    length = arcRadius * std::abs(sweep);
  } else {
    length = (b - a).norm();
  }
  auto at = [&](double s) -> ir::Vec3 {
    const double t = length > 0 ? s / length : 0;
    const double z = from.z() + (m.to.z() - from.z()) * t;
    if (s >= length)
      return ir::Vec3(b.x(), b.y(), z);
    if (m.kind == ir::MoveKind::Arc) {
      const Vec2 q = centre + arcRadius * unitAt(start + sweep * t);
      return ir::Vec3(q.x(), q.y(), z);
    }
    const Vec2 q = a + (b - a) * t;
    return ir::Vec3(q.x(), q.y(), z);
  };
  // Stretches between the heights where the walls in force change.
  std::vector<double> cuts{0, length};
  if (length > 0 && std::abs(m.to.z() - from.z()) > 0)
    for (double level : walls.levels(tol)) {
      const double t = (level - from.z()) / (m.to.z() - from.z());
      if (t > 0 && t < 1)
        cuts.push_back(t * length);
    }
  std::sort(cuts.begin(), cuts.end());
  const double minStep = std::max({tol / 2, 0.001, length / 2e6});
  auto sample = [&](double s, double z) {
    const ir::Vec3 p = at(s);
    const WallContact c = walls.contact(Vec2(p.x(), p.y()), z, radius, tol, ToolBody{corner, lowered, p.z()});
    ++best.samples;
    if (c.depth > best.contact.depth) {
      best.contact = c;
      best.at = p;
    }
    return c.depth;
  };
  if (length <= 0) {  // along the tool axis: where it is lowest, the most walls hold
    sample(0, std::min(from.z(), m.to.z()));
    best.at.z() = std::min(from.z(), m.to.z());
    return best;
  }
  // Where the deepest sample is: its stretch, and how far its neighbours were.
  double bestS = 0, bestStep = 0, bestS0 = 0, bestS1 = 0, bestZ = 0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double s0 = cuts[k], s1 = cuts[k + 1];
    if (s1 <= s0)
      continue;
    const double z = at((s0 + s1) / 2).z();  // the walls in force along the stretch
    for (double s = s0;;) {
      const double before = best.contact.depth;
      const double depth = sample(s, z);
      // The depth changes no faster than the centre moves: where the disc
      // has room, that much can be skipped; inside a wall, a quarter of
      // the depth, refined below.
      const double step = std::max(minStep, depth < 0 ? -depth : depth / 4);
      if (best.contact.depth > before)
        std::tie(bestS, bestStep, bestS0, bestS1, bestZ) = std::tuple(s, step, s0, s1, z);
      if (s >= s1)
        break;
      s = std::min(s1, s + step);
    }
  }
  // A gouge between samples: halve the distance to the deepest sample's
  // neighbours until the samples are minStep apart.
  if (best.contact.depth > 0)
    for (double h = bestStep / 2; h >= minStep / 2; h /= 2) {
      const double around = bestS;
      for (double s : {around - h, around + h})
        if (s > bestS0 && s < bestS1) {
          const double before = best.contact.depth;
          sample(s, bestZ);
          if (best.contact.depth > before)
            bestS = s;
        }
    }
  return best;
}

} // namespace stepnc::passes
