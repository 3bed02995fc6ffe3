// Hole making: drilling, centre drilling, multistep (peck) drilling, reaming,
// boring, tapping, thread drilling and countersinking as axial moves on a
// round hole's axis. Rapid to the clearance height, feed to the depth,
// pecks with a rapid out between them, and out at rapid (drills) or at feed
// (reamers, boring bars, taps). The moves are written out in full; a backend
// that recognises them writes its controller's canned cycle instead.
#include "passes/expand/Expand.h"

#include "support/Format.h"

#include <algorithm>

namespace stepnc::passes::expand {

namespace {

/// The attributes of a drilling_strategy, none of which the moves follow.
constexpr std::string_view kDrillingStrategyAttributes[] = {
    "reduced_cut_at_start", "reduced_feed_at_start", "depth_of_start",
    "reduced_cut_at_end",   "reduced_feed_at_end",   "depth_of_end"};

/// Says what of the operation the moves do not follow: a drilling
/// strategy's reduced cut and feed (the whole depth is at one feed), a
/// peck's retract distance (the tool leaves the hole between pecks) and
/// dwells.
void reportIgnored(Expander &x, const Step &step) {
  const Node &ws = step.ws, &op = step.op;
  if (const Node *ds = step.strategy)
    for (std::string_view attribute : kDrillingStrategyAttributes)
      if (ds->has(attribute)) {
        x.assumed(ws, *ds,
                  "drilling_strategy " + std::string(attribute) +
                      " is not supported: the whole depth at the operation's feed");
        break;
      }
  if (op.kind == ir::Kind::MultistepDrilling)
    if (auto distance = op.number("retract_distance"))
      x.assumed(ws, op,
                "retract_distance " + formatFixed(*distance, 3) +
                    " mm is not supported: out to the clearance height between pecks");
  // The moves have no dwell: the tool leaves as soon as it is down.
  for (std::string_view dwell : {"dwell_bottom", "dwell_step"})
    if (auto seconds = op.number(dwell); seconds && *seconds > 0)
      x.assumed(ws, op, std::string(dwell) + " " + formatFixed(*seconds, 3) + " s is not supported: no dwell");
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
  Emitter e(step.moves, ws.number("secplane").value_or(0));
  const Vec2 c = *s.holeCentre;
  e.travel(c, p.clearanceZ);
  if (op.kind == ir::Kind::MultistepDrilling) {
    const double first = op.number("first_depth").value_or(s.top - bottom);
    const double stepDown = std::max(op.number("depth_increment").value_or(first), 0.1);
    double reached = p.clearanceZ;
    for (double target = s.top - first;; target -= stepDown) {
      target = std::max(target, bottom);
      if (reached < p.clearanceZ)
        e.rapid(at(c, std::min(reached + 0.5, p.clearanceZ)), "approach");
      e.linear(at(c, target), p.plungeFeed, "plunge");
      reached = target;
      if (target <= bottom + 1e-9)
        break;
      // Chip clearing: out of the hole, back down in free space.
      e.rapid(at(c, p.clearanceZ), "retract");
    }
  } else {
    e.linear(at(c, bottom), p.plungeFeed, "plunge");
  }
  // Reamers, boring bars and taps leave at feed (a tap with the spindle
  // reversed: the backend's tapping cycle); drills leave at rapid.
  const bool feedOut = op.spec().isAny(ir::Trait::BoreCycle | ir::Trait::TapCycle);
  if (feedOut)
    e.linear(at(c, p.clearanceZ), p.feed * op.number("feed_on_retract").value_or(1.0), "retract");
  e.retract();
  return true;
}

} // namespace stepnc::passes::expand
