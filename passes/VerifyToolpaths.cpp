// verify-toolpaths: checks the moves of every workingstep against its feature,
// independently of the code that generated them. The gouge check reads the
// feature's walls by code of its own (FeatureWalls); the uncut checks share
// with strategy expansion the reading of the feature (ir::FeatureShape) and
// compute every area with the exact Booleans of geom/Boolean.h (never with
// geom::offset or geom::clip, the generator's tools). All read the moves
// through MoveWalk.
//
// Per executable with moves (docs/toolpaths.md, "Verification", says the same
// in prose):
//   safety  rapids at or above the security plane, or along the tool axis
//           (up, or down into the free space above the feature); the first
//           move a rapid up to the security plane; the spindle turning while
//           feeding;
//   reach   the material a step's feed moves meet stands no higher above
//           the tool's tip than its overall length (else the holder hits:
//           error) and its cutting edge length (else the shank rubs:
//           warning), on the in-process stock; a holder wider than the
//           tool (holder_diameter) meets no material, within its diameter,
//           higher than the overall length either (error);
//   depth   no move below the floor (bottom + allowance_bottom; through
//           bottoms allow the tool's point and an overcut);
//   gouge   no feed move below the feature's top takes the tool's disc,
//           grown by the side allowance, more than the tolerance into a
//           wall, a corner radius or an island (round holes made by hole
//           making: on the axis, tool no wider than the hole);
//   uncut   at the floor level the sweep covers what the tool can reach
//           (the opening of the allowed area with the tool radius);
//   slots with slanted or curved walls instead: the tool as a body (its
//           corner or ball), grown by the side allowance, at sampled
//           heights within the slot's cross-section there; each level
//           reaching as far as the tool fits;
// then, per feature, the floors of roughing and finishing together cover what
// the smallest tool can reach. Figures go into the `moves` node's comment.
// Moves are read on the path the tool is predicted to follow: a move
// compensated for tool deflection is checked at its `nominal` end.
#include "passes/Pass.h"

#include "geom/Boolean.h"
#include "ir/Kinds.h"
#include "ir/Plausible.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "passes/FeatureWalls.h"
#include "passes/VerifyFiveAxis.h"
#include "passes/InProcessStock.h"
#include "passes/VerifyDeposition.h"
#include "passes/VerifyTurning.h"
#include "support/Format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <map>
#include <numbers>

namespace stepnc::passes {

namespace {

using geom::Region;
using geom::Seg;
using geom::Vec2;
using ir::Vec3;

using ir::kDefaultTolerance;
constexpr double kLevelEps = 1e-6;          ///< heights closer than this are one depth level
constexpr double kUncutShare = 0.001;       ///< uncut area allowed at the floor: 0.1 % of the target
/// mm a tool may pass a through bottom beyond its point when the overcut is
/// smaller: the generator breaks through by 1 mm; explicit paths written by
/// others commonly by up to 2 (ISO 14649-11 Example 1: 1.13 mm).
constexpr double kThroughOvercut = 2.0;
constexpr size_t kMaxReports = 3;           ///< errors of one kind reported per executable

// --- Operations ------------------------------------------------------------------

bool isMilling(ir::Kind op) { return ir::hasTraits(op, ir::Trait::Milling); }
bool isFinishing(ir::Kind op) { return ir::hasTraits(op, ir::Trait::Finishing); }
bool isSideMilling(ir::Kind op) { return ir::hasTraits(op, ir::Trait::SideOnly); }


// --- Text --------------------------------------------------------------------------

std::string mm(double v) { return formatFixed(v, 4) + " mm"; }
std::string mm2(double v) { return formatFixed(v, 3) + " mm2"; }
std::string pointText(const ir::Vec3 &p) { return formatTuple({p.x(), p.y(), p.z()}, 4); }

// --- Regions -----------------------------------------------------------------------

/// The region grown (d > 0) or shrunk (d < 0) by |d|, with the exact Booleans.
Region offsetExact(const Region &r, double d) {
  if (r.empty() || d == 0)
    return r;
  return d > 0 ? geom::growExact(r, d) : geom::shrinkExact(r, -d);
}

bool sameRegion(const Region &a, const Region &b) {
  if (a.loops.size() != b.loops.size())
    return false;
  for (size_t i = 0; i < a.loops.size(); ++i) {
    const auto &s = a.loops[i].segs, &t = b.loops[i].segs;
    if (s.size() != t.size())
      return false;
    for (size_t k = 0; k < s.size(); ++k)
      if (s[k].a != t[k].a || s[k].b != t[k].b || s[k].turn != t[k].turn ||
          (s[k].isArc() && s[k].c != t[k].c))
        return false;
  }
  return true;
}

/// Indices of the islands standing above height z: the ones a cut at z must avoid.
std::vector<size_t> islandsAbove(const ir::FeatureShape &shape, double z, double tol) {
  std::vector<size_t> out;
  for (size_t i = 0; i < shape.islands.size(); ++i)
    if (shape.islands[i].top > z + tol)
      out.push_back(i);
  return out;
}

std::string indexKey(const std::vector<size_t> &indices) {
  std::string key;
  for (size_t i : indices)
    key += std::to_string(i) + ",";
  return key;
}

/// The areas derived from a feature's shape, each computed once per set of
/// inputs (feature, tool radius, allowance, islands in force) and reused for
/// every depth level and every workingstep that needs it.
class RegionCache {
public:
  /// The islands with the given indices, united and grown by d.
  const Region &islands(const ir::FeatureShape &s, const std::vector<size_t> &idx, double d) {
    return get("islands", s, {d}, idx, [&] {
      std::vector<Region> parts;
      for (size_t i : idx)
        parts.push_back(s.islands[i].region);
      return parts.empty() ? Region{} : offsetExact(geom::uniteAll(parts), d);
    });
  }

  /// Where the tool's edge may be (bounded shapes): the limit shrunk by the
  /// side allowance, without the islands grown by it.
  const Region &allowed(const ir::FeatureShape &s, double allowance, const std::vector<size_t> &idx) {
    return get("allowed", s, {allowance}, idx, [&] {
      const Region walls = offsetExact(s.limit, -allowance);
      const Region &isl = islands(s, idx, allowance);
      return isl.empty() ? walls : geom::subtract(walls, isl);
    });
  }

  /// What a tool of radius r can reach of the target: the opening of the
  /// allowed area (shrunk by r, grown back by r) within the target; for
  /// unbounded shapes, the target without the closing of the grown islands.
  const Region &reachable(const ir::FeatureShape &s, double r, double allowance, const std::vector<size_t> &idx) {
    return get("reachable", s, {r, allowance}, idx, [&] {
      if (s.unbounded) {
        const Region &isl = islands(s, idx, allowance + r);
        return isl.empty() ? s.target : geom::subtract(s.target, geom::shrinkExact(isl, r));
      }
      Region open = geom::growExact(geom::shrinkExact(allowed(s, allowance, idx), r), r);
      return sameRegion(s.limit, s.target) ? open : geom::intersect(open, s.target);
    });
  }

