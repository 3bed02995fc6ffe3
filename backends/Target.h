// What a controller can do, chosen per target and overridable from the
// command line (`--target-opt key=value`). Emitters read the descriptor
// instead of hard-coding a dialect's choices, so one G-code emitter core
// (common/) serves every target and a new target is a descriptor plus the
// words that are its own.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace stepnc::backends {

/// How an arc's centre is written.
enum class ArcForm {
  IncrementalCentre,  ///< I J K from the start point (RS274, 840D)
  Radius,             ///< radius word, negative beyond 180 deg (R, CR=); no full circles
  ModalCentre,        ///< centre block then the end point (Heidenhain CC + C)
};

enum class Numbering {
  None,      ///< no block numbers
  Every,     ///< N10, N20, ... (the step is `numberStep`)
  FromZero,  ///< 0, 1, 2, ... on every line (Heidenhain)
};

/// How a run of lines that are chords of one smooth curve (toolpath IR
/// `smooth`, e.g. a trochoid) is written.
enum class SplineForm {
  None,          ///< as the lines
  CubicBezier,   ///< one cubic Bézier block per line, the C2 spline through the points (LinuxCNC G5 X Y I J P Q)
  Interpolating, ///< the points in the controller's cubic spline mode, C2 through them (840D CSPLINE)
};

/// Canned cycles a controller has, by what they do.
enum class CycleKind { Drill, Peck, Bore, Tap };

/// "drill", "peck", "bore", "tap".
const char *cycleKindName(CycleKind kind);

/// What a target's canned cycle of one family can do beyond feeding in and
/// out: a cycle that needs more is written as its moves (dwells as the
/// controller's dwell block, reduced feeds as lines at those feeds).
struct CycleForm {
  bool dwell = false;         ///< a dwell at the bottom (G82, CYCLE82's DTB, Q211)
  bool dwellStep = false;     ///< a dwell at the bottom of every peck
  bool reducedFeeds = false;  ///< reduced feeds over the top or the bottom of the hole
};

struct TargetDescriptor {
  std::string name;         ///< as given to --target
  std::string description;  ///< one line, for --list-targets
  std::string extension;    ///< of the program file, with its dot
  ArcForm arcs = ArcForm::IncrementalCentre;
  bool helix = true;         ///< helical arcs (a z change along an arc) in one block
  bool helixTurns = true;    ///< several turns of a helix in one block
  /// Arcs in the ZX and YZ planes (G18, G19) as well as XY; without, they are
  /// written as lines along their chords (within ir::kOutOfPlaneArcChord).
  bool arcPlanes = false;
  /// Canned cycles used when they make the planned moves, and what each can do.
  std::map<CycleKind, CycleForm> cycles;
  SplineForm splines = SplineForm::None;
  Numbering numbering = Numbering::None;
  int numberStep = 10;
  size_t maxLineLength = 0;  ///< 0: no limit
  int coordDecimals = 3;     ///< X Y Z I J K and radii, mm
  int feedDecimals = 0;      ///< mm/min
  int speedDecimals = 0;     ///< rev/min
  double tolerance = 0.01;   ///< contour tolerance for the path mode (mm), --tolerance overrides
  /// Lathe programs: the target can write a finishing pass as the surface
  /// with the controller's nose radius compensation (G41/G42) ...
  bool latheCompensation = false;
  /// Deposition programs: the target writes the head's state changes with
  /// the machine's codes (docs/additive.md).
  bool deposition = false;
  /// Features on several faces on a machine with a rotary table: the target
  /// turns its rotary axes to each face (3+2, positions computed by stepnc,
  /// backends/common/Indexing.h) instead of stopping to re-clamp.
  bool rotaryIndexing = false;
  /// ... or with the controller's tilted working plane: each face's moves
  /// stay in its own frame, the program shifts the datum to the face's
  /// origin and tilts the working plane to it, and the controller turns the
  /// rotary axes (Step::plane; heidenhain-tnc PLANE SPATIAL).
  bool workingPlanes = false;
  /// The swivel data set the working plane is tilted with (siemens-840d's
  /// CYCLE800 _TC, the machine's own name for its kinematics; --target-opt
  /// swivel-data=NAME). Empty: the target names none.
  std::string swivelDataSet;
  /// Steps that tilt the tool (5-axis moves): the target writes them as the
  /// machine's joint positions with rotary words and inverse-time feeds, for
  /// a machine without tool-centre-point control (backends/common/FiveAxis.h).
  bool jointMoves = false;
  /// Steps that tilt the tool written with the controller's tool-centre-
  /// point control: the words that turn it on and off ("TRAORI",
  /// "TRAFOOF"), X Y Z the tool tip in the workpiece and the rotary axes'
  /// angles on each move, feeds along the tip's path (FiveAxis.h,
  /// tcpMoves). Empty: the target has none.
  std::string tcpOn, tcpOff;
  /// Reading back a program that deposits: feed moves run with the spindle
  /// off (a deposition head turns nothing).
  bool feedsWithoutSpindle = false;
  /// ... and is asked to (--target-opt nose-compensation=controller);
  /// otherwise the moves carry the nose radius and the program stays G40.
  bool controllerNoseCompensation = false;
};

/// Applies `key=value` overrides (--target-opt) to a descriptor: decimals,
/// line-numbers (none|every), number-step, max-line-length, arcs
/// (ijk|radius), cycles (on|off), splines (on|off), nose-compensation
/// (path|controller). Returns an error
/// message, or "" when all applied.
std::string applyOverrides(TargetDescriptor &d, const std::vector<std::string> &overrides);

/// The overrides applyOverrides understands, one per line, for --help.
std::string overrideHelp();

} // namespace stepnc::backends
