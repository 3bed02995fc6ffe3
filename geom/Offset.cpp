// Offsets of regions bounded by lines and arcs, and clipping a segment to a
// region.
//
// offset(region, d) works on the "raw offset curve" of the boundary:
//  1. every segment moved by d along its right-hand normal (the side away from
//     the region: the region lies left of its boundary), a line to a parallel
//     line, an arc to a concentric arc of radius r +- d (gone when that is not
//     positive), plus a join arc of radius |d| about every vertex where the
//     moved pieces separate (corners that are convex seen from the offset side);
//  2. all raw pieces split at their mutual intersections (a grid over the
//     pieces finds the pairs whose boxes overlap);
//  3. a piece is kept only when its midpoint is at distance >= |d| from the
//     boundary and on the right side (outside to grow, inside to shrink): every
//     point of the true offset boundary lies on the raw curve, and along a piece
//     that property can only change where another raw piece crosses it;
//  4. the kept pieces are chained end to end into loops. They keep the
//     direction of the boundary they come from, so outer loops stay
//     counter-clockwise and holes clockwise.
// Each step is near-linear in the number of segments (grids, sorting, no
// all-pairs loops), plus the number of crossings of the raw curve.
//
// Chaining does not match end points by distance: every end of a piece is a
// vertex with an identity (an end of a raw piece, or one crossing of two raw
// pieces), and vertices that are the same point by construction or closer
// than kSplitTol along a piece are united. Pieces far shorter than any
// distance tolerance then still chain exactly.
#include "geom/Geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <utility>

namespace stepnc::geom {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
/// Split points closer than this (mm along a piece) to its ends or to each
/// other are one point.
constexpr double kSplitTol = kEps;

Vec2 rightNormal(const Vec2 &t) { return {t.y(), -t.x()}; }

/// Angle travelled along the arc `s` from its start to the direction of q, in [0, 2pi).
double travelTo(const Seg &s, const Vec2 &q) {
  const Vec2 u = s.a - s.c, v = q - s.c;
  const double angle = std::atan2(cross(u, v), u.dot(v)) * s.turn;
  return angle < 0 ? angle + kTwoPi : angle;
}

/// Distance along s from its start to the point of s nearest q (q on s).
double along(const Seg &s, const Vec2 &q, double len) {
  if (!s.isArc()) {
    const Vec2 d = s.b - s.a;
    return std::clamp((q - s.a).dot(d) / d.squaredNorm(), 0.0, 1.0) * len;
  }
  const double sweep = std::abs(s.sweep());
  double travel = travelTo(s, q);
  if (travel > sweep) // just outside the arc (within tolerance): the nearer end
    travel = travel - sweep < kTwoPi - travel ? sweep : 0;
  return travel / sweep * len;
}

/// Vertex identities, and which of them are one point (union-find).
class Vertices {
public:
  uint32_t add() {
    parent_.push_back(uint32_t(parent_.size()));
    return parent_.back();
  }
  uint32_t find(uint32_t v) {
    while (parent_[v] != v)
      v = parent_[v] = parent_[parent_[v]];
    return v;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b)
      parent_[std::max(a, b)] = std::min(a, b);
  }
  uint32_t size() const { return uint32_t(parent_.size()); }

private:
  std::vector<uint32_t> parent_;
};

/// A segment of the raw curve or a part of one, between two vertices.
struct Piece {
  Seg seg;
  uint32_t from = 0, to = 0; ///< vertices at seg.a and seg.b
  uint32_t raw = 0;          ///< the raw piece it is part of
  Vec2 mid = Vec2::Zero();
};

