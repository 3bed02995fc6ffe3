// The deposition half of verify-toolpaths (see VerifyDeposition.h).
//
// The feature is read here as a membership test in its own frame: an
// extruded profile is a polygon (its arcs cut into chords of at most
// kChord), its section at height z the points whose signed distance to the
// polygon is at most -z tan(draft); a faceted solid the points behind every
// plane, the distance outside it the largest distance to one of them (a
// lower bound at its edges). Channels are polylines of the same chord; a
// point is in one when it lies within its radius in space.
//
// Coverage is sampled on a grid of kGridShare bead widths over every layer,
// at the bottom, middle and top of the layer; overflow along every bead,
// every quarter width, at its centre line and both edges.
#include "passes/VerifyDeposition.h"

#include "geom/Geometry.h"
#include "ir/Program.h"
#include "ir/geom/Curves.h"
#include "ir/geom/MoveWalk.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

namespace stepnc::passes {

namespace {

using geom::Seg;
using geom::Vec2;
using ir::Node;
using ir::Vec3;

constexpr double kPi = std::numbers::pi;
/// Chord of the polygons the profile and the channels are read as (mm).
constexpr double kChord = 0.002;
/// Spacing of the coverage grid, as a share of the bead width.
constexpr double kGridShare = 0.25;

/// A curve node's pieces as points, arcs cut by angle so that no chord is
/// further than kChord from its arc.
std::vector<Vec3> sampled(const Node &curve, std::string &error) {
  ir::CurveResult cr = ir::curvePieces(curve, ir::ArcPlanes::Principal);
  error = cr.error;
  std::vector<Vec3> out;
  for (const ir::CurvePiece &p : cr.pieces) {
    if (out.empty())
      out.push_back(p.from);
    if (!p.arc) {
      out.push_back(p.to);
      continue;
    }
    const Vec3 a = p.plane.local(p.from), b = p.plane.local(p.to), c = p.plane.local(p.center);
    const double r = (a.head<2>() - c.head<2>()).norm();
    double start = std::atan2(a.y() - c.y(), a.x() - c.x()), end = std::atan2(b.y() - c.y(), b.x() - c.x());
    const double turn = p.ccw ? 1 : -1;
    double sweep = turn * (end - start);
    while (sweep <= 1e-12)
      sweep += 2 * kPi;
    sweep += 2 * kPi * static_cast<double>(p.turns);
    const double maxStep = r > kChord ? 2 * std::acos(1 - kChord / r) : kPi / 8;
    const int steps = std::max(1, static_cast<int>(std::ceil(sweep / maxStep)));
    for (int k = 1; k <= steps; ++k) {
      const double phi = start + turn * sweep * k / steps;
      out.push_back(p.plane.world({c.x() + r * std::cos(phi), c.y() + r * std::sin(phi),
                                   a.z() + (b.z() - a.z()) * k / steps}));
    }
  }
  return out;
}

/// Distance between segments p0p1 and q0q1 in space (the closest points of
/// the two lines, clamped to the segments; Ericson, Real-Time Collision
/// Detection, 5.1.9).
double segmentSegment(const Vec3 &p0, const Vec3 &p1, const Vec3 &q0, const Vec3 &q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 1e-18 && e <= 1e-18)
    return r.norm();
  if (a <= 1e-18) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-18) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-18 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + d1 * s) - (q0 + d2 * t)).norm();
}

/// The added feature as this check reads it, in its own frame.
struct Solid {
  Vec3 origin = Vec3::Zero(), x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  double height = 0;
  std::vector<Vec2> polygon;  ///< extruded: the profile; revolved: the meridian (radius, height)
  bool revolved = false;
  double draftTan = 0;
  std::vector<std::pair<Vec3, Vec3>> planes;  ///< faceted: point, outward normal
  struct Channel {
    std::string label;
    double radius = 0;
    std::vector<Vec3> points;
  };
  std::vector<Channel> channels;

