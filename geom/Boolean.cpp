// Exact Booleans on regions of lines and arcs, computed by CGAL's
// General_polygon_set_2 with the circle-segment traits (see Boolean.h).
//
// The work is in the two conversions:
// - toPolygons: Region -> CGAL polygons with holes. Each loop is cleaned
//   (segments shorter than kEps dropped, small gaps closed so that consecutive
//   pieces share one exact point), every piece becomes a CGAL curve (a segment,
//   or the circular arc through its end points and its mid point) split into
//   x-monotone parts. Each hole (a clockwise loop) goes to the smallest outer
//   loop around it; an island inside a hole is just another outer loop.
// - toRegion: CGAL polygons with holes -> Region. Exact coordinates are rounded
//   to doubles, the parts CGAL split a line or an arc into are merged again,
//   pieces shorter than kEps and loops thinner than kEps are dropped, and every
//   loop is closed exactly (a segment starts bitwise where the previous ends).
//
// This is the only file of stepnc that includes CGAL.
#include "geom/Boolean.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/General_polygon_set_2.h>
#include <CGAL/Gps_circle_segment_traits_2.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <stdexcept>
#include <string>

namespace stepnc::geom {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using FT = Kernel::FT;
using KPoint = Kernel::Point_2;  // rational point: what our doubles become
using Traits = CGAL::Gps_circle_segment_traits_2<Kernel>;
using Curve = Traits::Curve_2;
using XCurve = Traits::X_monotone_curve_2;
using TPoint = Traits::Point_2;  // point whose coordinates may hold one square root
using CgalPolygon = Traits::Polygon_2;
using CgalPolygonWithHoles = Traits::Polygon_with_holes_2;
using PolygonSet = CGAL::General_polygon_set_2<Traits>;

constexpr double kPi = std::numbers::pi;

/// Loops whose consecutive segments are this far apart (or closer) are closed
/// by moving one end; wider gaps are an error. The same tolerance as Chain::closed.
constexpr double kGapTolerance = kEps * 1e3;

/// The largest sweep of an arc made by merging CGAL's x-monotone parts back:
/// below 2*pi with a margin, so that the arc's end points stay distinct.
constexpr double kMaxMergedSweep = 2 * kPi - 1e-6;

/// Bad input (a loop that is not closed, a coordinate that is not finite):
/// reported to the caller as std::runtime_error with the operation's name.
struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

Vec2 rotated(const Vec2 &v, double angle) {
  double cs = std::cos(angle), sn = std::sin(angle);
  return {cs * v.x() - sn * v.y(), sn * v.x() + cs * v.y()};
}

/// The point of arc s at fraction t of its sweep.
Vec2 arcPoint(const Seg &s, double sweep, double t) { return s.c + rotated(s.a - s.c, sweep * t); }

// --- Region -> CGAL ------------------------------------------------------------

/// One piece of a cleaned loop: a line, or an arc passing through `mid`, from
/// `from` to the next piece's `from`.
struct Piece {
  Vec2 from;
  Vec2 mid = Vec2::Zero();
  int turn = 0;  ///< 0: line, +1/-1: counter-clockwise/clockwise arc
};

bool finite(const Vec2 &p) { return std::isfinite(p.x()) && std::isfinite(p.y()); }

/// The pieces of a loop, ready for CGAL: segments whose chord is at most kEps
/// dropped (unless they are arcs sweeping more than a half turn), gaps of at
/// most kGapTolerance closed, arcs sweeping more than 1.5 pi split in two (the
/// circle through three points is poorly defined when the ends almost meet).
/// Empty when fewer than two pieces remain.
std::vector<Piece> cleanLoop(const Loop &loop, size_t loopIndex) {
  struct Kept {
    const Seg *seg;
    double sweep;
  };
  std::vector<Kept> kept;
  kept.reserve(loop.segs.size());
  for (const Seg &s : loop.segs) {
    if (!finite(s.a) || !finite(s.b) || (s.isArc() && !finite(s.c)))
      throw BadInput("loop " + std::to_string(loopIndex) + " has a coordinate that is not finite");
    double sweep = s.isArc() ? s.sweep() : 0.0;
    if ((s.b - s.a).norm() > kEps || std::abs(sweep) > kPi)
      kept.push_back({&s, sweep});
  }
  if (kept.empty())
    return {};
  for (size_t i = 0; i < kept.size(); ++i) {
    const Seg &s = *kept[i].seg, &next = *kept[(i + 1) % kept.size()].seg;
    double gap = (s.b - next.a).norm();
    if (!(gap <= kGapTolerance))
      throw BadInput("loop " + std::to_string(loopIndex) + " is not closed (a gap of " + std::to_string(gap) +
                     " mm)");
  }

  // Piece i runs from kept[i].a to kept[i + 1].a: the gaps close there.
  std::vector<Piece> pieces;
  pieces.reserve(kept.size() + 1);
  for (const Kept &k : kept) {
    const Seg &s = *k.seg;
    if (!s.isArc()) {
      pieces.push_back({s.a, Vec2::Zero(), 0});
    } else if (std::abs(k.sweep) > 1.5 * kPi) {
      pieces.push_back({s.a, arcPoint(s, k.sweep, 0.25), s.turn});
      pieces.push_back({arcPoint(s, k.sweep, 0.5), arcPoint(s, k.sweep, 0.75), s.turn});
    } else {
      pieces.push_back({s.a, arcPoint(s, k.sweep, 0.5), s.turn});
    }
  }
  if (pieces.size() < 2)
    return {};
  return pieces;
}

/// A loop as a CGAL polygon: its pieces as curves, split into x-monotone parts.
/// An arc whose mid point does not lie on the side of its (snapped) ends that
/// its turn says (or on the line through them) becomes a line: it is too flat
/// or too short to matter, and the circle through the three points would go
/// the wrong way round.
CgalPolygon toPolygon(const std::vector<Piece> &pieces) {
  std::vector<KPoint> vertices;
  vertices.reserve(pieces.size());
  for (const Piece &p : pieces)
    vertices.emplace_back(p.from.x(), p.from.y());

  Traits traits;
  auto makeXMonotone = traits.make_x_monotone_2_object();
  // CGAL 5.5 reports the parts as boost::variant<Point_2, X_monotone_curve_2>.
  std::vector<boost::variant<TPoint, XCurve>> parts;
  CgalPolygon polygon;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const KPoint &from = vertices[i], &to = vertices[(i + 1) % vertices.size()];
    if (from == to)
      continue;
    Curve curve(from, to);
    if (pieces[i].turn != 0) {
      // Three points in counter-clockwise order on a circle make a left turn.
      KPoint mid(pieces[i].mid.x(), pieces[i].mid.y());
      if (CGAL::orientation(from, mid, to) == (pieces[i].turn > 0 ? CGAL::LEFT_TURN : CGAL::RIGHT_TURN))
        curve = Curve(from, mid, to);
    }
    parts.clear();
    makeXMonotone(curve, std::back_inserter(parts));
    for (const auto &part : parts)
      if (const XCurve *x = boost::get<XCurve>(&part))
        polygon.push_back(*x);
  }
  return polygon;
}