  /// What side milling must clear: the reachable area within `band` of the
  /// allowed area's boundary (walls and islands; only islands when unbounded).
  const Region &sideBand(const ir::FeatureShape &s, double r, double allowance, double band,
                         const std::vector<size_t> &idx) {
    return get("band", s, {r, allowance, band}, idx, [&] {
      const Region &reach = reachable(s, r, allowance, idx);
      if (s.unbounded) {
        // No walls: the band round what stands (nothing, on a bare face).
        const Region &isl = islands(s, idx, allowance);
        return isl.empty() ? Region{} : geom::intersect(reach, geom::growExact(isl, band));
      }
      const Region inner = geom::shrinkExact(allowed(s, allowance, idx), band);
      return inner.empty() ? reach : geom::subtract(reach, inner);
    });
  }

private:
  template <class Make>
  const Region &get(const char *what, const ir::FeatureShape &s, std::initializer_list<double> numbers,
                    const std::vector<size_t> &idx, Make &&make) {
    std::string key = what;
    for (const std::string &part : {s.symbol, indexKey(idx)})
      key.append("|").append(part);
    for (double v : numbers)
      key.append("|").append(formatShortest(v));
    auto it = regions_.find(key);
    if (it == regions_.end())
      it = regions_.emplace(key, make()).first;
    return it->second;
  }

  std::map<std::string, Region> regions_;
};

// --- Cuts ----------------------------------------------------------------------------

/// A feed move below the feature's top, in the plane: what the tool sweeps.
struct Cut {
  std::vector<Seg> segs;  ///< the move's planar segments; a point for a move along the axis
  double low = 0;         ///< its lowest height
  bool horizontal = false;
  Vec2 lowPoint = Vec2::Zero();  ///< where it is lowest, in the plane
};

Cut cutOf(const ir::Move &m) {
  Cut c;
  const ir::Vec3 &low = m.from->z() < m.to.z() ? *m.from : m.to;
  c.low = low.z();
  c.lowPoint = low.head<2>();
  c.horizontal = std::abs(m.to.z() - m.from->z()) <= kLevelEps;
  c.segs = m.planar();
  if (c.segs.empty())
    c.segs.push_back(Seg::line(c.lowPoint, c.lowPoint));  // a plunge cuts a disc
  return c;
}

/// The cuts grouped by depth level (lowest heights within kLevelEps), lowest level first.
std::vector<std::vector<const Cut *>> byLevel(std::vector<const Cut *> cuts) {
  std::sort(cuts.begin(), cuts.end(), [](const Cut *a, const Cut *b) { return a->low < b->low; });
  std::vector<std::vector<const Cut *>> levels;
  for (const Cut *c : cuts) {
    if (levels.empty() || c->low - levels.back().front()->low > kLevelEps)
      levels.emplace_back();
    levels.back().push_back(c);
  }
  return levels;
}

Region sweep(const std::vector<const Cut *> &cuts, double r) {
  std::vector<Seg> segs;
  for (const Cut *c : cuts)
    segs.insert(segs.end(), c->segs.begin(), c->segs.end());
  return segs.empty() ? Region{} : geom::sweptDisc(segs, r);
}

// --- The checker -----------------------------------------------------------------------

struct Figures {
  std::optional<double> swept, uncut, uncutPercent, gouge;
  std::optional<double> wallDepth;  ///< mm: the deepest any move reaches into the walls (0: none)
  double path = 0;
  size_t moves = 0;
};

/// One executable being verified, with everything its checks need.
struct Step {
  ir::Node *exec = nullptr;
  const ir::Node *movesNode = nullptr;
  std::string name;  ///< "workingstep @ws1", for messages
  const ir::Node *op = nullptr;
  const ir::Node *feature = nullptr;
  const ir::FeatureShape *shape = nullptr;  ///< null: no feature, or one ir::FeatureShape cannot handle
  const ir::Node *tool = nullptr;
  double radius = 0;  ///< 0: unknown
  double tol = kDefaultTolerance;
  double secplane = 0;
  double allowanceSide = 0, allowanceBottom = 0;
  std::vector<ir::Move> moves;
  Figures figures;
};

/// A move that broke a rule, with what to say about it.
struct Offence {
  const ir::Node *at;
  std::string message;
};

/// A workingstep's floor, kept for the per-feature check of roughing and finishing together.
struct Floor {
  const ir::Node *exec;
  double radius;
  double z;
  bool finishing;
  Region swept;
};

class ToolpathChecker {
public:
  ToolpathChecker(ir::Module &module, DiagnosticEngine &diags, PassStats &stats,
                  std::optional<double> tolerance)
      : module_(module), diags_(diags), stats_(stats), tolerance_(tolerance) {}

  PassResult run() {
    for (const ir::Node &n : module_.root.children)
      if (n.kind == ir::Kind::Tool)
        tools_[n.symbol] = &n;
    walkProgram();
    visit(module_.root);
    checkFeatures();
    return {errorsBefore_ == diags_.errorCount(), changed_};
  }

private:
  /// What the program order tells about each step: where a step starts that
  /// goes on from where the one before left the tool below its security
  /// plane (the file's paths joined, with the same tool), and which rapids
  /// meet the stock that remains when they run (passes/InProcessStock.h).
  void walkProgram() {
    std::optional<Vec3> position;
    double secplane = 0;
    std::string lastTool, lastSetup;
    for (const ir::Node *e : ir::programOrder(module_)) {
      const ir::Node *moves = ir::millingMoves(*e);
      if (!moves)
        continue;
      const std::string tool = moves->text("tool").value_or("");
      const std::string setup = moves->text("setup").value_or("");
      if (position && tool == lastTool && setup == lastSetup && position->z() < secplane - kLevelEps)
        starts_[e] = *position;
      lastTool = tool;
      lastSetup = setup;
      secplane = moves->number("secplane").value_or(0);
      for (const ir::Move &m : ir::walkMoves(*moves, position, ir::PathKind::Predicted))
        position = m.to;
    }
    const double tol = tolerance_.value_or(kDefaultTolerance);
    const ir::Node *holderOf = nullptr;  // the step `holder` is the holder radius of
    double holder = 0;
    walkStock(module_, rapidCheckCell(module_), [&](const StockMove &sm) {
      if (sm.move->kind == ir::MoveKind::Rapid) {
        if (std::optional<StockHit> hit = rapidMeetsStock(*sm.stock, *sm.move, sm.radius, sm.point, tol))
          stockHits_.emplace(sm.move->node, std::pair(*hit, *sm.move->from));
      } else if (sm.move->isFeed()) {
        // How high the material the tool's disc meets stands above its tip
        // (the chord of an arc): what its flutes, then its body and holder,
        // must clear.
        const Vec2 a = sm.move->from->head<2>(), b = sm.move->to.head<2>();
        const double tip = std::min(sm.move->from->z(), sm.move->to.z());
        const cutting::HeightMap::Peak peak = sm.stock->highest(a, b, std::max(0.0, sm.radius - sm.stock->cell()));
        Reach &r = reach_[sm.executable];
        r.flutes.raise(peak, tip, sm.move->node);
        // A holder wider than the tool sweeps a wider disc: a wall beside
        // the tool can meet it.
        if (sm.executable != holderOf) {  // once per step, not per move
          holderOf = sm.executable;
          holder = holderRadius(sm.executable);
        }
        if (holder > sm.radius)
          r.holder.raise(sm.stock->highest(a, b, holder - sm.stock->cell()), tip, sm.move->node);
      }
    });
  }