/// Step 1: the raw offset curve of every loop of the region.
std::vector<Piece> rawOffset(const Region &region, double d, Vertices &vertices) {
  std::vector<Piece> raw;
  std::vector<Seg> segs;
  std::vector<Vec2> t0, t1;
  std::vector<uint32_t> startVertex, endVertex;
  for (const Loop &loop : region.loops) {
    segs.clear();
    for (const Seg &s : loop.segs)
      if (s.length() > kEps)
        segs.push_back(s);
    const size_t n = segs.size();
    if (n < 2)
      continue;
    t0.resize(n);
    t1.resize(n);
    startVertex.resize(n);
    endVertex.resize(n);
    for (size_t i = 0; i < n; ++i) {
      t0[i] = segs[i].tangent(0);
      t1[i] = segs[i].tangent(1);
      startVertex[i] = vertices.add();
      endVertex[i] = vertices.add();
    }
    for (size_t i = 0; i < n; ++i) {
      const Seg &s = segs[i];
      // The moved ends are computed once and shared with the joins, so that
      // consecutive raw pieces meet exactly.
      const Vec2 a = s.a + d * rightNormal(t0[i]);
      const Vec2 b = s.b + d * rightNormal(t1[i]);
      const double radius = s.radius() + s.turn * d;
      if (!s.isArc())
        raw.push_back({Seg::line(a, b), startVertex[i], endVertex[i]});
      else if (radius > kEps)
        raw.push_back({Seg::arc(a, b, s.c, s.turn > 0), startVertex[i], endVertex[i]});
      else if (radius > -kEps)
        vertices.unite(startVertex[i], endVertex[i]); // shrunk to its centre

      // The join towards the next segment: where the direction turns towards
      // the offset side (d * turn > 0) the moved pieces separate; a reversal
      // (spike) is joined by a half circle. Where they meet (tangent
      // segments), the two ends are one vertex.
      const size_t next = (i + 1) % n;
      const double turnCross = cross(t1[i], t0[next]);
      const bool separate = d * turnCross > 0 || (std::abs(turnCross) <= 1e-12 && t1[i].dot(t0[next]) < 0);
      const Vec2 q = segs[next].a + d * rightNormal(t0[next]);
      if ((q - b).norm() <= kEps)
        vertices.unite(endVertex[i], startVertex[next]);
      else if (separate)
        raw.push_back({Seg::arc(b, q, s.b, d > 0), endVertex[i], startVertex[next]});
    }
  }
  return raw;
}

/// Step 2: the raw pieces split at all their mutual intersections. Each
/// crossing is a new vertex, united with a piece's end when it is (within
/// kSplitTol) that end.
std::vector<Piece> splitPieces(const std::vector<Piece> &raw, Vertices &vertices) {
  struct Split {
    uint32_t piece;
    double at; ///< mm along the piece
    Vec2 p;
    uint32_t vertex;
  };
  const uint32_t n = uint32_t(raw.size());
  std::vector<double> lengths(n);
  std::vector<Seg> rawSegs(n);
  for (uint32_t i = 0; i < n; ++i) {
    lengths[i] = raw[i].seg.length();
    rawSegs[i] = raw[i].seg;
  }
  const SegIndex index(std::move(rawSegs));
  const std::vector<Seg> &segs = index.segs();

  std::vector<Split> splits;
  std::vector<uint32_t> near, count(n + 1, 0);
  auto add = [&](uint32_t i, const Vec2 &x, uint32_t vertex) {
    const double at = along(segs[i], x, lengths[i]);
    if (at <= kSplitTol) {
      vertices.unite(vertex, raw[i].from);
    } else if (at >= lengths[i] - kSplitTol) {
      vertices.unite(vertex, raw[i].to);
    } else {
      splits.push_back({i, at, x, vertex});
      ++count[i + 1];
    }
  };
  for (uint32_t i = 0; i < n; ++i) {
    index.query(segs[i].box().grown(kEps), near);
    for (uint32_t j : near) {
      if (j <= i)
        continue;
      for (const Vec2 &x : intersect(segs[i], segs[j])) {
        const uint32_t vertex = vertices.add();
        add(i, x, vertex);
        add(j, x, vertex);
      }
    }
  }

  // The split points grouped by piece (counting sort), then in order along it.
  for (uint32_t i = 0; i < n; ++i)
    count[i + 1] += count[i];
  std::vector<Split> grouped(splits.size());
  {
    std::vector<uint32_t> fill(count.begin(), count.end() - 1);
    for (const Split &sp : splits)
      grouped[fill[sp.piece]++] = sp;
  }
  std::vector<Piece> pieces;
  pieces.reserve(n + splits.size());
  for (uint32_t i = 0; i < n; ++i) {
    const Seg &s = segs[i];
    const double len = lengths[i];
    if (!(len > kEps)) {
      vertices.unite(raw[i].from, raw[i].to); // too short to split: a point
      continue;
    }
    const auto first = grouped.begin() + count[i], last = grouped.begin() + count[i + 1];
    std::sort(first, last, [](const Split &x, const Split &y) { return x.at < y.at; });
    double fromAt = 0;
    Vec2 from = s.a;
    uint32_t fromVertex = raw[i].from;
    auto emit = [&](double toAt, const Vec2 &to, uint32_t toVertex) {
      const Seg part = s.isArc() ? Seg::arc(from, to, s.c, s.turn > 0) : Seg::line(from, to);
      pieces.push_back({part, fromVertex, toVertex, i, s.at((fromAt + toAt) / (2 * len))});
      fromAt = toAt;
      from = to;
      fromVertex = toVertex;
    };
    for (auto it = first; it != last; ++it) {
      if (it->at - fromAt <= kSplitTol)
        vertices.unite(it->vertex, fromVertex); // the same point as the last one
      else if (len - it->at <= kSplitTol)
        vertices.unite(it->vertex, raw[i].to);
      else
        emit(it->at, it->p, it->vertex);
    }
    emit(len, s.b, raw[i].to);
  }
  return pieces;
}