/// The polygons with holes of a region, each outer loop with its holes. A
/// clockwise loop no outer loop surrounds is inside by the non-zero rule and
/// is read as an outer loop.
std::vector<CgalPolygonWithHoles> toPolygons(const Region &region) {
  struct Cleaned {
    const Loop *loop;
    std::vector<Piece> pieces;
    double area;
    Box box;
  };
  std::vector<Cleaned> outers, holes;
  for (size_t i = 0; i < region.loops.size(); ++i) {
    const Loop &loop = region.loops[i];
    std::vector<Piece> pieces = cleanLoop(loop, i);
    if (pieces.empty())
      continue;
    // A loop thinner than kEps encloses nothing.
    double area = loop.area(), perimeter = 0;
    for (size_t k = 0; k < pieces.size(); ++k)
      perimeter += (pieces[(k + 1) % pieces.size()].from - pieces[k].from).norm();
    if (!std::isfinite(area) || std::abs(area) <= kEps * perimeter)
      continue;
    (area > 0 ? outers : holes).push_back({&loop, std::move(pieces), std::abs(area), loop.box()});
  }
  // Smallest outer loop first: the first one around a hole is the hole's own.
  std::sort(outers.begin(), outers.end(), [](const Cleaned &l, const Cleaned &r) { return l.area < r.area; });

  std::vector<std::vector<CgalPolygon>> holesOf(outers.size());
  std::vector<CgalPolygonWithHoles> result;
  for (Cleaned &hole : holes) {
    // A point of the hole's boundary away from its vertices (where another
    // loop may touch it): the middle of its longest piece.
    size_t longest = 0;
    double longestChord = -1;
    for (size_t k = 0; k < hole.pieces.size(); ++k) {
      double chord = (hole.pieces[(k + 1) % hole.pieces.size()].from - hole.pieces[k].from).norm();
      if (chord > longestChord) {
        longestChord = chord;
        longest = k;
      }
    }
    const Piece &p = hole.pieces[longest];
    Vec2 probe = p.turn != 0 ? p.mid : 0.5 * (p.from + hole.pieces[(longest + 1) % hole.pieces.size()].from);
    Box probeBox;
    probeBox.add(probe);

    size_t owner = outers.size();
    for (size_t k = 0; k < outers.size() && owner == outers.size(); ++k)
      if (outers[k].area > hole.area && outers[k].box.overlaps(probeBox) &&
          outers[k].loop->winding(probe) != 0)
        owner = k;
    if (owner < outers.size()) {
      holesOf[owner].push_back(toPolygon(hole.pieces));
    } else {
      // Reverse the pieces: each keeps its mid point, the order and the ends swap.
      const std::vector<Piece> &forward = hole.pieces;
      std::vector<Piece> reversed;
      for (size_t k = forward.size(); k-- > 0;)
        reversed.push_back({forward[(k + 1) % forward.size()].from, forward[k].mid, -forward[k].turn});
      result.emplace_back(toPolygon(reversed));
    }
  }
  for (size_t k = 0; k < outers.size(); ++k)
    result.emplace_back(toPolygon(outers[k].pieces), holesOf[k].begin(), holesOf[k].end());
  return result;
}