  /// The tool's flutes and length against the material its feed moves meet
  /// (walkProgram): a tool whose holder would meet the stock (it meets
  /// material higher above its tip than its overall length) is an error; one
  /// whose shank would rub it (higher than its cutting edge length) a
  /// warning: tools with a neck relieved behind the flutes clear it, and
  /// ISO 14649-111 does not say which have one.
  void checkReach(const Step &s) {
    const auto it = reach_.find(s.exec);
    if (it == reach_.end() || !s.tool)
      return;
    const Reach &r = it->second;
    const std::optional<double> flutes = s.tool->number("cutting_edge_length");
    const std::optional<double> overall = s.tool->number("overall_length");
    auto where = [](const Reach::Peak &p) {
      return " stands " + mm(p.engaged) + " above the tool's tip (at " + pointText(p.at) + ")";
    };
    if (overall && r.flutes.move && r.flutes.engaged > *overall + s.tol) {
      report(s,
             {{r.flutes.move, "the material its tool " + s.tool->symbol + " meets" + where(r.flutes) +
                                  ", more than its overall length " + mm(*overall) +
                                  ": the holder or spindle would hit the stock; a longer tool reaches it"}},
             "holder collisions");
    } else if (overall && r.holder.move && r.holder.engaged > *overall + s.tol) {
      report(s,
             {{r.holder.move, "the material within the " + mm(2 * holderRadius(s.exec)) + " holder of its tool " +
                                  s.tool->symbol + where(r.holder) + ", more than the tool's overall length " +
                                  mm(*overall) +
                                  ": the holder would hit the stock beside the tool; a longer tool or a slimmer "
                                  "holder reaches it"}},
             "holder collisions");
    } else if (flutes && r.flutes.move && r.flutes.engaged > *flutes + s.tol) {
      report(s,
             {{r.flutes.move, "the material its tool " + s.tool->symbol + " meets" + where(r.flutes) +
                                  ", more than its cutting edge length " + mm(*flutes) +
                                  ": the shank above the flutes would rub it (unless the tool is necked)"}},
             "shank rubs", /*warning=*/true);
    }
  }

  /// The radius of the holder of the tool `exec`'s moves name (its
  /// `holder_diameter`, ISO 14649-111's tool_holder_diameter_for_spindle_-
  /// orientation); 0 when the tool does not give one.
  double holderRadius(const ir::Node *exec) const {
    const ir::Node *moves = exec ? exec->child(ir::Kind::Moves) : nullptr;
    if (!moves)
      return 0;
    const auto it = tools_.find(moves->text("tool").value_or(""));
    if (it == tools_.end() || !it->second)
      return 0;
    return it->second->number("holder_diameter").value_or(0.0) / 2;
  }

  void visit(ir::Node &n) {
    for (ir::Node &c : n.children) {
      if (c.kind == ir::Kind::Workplan)
        visit(c);
      else if ((c.kind == ir::Kind::Workingstep || c.kind == ir::Kind::RapidMovement) && !ir::isTurningStep(c) &&
               !ir::isAdditiveStep(c) && !ir::tiltsTool(c))  // verifyFiveAxis checks those
        for (ir::Node &m : c.children)
          if (m.kind == ir::Kind::Moves)
            verify(c, m);
    }
  }

  void verify(ir::Node &exec, ir::Node &movesNode) {
    Step s = prepare(exec, movesNode);
    std::string reason = locate(s);
    checkSafety(s);
    checkReach(s);
    if (s.shape) {
      try {
        checkShape(s);
      } catch (const std::exception &e) {
        reason = e.what();
      }
    }
    if (!reason.empty()) {
      diags_.warning(exec.origin.loc, s.name + ": not verified: " + reason).entity(exec.origin.entityId);
      ++stats_["workingsteps not verified"];
    } else {
      ++stats_["workingsteps verified"];
    }
    writeFigures(movesNode, s.figures);
  }

  Step prepare(ir::Node &exec, const ir::Node &movesNode) {
    Step s;
    s.exec = &exec;
    s.movesNode = &movesNode;
    s.name = exec.kindName() + " " + exec.symbol;
    s.op = ir::operationOf(exec);
    s.secplane = movesNode.number("secplane").value_or(0.0);
    if (auto it = tools_.find(movesNode.text("tool").value_or("")); it != tools_.end())
      s.tool = it->second;
    if (s.tool)
      s.radius = s.tool->number("diameter").value_or(0.0) / 2;
    if (s.op) {
      s.allowanceSide = s.op->number("allowance_side").value_or(0.0);
      s.allowanceBottom = s.op->number("allowance_bottom").value_or(0.0);
    }
    // Where the tool is predicted to go: moves compensated for its deflection
    // are programmed off the part and reach their `nominal` ends.
    const auto start = starts_.find(&exec);
    s.moves = ir::walkMoves(movesNode, start == starts_.end() ? std::nullopt : std::optional(start->second),
                            ir::PathKind::Predicted);
    s.figures.moves = s.moves.size();
    for (const ir::Move &m : s.moves)
      s.figures.path += m.length();
    stats_["moves checked"] += static_cast<long long>(s.moves.size());
    const std::optional<std::string> feature = exec.text("feature");
    s.feature = feature ? ir::findFeature(module_, *feature) : nullptr;
    s.tol = tolerance_.value_or(workpieceTolerance(s.feature));
    return s;
  }

  /// The feature's shape and the tool's radius; why the step cannot be fully verified, or empty.
  std::string locate(Step &s) {
    if (s.exec->kind == ir::Kind::RapidMovement)
      return {};  // no feature: only the safety rules apply
    if (!s.feature)
      return "its feature " + s.exec->text("feature").value_or("?") + " is not a feature of the module";
    if (!s.tool || !(s.radius > 0))
      return "its tool has no diameter";
    auto it = shapes_.find(s.feature->symbol);
    if (it == shapes_.end())
      it = shapes_.emplace(s.feature->symbol, ir::featureShape(module_, *s.feature)).first;
    if (!it->second.shape)
      return it->second.error;
    s.shape = &*it->second.shape;
    return {};
  }

