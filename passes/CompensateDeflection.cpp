// compensate-deflection: programs each finishing wall off the part by the
// amount the cutting force is predicted to bend the tool away from it
// (docs/deflection-compensation.md).
//
// On the cutting model of the program (passes/CuttingModel), every sample of
// a finishing move that meets material on one side is a wall: straight,
// taken to the sample's equivalent radial depth ae over its axial depth ap.
// The peak force pushing the tool off that wall (cutting::ForceModel), spread
// over the engaged height, bends the tool as a stepped cantilever
// (cutting::deflectionUnderSpreadLoad). Moving the path `c` into the wall
// takes ae + c and bends the tool further, so the offset is the fixed point
// c = delta(ae + c) at mid-height of the cut, iterated from the nominal
// path. Where c would exceed max-offset, the feed is lowered until it does
// not.
//
// The offset the program gets is one continuous, piecewise-linear function
// of the distance along each run of moves that join tangentially (a wall
// with its rounded corners), within 1 um of every wall sample's fixed point
// and with as few changes of slope as that allows. The path therefore never
// steps where the offset changes: it turns by the change of slope, a few
// micro-radians, which the machine runs at full feed. Lines along which the
// offset changes stay lines; arcs become arcs about a centre moved a little
// so that both their ends sit at their offsets. Each move is cut where the
// slope or the feed changes, and every offset move records the nominal end
// it is predicted to reach as `nominal`. Where two runs meet at a corner of
// two lines, both run to where their offset lines cross; elsewhere a short
// connecting line joins them.
#include "passes/CuttingModel.h"
#include "ir/Program.h"
#include "passes/CuttingPass.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace stepnc::passes {

namespace {

using geom::Vec2;

/// mm: the programmed offset stays this close to every wall sample's fixed
/// point (the residual error is then within about as much).
constexpr double kFitTolerance = 0.001;
constexpr double kConverged = 1e-7; ///< mm: fixed-point tolerance
constexpr double kDiverged = 1.0;   ///< mm: an offset this large means the iteration runs away
constexpr int kMaxIterations = 200;
constexpr double kSamePoint = 1e-6; ///< mm: closer positions need no connector
constexpr double kAbsorbedGap = 1e-3; ///< mm: a gap a move's end is moved across instead of a connector
/// Two moves meet tangentially (one run) when their directions differ by
/// less than this (rad); otherwise they make a corner.
constexpr double kTangentTurn = 0.01;
/// At a corner the two offset lines run to where they cross when that is
/// within this many times the step between them (and half of either line).
constexpr double kCornerReach = 10.0;

struct Solution {
  double offset = 0; ///< mm into the wall
  WallBend bend;     ///< at that offset
  bool converged = true;
};

/// The offset that cancels the bend it causes at mid-height, c = bend(c), by
/// fixed-point iteration from the nominal path (c = 0).
Solution solve(const CutStep &step, const CutSample &sample, double fz) {
  Solution s;
  s.bend = wallBend(step, sample, 0, fz);
  for (int i = 0; i < kMaxIterations; ++i) {
    if (std::abs(s.bend.mid - s.offset) <= kConverged)
      return s;
    s.offset = s.bend.mid;
    if (s.offset > kDiverged)
      break;
    s.bend = wallBend(step, sample, s.offset, fz);
  }
  s.converged = false;
  return s;
}

/// One sample's plan.
struct SamplePlan {
  const CutSample *wall = nullptr; ///< the sample, when it cuts a wall of the part
  double fz = 0;                   ///< mm per tooth: the move's, or lowered to keep the offset within the limit
  Solution sol;                    ///< at fz
  bool beyond = false;             ///< even the lowest feed cannot keep the offset within the limit
};

/// A stretch [from, to] of a move (mm along it) cut at one feed.
struct FeedPiece {
  double from = 0, to = 0;
  double fz = 0; ///< mm per tooth
};

/// Where the offset must be at a place along a run: within [lo, hi] (mm to
/// the left of the path; negative to the right), `want` if nothing else
/// decides.
struct Band {
  double s = 0; ///< mm along the run
  double lo = 0, hi = 0, want = 0;
};

/// A continuous, piecewise-linear offset along a run: mm to the left of
/// the path (negative to the right), constant before the first vertex and
/// after the last; zero everywhere without vertices.
struct Profile {
  std::vector<std::pair<double, double>> vertices; ///< (s, offset), s increasing