  Vec3 local(const Vec3 &p) const {
    const Vec3 d = p - origin;
    return {d.dot(x), d.dot(y), d.dot(z)};
  }
  /// Signed distance from p (local, in the plane) to the section at height
  /// h: negative inside.
  double distance(const Vec2 &p, double h) const {
    if (!planes.empty()) {
      double worst = -1e300;
      for (const auto &[a, n] : planes) {
        const Vec2 nxy(n.x(), n.y());
        const double excess = n.dot(Vec3(p.x(), p.y(), h) - a);
        worst = std::max(worst, nxy.norm() > 1e-12 ? excess / nxy.norm() : (excess > 0 ? 1e300 : -1e300));
      }
      return worst;
    }
    double d = 1e300;
    bool inside = false;
    // A revolved solid: the distance in its meridian plane, through p.
    const Vec2 q = revolved ? Vec2(p.norm(), h) : p;
    for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
      const Vec2 &a = polygon[j], &b = polygon[i];
      const Vec2 ab = b - a;
      const double t = std::clamp((q - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
      d = std::min(d, (a + ab * t - q).norm());
      if ((a.y() > q.y()) != (b.y() > q.y()) && q.x() < a.x() + (q.y() - a.y()) * ab.x() / ab.y())
        inside = !inside;
    }
    return (inside ? -d : d) + (revolved ? 0.0 : h * draftTan);
  }
  /// The smallest distance from the vertical segment at p between heights
  /// h0 and h1 to a channel's axis, less its radius: negative inside.
  double channelClearance(const Vec2 &p, double h0, double h1) const {
    double best = 1e300;
    for (const Channel &c : channels)
      for (size_t i = 0; i + 1 < c.points.size(); ++i)
        best = std::min(best, segmentSegment(Vec3(p.x(), p.y(), h0), Vec3(p.x(), p.y(), h1), c.points[i],
                                             c.points[i + 1]) -
                                  c.radius);
    return best;
  }
};

std::optional<Solid> readSolid(const Node &f, std::string &error) {
  Solid s;
  s.origin = f.vec("at").value_or(Vec3::Zero());
  s.z = f.vec("axis").value_or(Vec3::UnitZ()).normalized();
  s.x = f.vec("ref").value_or(Vec3::UnitX());
  s.x = (s.x - s.z * s.x.dot(s.z)).normalized();
  s.y = s.z.cross(s.x);
  if (f.text("shape").value_or("") == "faceted") {
    for (const Node *p : f.childrenOf(ir::Kind::BoundingPlane))
      s.planes.push_back({*p->vec("at"), p->vec("normal")->normalized()});
    s.height = -1e300;
    // The top: the highest point on a plane whose section there is not empty
    // is not known without the corners; the feature's height, when given,
    // else the highest of the planes' own points that lie inside all.
    if (auto h = f.number("height"))
      s.height = *h;
    else
      for (const auto &[a, n] : s.planes)
        if (n.z() > 0.5)
          s.height = std::max(s.height, a.z());
  } else {
    const Node *profile = nullptr;
    for (const Node &c : f.children)
      if (c.category() == ir::Category::Profile) {
        profile = &c;
        break;
      }
    if (!profile) {
      error = "has no profile";
      return std::nullopt;
    }
    Vec3 po = profile->vec("at").value_or(Vec3::Zero());
    Vec3 pz = profile->vec("axis").value_or(Vec3::UnitZ()), px = profile->vec("ref").value_or(Vec3::UnitX());
    const Vec3 py = pz.cross(px);
    auto put = [&](double u, double v) { s.polygon.push_back((po + u * px + v * py).head<2>()); };
    if (profile->kind == ir::Kind::RectangularProfile) {
      const double l = *profile->number("length") / 2, w = *profile->number("width") / 2;
      put(-l, -w), put(l, -w), put(l, w), put(-l, w);
    } else if (profile->kind == ir::Kind::CircularProfile) {
      const double r = *profile->number("diameter") / 2;
      const int n = static_cast<int>(std::ceil(kPi / std::acos(1 - kChord / r)));
      for (int k = 0; k < n; ++k)
        put(r * std::cos(2 * kPi * k / n), r * std::sin(2 * kPi * k / n));
    } else if (profile->kind == ir::Kind::GeneralProfile && !profile->children.empty()) {
      for (const Vec3 &p : sampled(profile->children.front(), error))
        put(p.x(), p.y());
      if (!error.empty())
        return std::nullopt;
    } else {
      error = "has a profile this check does not read";
      return std::nullopt;
    }
    s.revolved = f.text("shape").value_or("") == "revolved";
    s.height = f.number("height").value_or(0);
    if (s.revolved)
      for (const Vec2 &p : s.polygon)
        s.height = std::max(s.height, p.y());
    s.draftTan = std::tan(f.number("draft").value_or(0) * kPi / 180);
  }
  for (const Node *v : f.childrenOf(ir::Kind::AmVoid)) {
    Solid::Channel c;
    c.label = v->label;
    c.radius = v->number("diameter").value_or(0) / 2;
    if (!v->children.empty())
      c.points = sampled(v->children.front(), error);
    if (!error.empty())
      return std::nullopt;
    s.channels.push_back(std::move(c));
  }
  return s;
}

/// A bead: its centre line in workpiece coordinates (the plane segment and
/// its height), as laid.
struct Bead {
  Seg seg;
  double z = 0;
};

class Checker {
public:
  Checker(const ir::Module &m, DiagnosticEngine &d, PassStats &s, double tol, std::vector<std::string> *reports)
      : module_(m), diags_(d), stats_(s), tol_(tol), reports_(reports) {}