  /// The global tolerance of the feature's workpiece (else of the first workpiece giving one).
  double workpieceTolerance(const ir::Node *feature) const {
    std::optional<double> first;
    for (const ir::Node &wp : module_.root.children) {
      if (wp.kind != ir::Kind::Workpiece)
        continue;
      const std::optional<double> tol = wp.number("global_tolerance");
      if (feature && tol && std::any_of(wp.children.begin(), wp.children.end(),
                                        [&](const ir::Node &c) { return &c == feature; }))
        return *tol;
      if (!first && tol)
        first = tol;
    }
    return first.value_or(kDefaultTolerance);
  }

  // --- Safety ---------------------------------------------------------------------

  void checkSafety(Step &s) {
    if (s.moves.empty())
      return;
    std::vector<Offence> offences;
    const ir::Move &first = s.moves.front();
    if (!first.from && (first.isFeed() || first.to.z() < s.secplane - s.tol))
      offences.push_back(
          {first.node, "the first move starts from an unknown position: it must be a rapid ending "
                       "at or above the security plane z=" +
                           mm(s.secplane) + ", not a " + first.node->kindName() + " to " + pointText(first.to)});
    if (s.movesNode->number("spindle").value_or(0.0) == 0)
      for (const ir::Move &m : s.moves)
        if (m.isFeed()) {
          offences.push_back({m.node, "feed move with the spindle stopped (spindle=0 on its moves)"});
          break;
        }
    // A feed no machine is programmed to: a controller reads F0 (what it
    // rounds to) as no feed and refuses the move.
    for (const ir::Move &m : s.moves)
      if (m.isFeed() && !(m.feed >= ir::kPlausibleMinFeedMmPerMin)) {
        offences.push_back({m.node, "feed move at " + formatShortest(m.feed) + " mm/min, below the " +
                                        formatTrimmed(ir::kPlausibleMinFeedMmPerMin, 3) +
                                        " mm/min any machine is programmed to feed"});
        break;
      }
    // The rapids of a rapid movement or of the file's explicit toolpaths are
    // the file's own path: below the security plane they are judged on the
    // stock alone (expand-strategies lifted those it showed in the way).
    const bool explicitRapids = s.exec->kind == ir::Kind::RapidMovement ||
                                (s.op && !s.op->childrenOf(ir::Kind::Toolpath).empty());
    // Bores this step has cut along the tool axis, by position: their lowest point.
    std::vector<std::pair<Vec2, double>> bores;
    for (const ir::Move &m : s.moves) {
      if (m.isFeed() && m.from && (m.to.head<2>() - m.from->head<2>()).norm() <= s.tol && m.to.z() < m.from->z()) {
        auto bore = std::find_if(bores.begin(), bores.end(), [&](const auto &b) {
          return (b.first - m.to.head<2>()).norm() <= s.tol;
        });
        if (bore == bores.end())
          bores.emplace_back(m.to.head<2>(), m.to.z());
        else
          bore->second = std::min(bore->second, m.to.z());
      }
      if (m.kind != ir::MoveKind::Rapid)
        continue;
      // Where the step does not know the rapid's start, the program's walk did.
      const auto hit = stockHits_.find(m.node);
      const bool safe = !m.from || rapidSafe(s, m, bores);
      if (!safe && !explicitRapids) {
        offences.push_back({m.node, "rapid from " + pointText(*m.from) + " to " + pointText(m.to) +
                                        " below the security plane z=" + mm(s.secplane) +
                                        (s.shape ? " and not along the tool axis above " + s.shape->symbol
                                                 : " and not along the tool axis")});
      } else if (hit != stockHits_.end()) {
        const StockHit &at = hit->second.first;
        offences.push_back({m.node, "rapid from " + pointText(hit->second.second) + " to " + pointText(m.to) +
                                        " meets the stock that remains (up to z=" + mm(at.height) + " at (" +
                                        formatFixed(at.at.x(), 4) + ", " + formatFixed(at.at.y(), 4) + "))"});
      } else if (!safe) {
        ++stats_["explicit rapids below the security plane, clear of the stock"];
      }
    }
    report(s, offences, "safety errors");
  }

  /// At or above the security plane, or along the tool axis: upwards (the
  /// tool leaves through the space its own body fills) or downwards ending in
  /// the free space above the feature, or above the bottom of a bore this
  /// step has already cut there (back into a drilled hole between pecks).
  bool rapidSafe(const Step &s, const ir::Move &m, const std::vector<std::pair<Vec2, double>> &bores) const {
    const double low = std::min(m.from->z(), m.to.z());
    if (low >= s.secplane - s.tol)
      return true;
    if ((m.to.head<2>() - m.from->head<2>()).norm() > s.tol)
      return false;
    if (m.to.z() >= m.from->z() || !s.shape)
      return true;
    for (const auto &[xy, bottom] : bores)
      if ((xy - m.to.head<2>()).norm() <= s.tol && m.to.z() >= bottom)
        return true;
    return m.to.z() >= clearHeight(s, m.to.head<2>()) - s.tol;
  }

  /// The height above which the tool at xy is in free space: the feature's
  /// top, or the top of an island standing higher within reach of the tool.
  double clearHeight(const Step &s, const Vec2 &xy) const {
    double z = s.shape->top;
    for (const ir::IslandShape &island : s.shape->islands) {
      if (island.top <= z)
        continue;
      const bool near = island.region.contains(xy) ||
                        geom::SegIndex::of(island.region).distance(xy) < s.radius + s.tol;
      if (near)
        z = island.top;
    }
    return z;
  }

  // --- Shape-dependent checks --------------------------------------------------------

  void checkShape(Step &s) {
    checkDepth(s);
    const bool holeMaking = s.op && !isMilling(s.op->kind);
    if (s.shape->holeCentre && holeMaking) {
      checkHole(s);
      return;
    }
    std::vector<Cut> cuts;
    for (const ir::Move &m : s.moves)
      if (m.isFeed() && m.from && std::min(m.from->z(), m.to.z()) < s.shape->top - s.tol)
        cuts.push_back(cutOf(m));
    if (s.shape->section) {
      checkSection(s, cuts);
      return;
    }
    checkWalls(s);
    if (s.op && isMilling(s.op->kind))
      checkUncut(s, cuts);
  }

  void checkDepth(Step &s) {
    const double floor = s.shape->bottom + s.allowanceBottom;
    const double lowest = floor - throughAllowance(s);
    std::vector<Offence> offences;
    for (const ir::Move &m : s.moves) {
      const double low = m.from ? std::min(m.from->z(), m.to.z()) : m.to.z();
      if (low < lowest - s.tol)
        offences.push_back(
            {m.node, m.node->kindName() + " to " + pointText(m.to) + " goes below the floor of " + s.shape->symbol +
                         ": z=" + mm(low) + ", lowest allowed z=" + mm(lowest) + " (bottom " +
                         mm(s.shape->bottom) + " + allowance_bottom " + mm(s.allowanceBottom) + ")"});
    }
    report(s, offences, "depth errors");
  }