PolygonSet toSet(const Region &region) {
  PolygonSet set;
  std::vector<CgalPolygonWithHoles> polygons = toPolygons(region);
  if (!polygons.empty())
    set.join(polygons.begin(), polygons.end());
  return set;
}

// --- CGAL -> Region ------------------------------------------------------------

/// The double nearest to an exact number, within a few ulps: the filtered
/// interval is used when it is tight, else the exact value is computed.
double toDouble(const FT &x) {
  std::pair<double, double> range = CGAL::to_interval(x);
  if (range.second - range.first > 1e-14 * std::max(std::abs(range.first), std::abs(range.second))) {
    x.exact();
    range = CGAL::to_interval(x);
  }
  return range.first == range.second ? range.first : range.first + 0.5 * (range.second - range.first);
}

/// A coordinate a0 + a1 * sqrt(root), added up in long double so that the
/// cancellation of a0 and a1 * sqrt(root) loses little.
template <typename CoordNT>
double toDouble(const CoordNT &x) {
  if (!x.is_extended())
    return toDouble(x.a0());
  long double a0 = toDouble(x.a0()), a1 = toDouble(x.a1()), root = toDouble(x.root());
  return double(a0 + a1 * std::sqrt(std::max(root, 0.0L)));
}

Vec2 toVec(const TPoint &p) { return {toDouble(p.x()), toDouble(p.y())}; }

/// One x-monotone curve of a CGAL polygon, from `from` to the next one's `from`.
struct OutPiece {
  Vec2 from;
  Vec2 c = Vec2::Zero();  ///< centre of an arc
  double r = 0;           ///< radius of an arc
  int turn = 0;           ///< 0: line, +1/-1: counter-clockwise/clockwise arc
};

/// The angle an x-monotone arc piece sweeps (at most pi).
double pieceSweep(const OutPiece &p, const Vec2 &to) {
  Vec2 u = p.from - p.c, v = to - p.c;
  return std::abs(std::atan2(cross(u, v), u.dot(v)));
}