/// Whether t is s traversed backwards, t going from s's end vertex to its
/// start (a raw piece doubled in the opposite direction: the two sides of a
/// part exactly 2|d| wide).
bool reverses(const Seg &s, const Seg &t) {
  return s.turn == -t.turn && (!s.isArc() || (s.c - t.c).norm() <= 1e-6);
}

/// Whether t repeats s, both going between the same vertices (raw pieces that
/// nearly coincide: the offsets of a very short segment and its almost
/// collinear neighbour).
bool repeats(const Seg &s, const Seg &t) {
  return s.turn == t.turn && (!s.isArc() || (s.c - t.c).norm() <= 1e-6);
}

/// Whether two consecutive segments are one line or one arc, and that piece.
bool mergeable(const Seg &s, const Seg &t, Seg &merged) {
  if (s.turn != t.turn)
    return false;
  if (!s.isArc()) {
    const Vec2 chord = t.b - s.a;
    const double len = chord.norm();
    if (len <= kEps || (s.b - s.a).dot(t.b - t.a) <= 0 || std::abs(cross(chord, s.b - s.a)) / len > 1e-10)
      return false;
    merged = Seg::line(s.a, t.b);
    return true;
  }
  if ((s.c - t.c).norm() > 1e-9 || std::abs(s.radius() - t.radius()) > 1e-9 ||
      std::abs(s.sweep()) + std::abs(t.sweep()) > kTwoPi - 1e-3)
    return false;
  merged = Seg::arc(s.a, t.b, s.c, s.turn > 0);
  return true;
}

/// Consecutive pieces of one line or one arc become one segment.
void mergeLoop(std::vector<Seg> &segs) {
  std::vector<Seg> out;
  out.reserve(segs.size());
  Seg merged;
  for (const Seg &s : segs) {
    if (!out.empty() && mergeable(out.back(), s, merged))
      out.back() = merged;
    else
      out.push_back(s);
  }
  while (out.size() > 2 && mergeable(out.back(), out.front(), merged)) {
    out.front() = merged;
    out.pop_back();
  }
  segs = std::move(out);
}

