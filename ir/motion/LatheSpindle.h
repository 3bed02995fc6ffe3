// The spindle a lathe step asks for (docs/turning.md): a constant speed, or
// a constant surface speed (G96, ISO 14649-121's constant cutting speed)
// under which the speed follows the radius the tool is at, n = v / (2 pi r),
// held below the step's limit and the machine's maximum and above the
// machine's minimum. The timer of lathe programs (LatheTime.h) and the lathe
// motion planner (LathePlan.h) both ask here.
#pragma once

#include "ir/Node.h"
#include "runtime/Machine.h"

#include <optional>

namespace stepnc::ir {

struct LatheSpindle {
  std::optional<double> surfaceSpeed;  ///< mm/min, when at constant surface speed
  double limit = 0;     ///< rev/min: the step's maximum within the machine's (surface speed only)
  double constant = 0;  ///< rev/min, signed as the IR's (negative: the other way), when not
  double minimum = 0;   ///< rev/min, the machine's lowest
  bool reverse = false; ///< turning the other way (M4)

  /// The spindle of the `moves` of a lathe step on `machine`.
  static LatheSpindle of(const Node &moves, const runtime::Machine &machine);

  /// The speed asked for with the tool at `radius` mm from the axis
  /// (either side), rev/min >= 0; `clamped` when a limit holds it below the
  /// surface speed.
  double at(double radius, bool *clamped = nullptr) const;
  /// The same with the direction's sign.
  double signedAt(double radius) const { return reverse ? -at(radius) : at(radius); }
};

} // namespace stepnc::ir
