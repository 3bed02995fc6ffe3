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
// not. Moves are split where the offset changes by more than 2 um, offset
// pieces keep the nominal end they are predicted to reach as `nominal`, and
// short connecting lines join offset and nominal positions. Offsets are
// whole micrometres; each sample's residual error stays within 1.5 um.
#include "passes/CuttingModel.h"
#include "passes/CuttingPass.h"

#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace stepnc::passes {

namespace {

using geom::Vec2;

constexpr double kDefaultMaxOffset = 0.05; ///< mm
/// mm: the offsets of the samples in one piece differ by at most this, so
/// that the piece's offset is within 1 um of each one's.
constexpr double kPieceSpread = 0.002;
/// mm: pieces offset less than this stay on the nominal path, where the
/// tool then bends less than this (bend(0) < the fixed point).
constexpr double kMinOffset = 0.0015;
/// mm: offsets are whole micrometres, so that pieces either share one or
/// are joined by a connector a controller's output resolution can hold.
constexpr double kOffsetGrid = 0.001;
constexpr double kConverged = 1e-7; ///< mm: fixed-point tolerance
constexpr double kDiverged = 1.0;   ///< mm: an offset this large means the iteration runs away
constexpr int kMaxIterations = 200;
constexpr double kSamePoint = 1e-6; ///< mm: closer positions need no connector

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

  double offset() const { return wall ? sol.offset : 0.0; }
  /// The side of the wall the sample is offset towards; 0 below kMinOffset.
  int side() const { return wall && sol.offset >= kMinOffset ? wall->side : 0; }
};

struct Piece {
  double from = 0, to = 0; ///< mm along the move
  double fz = 0;
  double offset = 0; ///< mm into the wall on `side`
  int side = 0;
};

/// The point `offset` mm into the wall on `side` from the nominal point p of
/// a horizontal move: a line is shifted along its normal, an arc's radius
/// changes about the same centre.
ir::Vec3 offsetPoint(const Move &m, const ir::Vec3 &p, int side, double offset) {
  if (offset == 0 || side == 0)
    return p;
  Vec2 n;
  if (m.kind == MoveKind::Arc) {
    const Vec2 u = (p.head<2>() - m.center.head<2>()).normalized();
    n = m.ccw ? -u : u; // the left of a counter-clockwise arc is its centre
  } else {
    const Vec2 d = (m.to - *m.from).head<2>().normalized();
    n = Vec2(-d.y(), d.x());
  }
  const Vec2 q = p.head<2>() + side * offset * n;
  return {q.x(), q.y(), p.z()};
}

/// Per workingstep: what the report shows.
struct StepFigures {
  double errorBefore = 0, errorAfter = 0; ///< mm, largest position error at mid-height
  double taperBefore = 0, taperAfter = 0; ///< mm, largest tip-to-top difference
  double offsetMax = 0;                   ///< mm
  double wallLength = 0, loweredLength = 0;
  int beyond = 0; ///< samples whose offset stays above the limit at any feed
};

class CompensateDeflectionPass final : public CuttingPass {
public:
  CompensateDeflectionPass(std::string data, double maxOffset, std::string error)
      : CuttingPass(std::move(data), std::move(error)), maxOffset_(maxOffset) {}