  double at(double s) const {
    if (vertices.empty())
      return 0;
    if (s <= vertices.front().first)
      return vertices.front().second;
    if (s >= vertices.back().first)
      return vertices.back().second;
    const auto hi = std::upper_bound(vertices.begin(), vertices.end(), s,
                                     [](double x, const std::pair<double, double> &v) { return x < v.first; });
    const auto lo = hi - 1;
    return lo->second + (hi->second - lo->second) * (s - lo->first) / (hi->first - lo->first);
  }
};

/// The profile through `bands` (ordered by s): from the first band's wanted
/// value, each stretch runs as far as one straight line stays within every
/// band it passes, with the slope of the stretch before when that fits
/// (else the nearest that does), so that the slope changes as seldom and as
/// little as the bands allow.
Profile fitProfile(std::vector<Band> bands) {
  // Bands at one place: their common part (the middle when they have none).
  std::vector<Band> merged;
  for (const Band &b : bands) {
    if (!merged.empty() && b.s - merged.back().s <= kSamePoint) {
      Band &m = merged.back();
      m.lo = std::max(m.lo, b.lo);
      m.hi = std::min(m.hi, b.hi);
      if (m.lo > m.hi)
        m.lo = m.hi = (m.lo + m.hi) / 2;
      m.want = std::clamp(m.want, m.lo, m.hi);
    } else {
      merged.push_back(b);
    }
  }
  Profile p;
  if (merged.empty())
    return p;
  double s0 = merged[0].s, v0 = std::clamp(merged[0].want, merged[0].lo, merged[0].hi), slope = 0;
  p.vertices.emplace_back(s0, v0);
  for (size_t i = 1; i < merged.size();) {
    double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
    size_t j = i;
    for (; j < merged.size(); ++j) {
      const double ds = merged[j].s - s0;
      const double nlo = std::max(lo, (merged[j].lo - v0) / ds), nhi = std::min(hi, (merged[j].hi - v0) / ds);
      if (nlo > nhi)
        break;
      lo = nlo;
      hi = nhi;
    }
    slope = std::clamp(slope, lo, hi);
    const double s1 = merged[j - 1].s;
    v0 += slope * (s1 - s0);
    s0 = s1;
    p.vertices.emplace_back(s0, v0);
    i = j;
  }
  return p;
}

/// The unit direction of a horizontal move at its point p.
Vec2 tangentAt(const ir::Move &m, const ir::Vec3 &p) {
  if (m.kind == ir::MoveKind::Arc) {
    const Vec2 u = (p.head<2>() - m.center.head<2>()).normalized();
    return m.ccw ? Vec2(-u.y(), u.x()) : Vec2(u.y(), -u.x());
  }
  return (m.to - *m.from).head<2>().normalized();
}

/// The point `offset` mm to the left (right when negative) of the nominal
/// point p of a horizontal move, square to its direction there: a line is
/// shifted along its normal, an arc's radius changes about its centre.
ir::Vec3 offsetPoint(const ir::Move &m, const ir::Vec3 &p, double offset) {
  if (offset == 0)
    return p;
  const Vec2 t = tangentAt(m, p);
  const Vec2 q = p.head<2>() + offset * Vec2(-t.y(), t.x());
  return {q.x(), q.y(), p.z()};
}

/// A horizontal milling move the model measured.
bool flat(const CutMove &cm) { return cm.measured && cm.move.from && !cm.move.changesHeight(); }

/// Whether b continues a in one run: both flat at one height, b starting
/// where a ends in the direction a ends in.
bool continues(const CutMove &a, const CutMove &b) {
  if (!flat(a) || !flat(b) || (*b.move.from - a.move.to).norm() > kSamePoint)
    return false;
  const Vec2 u = tangentAt(a.move, a.move.to), v = tangentAt(b.move, *b.move.from);
  return std::abs(std::atan2(geom::cross(u, v), u.dot(v))) <= kTangentTurn;
}

/// What the rewrite changed, for the statistics.
struct RewriteCounts {
  long long compensated = 0, connectors = 0, lowered = 0;
};

/// A move of the rewritten step (or another child, passed through), with
/// where it is programmed to start and end and the nominal ends it is
/// predicted to reach.
struct Placed {
  explicit Placed(ir::Node n, const ir::Move *m = nullptr) : node(std::move(n)), move(m) {}