  /// How far below the floor a through bottom lets the tool go: its point
  /// (ir::pointLength) plus the operation's overcut, at least 1 mm.
  double throughAllowance(const Step &s) const {
    if (s.feature->text("bottom") != "through")
      return 0;
    const double point = ir::pointLength(*s.tool);
    const double overcut = s.op ? s.op->number("overcut").value_or(0.0) : 0.0;
    return point + std::max(kThroughOvercut, overcut);
  }

  /// Hole making: on the axis below the top, and no wider than the hole.
  void checkHole(Step &s) {
    const Vec2 axis = *s.shape->holeCentre;
    std::vector<Offence> offences;
    // Spot drills and countersinks are wider than the hole they chamfer.
    const bool sized = !s.op->is(ir::Trait::Chamfers);
    if (sized && 2 * s.radius > s.shape->holeDiameter + s.tol)
      offences.push_back({s.exec, "tool " + s.tool->symbol + " of diameter " + mm(2 * s.radius) +
                                      " is wider than " + s.shape->symbol + " (diameter " +
                                      mm(s.shape->holeDiameter) + ")"});
    for (const ir::Move &m : s.moves) {
      if (!m.from || std::min(m.from->z(), m.to.z()) >= s.shape->top - s.tol)
        continue;
      const double off = farthestFrom(m, axis);
      if (off > s.tol)
        offences.push_back({m.node, m.node->kindName() + " to " + pointText(m.to) + " leaves the axis of " +
                                        s.shape->symbol + " below its top by " + mm(off)});
    }
    report(s, offences, "gouge errors");
  }

  /// The largest distance in the plane from p to the move.
  static double farthestFrom(const ir::Move &m, const Vec2 &p) {
    double d = std::max((m.from->head<2>() - p).norm(), (m.to.head<2>() - p).norm());
    for (const Seg &seg : m.planar()) {
      if (!seg.isArc())
        continue;
      // The farthest point of the circle lies opposite p; it counts when the arc passes it.
      const Vec2 out = seg.c - p;
      const double far = out.norm() + seg.radius();
      if (out.norm() <= geom::kEps || arcPasses(seg, out))
        d = std::max(d, far);
    }
    return d;
  }

  /// True when the arc passes the direction `dir` from its centre.
  static bool arcPasses(const Seg &arc, const Vec2 &dir) {
    const double start = std::atan2((arc.a - arc.c).y(), (arc.a - arc.c).x());
    double to = std::atan2(dir.y(), dir.x()) - start;  // ccw angle from the start to dir
    to = std::fmod(to + 4 * std::numbers::pi, 2 * std::numbers::pi);
    const double sweep = arc.sweep();
    return sweep >= 0 ? to <= sweep : (to == 0 || 2 * std::numbers::pi - to <= -sweep);
  }

  // --- Walls --------------------------------------------------------------------------

  /// Every feed move below the top of the feature or of one of its islands,
  /// against the walls as FeatureWalls reads them (by code of its own, not
  /// ir::FeatureShape's): where the disc of the tool's radius plus the side
  /// allowance reaches into a wall, a corner radius or an island by more
  /// than the tolerance, the move gouges; it is reported at the move, with
  /// how deep and where.
  void checkWalls(Step &s) {
    auto it = walls_.find(s.feature->symbol);
    if (it == walls_.end()) {
      std::string error;
      std::optional<FeatureWalls> w = FeatureWalls::read(module_, *s.feature, error);
      it = walls_.emplace(s.feature->symbol, std::pair(std::move(w), error)).first;
    }
    if (!it->second.first) {
      diags_.warning(s.exec->origin.loc, s.name + ": not checked against the walls of " + s.feature->symbol + ": " +
                                             it->second.second)
          .entity(s.exec->origin.entityId);
      ++stats_["workingsteps not checked against walls"];
      return;
    }
    const FeatureWalls &walls = *it->second.first;
    const std::vector<double> levels = walls.levels(s.tol);
    const double highest = *std::max_element(levels.begin(), levels.end());
    const double reach = s.radius + s.allowanceSide;
    std::vector<Offence> offences;
    double deepest = 0;
    for (const ir::Move &m : s.moves) {
      if (!m.isFeed() || !m.from || std::min(m.from->z(), m.to.z()) >= highest)
        continue;
      const MoveContact c =
          deepestContact(walls, m, reach, s.tol, (s.tool ? ir::cornerRadius(*s.tool) : 0) + s.allowanceSide,
                         s.allowanceSide);
      deepest = std::max(deepest, c.contact.depth);
      if (c.contact.depth > s.tol)
        offences.push_back({m.node, m.node->kindName() + " to " + pointText(m.to) + " gouges " + walls.describe(c.contact) +
                                        " by " + mm(c.contact.depth) + " at " + pointText(c.at) + " (tool " + s.tool->symbol + ", radius " + mm(s.radius) +
                                        ", allowance_side " + mm(s.allowanceSide) + ", tolerance " + mm(s.tol) +
                                        ")"});
    }
    s.figures.wallDepth = deepest;
    // Required toolpaths run as the file writes them: where they enter a
    // wall (a finishing path compensated for tool deflection does, by its
    // offset), stepnc warns but does not refuse the file.
    if (ir::runsAsWritten(*s.exec)) {
      for (Offence &o : offences)
        o.message += " (a required toolpath of the file, run as written)";
      report(s, offences, "gouges of required toolpaths", /*warning=*/true);
      return;
    }
    report(s, offences, "gouge errors");
  }

  // --- Uncut ----------------------------------------------------------------------------