  std::string_view name() const override { return "compensate-deflection"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    const auto data = start(diags);
    if (!data)
      return {false, false};
    const CutAnalysis analysis = analyseCuts(module, {&*data, nullptr});

    long long compensated = 0, connectors = 0, lowered = 0;
    std::vector<std::pair<const CutStep *, StepFigures>> figures;
    for (const CutStep &step : analysis.steps) {
      if (!finishesWalls(step) || !step.tool || !step.tool->mill || !step.material)
        continue;
      StepFigures f;
      std::map<const ir::Node *, std::vector<Piece>> pieces;
      for (const CutMove &cm : step.moves) {
        if (!cm.measured || cm.samples.empty())
          continue;
        std::vector<SamplePlan> plans = planSamples(analysis, step, cm, f);
        std::vector<Piece> ps = group(step, cm, plans, f);
        const bool changes =
            std::any_of(ps.begin(), ps.end(), [&](const Piece &p) { return p.offset != 0 || p.fz < cm.fz; });
        if (changes)
          pieces[cm.move.node] = std::move(ps);
      }
      if (!pieces.empty())
        rewrite(step, pieces, compensated, connectors, lowered);
      if (f.wallLength > 0) {
        writeComment(*const_cast<ir::Node *>(step.movesNode), f);
        figures.emplace_back(&step, f);
      }
    }
    writeReport(analysis, figures);
    stats["moves compensated"] = compensated;
    stats["connectors added"] = connectors;
    stats["feeds lowered for deflection"] = lowered;
    return {true, compensated + lowered > 0};
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

  /// Pieces of a move: consecutive samples on the same side whose offsets
  /// are within kPieceSpread and feeds within kFeedRatio (a move with whole
  /// turns is one piece); each piece takes the lowest feed of its samples and
  /// the middle of their offsets at it.
  std::vector<Piece> group(const CutStep &step, const CutMove &cm, std::vector<SamplePlan> &plans,
                           StepFigures &f) const {
    std::vector<Piece> out;
    const bool splittable = cm.move.turns == 0;
    size_t i = 0;
    while (i < plans.size()) {
      double lo = plans[i].offset(), hi = lo, fzLo = plans[i].fz, fzHi = fzLo;
      int side = plans[i].side();
      size_t end = i + 1;
      for (; end < plans.size(); ++end) {
        const SamplePlan &p = plans[end];
        const bool apart = (p.side() != 0 && side != 0 && p.side() != side) ||
                           std::max(hi, p.offset()) - std::min(lo, p.offset()) > kPieceSpread ||
                           std::min(fzLo, p.fz) < kFeedRatio * std::max(fzHi, p.fz);
        if (splittable && apart)
          break;
        lo = std::min(lo, p.offset());
        hi = std::max(hi, p.offset());
        fzLo = std::min(fzLo, p.fz);
        fzHi = std::max(fzHi, p.fz);
        side = side ? side : p.side();
      }
      Piece piece;
      piece.from = out.empty() ? 0 : out.back().to;
      piece.to = cm.pieceEnd(end);
      piece.fz = fzLo;
      piece.side = side;
      // The samples at the piece's feed; its offset in the middle of theirs.
      if (fzLo < fzHi) {
        lo = kDiverged;
        hi = 0;
        for (size_t q = i; q < end; ++q)
          if (plans[q].wall && !plans[q].beyond) {
            plans[q].sol = solve(step, *plans[q].wall, fzLo);
            lo = std::min(lo, plans[q].sol.offset);
            hi = std::max(hi, plans[q].sol.offset);
          }
        if (hi < lo)
          lo = hi = 0;
      }
      const double middle = (lo + hi) / 2;
      piece.offset =
          side != 0 && middle >= kMinOffset ? std::min(std::round(middle / kOffsetGrid) * kOffsetGrid, maxOffset_) : 0;
      for (size_t q = i; q < end; ++q)
        if (plans[q].wall) {
          const WallBend b = wallBend(step, *plans[q].wall, piece.offset, piece.fz);
          f.errorAfter = std::max(f.errorAfter, std::abs(b.mid - piece.offset));
          f.taperAfter = std::max(f.taperAfter, b.taper());
        }
      f.offsetMax = std::max(f.offsetMax, piece.offset);
      if (!out.empty() && out.back().offset == piece.offset && out.back().fz == piece.fz &&
          out.back().side == piece.side)
        out.back().to = piece.to;
      else
        out.push_back(piece);
      i = end;
    }
    return out;
  }

  /// Rewrites the step's moves: compensated moves as their pieces, with
  /// connecting lines where the programmed position leaves the nominal one
  /// or comes back to it.
  void rewrite(const CutStep &step, const std::map<const ir::Node *, std::vector<Piece>> &pieces,
               long long &compensated, long long &connectors, long long &lowered) const {
    auto *movesNode = const_cast<ir::Node *>(step.movesNode);
    std::vector<ir::Node> children;
    children.reserve(movesNode->children.size());
    std::optional<ir::Vec3> programmed; // where the new program leaves the tool
    size_t cursor = 0;
    auto connect = [&](const ir::Vec3 &to, const ir::Vec3 &nominal, double feed, const ir::Node &next) {
      if (!programmed || (*programmed - to).norm() <= kSamePoint)
        return;
      ir::Node line("linear");
      line.set("to", ir::Value::point(to)).set("feed", ir::Value::feed(feed));
      if (auto role = next.text("role"))
        line.set("role", ir::Value::word(*role));
      if ((to - nominal).norm() > kSamePoint)
        line.set("nominal", ir::Value::point(nominal));
      children.push_back(std::move(line));
      ++connectors;
    };
    for (ir::Node &child : movesNode->children) {
      const CutMove *cm = step.moveOf(child, cursor);
      if (!cm) {
        children.push_back(std::move(child));
        continue;
      }
      const Move &m = cm->move;
      const auto it = pieces.find(m.node);
      if (it == pieces.end()) {
        // Unchanged: a feed move starts where it did.
        if (m.isFeed() && m.from)
          connect(*m.from, *m.from, m.feed, child);
        programmed = m.to;
        children.push_back(std::move(child));
        continue;
      }
      ++compensated;
      for (const Piece &p : it->second) {
        const double feed = p.fz < cm->fz ? cm->feedFor(p.fz) : m.feed;
        lowered += feed < m.feed;
        const ir::Vec3 nominalFrom = p.from == 0 ? *m.from : m.pointAt(p.from);
        const ir::Vec3 nominalTo = p.to >= m.length() ? m.to : m.pointAt(p.to);
        connect(offsetPoint(m, nominalFrom, p.side, p.offset), nominalFrom, feed, child);
        ir::Node piece = child;
        const ir::Vec3 to = offsetPoint(m, nominalTo, p.side, p.offset);
        piece.set("to", ir::Value::point(to)).set("feed", ir::Value::feed(feed));
        if (p.offset != 0)
          piece.set("nominal", ir::Value::point(nominalTo));
        children.push_back(std::move(piece));
        programmed = to;
      }
    }
    movesNode->children = std::move(children);
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
      const std::string name = step->executable->symbol.empty() ? step->executable->kind : step->executable->symbol;
      std::string line = "  " + name + ": " + um(f.errorBefore) + " -> " + um(f.errorAfter) + ", " + um(f.taperBefore) +
                         " -> " + um(f.taperAfter) + ", " + formatFixed(f.offsetMax, 4) + ", " +
                         formatFixed(100 * f.loweredLength / f.wallLength, 0) + " %";
      if (f.beyond)
        line += "; " + std::to_string(f.beyond) +
                " samples need more than max-offset even at the lowest feed (edge forces): offset by the limit";
      report_.push_back(line);
    }
  }

  double maxOffset_ = kDefaultMaxOffset;
};

} // namespace

std::unique_ptr<Pass> createCompensateDeflectionPass(const PassOptions &options) {
  std::string data, error;
  double maxOffset = kDefaultMaxOffset;
  if (auto it = options.find("data"); it != options.end())
    data = it->second;
  if (auto it = options.find("max-offset"); it != options.end()) {
    if (auto v = parseLengthOption(it->second))
      maxOffset = *v;
    else
      error = "compensate-deflection: max-offset='" + it->second +
              "' is not a length: expected a positive number of mm, such as max-offset=0.05";
  }
  return std::make_unique<CompensateDeflectionPass>(std::move(data), maxOffset, std::move(error));
}

} // namespace stepnc::passes
