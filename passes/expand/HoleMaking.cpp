// Hole making: drilling, centre drilling, multistep (peck) drilling, reaming,
// boring, tapping, thread drilling and countersinking as axial moves on a
// round hole's axis. Rapid to the clearance height, feed to the depth (at the
// drilling strategy's reduced feeds near the top and the bottom), pecks with
// a rapid out between them, dwells at the bottom, and out at rapid (drills)
// or at feed (reamers, boring bars, taps). The moves are written out in full
// inside a `cycle` node that says what they are (ir/Kinds.def): a target
// with the controller's canned cycle writes that instead.
#include "passes/expand/Expand.h"

#include "ir/Plausible.h"

#include "support/Format.h"

#include <algorithm>

namespace stepnc::passes::expand {

namespace {

/// The distance above the last peck's bottom to which the tool comes back
/// down at rapid before feeding on.
constexpr double kReapproach = 0.5;

/// A height band of the hole fed at a reduced feed.
struct Zone {
  double top = 0, bottom = 0;  ///< z, top > bottom
  double feed = 0;             ///< mm/min
  bool atStart = false;        ///< the zone below the top (else the one above the bottom)
};

/// The reduced feeds of a drilling strategy: over `depth_of_start` below the
/// hole's top and over `depth_of_end` above its bottom. A ratio or depth
/// outside physical sense, or one given without the other, is a warning
/// and that zone is not applied.
std::vector<Zone> reducedFeedZones(Expander &x, const Step &step, double top, double bottom, double feed) {
  std::vector<Zone> zones;
  const Node *ds = step.strategy;
  if (!ds || ds->kind != ir::Kind::DrillingStrategy)
    return zones;
  struct End {
    const char *ratio, *depth;
    bool atStart;
  };
  for (End end : {End{"reduced_feed_at_start", "depth_of_start", true}, End{"reduced_feed_at_end", "depth_of_end", false}}) {
    const std::optional<double> ratio = ds->number(end.ratio), depth = ds->number(end.depth);
    if (!ratio && !depth)
      continue;
    if (step.op.is(ir::Trait::TapCycle)) {
      x.assumed(step.ws, *ds,
                std::string("drilling_strategy ") + end.ratio +
                    " does not apply to tapping: a tap feeds by its thread's pitch, the whole depth at one feed");
      continue;
    }
    if (!ratio || !depth) {
      x.assumed(step.ws, *ds,
                std::string("drilling_strategy ") + (ratio ? end.ratio : end.depth) + " without " +
                    (ratio ? end.depth : end.ratio) + ": the whole depth at the operation's feed");
      continue;
    }
    if (*ratio <= 0 || *ratio > 1 || *depth <= 0) {
      x.assumed(step.ws, *ds,
                std::string("drilling_strategy ") + end.ratio + " " + formatFixed(*ratio, 3) + " over " + end.depth +
                    " " + formatFixed(*depth, 3) +
                    " mm is not a reduced feed (a ratio in (0, 1] over a positive depth): not applied");
      continue;
    }
    if (feed * *ratio < ir::kPlausibleMinFeedMmPerMin) {
      x.assumed(step.ws, *ds,
                std::string("drilling_strategy ") + end.ratio + " " + formatShortest(*ratio) + " of " +
                    formatTrimmed(feed, 3) + " mm/min makes a feed below the " +
                    formatTrimmed(ir::kPlausibleMinFeedMmPerMin, 3) +
                    " mm/min any machine is programmed to feed: not applied");
      continue;
    }
    Zone z;
    z.feed = feed * *ratio;
    z.atStart = end.atStart;
    z.top = end.atStart ? top : std::min(bottom + *depth, top);
    z.bottom = end.atStart ? std::max(top - *depth, bottom) : bottom;
    if (z.top > z.bottom)
      zones.push_back(z);
  }
  return zones;
}

/// The feed at height z going down: the lowest of the zones holding it, else `feed`.
double feedAt(double z, const std::vector<Zone> &zones, double feed) {
  for (const Zone &zone : zones)
    if (z < zone.top && z > zone.bottom)
      feed = std::min(feed, zone.feed);
  return feed;
}

/// Feeds down the axis from where the tool is to `z`, a line per feed.
void feedDown(Emitter &e, const Vec2 &c, double z, const std::vector<Zone> &zones, double feed) {
  std::vector<double> cuts;
  const double from = e.position().z();
  for (const Zone &zone : zones)
    for (double b : {zone.top, zone.bottom})
      if (b < from - geom::kEps && b > z + geom::kEps)
        cuts.push_back(b);
  cuts.push_back(z);
  std::sort(cuts.begin(), cuts.end(), std::greater<>());
  double reached = from;
  for (size_t k = 0; k < cuts.size(); ++k) {
    const double f = feedAt(0.5 * (reached + cuts[k]), zones, feed);
    // Merge with the next piece when it is fed the same.
    if (k + 1 < cuts.size() && feedAt(0.5 * (cuts[k] + cuts[k + 1]), zones, feed) == f)
      continue;
    e.linear(at(c, cuts[k]), f, "plunge");
    reached = cuts[k];
  }
}

/// Says what of the operation the moves do not follow: a drilling
/// strategy's reduced cutting speeds, a peck's retract distance (the tool
/// leaves the hole between pecks) and a tap's dwells.
void reportIgnored(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  if (const Node *ds = step.strategy)
    for (std::string_view attribute : {"reduced_cut_at_start", "reduced_cut_at_end"})
      if (ds->has(attribute)) {
        x.assumed(ws, *ds,
                  "drilling_strategy " + std::string(attribute) +
                      " is not supported: the whole depth at the operation's spindle speed");
        break;
      }
  if (op.kind == ir::Kind::MultistepDrilling)
    if (auto distance = op.number("retract_distance"))
      x.assumed(ws, op,
                "retract_distance " + formatFixed(*distance, 3) +
                    " mm is not supported: out to the clearance height between pecks");
  if (op.is(ir::Trait::TapCycle))
    if (auto ratio = op.number("feed_on_retract"); ratio && std::abs(*ratio - 1) > 1e-9)
      x.assumed(ws, op,
                "feed_on_retract " + formatFixed(*ratio, 3) +
                    " does not apply to tapping: the tap leaves by its thread's pitch, at the feed it entered with");
  if (op.is(ir::Trait::TapCycle))
    for (std::string_view dwell : {"dwell_bottom", "dwell_step"})
      if (auto seconds = op.number(dwell); seconds && *seconds > 0)
        x.assumed(ws, op,
                  std::string(dwell) + " " + formatFixed(*seconds, 3) +
                      " s does not apply to tapping: the tap reverses at the bottom without waiting");
}

const char *cycleType(const Node &op) {
  if (op.is(ir::Trait::PeckCycle))
    return "peck";
  if (op.is(ir::Trait::BoreCycle))
    return "bore";
  if (op.is(ir::Trait::TapCycle))
    return "tap";
  return "drill";
}

} // namespace

bool expandHoleMaking(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  const ir::FeatureShape &s = *step.shape;
  const Plan &p = step.plan;
  if (!s.holeCentre) {
    x.unsupported(ws, op.kindName() + " on a " + s.kindName() +
                          ": hole-making operations are expanded on round holes only");
    return false;
  }
  // Spot drills and countersinks are wider than the hole they chamfer.
  const bool chamfers = op.is(ir::Trait::Chamfers);
  if (!chamfers && 2 * p.radius > s.holeDiameter + 1e-6) {
    x.report(ws, "its tool " + p.tool->symbol + " (diameter " + formatFixed(2 * p.radius, 3) +
                     " mm) is wider than the hole (" + formatFixed(s.holeDiameter, 3) + " mm)");
    return false;
  }
  reportIgnored(x, step);
  const Node &feature = *p.feature;
  // The depth the tool's tip reaches: the floor, or past it for through holes.
  double bottom = s.bottom;
  const double point = ir::pointLength(*p.tool);
  if (feature.text("bottom") == "through")
    bottom -= point + std::max(kBreakthrough, op.number("overcut").value_or(0));
  if (auto depth = op.number("cutting_depth"))
    bottom = std::max(bottom, s.top - *depth);
  if (op.kind == ir::Kind::CenterDrilling && !op.has("cutting_depth"))
    bottom = std::max(bottom, s.top - std::max(point, p.radius));
  const bool taps = op.is(ir::Trait::TapCycle);
  const double dwellBottom = taps ? 0 : op.number("dwell_bottom").value_or(0);
  const double dwellStep = taps ? 0 : op.number("dwell_step").value_or(0);
  const std::vector<Zone> zones = reducedFeedZones(x, step, s.top, bottom, p.plungeFeed);

  Node cycle(ir::Kind::Cycle);
  Emitter e(cycle, step.moves.number("secplane").value_or(0));
  const Vec2 c = *s.holeCentre;
  e.travel(c, p.clearanceZ);
  std::vector<double> pecks;
  if (op.kind == ir::Kind::MultistepDrilling) {
    const double first = op.number("first_depth").value_or(s.top - bottom);
    const double stepDown = std::max(op.number("depth_increment").value_or(first), 0.1);
    double reached = p.clearanceZ;
    for (double target = s.top - first;; target -= stepDown) {
      target = std::max(target, bottom);
      if (reached < p.clearanceZ)
        e.rapid(at(c, std::min(reached + kReapproach, p.clearanceZ)), "approach");
      feedDown(e, c, target, zones, p.plungeFeed);
      reached = target;
      pecks.push_back(target);
      if (target <= bottom + 1e-9)
        break;
      e.dwell(dwellStep);
      // Chip clearing: out of the hole, back down in free space.
      e.rapid(at(c, p.clearanceZ), "retract");
    }
  } else {
    feedDown(e, c, bottom, zones, p.plungeFeed);
  }
  e.dwell(dwellBottom);
  // Reamers, boring bars and taps leave at feed (a tap with the spindle
  // reversed: the backend's tapping cycle); drills leave at rapid.
  const bool feedOut = op.spec().isAny(ir::Trait::BoreCycle | ir::Trait::TapCycle);
  const double outFeed = op.is(ir::Trait::TapCycle) ? p.feed : p.feed * op.number("feed_on_retract").value_or(1.0);
  if (feedOut)
    e.linear(at(c, p.clearanceZ), outFeed, "retract");
  e.retract();

  cycle.set("type", ir::Value::word(cycleType(op)));
  cycle.set("at", ir::Value::point(at(c, s.top)));
  cycle.set("clearance", ir::Value::length(p.clearanceZ));
  cycle.set("bottom", ir::Value::length(bottom));
  cycle.set("feed", ir::Value::feed(p.plungeFeed));
  if (feedOut)
    cycle.set("feed_out", ir::Value::feed(outFeed));
  if (pecks.size() > 1) {
    cycle.set("pecks", ir::Value::reals(pecks));
    cycle.set("reapproach", ir::Value::length(kReapproach));
  }
  if (dwellBottom > 0)
    cycle.set("dwell", ir::Value::time(dwellBottom));
  if (dwellStep > 0 && pecks.size() > 1)
    cycle.set("dwell_step", ir::Value::time(dwellStep));
  for (const Zone &z : zones) {
    cycle.set(z.atStart ? "start_feed" : "end_feed", ir::Value::feed(z.feed));
    cycle.set(z.atStart ? "start_depth" : "end_depth", ir::Value::length(z.top - z.bottom));
  }
  step.moves.children.push_back(std::move(cycle));
  return true;
}

} // namespace stepnc::passes::expand