/// Whether two consecutive arc pieces lie on one circle (up to rounding: CGAL
/// sees circles through rounded points that differ in the last bits).
bool sameCircle(const OutPiece &p, const OutPiece &q) {
  return p.turn != 0 && p.turn == q.turn && (p.c - q.c).norm() <= kEps && std::abs(p.r - q.r) <= kEps;
}

/// Distance from p to the line through a and b.
double lineDistance(const Vec2 &p, const Vec2 &a, const Vec2 &b) {
  Vec2 d = b - a;
  double len = d.norm();
  return len > 0 ? std::abs(cross(d, p - a)) / len : (p - a).norm();
}

/// The loop of a CGAL polygon, its parts merged back into lines and arcs.
/// Empty when nothing thicker than kEps remains.
Loop toLoop(const CgalPolygon &polygon) {
  std::vector<OutPiece> raw;
  raw.reserve(polygon.size());
  for (auto it = polygon.curves_begin(); it != polygon.curves_end(); ++it) {
    OutPiece p;
    p.from = toVec(it->source());
    if (it->is_circular()) {
      Kernel::Circle_2 circle = it->supporting_circle();
      p.c = {toDouble(circle.center().x()), toDouble(circle.center().y())};
      p.r = std::sqrt(toDouble(circle.squared_radius()));
      p.turn = it->orientation() == CGAL::COUNTERCLOCKWISE ? 1 : -1;
    }
    raw.push_back(p);
  }

  // Drop pieces whose chord is at most kEps: the previous piece then ends
  // where the next begins (a move of at most kEps).
  std::vector<OutPiece> pieces;
  pieces.reserve(raw.size());
  for (size_t i = 0; i < raw.size(); ++i)
    if ((raw[(i + 1) % raw.size()].from - raw[i].from).norm() > kEps)
      pieces.push_back(raw[i]);
  size_t n = pieces.size();
  if (n < 2)
    return {};
  auto to = [&](size_t i) -> const Vec2 & { return pieces[(i + 1) % n].from; };

  // Runs of pieces on one circle or one line become one segment. Start at a
  // piece that cannot continue the one before it, so that no run wraps around.
  auto continues = [&](size_t prev, size_t next) {
    const OutPiece &p = pieces[prev], &q = pieces[next];
    if (p.turn == 0 && q.turn == 0)
      return (to(prev) - p.from).dot(to(next) - q.from) > 0 && lineDistance(q.from, p.from, to(next)) <= kEps;
    return sameCircle(p, q);
  };
  size_t start = n;
  for (size_t i = 0; i < n && start == n; ++i)
    if (!continues((i + n - 1) % n, i))
      start = i;

  Loop loop;
  if (start == n) {
    // The whole loop is one circle (a closed loop of lines has a corner, or
    // no area): cut it into arcs of about equal sweep, fewer than 2 pi each.
    if (pieces[0].turn == 0)
      return {};
    std::vector<double> cumulative(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i)
      cumulative[i + 1] = cumulative[i] + pieceSweep(pieces[i], to(i));
    double total = cumulative[n];
    size_t parts = std::max<size_t>(2, size_t(std::ceil(total / kMaxMergedSweep)));
    size_t begin = 0;
    for (size_t k = 1; k <= parts; ++k) {
      size_t end = n;
      if (k < parts) {
        // The cut nearest to k / parts of the way round, leaving room for the rest.
        double target = total * double(k) / double(parts);
        end = begin + 1;
        while (end + (parts - k) < n &&
               std::abs(cumulative[end + 1] - target) < std::abs(cumulative[end] - target))
          ++end;
      }
      const OutPiece &first = pieces[begin];
      loop.segs.push_back(Seg::arc(first.from, pieces[end % n].from, first.c, first.turn > 0));
      begin = end;
    }
  } else {
    for (size_t done = 0; done < n;) {
      size_t first = (start + done) % n;
      const OutPiece &p = pieces[first];
      size_t count = 1;
      double sweep = p.turn != 0 ? pieceSweep(p, to(first)) : 0.0;
      while (done + count < n) {
        size_t next = (first + count) % n;
        if (!continues((next + n - 1) % n, next))
          break;
        if (p.turn != 0) {
          // Same circle as the run's first piece (no drift along a chain of
          // near-equal circles), and the merged arc below a full turn.
          double more = pieceSweep(pieces[next], to(next));
          if (!sameCircle(p, pieces[next]) || sweep + more > kMaxMergedSweep)
            break;
          sweep += more;
        } else {
          // Every vertex of the run near the merged line.
          bool straight = true;
          for (size_t k = 1; k <= count && straight; ++k)
            straight = lineDistance(pieces[(first + k) % n].from, p.from, to(next)) <= kEps;
          if (!straight)
            break;
        }
        ++count;
      }
      const Vec2 &end = pieces[(first + count) % n].from;
      loop.segs.push_back(p.turn == 0 ? Seg::line(p.from, end) : Seg::arc(p.from, end, p.c, p.turn > 0));
      done += count;
    }
  }

  // A loop thinner than kEps (a sliver between two nearly equal curves) is dropped.
  double perimeter = 0;
  for (const Seg &s : loop.segs)
    perimeter += (s.b - s.a).norm();
  if (loop.segs.size() < 2 || !(std::abs(loop.area()) > kEps * perimeter))
    return {};
  return loop;
}