/// Step 4: the kept pieces chained end to end into closed loops. Pieces that do
/// not close a loop (numerical trouble) are dropped.
Region chainLoops(std::vector<Piece> pieces, Vertices &vertices, bool shrink) {
  const uint32_t n = uint32_t(pieces.size()), nv = vertices.size();
  std::vector<char> dead(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    pieces[i].from = vertices.find(pieces[i].from);
    pieces[i].to = vertices.find(pieces[i].to);
    dead[i] = pieces[i].from == pieces[i].to; // shorter than the tolerances
  }
  // Pieces leaving and entering each vertex, in CSR form.
  std::vector<uint32_t> outStart(nv + 1, 0), inStart(nv + 1, 0), outItems(n), inItems(n);
  for (const Piece &p : pieces) {
    ++outStart[p.from + 1];
    ++inStart[p.to + 1];
  }
  for (uint32_t v = 0; v < nv; ++v) {
    outStart[v + 1] += outStart[v];
    inStart[v + 1] += inStart[v];
  }
  {
    std::vector<uint32_t> outFill(outStart.begin(), outStart.end() - 1),
        inFill(inStart.begin(), inStart.end() - 1);
    for (uint32_t i = 0; i < n; ++i) {
      outItems[outFill[pieces[i].from]++] = i;
      inItems[inFill[pieces[i].to]++] = i;
    }
  }

  // A piece and its reverse cancel; a piece repeated is kept once.
  for (uint32_t i = 0; i < n; ++i) {
    const Piece &p = pieces[i];
    for (uint32_t k = outStart[p.from]; k < outStart[p.from + 1] && !dead[i]; ++k) {
      const uint32_t j = outItems[k];
      if (j != i && !dead[j] && pieces[j].to == p.to && repeats(p.seg, pieces[j].seg))
        dead[j] = 1;
    }
    for (uint32_t k = outStart[p.to]; k < outStart[p.to + 1] && !dead[i]; ++k) {
      const uint32_t j = outItems[k];
      if (!dead[j] && pieces[j].to == p.from && reverses(p.seg, pieces[j].seg))
        dead[i] = dead[j] = 1;
    }
  }

  // Dangling pieces go, until every piece left has a successor and a
  // predecessor. (A raw piece that crosses another at a very small angle
  // overshoots the crossing by pieces too close to |d| to tell by distance;
  // they end or start where nothing continues.)
  std::vector<uint32_t> leaving(nv, 0), entering(nv, 0), dangling;
  for (uint32_t i = 0; i < n; ++i) {
    if (!dead[i]) {
      ++leaving[pieces[i].from];
      ++entering[pieces[i].to];
    }
  }
  for (uint32_t i = 0; i < n; ++i)
    if (!dead[i] && (leaving[pieces[i].to] == 0 || entering[pieces[i].from] == 0))
      dangling.push_back(i);
  while (!dangling.empty()) {
    const uint32_t i = dangling.back();
    dangling.pop_back();
    if (dead[i])
      continue;
    dead[i] = 1;
    const uint32_t from = pieces[i].from, to = pieces[i].to;
    if (--leaving[from] == 0)
      for (uint32_t k = inStart[from]; k < inStart[from + 1]; ++k)
        if (!dead[inItems[k]])
          dangling.push_back(inItems[k]);
    if (--entering[to] == 0)
      for (uint32_t k = outStart[to]; k < outStart[to + 1]; ++k)
        if (!dead[outItems[k]])
          dangling.push_back(outItems[k]);
  }

  Region out;
  std::vector<uint32_t> chain;
  for (uint32_t first = 0; first < n; ++first) {
    if (dead[first])
      continue;
    dead[first] = 1;
    chain.assign(1, first);
    bool closed = false;
    for (;;) {
      const Piece &last = pieces[chain.back()];
      if (last.to == pieces[first].from) {
        closed = true;
        break;
      }
      // Several pieces leave a vertex where loops touch, or where raw pieces
      // cross at a very small angle and the overshoots are within rounding of
      // |d|. A sharp corner of a shrunk region is convex (the region is
      // locally an intersection) and of a grown one concave (a union), so the
      // loop turns left at corners when shrinking and right when growing: the
      // piece turning most that way is taken.
      const Vec2 dir = last.seg.tangent(1);
      int64_t best = -1;
      double bestTurn = -10;
      for (uint32_t k = outStart[last.to]; k < outStart[last.to + 1]; ++k) {
        const uint32_t j = outItems[k];
        if (dead[j])
          continue;
        const Vec2 t = pieces[j].seg.tangent(0);
        const double turn = std::atan2(cross(dir, t), dir.dot(t)) * (shrink ? 1 : -1);
        if (turn > bestTurn) {
          bestTurn = turn;
          best = j;
        }
      }
      if (best < 0)
        break;
      dead[best] = 1;
      chain.push_back(uint32_t(best));
    }
    if (!closed)
      continue; // numerical trouble: these pieces are dropped

    Loop loop;
    loop.segs.reserve(chain.size());
    for (uint32_t i : chain)
      loop.segs.push_back(pieces[i].seg);
    // Make the ends meet exactly (they differ by rounding where vertices were united).
    for (size_t k = 0; k < loop.segs.size(); ++k) {
      Seg &before = loop.segs[(k + loop.segs.size() - 1) % loop.segs.size()];
      Seg &cur = loop.segs[k];
      if (before.b != cur.a)
        before.b = cur.a = (before.b + cur.a) / 2;
    }
    mergeLoop(loop.segs);
    if (loop.segs.size() >= 2 && std::abs(loop.area()) >= 1e-9)
      out.loops.push_back(std::move(loop));
  }
  return out;
}

} // namespace