  bool run() {
    for (const Node *e : ir::programOrder(module_))
      if (ir::isAdditiveStep(*e))
        if (const Node *moves = e->child(ir::Kind::Moves))
          step(*e, *moves);
    return ok_;
  }

private:
  void error(const Node &ws, const std::string &message) {
    diags_.error(ws.origin.loc, "workingstep " + ws.symbol + ": " + message).entity(ws.origin.entityId);
    ok_ = false;
  }

  static std::string at(const Vec3 &p) {
    return "(" + formatFixed(p.x(), 3) + ", " + formatFixed(p.y(), 3) + ", " + formatFixed(p.z(), 3) + ")";
  }

  void step(const Node &ws, const Node &moves) {
    const Node *op = ir::operationOf(ws);
    const Node *feature = ir::findFeature(module_, ws.text("feature").value_or(""));
    const Node *tool = ir::findTool(module_, moves.text("tool").value_or(""));
    const Node *tech = op ? op->child(ir::Kind::DepositionTechnology) : nullptr;
    if (!op || !feature || !tool)
      return;  // the IR verifier reports dangling references
    if (!tech) {
      error(ws, "its deposition operation has no deposition technology: its beads (their width and height) "
                "cannot be checked");
      return;
    }
    std::string why;
    std::optional<Solid> solid = readSolid(*feature, why);
    if (!solid) {
      error(ws, "its feature " + feature->symbol + " " + why);
      return;
    }
    const double w = *tech->number("bead_width"), t = *tech->number("bead_height");
    const double layer = op->number("layer_thickness").value_or(t);
    const double allowance = op->number("allowance").value_or(0);
    const double feed = *tech->number("feed");
    // The beads, and the energy against the moves.
    std::vector<Bead> beads;
    double energyTime = 0;
    const std::vector<std::pair<ir::Move, bool>> walk = ir::walkWithEnergy(moves);
    for (const auto &[m, energy] : walk) {
      if (energy && m.kind == ir::MoveKind::Rapid) {
        error(ws, "the energy is on during a rapid to " + at(m.to));
        return;
      }
      if (!energy || !m.isFeed() || !m.from)
        continue;
      energyTime += m.length() / m.feed * 60;
      for (const Seg &s : m.planar())
        beads.push_back({s, std::min(m.from->z(), m.to.z())});
    }
    // The energy after the last move: a state after it may still switch it.
    bool energy = false;
    for (const Node &c : moves.children)
      if (c.kind == ir::Kind::State)
        if (auto e = c.text("energy"))
          energy = *e == "on";
    if (energy) {
      error(ws, "the energy is still on when its moves end");
      return;
    }
    if (beads.empty()) {
      error(ws, "lays no bead (the energy is never on during a feed move)");
      return;
    }
    // Layers by height (local), and a lookup of every layer's beads.
    std::map<long, std::vector<Seg>> layers;
    for (const Bead &b : beads) {
      const double h = solid->local(Vec3(b.seg.a.x(), b.seg.a.y(), b.z)).z();
      layers[std::lround(h / layer)].push_back(b.seg);
    }
    const long needed = static_cast<long>(std::ceil(solid->height / layer - 1e-9));
    double worstGap = 0, worstOver = 0, worstChannel = 1e300;
    Vec3 gapAt = Vec3::Zero(), overAt = Vec3::Zero(), channelAt = Vec3::Zero();
    long samples = 0;
    auto toWorld = [&](const Vec2 &p, double h) { return solid->origin + p.x() * solid->x + p.y() * solid->y + h * solid->z; };
    for (long k = 0; k < needed; ++k) {
      const double h0 = static_cast<double>(k) * layer, h1 = std::min(h0 + layer, solid->height);
      auto found = layers.find(k);
      std::vector<Seg> segs;
      if (found != layers.end())
        for (const Seg &s : found->second) {
          Seg l = s;
          auto toLocal = [&](const Vec2 &p) {
            const Vec3 q = solid->local(Vec3(p.x(), p.y(), 0));
            return Vec2(q.x(), q.y());
          };
          l.a = toLocal(s.a), l.b = toLocal(s.b), l.c = toLocal(s.c);
          segs.push_back(l);
        }
      std::optional<geom::SegIndex> index;
      if (!segs.empty())
        index.emplace(segs);
      // Coverage: the grid over the section's box at the layer's bottom.
      geom::Box box;
      if (solid->revolved)
        for (const Vec2 &p : solid->polygon)
          box.add(geom::Box{Vec2(-p.x(), -p.x()), Vec2(p.x(), p.x())});
      else if (!solid->polygon.empty())
        for (const Vec2 &p : solid->polygon)
          box.add(p);
      else
        for (const Seg &s : segs)
          box.add(s.box().grown(w));
      const double step = w * kGridShare;
      for (double gx = box.lo.x() + step / 2; gx < box.hi.x(); gx += step)
        for (double gy = box.lo.y() + step / 2; gy < box.hi.y(); gy += step) {
          const Vec2 p(gx, gy);
          const bool inside = solid->distance(p, h0) < -tol_ || solid->distance(p, (h0 + h1) / 2) < -tol_ ||
                              solid->distance(p, h1) < -tol_;
          if (!inside || (!solid->channels.empty() && solid->channelClearance(p, h0, h0 + layer) < tol_))
            continue;
          ++samples;
          const double gap = (index ? index->distance(p) : 1e300) - w / 2;
          if (gap > worstGap) {
            worstGap = gap;
            gapAt = toWorld(p, h0);
          }
        }
      // Overflow and channels: along every bead.
      for (const Seg &s : segs) {
        const int n = std::max(1, static_cast<int>(std::ceil(s.length() / (w / 4))));
        for (int i = 0; i <= n; ++i) {
          const double u = static_cast<double>(i) / n;
          const Vec2 c = s.at(u), across(-s.tangent(u).y(), s.tangent(u).x());
          for (double side : {-0.5, 0.0, 0.5}) {
            const Vec2 p = c + across * (side * w);
            const double over = std::min({solid->distance(p, h0), solid->distance(p, std::min(h0 + t / 2, solid->height)),
                                          solid->distance(p, std::min(h0 + t, solid->height))});
            if (over > worstOver) {
              worstOver = over;
              overAt = toWorld(p, h0);
            }
            if (!solid->channels.empty()) {
              const double clear = solid->channelClearance(p, h0, h0 + t);
              if (clear < worstChannel) {
                worstChannel = clear;
                channelAt = toWorld(p, h0);
              }
            }
          }
        }
      }
    }
    const double top = static_cast<double>(layers.empty() ? 0 : layers.rbegin()->first + 1) * layer;
    stats_["deposition samples checked"] += samples;
    if (worstGap > tol_)
      error(ws, "leaves its feature " + feature->symbol + " uncovered: a point " + formatFixed(worstGap, 3) +
                    " mm beyond the edge of the nearest bead of its layer, at " + at(gapAt) +
                    " (beads as rectangles of " + formatShortest(w) + " x " + formatShortest(t) + " mm)");
    if (worstOver > allowance + tol_)
      error(ws, "deposits " + formatFixed(worstOver, 3) + " mm outside its feature " + feature->symbol + " at " +
                    at(overAt) + ", more than the allowance " + formatShortest(allowance) + " mm");
    if (top > solid->height + allowance + tol_)
      error(ws, "builds to " + formatShortest(top) + " mm over the base, more than its feature's height " +
                    formatShortest(solid->height) + " mm and the allowance " + formatShortest(allowance) + " mm");
    if (!solid->channels.empty() && worstChannel < -tol_)
      error(ws, "deposits " + formatFixed(-worstChannel, 3) + " mm into a channel of " + feature->symbol + " at " +
                    at(channelAt));
    clearance(ws, moves, *tool, w, t);
    if (reports_) {
      double length = 0;
      for (const Bead &b : beads)
        length += b.seg.length();
      char line[400];
      std::snprintf(line, sizeof line,
                    "%s: %zu layers, bead %.0f mm, energy on %.1f s at %.0f mm/min; largest gap %.3f mm, overflow "
                    "%.3f mm (allowance %.3f)%s",
                    ws.symbol.c_str(), layers.size(), length, energyTime, feed, std::max(worstGap, 0.0),
                    std::max(worstOver, 0.0), allowance,
                    solid->channels.empty() ? ""
                                            : (", channels kept clear by " + formatFixed(worstChannel, 3) + " mm").c_str());
      reports_->push_back(line);
    }
  }