  void checkUncut(Step &s, const std::vector<Cut> &cuts) {
    const bool explicitPaths = s.op->kind == ir::Kind::FreeformOperation;
    const double targetArea = s.shape->target.area();
    // The floor level is that of the lowest horizontal cut; a step that only
    // plunges (a tool as wide as the hole it mills) reaches it by its plunges.
    std::optional<double> floorZ;
    for (const Cut &c : cuts)
      if (c.horizontal && (!floorZ || c.low < *floorZ))
        floorZ = c.low;
    if (!floorZ)
      for (const Cut &c : cuts)
        if (!floorZ || c.low < *floorZ)
          floorZ = c.low;
    std::vector<Offence> offences;
    if (!floorZ) {
      if (!explicitPaths)
        offences.push_back({s.exec, "no cutting move below the top of " + s.shape->symbol + " (z=" +
                                        mm(s.shape->top) + "): nothing of it is cleared"});
      report(s, offences, "uncut errors");
      return;
    }
    // At the floor: horizontal cuts, and the lowest point of moves ending there (plunges, ramps, helices).
    std::vector<Cut> points;
    for (const Cut &c : cuts)
      if (!c.horizontal && std::abs(c.low - *floorZ) <= kLevelEps)
        points.push_back({{Seg::line(c.lowPoint, c.lowPoint)}, c.low, false, c.lowPoint});
    std::vector<const Cut *> atFloor;
    for (const Cut &c : cuts)
      if (c.horizontal && std::abs(c.low - *floorZ) <= kLevelEps)
        atFloor.push_back(&c);
    for (const Cut &p : points)
      atFloor.push_back(&p);
    const std::vector<size_t> idx = islandsAbove(*s.shape, *floorZ, s.tol);
    const Region swept = sweep(atFloor, s.radius);
    const double uncut = geom::subtract(required(s, idx), swept).area();
    s.figures.swept = swept.area();
    s.figures.uncut = uncut;
    s.figures.uncutPercent = targetArea > 0 ? 100 * uncut / targetArea : 0.0;
    floors_[s.feature->symbol].push_back({s.exec, s.radius, *floorZ, isFinishing(s.op->kind), swept});
    if (explicitPaths)
      return;
    // A finishing step must clear everything it can reach; what roughing
    // leaves (scallops of a zigzag, say) is reported, and the check of
    // roughing and finishing together decides.
    if (uncut > kUncutShare * targetArea) {
      std::vector<Offence> uncutReport = {
          {s.exec, "leaves " + mm2(uncut) + " (" + formatFixed(*s.figures.uncutPercent, 3) + " %) of " +
                       s.shape->symbol + " uncut at its floor level z=" + mm(*floorZ) + " (tool " +
                       s.tool->symbol + ", radius " + mm(s.radius) + ", allowance_side " + mm(s.allowanceSide) +
                       ")"}};
      if (isFinishing(s.op->kind))
        offences.insert(offences.end(), uncutReport.begin(), uncutReport.end());
      else
        report(s, uncutReport, "roughing steps leaving uncut area", /*warning=*/true);
    }
    const double floor = s.shape->bottom + s.allowanceBottom;
    if (*floorZ > floor + s.tol)
      offences.push_back({s.exec, "its lowest cutting level z=" + mm(*floorZ) + " is above the floor of " +
                                      s.shape->symbol + " at z=" + mm(floor)});
    report(s, offences, "uncut errors");
  }

  /// What the step must clear at its floor: everything the tool can reach, or
  /// for side milling the band along the walls (radial_depth wide, else the tool radius).
  const Region &required(const Step &s, const std::vector<size_t> &idx) {
    if (!isSideMilling(s.op->kind))
      return cache_.reachable(*s.shape, s.radius, s.allowanceSide, idx);
    const double band = s.op->number("radial_depth").value_or(s.radius);
    return cache_.sideBand(*s.shape, s.radius, s.allowanceSide, band > 0 ? band : s.radius, idx);
  }

  // --- Slots with slanted or curved walls -----------------------------------------------
  //
  // The tool is a body, not a disc: at height h above its tip it is a disc of
  // radius R - rc + sqrt(rc^2 - (rc - h)^2) below its corner (rc), R above.
  // Grown all round by the side allowance (R + a, rc + a, its tip a lower) it
  // must stay, at every height, within the slot's outline at that height
  // (ir::SlotSection, the walls as the profile gives them). Heights are
  // sampled: finely through the corner, at every vertex of the walls and at
  // the top, where the room left between body and wall is smallest on
  // straight walls and arcs that open upwards.

  /// The heights (workpiece z) at which a grown tool with its tip at `tip` is
  /// measured against the walls: through its corner, the walls' vertices, the top.
  static std::vector<double> sampleHeights(const ir::FeatureShape &shape, double tip, double corner) {
    constexpr int kCornerSamples = 32;
    std::vector<double> out;
    for (int k = 0; k <= kCornerSamples; ++k)
      out.push_back(tip + corner * k / kCornerSamples);
    for (double b : shape.section->breaks())
      out.push_back(shape.bottom + b);
    out.push_back(shape.top - 1e-9);
    std::erase_if(out, [&](double z) { return z < tip || z < shape.bottom || z >= shape.top; });
    std::sort(out.begin(), out.end());
    return out;
  }

  /// Where the tool centre may be across the slot (left of its course) with
  /// the tool's tip at z: every sampled height leaves room for the grown
  /// body's disc between the walls. Empty (lo > hi) where it does not fit.
  std::pair<double, double> centreRoom(const Step &s, double z) const {
    const double a = s.allowanceSide, corner = ir::cornerRadius(*s.tool) + a, radius = s.radius + a;
    const double tip = z - a;
    // The room each height leaves on either side (lo: the least u, hi: the
    // most); none where the body or the walls are not there.
    auto room = [&](double v) -> std::optional<std::pair<double, double>> {
      const double rho = bodyRadius(radius, corner, v - tip);
      const auto span = s.shape->section->span(v - s.shape->bottom);
      if (rho < 0 || !span)
        return std::nullopt;
      return std::pair(span->first + rho, span->second - rho);
    };
    const std::vector<double> heights = sampleHeights(*s.shape, tip, corner);
    double lo = -1e300, hi = 1e300;
    for (const bool low : {true, false}) {
      // The tightest sample, then the tightest height between its neighbours
      // (golden section: the room is smooth there).
      size_t best = heights.size();
      double bound = low ? -1e300 : 1e300;
      for (size_t k = 0; k < heights.size(); ++k)
        if (auto r = room(heights[k]); r && (low ? r->first > bound : r->second < bound)) {
          bound = low ? r->first : r->second;
          best = k;
        }
      if (best == heights.size())
        continue;
      double x0 = heights[best > 0 ? best - 1 : best], x1 = heights[best + 1 < heights.size() ? best + 1 : best];
      auto value = [&](double v) {
        const auto r = room(v);
        return !r ? (low ? -1e300 : 1e300) : (low ? r->first : r->second);
      };
      constexpr double kGolden = 0.6180339887498949;
      for (int i = 0; i < 60 && x1 - x0 > 1e-9; ++i) {
        const double m0 = x1 - kGolden * (x1 - x0), m1 = x0 + kGolden * (x1 - x0);
        const bool firstTighter = low ? value(m0) > value(m1) : value(m0) < value(m1);
        (firstTighter ? x1 : x0) = firstTighter ? m1 : m0;
        bound = low ? std::max(bound, value(m0)) : std::min(bound, value(m0));
      }
      (low ? lo : hi) = bound;
    }
    return {lo, hi};
  }

