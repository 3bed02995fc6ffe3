// Reading back what a G-code emitter wrote, before it is written to a file.
// Each dialect has a reader of its own (the subset of the controller's
// language its emitter writes, read the way the controller's manual says the
// controller reads it): it tracks the modal state and the position through the
// printed numbers, reports what the controller would refuse or do differently
// (the structural checks of tests/backends/check-*.py), and lists the motions
// the program makes, canned cycles expanded. checkReadBack() then compares
// those motions with the program model's moves. A program that fails is a bug
// in stepnc: an error at the workingstep, and no file.
#pragma once

#include "backends/common/Program.h"
#include "geom/ArcPlane.h"
#include "support/Diagnostics.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

/// A motion the written program makes, as its reader understands the text.
/// Coordinates the program leaves to the machine (X and Y after a tool
/// change, before anything sets them) are NaN.
struct ReadMove {
  Move::Kind kind = Move::Kind::Rapid;
  Vec3 from = Vec3::Zero();
  Vec3 to = Vec3::Zero();
  geom::Vec2 centre = geom::Vec2::Zero();  ///< arcs, in their plane's coordinates
  bool ccw = false;                        ///< arcs
  geom::ArcPlane plane = geom::ArcPlane::xy();  ///< arcs: G17, G18 or G19 in force
  double sweep = 0;  ///< arcs: the whole angle turned, radians (> 0), full turns included
  double feed = 0;   ///< mm/min, feed moves (the modal feed in force); 1/min in inverse time
  bool inverseTime = false;  ///< a feed move in inverse time (G93)
  /// The rotary axes A, B, C after the move, as the program last wrote them
  /// (NaN: never written).
  std::array<double, 3> abc = {std::nan(""), std::nan(""), std::nan("")};
  double dwell = 0;  ///< dwells, s
  /// A piece of a spline the controller draws through its end points (G5,
  /// CSPLINE): compared by its end. With a Bézier form, its inner control
  /// points (absolute), which must keep the curve within the tolerance of the
/// chord.
  bool spline = false;
  std::optional<std::pair<geom::Vec2, geom::Vec2>> bezier;
  /// Made by a canned cycle: the cycle's rapids are the controller's, and a
  /// step with one is compared by its feed moves and dwells only.
  bool cycle = false;
  size_t line = 0;  ///< 1-based line of the block in the program text
};

/// What a dialect's reader found in a program text.
struct ProgramReading {
  std::vector<ReadMove> moves;
  /// What the controller would refuse or read otherwise: the line and why.
  std::vector<std::pair<size_t, std::string>> problems;

  void problem(size_t line, std::string why) { problems.emplace_back(line, std::move(why)); }
};

/// `text` with the given lines (1-based) emptied, the others where they were.
std::string blankLines(const std::string &text, const std::vector<size_t> &lines);

/// Where each step of the program starts in the text: the 1-based line of
/// its first block (a step that wrote nothing has the line of what follows).
/// One entry per Program::steps element.
using StepLines = std::vector<size_t>;

/// Compares what the reader found with the program `p` the text was written
/// from: the reader's problems, then the motions step by step (runs of rapids
/// by where they end; feed moves by end point and feed; arcs also by centre,
/// direction and sweep, an arc written in pieces as one; spline pieces by end
/// point and, with control points, by how far the curve leaves the chord;
/// dwells by time; in a step written as a canned cycle, feed moves and dwells
/// only). `text` is the program (to quote a line). Positions agree within
/// the printed precision (the descriptor's decimals) and 0.001 mm, feeds
/// within their rounding. The first difference is reported as an error at its
/// workingstep (a bug in stepnc). True when clean.
bool checkReadBack(const Program &p, const TargetDescriptor &d, const StepLines &stepLines, const std::string &text,
                   const ProgramReading &reading, double tolerance, DiagnosticEngine &diags);

/// The moves of `p` the written program must make, step by step: element i
/// lists Program::steps[i]'s moves that print as motion (a move whose printed
/// end is where the one before ended is none), an arc whose ends print as
/// one point as the line it is written as (arcPrintsClosed).
std::vector<std::vector<Move>> expectedMoves(const Program &p, const TargetDescriptor &d);

/// How far the radius of an arc block may be at its end from its start: the
/// emitters balance the centre between the printed ends, which leaves the
/// radii within a unit of the last decimal; 0.001 mm at 3 or more decimals
/// (LinuxCNC allows 0.00127 mm; the 840D's and the TNC's limits are machine
/// data), one unit with fewer (--target-opt decimals=2 cannot do better).
double arcRadiusTolerance(const TargetDescriptor &d);

/// True when `text` is a number as controllers read it in the style of
/// `decimals`: digits with an optional sign and point, no exponent; `why`
/// says what is wrong otherwise (exponent, negative zero, no decimal point
/// where `needPoint`, not a number). Shared by the dialects' readers.
bool wellFormedNumber(const std::string &text, bool needPoint, std::string &why);

} // namespace stepnc::backends
