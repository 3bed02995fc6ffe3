#include "ir/motion/LatheSpindle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace stepnc::ir {

LatheSpindle LatheSpindle::of(const Node &moves, const runtime::Machine &machine) {
  LatheSpindle s;
  s.constant = moves.number("spindle").value_or(0);
  s.reverse = s.constant < 0;
  s.minimum = machine.spindleMin;
  for (const Node &c : moves.children)
    if (c.kind == Kind::State && c.has("surface_speed")) {
      s.surfaceSpeed = *c.number("surface_speed");
      s.limit = std::min(c.number("spindle_max").value_or(machine.spindleMax), machine.spindleMax);
    }
  return s;
}

double LatheSpindle::at(double radius, bool *clamped) const {
  if (clamped)
    *clamped = false;
  if (!surfaceSpeed)
    return std::abs(constant);
  const double r = std::abs(radius);
  const double wanted =
      r > 1e-9 ? *surfaceSpeed / (2 * std::numbers::pi * r) : std::numeric_limits<double>::infinity();
  if (wanted > limit) {
    if (clamped)
      *clamped = true;
    return limit;
  }
  return std::max(wanted, minimum);
}

} // namespace stepnc::ir