  void checkSection(Step &s, const std::vector<Cut> &cuts) {
    const ir::FeatureShape &shape = *s.shape;
    // Moves read back from IR text are rounded to 0.0001 mm: a tool on a
    // slanted wall may stand a few times that into it, when its height is
    // rounded down. Half a micrometre is let pass.
    constexpr double kTextPrecision = 5e-4;
    const double a = s.allowanceSide, corner = ir::cornerRadius(*s.tool) + a,
                 radius = s.radius + a - kTextPrecision;
    std::vector<const Cut *> all;
    for (const Cut &c : cuts)
      all.push_back(&c);
    const auto levels = byLevel(all);
    // Gouge: per level, the worst sampled height.
    std::vector<Offence> gouges;
    double gougeTotal = 0;
    for (const auto &level : levels) {
      const double tip = level.front()->low - a;
      double worst = 0, worstZ = tip;
      for (double v : sampleHeights(shape, tip, corner)) {
        const double rho = bodyRadius(radius, corner, v - tip);
        const auto span = shape.section->span(v - shape.bottom);
        if (rho <= 0 || !span)
          continue;
        const Region allowed = ir::slotBetween(shape, span->first, span->second).limit;
        if (discsInside(level, allowed, rho))
          continue;
        const double area = geom::subtract(sweep(level, rho), allowed).area();
        if (area > worst) {
          worst = area;
          worstZ = v;
        }
      }
      gougeTotal += worst;
      if (worst > s.tol * s.tol)
        gouges.push_back({s.exec, "gouge of " + mm2(worst) + " into the walls of " + shape.symbol +
                                      " at depth level z=" + mm(level.front()->low) + ", at z=" + mm(worstZ) +
                                      " (tool " + s.tool->symbol + ", radius " + mm(s.radius) + ", corner radius " +
                                      mm(corner - a) + ", allowance_side " + mm(a) + ")"});
    }
    s.figures.gouge = gougeTotal;
    if (ir::runsAsWritten(*s.exec)) {
      // As for any feature: the file's required toolpaths run as written.
      for (Offence &o : gouges)
        o.message += " (a required toolpath of the file, run as written)";
      report(s, gouges, "gouges of required toolpaths", /*warning=*/true);
    } else {
      report(s, gouges, "gouge errors");
    }
    if (!isMilling(s.op->kind))
      return;
    checkSectionUncut(s, cuts);
  }

  /// True when every segment of the cuts keeps a disc of radius rho inside
  /// `allowed` (its start inside, the whole segment at least rho from the boundary).
  static bool discsInside(const std::vector<const Cut *> &cuts, const Region &allowed, double rho) {
    std::vector<Seg> boundary;
    for (const geom::Loop &l : allowed.loops)
      boundary.insert(boundary.end(), l.segs.begin(), l.segs.end());
    for (const Cut *c : cuts)
      for (const Seg &seg : c->segs) {
        if (!allowed.contains(seg.a))
          return false;
        for (const Seg &b : boundary)
          if (geom::distance(seg, b) < rho - geom::kEps)
            return false;
      }
    return true;
  }

  /// Uncut, level by level: each level's horizontal cuts sweep what the tool
  /// reaches at that level with its full radius (the room found by
  /// centreRoom, widened by the radius): all of it when roughing and at the
  /// last level, the band along each wall when finishing the walls above.
  /// The lowest level must be as low as the tool fits (or the floor).
  void checkSectionUncut(Step &s, const std::vector<Cut> &cuts) {
    const ir::FeatureShape &shape = *s.shape;
    const double targetArea = shape.target.area();
    std::vector<const Cut *> flat;
    for (const Cut &c : cuts)
      if (c.horizontal)
        flat.push_back(&c);
    std::vector<Offence> offences;
    if (flat.empty()) {
      offences.push_back({s.exec, "no cutting move below the top of " + shape.symbol + " (z=" + mm(shape.top) +
                                      "): nothing of it is cleared"});
      report(s, offences, "uncut errors");
      return;
    }
    const auto levels = byLevel(flat);
    const bool wallsOnly = isSideMilling(s.op->kind);
    const bool finishing = isFinishing(s.op->kind);
    double uncutTotal = 0;
    std::vector<Offence> uncut;
    for (size_t i = 0; i < levels.size(); ++i) {
      const double z = levels[i].front()->low;
      const auto [lo, hi] = centreRoom(s, z);
      if (lo > hi + s.tol)
        continue;  // the tool does not fit here: a gouge, reported above
      const double reachLo = std::min(lo, hi) - s.radius, reachHi = std::max(lo, hi) + s.radius;
      Region required = reachOf(shape, reachLo, reachHi, s.radius);
      // Finishing follows the walls above its last (lowest) level.
      const bool band = wallsOnly || (finishing && i > 0);
      if (band && reachHi - reachLo > 2 * s.radius + 1e-6)
        required = geom::subtract(required, ir::slotBetween(shape, reachLo + s.radius, reachHi - s.radius).target);
      const Region swept = sweep(levels[i], s.radius);
      const double area = geom::subtract(required, swept).area();
      uncutTotal += area;
      if (i == 0)
        s.figures.swept = swept.area();
      if (area > kUncutShare * targetArea)
        uncut.push_back({s.exec, "leaves " + mm2(area) + " of " + shape.symbol + " uncut at depth level z=" + mm(z) +
                                     " (tool " + s.tool->symbol + ", radius " + mm(s.radius) + ", allowance_side " +
                                     mm(s.allowanceSide) + ")"});
    }
    s.figures.uncut = uncutTotal;
    s.figures.uncutPercent = targetArea > 0 ? 100 * uncutTotal / targetArea : 0.0;
    if (s.op->kind == ir::Kind::FreeformOperation)
      return;
    if (finishing)
      offences.insert(offences.end(), uncut.begin(), uncut.end());
    else
      report(s, uncut, "roughing steps leaving uncut area", /*warning=*/true);
    // The lowest level: where the tool stops fitting, or the floor.
    const double floor = shape.bottom + s.allowanceBottom;
    double fits = shape.top, below = floor;
    auto roomAt = [&](double z) {
      const auto [lo, hi] = centreRoom(s, z);
      return lo <= hi + 1e-9;
    };
    if (roomAt(floor)) {
      fits = floor;
    } else {
      for (int k = 0; k < 60 && fits - below > 1e-7; ++k) {
        const double mid = (fits + below) / 2;
        (roomAt(mid) ? fits : below) = mid;
      }
    }
    const double lowest = levels.front().front()->low;
    if (lowest > fits + s.tol)
      offences.push_back({s.exec, "its lowest cutting level z=" + mm(lowest) + " is above the lowest the tool fits in " +
                                      shape.symbol + ", z=" + mm(fits)});
    report(s, offences, "uncut errors");
  }

  /// What a tool of radius r reaches of the slot between lo and hi (left of
  /// its course): the slot's outline there, opened by r where an end is not open.
  static Region reachOf(const ir::FeatureShape &shape, double lo, double hi, double r) {
    const ir::FeatureShape level = ir::slotBetween(shape, lo, hi);
    if (shape.slot->end1 == "open" && shape.slot->end2 == "open")
      return level.target;
    return geom::intersect(geom::growExact(geom::shrinkExact(level.limit, r), r), level.target);
  }

  // --- Roughing and finishing together ---------------------------------------------------

  void checkFeatures() {
    for (const auto &[symbol, floors] : floors_) {
      const bool finished =
          std::any_of(floors.begin(), floors.end(), [](const Floor &f) { return f.finishing; });
      if (floors.size() < 2 || !finished)
        continue;
      const ir::FeatureShape &shape = *shapes_.at(symbol).shape;
      try {
        checkFeature(shape, floors);
      } catch (const std::exception &e) {
        diags_.warning(floors.back().exec->origin.loc, "feature " + symbol + ": not verified: " + e.what());
      }
    }
  }