Region toRegion(const PolygonSet &set) {
  std::vector<CgalPolygonWithHoles> polygons;
  polygons.reserve(set.number_of_polygons_with_holes());
  set.polygons_with_holes(std::back_inserter(polygons));
  Region region;
  auto add = [&](const CgalPolygon &polygon) {
    Loop loop = toLoop(polygon);
    if (!loop.segs.empty())
      region.loops.push_back(std::move(loop));
  };
  for (const CgalPolygonWithHoles &polygon : polygons) {
    if (!polygon.is_unbounded())
      add(polygon.outer_boundary());
    for (auto hole = polygon.holes_begin(); hole != polygon.holes_end(); ++hole)
      add(*hole);
  }
  return region;
}

// --- Swept discs -----------------------------------------------------------------

Region disc(const Vec2 &c, double r) { return Region{{circleLoop(c, r, true)}}; }

/// The capsule a disc of radius r sweeps along the line a -> b (|b - a| > 0).
Region capsule(const Vec2 &a, const Vec2 &b, double r) {
  Vec2 d = (b - a).normalized();
  Vec2 n(-d.y(), d.x());  // left of the direction of travel
  Vec2 p1 = a - r * n, p2 = b - r * n, p3 = b + r * n, p4 = a + r * n;
  Loop loop;
  loop.segs = {Seg::line(p1, p2), Seg::arc(p2, p3, b, true), Seg::line(p3, p4), Seg::arc(p4, p1, a, true)};
  return Region{{loop}};
}

/// The parts a disc of radius r sweeps along an arc: the band of points within
/// r of the circle, between the radii through the arc's ends (an annular
/// sector, or a pie when the radius of the arc is at most r), plus a disc at
/// each end. A point outside the sector is nearest to one of the arc's ends.
std::vector<Region> sweptArcParts(const Seg &s, double r) {
  double sweep = s.sweep();
  // Counter-clockwise from a to b, whichever way the arc runs.
  Vec2 a = sweep >= 0 ? s.a : s.b, b = sweep >= 0 ? s.b : s.a;
  sweep = std::abs(sweep);
  const Vec2 &c = s.c;
  double rho = s.radius();
  if (rho <= kEps || ((b - a).norm() <= kEps && sweep < kPi))
    return {disc(a, r)};  // the arc is a point

  double outer = rho + r, inner = rho - r;
  std::vector<Region> parts;
  if ((b - a).norm() <= kEps) {
    // Almost a full circle: the sector is a whole annulus (or disc).
    Region ring = disc(c, outer);
    if (inner > kEps)
      ring.loops.push_back(circleLoop(c, inner, false));
    parts.push_back(std::move(ring));
  } else {
    Vec2 ua = (a - c).normalized(), ub = (b - c).normalized();
    Vec2 ao = c + outer * ua, bo = c + outer * ub;
    Loop loop;
    if (inner > kEps) {
      Vec2 ai = c + inner * ua, bi = c + inner * ub;
      loop.segs = {Seg::arc(ao, bo, c, true), Seg::line(bo, bi), Seg::arc(bi, ai, c, false),
                   Seg::line(ai, ao)};
    } else {
      loop.segs = {Seg::line(c, ao), Seg::arc(ao, bo, c, true), Seg::line(bo, c)};
    }
    parts.push_back(Region{{loop}});
  }
  parts.push_back(disc(a, r));
  parts.push_back(disc(b, r));
  return parts;
}