  ir::Node node;
  const ir::Move *move = nullptr; ///< the move it is or is a piece of; null for other children
  bool changed = false;       ///< its end is to be written
  ir::Vec3 from = ir::Vec3::Zero(), to = ir::Vec3::Zero();
  ir::Vec3 nominalFrom = ir::Vec3::Zero(), nominalTo = ir::Vec3::Zero();
  double feed = 0;
  std::optional<ir::Node> lead; ///< a connector run before it

  /// A horizontal feed line whose start is known.
  bool flatLine() const { return move && move->kind == ir::MoveKind::Linear && move->from && !move->changesHeight(); }
};

/// Per workingstep: what the report shows.
struct StepFigures {
  double errorBefore = 0, errorAfter = 0; ///< mm, largest position error at mid-height
  double taperBefore = 0, taperAfter = 0; ///< mm, largest tip-to-top difference
  double offsetMax = 0;                   ///< mm
  double wallLength = 0, loweredLength = 0;
  int beyond = 0; ///< samples whose offset stays above the limit at any feed
};

/// A measured move of a finishing step as planned: its samples, the feeds
/// of its stretches, and where it starts along its run.
struct MoveFit {
  const CutMove *cm = nullptr;
  std::vector<SamplePlan> samples;
  std::vector<FeedPiece> feeds;
  size_t run = 0;   ///< index of its run's profile
  double start = 0; ///< mm along the run
};

class CompensateDeflectionPass final : public CuttingPass {
public:
  CompensateDeflectionPass(std::string data, double maxOffset) : CuttingPass(std::move(data)), maxOffset_(maxOffset) {}

  std::string_view name() const override { return "compensate-deflection"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    if (!takes(module, diags, "its moves"))
      return {false, false};
    const auto data = start(diags);
    if (!data)
      return {false, false};
    const CutAnalysis analysis = analyseCuts(module, {&*data, nullptr});

    RewriteCounts counts;
    std::vector<std::pair<const CutStep *, StepFigures>> figures;
    for (const CutStep &step : analysis.steps) {
      if (!finishesWalls(step) || !step.tool || !step.tool->mill || !step.material)
        continue;
      StepFigures f;
      // The moves' samples and feeds, their runs and each run's profile.
      std::vector<MoveFit> fits(step.moves.size());
      std::vector<std::vector<Band>> bands;
      for (size_t k = 0; k < step.moves.size(); ++k) {
        const CutMove &cm = step.moves[k];
        MoveFit &fit = fits[k];
        fit.cm = &cm;
        if (!flat(cm) || cm.samples.empty())
          continue;
        fit.samples = planSamples(analysis, step, cm, f);
        fit.feeds = feedPieces(step, cm, fit.samples);
        if (k > 0 && !fits[k - 1].samples.empty() && cm.move.turns == 0 && step.moves[k - 1].move.turns == 0 &&
            continues(step.moves[k - 1], cm)) {
          fit.run = fits[k - 1].run;
          fit.start = fits[k - 1].start + step.moves[k - 1].move.length();
        } else {
          fit.run = bands.size();
          bands.emplace_back();
        }
        for (size_t q = 0; q < cm.samples.size(); ++q)
          if (const SamplePlan &sp = fit.samples[q]; sp.wall)
            bands[fit.run].push_back(band(fit.start + cm.samples[q].s, sp));
      }
      std::vector<Profile> profiles;
      for (std::vector<Band> &b : bands)
        profiles.push_back(fitProfile(std::move(b)));
      // The offsets the samples get.
      for (const MoveFit &fit : fits) {
        if (fit.samples.empty())
          continue;
        const Profile &profile = profiles[fit.run];
        for (size_t q = 0; q < fit.samples.size(); ++q) {
          const double offset = profile.at(fit.start + fit.cm->samples[q].s);
          f.offsetMax = std::max(f.offsetMax, std::abs(offset));
          if (const SamplePlan &sp = fit.samples[q]; sp.wall) {
            const double into = sp.wall->side * offset;
            const WallBend b = wallBend(step, *sp.wall, into, sp.fz);
            f.errorAfter = std::max(f.errorAfter, std::abs(b.mid - into));
            f.taperAfter = std::max(f.taperAfter, b.taper());
          }
        }
      }
      rewrite(step, fits, profiles, counts);
      if (f.wallLength > 0) {
        writeComment(*const_cast<ir::Node *>(step.movesNode), f);
        figures.emplace_back(&step, f);
      }
    }
    writeReport(analysis, figures);
    stats["moves compensated"] = counts.compensated;
    stats["connectors added"] = counts.connectors;
    stats["feeds lowered for deflection"] = counts.lowered;
    return {true, counts.compensated + counts.lowered > 0};
  }

private:
  /// Every sample of a measured finishing move: its wall (one-sided
  /// engagement of material the part keeps), the feed that keeps its offset
  /// within the limit, and the offset at that feed.
  std::vector<SamplePlan> planSamples(const CutAnalysis &analysis, const CutStep &step, const CutMove &cm,
                                      StepFigures &f) const {
    std::vector<SamplePlan> plans;
    const double spacing = cm.samples.size() > 1 ? cm.move.length() / double(cm.samples.size()) : cm.move.length();
    for (const CutSample &s : cm.samples) {
      SamplePlan p;
      p.fz = cm.fz;
      if (engagesPartWall(analysis, step, s, cm.move.to.z())) {
        p.wall = &s;
        p.sol = solve(step, s, cm.fz);
        const WallBend nominal = wallBend(step, s, 0, cm.fz);
        f.errorBefore = std::max(f.errorBefore, nominal.mid);
        f.taperBefore = std::max(f.taperBefore, nominal.taper());
        f.wallLength += spacing;
        if (!p.sol.converged || p.sol.offset > maxOffset_) {
          // The feed at which the offset meets the limit: offsets grow with fz.
          double lo = 0, hi = cm.fz;
          for (int i = 0; i < 40; ++i) {
            const double mid = (lo + hi) / 2;
            const Solution t = solve(step, s, mid);
            (t.converged && t.offset <= maxOffset_ ? lo : hi) = mid;
          }
          if (lo > 0) {
            p.fz = lo;
            p.sol = solve(step, s, lo);
            f.loweredLength += spacing;
          } else {
            p.beyond = true; // edge forces alone bend the tool further: keep the feed, offset by the limit
            p.sol.offset = maxOffset_;
            ++f.beyond;
          }
        }
      }
      plans.push_back(p);
    }
    return plans;
  }