  void checkFeature(const ir::FeatureShape &shape, const std::vector<Floor> &floors) {
    double radius = floors.front().radius, lowest = floors.front().z;
    std::vector<Region> swept;
    for (const Floor &f : floors) {
      radius = std::min(radius, f.radius);
      lowest = std::min(lowest, f.z);
      swept.push_back(f.swept);
    }
    const double tol = tolerance_.value_or(workpieceTolerance(ir::findFeature(module_, shape.symbol)));
    const Region &reach = cache_.reachable(shape, radius, 0, islandsAbove(shape, lowest, tol));
    const double uncut = geom::subtract(reach, geom::uniteAll(swept)).area();
    const double targetArea = shape.target.area();
    if (!(uncut > kUncutShare * targetArea))
      return;
    const ir::Node *feature = ir::findFeature(module_, shape.symbol);
    auto d =
        diags_.error(feature->origin.loc, "feature " + shape.symbol + ": rough + finish leave " + mm2(uncut) +
                                              " (" + formatFixed(100 * uncut / targetArea, 3) + " %) uncut");
    d.entity(feature->origin.entityId);
    for (const Floor &f : floors)
      d.note(f.exec->origin.loc, "cut by " + f.exec->kindName() + " " + f.exec->symbol + " at z=" + mm(f.z));
    ++stats_["uncut errors"];
  }

  // --- Reporting ---------------------------------------------------------------------------

  /// Reports the first few offences as errors (the last one noting how many more there are), at
  /// the node concerned, or at the executable when that node has no origin (moves made by a pass).
  void report(const Step &s, const std::vector<Offence> &offences, const char *counter, bool warning = false) {
    if (offences.empty())
      return;
    stats_[counter] += static_cast<long long>(offences.size());
    for (size_t i = 0; i < offences.size() && i < kMaxReports; ++i) {
      const ir::Origin &at = offences[i].at->origin.loc.valid() ? offences[i].at->origin : s.exec->origin;
      auto d = warning ? diags_.warning(at.loc, s.name + ": " + offences[i].message)
                       : diags_.error(at.loc, s.name + ": " + offences[i].message);
      d.entity(at.entityId);
      if (i + 1 == kMaxReports && offences.size() > kMaxReports)
        d.note(std::to_string(offences.size() - kMaxReports) + " more like this not reported");
    }
  }

  /// `swept 2081.27 mm2, uncut 0.00 mm2 (0.000 %), gouge 0.000 mm2, path 1234.5 mm, 87 moves`,
  /// replacing the figures of an earlier run and keeping any other comment.
  void writeFigures(ir::Node &movesNode, const Figures &f) {
    std::string text;
    auto add = [&](const std::string &part) { text += (text.empty() ? "" : ", ") + part; };
    if (f.swept)
      add("swept " + formatFixed(*f.swept, 2) + " mm2");
    if (f.uncut)
      add("uncut " + formatFixed(*f.uncut, 2) + " mm2 (" + formatFixed(f.uncutPercent.value_or(0), 3) +
          " %)");
    if (f.gouge)
      add("gouge " + formatFixed(*f.gouge, 3) + " mm2");
    if (f.wallDepth)
      add("gouge " + formatFixed(std::max(0.0, *f.wallDepth), 4) + " mm");
    add("path " + formatFixed(f.path, 1) + " mm");
    add(std::to_string(f.moves) + " moves");
    ir::replaceCommentPart(movesNode, {"swept ", "path "}, text);
    changed_ = true;
  }

  ir::Module &module_;
  DiagnosticEngine &diags_;
  PassStats &stats_;
  std::optional<double> tolerance_;
  const unsigned errorsBefore_ = diags_.errorCount();
  bool changed_ = false;
  std::map<std::string, const ir::Node *, std::less<>> tools_;
  std::map<const ir::Node *, Vec3> starts_;         ///< steps that go on from the step before
  /// Rapids that meet the stock, by move: where, and where the rapid starts.
  std::map<const ir::Node *, std::pair<StockHit, Vec3>> stockHits_;
  /// Per executable, the highest material its feed moves meet above the
  /// tool's tip, where, and the move (walkProgram).
  /// Per step, the highest material its feed moves meet above the tool's
  /// tip: within the tool's disc (what the flutes and shank meet) and, for a
  /// holder wider than the tool, within the holder's.
  struct Reach {
    struct Peak {
      double engaged = 0;
      Vec3 at = Vec3::Zero();
      const ir::Node *move = nullptr;
      void raise(const cutting::HeightMap::Peak &p, double tip, const ir::Node *by) {
        if (p.height - tip > engaged)
          *this = {p.height - tip, Vec3(p.at.x(), p.at.y(), p.height), by};
      }
    };
    Peak flutes, holder;
  };
  std::map<const ir::Node *, Reach> reach_;
  std::map<std::string, ir::ShapeResult> shapes_;
  std::map<std::string, std::vector<Floor>> floors_;
  RegionCache cache_;
  /// Per feature, its walls as FeatureWalls reads them, or why it cannot.
  std::map<std::string, std::pair<std::optional<FeatureWalls>, std::string>> walls_;
};

class VerifyToolpathsPass final : public Pass {
public:
  explicit VerifyToolpathsPass(std::optional<double> tolerance) : tolerance_(tolerance) {}

  std::string_view name() const override { return "verify-toolpaths"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    if (!ir::requireThreeAxisMilling(module, "verify-toolpaths", diags, ir::ArcPlanes::Principal,
                                     ir::OtherProcesses::Skip, ir::Deposition::Refuse, ir::ToolAxes::Skip))
      return {false, false};
    PassResult milling = ToolpathChecker(module, diags, stats, tolerance_).run();
    const bool turning = verifyTurning(module, diags, stats, tolerance_);
    reports_.clear();
    tilted_.clear();
    const bool deposition = verifyDeposition(module, diags, stats, std::nullopt, &reports_);
    const bool fiveAxis = verifyFiveAxis(module, diags, stats, tolerance_, &tilted_);
    return {milling.ok && turning && deposition && fiveAxis, milling.changed};
  }

  std::vector<std::string> report() const override {
    std::vector<std::string> lines;
    if (!reports_.empty()) {
      lines.push_back("deposition workingstep: layers, bead length, energy-on time at the feed; "
                      "largest uncovered gap and overflow (mm)");
      lines.insert(lines.end(), reports_.begin(), reports_.end());
    }
    if (!tilted_.empty()) {
      lines.push_back("workingsteps that tilt the tool (5-axis):");
      lines.insert(lines.end(), tilted_.begin(), tilted_.end());
    }
    return lines;
  }

private:
  std::optional<double> tolerance_;
  std::vector<std::string> reports_;
  std::vector<std::string> tilted_;
};

} // namespace

std::unique_ptr<Pass> createVerifyToolpathsPass(const PassOptions &options) {
  return std::make_unique<VerifyToolpathsPass>(options.number("tolerance"));
}

} // namespace stepnc::passes
