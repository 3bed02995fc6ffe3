// How long a lathe program takes on a lathe (docs/turning.md, `stepnc sim`):
// its turning steps' moves timed with the spindle as a lathe runs it. At
// constant surface speed the spindle follows the diameter the tool is at
// (n = v / (pi d)), clamped by the step's limit and the machine's range,
// and changes speed no faster than the machine's spindle acceleration; a
// feed per revolution moves the tool n times that per minute; a thread
// pass keeps the spindle's speed; each axis's velocity bounds the feed;
// rapids run each axis on a trapezoidal profile (its velocity and
// acceleration), the move as long as its slowest axis; a step's first cut
// waits for the spindle to reach its speed. Not modelled: jerk, blending
// between moves, tool changes (their time is the machine's).
#pragma once

#include "ir/Node.h"
#include "runtime/Machine.h"

#include <string>
#include <vector>

namespace stepnc::ir {

struct LatheStepTime {
  const Node *step = nullptr;
  double seconds = 0;
  double minRpm = 0, maxRpm = 0;  ///< the spindle speeds it cuts at
};

struct LatheTimeReport {
  double total = 0, cutting = 0, rapid = 0, dwell = 0, spindleWait = 0;  ///< s
  double cutLength = 0;     ///< mm at feed
  double clampedLength = 0; ///< mm of it where the surface speed could not be held (a spindle limit)
  double feedLimitedLength = 0;  ///< mm where an axis's velocity held the feed down
  std::vector<LatheStepTime> steps;
  /// Limits broken: a spindle speed outside the machine's range, the
  /// program longer than an axis's travel.
  std::vector<std::string> violations;
};

/// Times the turning steps of `module` (toolpath IR) on lathe `machine`.
LatheTimeReport timeLatheProgram(const Module &module, const runtime::Machine &machine);

/// The report as text, one line per step.
std::string formatLatheReport(const LatheTimeReport &r, const runtime::Machine &machine);

} // namespace stepnc::ir