  /// Stretches of a move at one feed: consecutive samples whose feeds are
  /// within kFeedRatio (a move with whole turns is one), at the lowest of
  /// them; each wall sample's offset is then solved at its stretch's feed.
  static std::vector<FeedPiece> feedPieces(const CutStep &step, const CutMove &cm, std::vector<SamplePlan> &plans) {
    std::vector<FeedPiece> out;
    for (size_t i = 0; i < plans.size();) {
      double lo = plans[i].fz, hi = lo;
      size_t end = i + 1;
      for (; end < plans.size(); ++end) {
        const double fz = plans[end].fz;
        if (cm.move.turns == 0 && std::min(lo, fz) < kFeedRatio * std::max(hi, fz))
          break;
        lo = std::min(lo, fz);
        hi = std::max(hi, fz);
      }
      for (size_t q = i; q < end; ++q) {
        SamplePlan &p = plans[q];
        if (p.wall && p.fz > lo && !p.beyond)
          p.sol = solve(step, *p.wall, lo);
        p.fz = lo;
      }
      const double from = out.empty() ? 0 : out.back().to, to = cm.pieceEnd(end);
      if (!out.empty() && out.back().fz == lo)
        out.back().to = to;
      else
        out.push_back({from, to, lo});
      i = end;
    }
    return out;
  }

  /// Where a wall sample `s` mm along its run wants the path: within
  /// kFitTolerance of its fixed point, into its wall (never away from it)
  /// by at most max-offset; on the nominal path when that is within.
  Band band(double s, const SamplePlan &p) const {
    const double c = p.wall->side * p.sol.offset;
    Band b{s, c - kFitTolerance, c + kFitTolerance, c};
    if (p.wall->side > 0)
      b = {s, std::max(b.lo, 0.0), std::max(b.lo, std::min(b.hi, maxOffset_)), c};
    else
      b = {s, std::min(b.hi, std::max(b.lo, -maxOffset_)), std::min(b.hi, 0.0), c};
    if (b.lo <= 0 && b.hi >= 0)
      b.want = 0;
    return b;
  }