Region offset(const Region &r, double d) {
  if (d == 0 || r.empty())
    return r;
  Vertices vertices;
  std::vector<Piece> pieces = splitPieces(rawOffset(r, d, vertices), vertices);

  // Step 3: keep the pieces at distance |d| from the boundary, on the offset
  // side. Valid pieces are at |d| to rounding; the tolerance is kept tight
  // because a raw piece crossing another at a very small angle overshoots it
  // by pieces whose distance falls short of |d| by very little.
  const SegIndex boundary = SegIndex::of(r);
  const double minDistance = std::abs(d) * (1 - 1e-10) - 1e-12;
  const bool shrink = d < 0;
  // Consecutive pieces of a raw piece are often too near the same boundary
  // segment: that one is tried first.
  uint32_t lastRaw = UINT32_MAX, lastNear = 0;
  std::erase_if(pieces, [&](const Piece &p) {
    if (p.raw == lastRaw && distance(boundary.segs()[lastNear], p.mid) < minDistance)
      return true;
    if (boundary.within(p.mid, minDistance, &lastNear)) {
      lastRaw = p.raw;
      return true;
    }
    return (boundary.winding(p.mid) != 0) != shrink;
  });
  return chainLoops(std::move(pieces), vertices, shrink);
}

std::vector<Seg> clip(const Region &r, const Vec2 &p, const Vec2 &q) {
  std::vector<Seg> out;
  const Vec2 d = q - p;
  const double len = d.norm();
  if (len <= kEps || r.empty())
    return out;
  const Seg line = Seg::line(p, q);
  const SegIndex index = SegIndex::of(r);

  // Where the segment meets the boundary, as fractions of its length.
  std::vector<double> cuts{0.0, 1.0};
  std::vector<uint32_t> near;
  index.query(line.box().grown(kEps), near);
  for (uint32_t i : near)
    for (const Vec2 &x : intersect(line, index.segs()[i]))
      cuts.push_back(std::clamp((x - p).dot(d) / (len * len), 0.0, 1.0));
  std::sort(cuts.begin(), cuts.end());
  std::vector<double> distinct;
  for (double t : cuts)
    if (distinct.empty() || (t - distinct.back()) * len > kEps)
      distinct.push_back(t);
  distinct.back() = 1.0;

  // Pieces between cuts whose midpoints are inside; neighbours join up.
  auto point = [&](double t) { return t >= 1.0 ? q : t <= 0.0 ? p : Vec2(p + t * d); };
  double openFrom = -1; // start of the piece being collected, or -1
  for (size_t k = 0; k + 1 < distinct.size(); ++k) {
    const bool inside = index.winding(p + (distinct[k] + distinct[k + 1]) / 2 * d) != 0;
    if (inside && openFrom < 0)
      openFrom = distinct[k];
    if (!inside && openFrom >= 0) {
      out.push_back(Seg::line(point(openFrom), point(distinct[k])));
      openFrom = -1;
    }
  }
  if (openFrom >= 0)
    out.push_back(Seg::line(point(openFrom), q));
  return out;
}

} // namespace stepnc::geom