/// The polygons of all parts a disc sweeps along the path, for one big join.
std::vector<CgalPolygonWithHoles> sweptPolygons(const std::vector<Seg> &path, double r) {
  std::vector<CgalPolygonWithHoles> polygons;
  for (const Seg &s : path)
    for (const Region &part : sweptDiscParts(s, r)) {
      std::vector<CgalPolygonWithHoles> more = toPolygons(part);
      std::move(more.begin(), more.end(), std::back_inserter(polygons));
    }
  return polygons;
}

PolygonSet sweptSet(const std::vector<Seg> &path, double r) {
  PolygonSet set;
  std::vector<CgalPolygonWithHoles> polygons = sweptPolygons(path, r);
  if (!polygons.empty())
    set.join(polygons.begin(), polygons.end());
  return set;
}

std::vector<Seg> boundaryOf(const Region &region) {
  std::vector<Seg> segs;
  for (const Loop &loop : region.loops)
    segs.insert(segs.end(), loop.segs.begin(), loop.segs.end());
  return segs;
}

/// Runs an operation, turning CGAL's failures and bad input into
/// std::runtime_error naming the operation.
template <typename F>
auto guarded(const char *operation, F &&f) -> decltype(f()) {
  try {
    return f();
  } catch (const BadInput &e) {
    throw std::runtime_error(std::string("geom::") + operation + ": " + e.what());
  } catch (const CGAL::Failure_exception &e) {
    throw std::runtime_error(std::string("geom::") + operation +
                             ": CGAL failed (is an input region self-intersecting?): " + e.what());
  }
}

} // namespace

Region unite(const Region &a, const Region &b) {
  return guarded("unite", [&] {
    PolygonSet set = toSet(a);
    set.join(toSet(b));
    return toRegion(set);
  });
}

Region subtract(const Region &a, const Region &b) {
  return guarded("subtract", [&] {
    PolygonSet set = toSet(a);
    set.difference(toSet(b));
    return toRegion(set);
  });
}

Region intersect(const Region &a, const Region &b) {
  return guarded("intersect", [&] {
    PolygonSet set = toSet(a);
    set.intersection(toSet(b));
    return toRegion(set);
  });
}

Region uniteAll(const std::vector<Region> &parts) {
  return guarded("uniteAll", [&] {
    std::vector<CgalPolygonWithHoles> polygons;
    for (const Region &part : parts) {
      std::vector<CgalPolygonWithHoles> more = toPolygons(part);
      std::move(more.begin(), more.end(), std::back_inserter(polygons));
    }
    PolygonSet set;
    if (!polygons.empty())
      set.join(polygons.begin(), polygons.end());
    return toRegion(set);
  });
}

std::vector<Region> sweptDiscParts(const Seg &s, double r) {
  if (!(r > 0) || !finite(s.a) || !finite(s.b) || (s.isArc() && !finite(s.c)))
    return {};
  if (s.isArc())
    return sweptArcParts(s, r);
  if ((s.b - s.a).norm() <= kEps)
    return {disc(s.a, r)};
  return {capsule(s.a, s.b, r)};
}

Region sweptDisc(const std::vector<Seg> &centrePath, double r) {
  return guarded("sweptDisc", [&] { return toRegion(sweptSet(centrePath, r)); });
}

Region shrinkExact(const Region &r, double d) {
  if (!(d > 0))
    return r;
  return guarded("shrinkExact", [&] {
    PolygonSet set = toSet(r);
    set.difference(sweptSet(boundaryOf(r), d));
    return toRegion(set);
  });
}

Region growExact(const Region &r, double d) {
  if (!(d > 0))
    return r;
  return guarded("growExact", [&] {
    PolygonSet set = toSet(r);
    set.join(sweptSet(boundaryOf(r), d));
    return toRegion(set);
  });
}

} // namespace stepnc::geom