  /// Rewrites the step's moves: each changed move as its stretches between
  /// the changes of slope of its run's profile and of feed, offset by the
  /// profile; other moves as they were, joined to what runs before them.
  void rewrite(const CutStep &step, const std::vector<MoveFit> &fits, const std::vector<Profile> &profiles,
               RewriteCounts &counts) const {
    auto *movesNode = const_cast<ir::Node *>(step.movesNode);
    std::vector<Placed> placed;
    placed.reserve(movesNode->children.size());
    size_t cursor = 0;
    for (ir::Node &child : movesNode->children) {
      const CutMove *cm = step.moveOf(child, cursor);
      if (!cm) {
        placed.emplace_back(std::move(child));
        continue;
      }
      const ir::Move &m = cm->move;
      const MoveFit &fit = fits[size_t(cm - step.moves.data())];
      std::vector<Placed> pieces;
      if (!fit.samples.empty())
        pieces = cut(child, fit, profiles[fit.run]);
      if (pieces.empty()) {
        Placed &p = placed.emplace_back(std::move(child), &m);
        p.from = p.nominalFrom = m.from.value_or(m.to);
        p.to = p.nominalTo = m.to;
        p.feed = m.feed;
        continue;
      }
      ++counts.compensated;
      for (Placed &p : pieces) {
        counts.lowered += p.feed < m.feed;
        placed.push_back(std::move(p));
      }
    }
    // Join each feed move to where the program before it leaves the tool.
    Placed *last = nullptr;
    for (Placed &p : placed) {
      if (!p.move)
        continue;
      if (last && p.move->isFeed() && p.move->from)
        join(*last, p, counts);
      last = &p;
    }
    movesNode->children.clear();
    for (Placed &p : placed) {
      if (p.lead)
        movesNode->children.push_back(std::move(*p.lead));
      if (p.changed) {
        p.node.set("to", ir::Value::point(p.to));
        if (p.move->isFeed())
          p.node.set("feed", ir::Value::feed(p.feed));
        if ((p.to - p.nominalTo).norm() > kSamePoint)
          p.node.set("nominal", ir::Value::point(p.nominalTo));
      }
      movesNode->children.push_back(std::move(p.node));
    }
  }