  /// The head along every move (its nozzle's tip `standoff` above the
  /// programmed point, its cone widening upwards to the head's diameter)
  /// against the material deposited before the move, this step's and the
  /// steps' before.
  void clearance(const Node &ws, const Node &moves, const Node &tool, double w, double t) {
    const double standoff = tool.number("standoff").value_or(0);
    const double nozzle = tool.number("diameter").value_or(0) / 2;
    const double half = tool.number("taper_angle").value_or(0) * kPi / 180;
    const double head = std::max(tool.number("holder_diameter").value_or(0) / 2, nozzle);
    for (const auto &[m, energy] : ir::walkWithEnergy(moves)) {
      if (!m.from)
        continue;
      const double tip = std::min(m.from->z(), m.to.z()) + standoff;
      if (tallest_ > tip + tol_)  // else nothing laid reaches up to the nozzle's tip
        for (const Bead &b : deposited_) {
          if (b.z + t <= tip + tol_)
            continue;
          for (const Seg &s : m.planar()) {
            const double reach = geom::distance(s, b.seg) - w / 2;
            if (reach > head)
              continue;
            const double lowest = reach <= nozzle || half <= 0 ? tip : tip + (reach - nozzle) / std::tan(half);
            if (b.z + t > lowest + tol_) {
              error(ws, "the head meets material deposited before (up to " + formatFixed(b.z + t, 3) +
                            " mm) on the move to " + at(m.to) + ": its nozzle's tip is " + formatShortest(standoff) +
                            " mm above the programmed point");
              return;
            }
          }
        }
      if (energy && m.isFeed())
        for (const Seg &s : m.planar()) {
          deposited_.push_back({s, std::min(m.from->z(), m.to.z())});
          tallest_ = std::max(tallest_, deposited_.back().z + t);
        }
    }
  }

  const ir::Module &module_;
  DiagnosticEngine &diags_;
  PassStats &stats_;
  double tol_;
  std::vector<std::string> *reports_;
  /// Every bead laid so far, all steps in program order, and the top of
  /// the tallest (no head whose tip is above it can meet any).
  std::vector<Bead> deposited_;
  double tallest_ = -1e300;
  bool ok_ = true;
};

} // namespace

bool verifyDeposition(const ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                      std::optional<double> tolerance, std::vector<std::string> *reports) {
  return Checker(module, diags, stats, tolerance.value_or(0.05), reports).run();
}

} // namespace stepnc::passes