  /// The stretches of a move offset by its run's profile: cut where the
  /// profile's slope or the feed changes (a move with whole turns keeps one
  /// offset, the profile's at its middle); none when the move stays as it
  /// is.
  static std::vector<Placed> cut(const ir::Node &node, const MoveFit &fit, const Profile &profile) {
    const ir::Move &m = fit.cm->move;
    const double length = m.length();
    std::vector<double> at{0, length};
    if (m.turns == 0) {
      for (size_t i = 0; i + 1 < fit.feeds.size(); ++i)
        at.push_back(fit.feeds[i].to);
      for (const auto &[s, v] : profile.vertices)
        if (s > fit.start && s < fit.start + length)
          at.push_back(s - fit.start);
    }
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end(), [](double a, double b) { return b - a <= kSamePoint; }), at.end());
    at.back() = length;
    const auto offsetAt = [&](double s) { return profile.at(fit.start + (m.turns == 0 ? s : length / 2)); };
    bool changes = false;
    for (const double s : at)
      changes = changes || offsetAt(s) != 0;
    for (const FeedPiece &piece : fit.feeds)
      changes = changes || piece.fz < fit.cm->fz;
    if (!changes)
      return {};
    std::vector<Placed> out;
    for (size_t i = 0; i + 1 < at.size(); ++i) {
      const double a = at[i], b = at[i + 1], oa = offsetAt(a), ob = offsetAt(b);
      Placed &p = out.emplace_back(node, &m);
      p.changed = true;
      p.nominalFrom = a == 0 ? *m.from : m.pointAt(a);
      p.nominalTo = b == length ? m.to : m.pointAt(b);
      p.from = offsetPoint(m, p.nominalFrom, oa);
      p.to = offsetPoint(m, p.nominalTo, ob);
      const auto piece =
          std::find_if(fit.feeds.begin(), fit.feeds.end(), [&](const FeedPiece &f) { return (a + b) / 2 <= f.to; });
      const double fz = piece == fit.feeds.end() ? fit.feeds.back().fz : piece->fz;
      p.feed = fz < fit.cm->fz ? fit.cm->feedFor(fz) : m.feed;
      if (m.kind == ir::MoveKind::Arc && oa != ob) {
        const Vec2 c = geom::balancedCentre(p.from.head<2>(), p.to.head<2>(), m.center.head<2>());
        p.node.set("center", ir::Value::point({c.x(), c.y(), m.center.z()}))
            .set("nominal_center", ir::Value::point(m.center));
      }
    }
    return out;
  }

  /// Joins b to a where b starts off a's programmed end: at a corner of two
  /// lines both run to where they cross; otherwise a connecting line steps
  /// across.
  static void join(Placed &a, Placed &b, RewriteCounts &counts) {
    const double step = (b.from - a.to).norm();
    if (step <= kSamePoint)
      return;
    if (a.flatLine() && b.flatLine() && std::abs(a.to.z() - b.from.z()) <= kSamePoint &&
        (a.nominalTo - b.nominalFrom).norm() <= kSamePoint) {
      const Vec2 da = (a.to - a.from).head<2>(), db = (b.to - b.from).head<2>();
      const double den = geom::cross(da, db);
      if (std::abs(den) > geom::kEps * da.norm() * db.norm()) {
        const double s = geom::cross((b.from - a.from).head<2>(), db) / den;
        const Vec2 x = a.from.head<2>() + s * da;
        const double reach = std::min({kCornerReach * step, da.norm() / 2, db.norm() / 2});
        if ((x - a.to.head<2>()).norm() <= reach && (x - b.from.head<2>()).norm() <= reach) {
          a.to = b.from = {x.x(), x.y(), a.to.z()};
          a.changed = true;
          return;
        }
      }
    }
    // A gap of a micrometre or less (two arcs' ends moved along normals a
    // little apart where the nominal path turns slightly): the first move
    // ends where the next starts, not a connector whose own two sharp turns
    // would stop the machine on the wall.
    if (step <= kAbsorbedGap && a.move && b.move && a.move->isFeed() && b.move->isFeed() &&
        std::abs(a.to.z() - b.from.z()) <= kSamePoint) {
      a.to = b.from;
      a.changed = true;
      return;
    }
    ir::Node line(ir::Kind::Linear);
    line.set("to", ir::Value::point(b.from)).set("feed", ir::Value::feed(std::min(a.feed, b.feed)));
    if (auto role = b.node.text("role"))
      line.set("role", ir::Value::word(*role));
    if ((b.from - b.nominalFrom).norm() > kSamePoint)
      line.set("nominal", ir::Value::point(b.nominalFrom));
    b.lead = std::move(line);
    ++counts.connectors;
  }

  static std::string um(double mm) { return formatFixed(mm * 1000, 1); }

  static void writeComment(ir::Node &movesNode, const StepFigures &f) {
    ir::replaceCommentPart(movesNode, {"compensate-deflection:"},
                           "compensate-deflection: error " + um(f.errorBefore) + " -> " + um(f.errorAfter) +
                               " um, taper " + um(f.taperAfter) + " um, offset up to " + formatFixed(f.offsetMax, 4) +
                               " mm");
  }

  void writeReport(const CutAnalysis &analysis, const std::vector<std::pair<const CutStep *, StepFigures>> &figures) {
    for (const std::string &note : analysis.notes)
      report_.push_back(note);
    report_.push_back("finishing workingstep: position error of the wall at mid-height of the cut before -> after "
                      "(um), taper over the cut before -> after (um, not removable by a path offset), largest "
                      "offset (mm), share of wall length with feed lowered (max-offset " +
                      formatShortest(maxOffset_) + " mm)");
    if (figures.empty())
      report_.push_back("  no finishing wall in the program");
    for (const auto &[step, f] : figures) {
      const std::string name = step->executable->symbol.empty() ? step->executable->kindName() : step->executable->symbol;
      std::string line = "  " + name + ": " + um(f.errorBefore) + " -> " + um(f.errorAfter) + ", " + um(f.taperBefore) +
                         " -> " + um(f.taperAfter) + ", " + formatFixed(f.offsetMax, 4) + ", " +
                         formatFixed(100 * f.loweredLength / f.wallLength, 0) + " %";
      if (f.beyond)
        line += "; " + std::to_string(f.beyond) +
                " samples need more than max-offset even at the lowest feed (edge forces): offset by the limit";
      report_.push_back(line);
    }
  }

  double maxOffset_;  ///< mm
};

} // namespace

std::unique_ptr<Pass> createCompensateDeflectionPass(const PassOptions &options) {
  return std::make_unique<CompensateDeflectionPass>(options.text("data"), options.number("max-offset").value());
}

} // namespace stepnc::passes
