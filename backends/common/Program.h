// The program every backend writes, flattened from the toolpath IR: the tools
// with their numbers, and in execution order each step's tool, spindle,
// coolant and moves, with hole-making steps also described as the canned
// cycle expansion recorded for them (the IR's `cycle`). Emitters only choose
// words; what to do was decided by the passes.
#pragma once

#include "backends/Target.h"
#include "backends/common/ToolTable.h"
#include "geom/ArcPlane.h"
#include "geom/Geometry.h"
#include "ir/Node.h"
#include "ir/geom/MoveWalk.h"
#include "support/Diagnostics.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

using Vec3 = ir::Vec3;

struct ToolCall {
  const ir::Node *node = nullptr;
  std::string label;  ///< its STEP-NC id (or symbol)
  int number = 0;     ///< T number: from the tool table, else order of first use
  std::optional<double> length;  ///< length offset from the tool table, mm
  double diameter = 0;
};

/// A change of the deposition head's state (toolpath IR `state`): what it
/// gives changes, the rest stays.
struct ProcessChange {
  const ir::Node *node = nullptr;
  std::optional<bool> energy;
  std::optional<double> power;   ///< W
  std::optional<double> powder;  ///< g/min
  std::optional<double> wire;    ///< mm/min
};

/// 3+2 machining (backends/common/Indexing.h): the rotary axes' positions
/// a step's face needs, reached before it with the tool up out of the way.
struct Index {
  std::vector<std::pair<std::string, double>> axes;  ///< name ("A"), deg
  double retractZ = 0;  ///< machine z the tool goes up to first (the top of its travel), mm
};

/// 3+2 with the controller's tilted working plane (TargetDescriptor::
/// workingPlanes): the frame a step's moves are in (its face's), placed in
/// the coordinates of the workpiece as clamped. A point q of the step is at
/// origin + turn q there; the tool goes along turn's third column.
struct WorkingPlane {
  Vec3 origin = Vec3::Zero();
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();  ///< the face frame's axes, as columns
};

struct Move {
  /// Dwell: the tool waits where it is for `dwell` seconds.
  enum class Kind { Rapid, Linear, Arc, Dwell } kind = Kind::Rapid;
  Vec3 from = Vec3::Zero();  ///< where the tool is before the move
  Vec3 to = Vec3::Zero();
  /// Arcs: the axis through the centre, along the plane's normal, in the
  /// plane's coordinates (x, y in the XY plane; geom/ArcPlane.h).
  geom::Vec2 centre = geom::Vec2::Zero();
  bool ccw = false;  ///< seen from the tip of the plane's normal
  geom::ArcPlane plane = geom::ArcPlane::xy();
  int64_t turns = 0;  ///< arcs: full turns before the last arc (toolpath IR rule)
  double feed = 0;    ///< mm/min; 0 for rapids
  bool smooth = false;  ///< a line that is a chord of a smooth curve (toolpath IR `smooth`)
  double dwell = 0;     ///< dwells: s
  /// A rapid along Z alone, to `to.z()`: the clearance move that starts
  /// every step after a tool change and the program (role "clearance").
  /// Where the tool is in X and Y is then the machine's business: only the
  /// Z word is written, and `from`/`to` carry X and Y as last planned.
  bool alongZOnly = false;
  std::string role;
  const ir::Node *node = nullptr;
  /// Deposition: the head's state changes made before the move, in order.
  std::vector<ProcessChange> before;
  /// The tool axis at the move's start and end, in the frame of the step's
  /// setup (the toolpath IR's; +z on a 3-axis step).
  Vec3 fromAxis = Vec3::UnitZ();
  Vec3 axis = Vec3::UnitZ();
  /// A step that tilts the tool, written as the machine's joints
  /// (backends/common/FiveAxis.h): the rotary axes' angles at the move's
  /// end (deg, in Program::rotaryAxes order), the feed in inverse time
  /// (1/min: the block takes 1/F minutes; G93), and a turn of the rotary
  /// axes made before the move with the tool up at the top of z.
  std::vector<double> rotary;
  double inverseTime = 0;
  std::optional<Index> turn;

  /// A rapid that takes the tool to where a step starts: the clearance
  /// move and the moves the IR marks `position`.
  bool positions() const { return kind == Kind::Rapid && (role == "position" || role == "clearance"); }

  /// The whole angle an arc sweeps (radians, > 0), full turns included; a
  /// last arc ending over its start is a whole turn.
  double sweep() const;
  /// Where an arc starts and ends in its plane's coordinates.
  geom::Vec2 fromInPlane() const { return plane.local(from).head<2>(); }
  geom::Vec2 toInPlane() const { return plane.local(to).head<2>(); }
};

/// A hole-making step whose moves are one axial cycle on one position, as
/// strategy expansion recorded it (the IR's `cycle`, ir/Kinds.def).
struct HoleCycle {
  CycleKind kind = CycleKind::Drill;
  geom::Vec2 at = geom::Vec2::Zero();
  double initialZ = 0;  ///< where the tool is before and after (the security plane)
  double retractZ = 0;  ///< the reference plane R: where feeding starts (clearance height)
  double surfaceZ = 0;  ///< the top of the hole
  double depthZ = 0;    ///< the lowest point of the tool tip
  std::vector<double> pecks;  ///< the bottom of each feed in (the last is depthZ)
  double reapproach = 0;  ///< pecks: the tool comes back down at rapid to this far above the last peck, mm
  double feed = 0;      ///< in, mm/min
  double feedOut = 0;   ///< out (bore, tap), mm/min; 0 for drills (rapid out)
  double dwell = 0;     ///< at the bottom, s
  double dwellStep = 0; ///< at the bottom of every peck but the last, s
  double startFeed = 0, startDepth = 0;  ///< a reduced feed over the first mm below the top (0: none)
  double endFeed = 0, endDepth = 0;      ///< a reduced feed over the last mm above the bottom (0: none)
};

/// Why target `d` cannot write `c` as its canned cycle ("" when it can, by
/// its descriptor: the family, dwells and reduced feeds it has); the
/// emitter may still find that its cycle does not make the planned moves.
std::string whyNotCycle(const TargetDescriptor &d, const HoleCycle &c);


struct Step {
  enum class Kind { Moves, Message, Stop, OptionalStop } kind = Kind::Moves;
  const ir::Node *exec = nullptr;
  std::string label;    ///< the workingstep's id, or the message
  std::optional<ir::Kind> operation;  ///< the operation's kind, if the step has one
  /// Its operation cuts a thread with a tap (a tapping cycle's family).
  bool taps() const { return operation && ir::hasTraits(*operation, ir::Trait::TapCycle); }
  /// The operation's name, for messages ("tapping").
  std::string operationName() const { return operation ? std::string(ir::kindName(*operation)) : std::string(); }
  int tool = -1;          ///< index into Program::tools
  /// The first step with moves, or the first after its tool changed in:
  /// its moves start with the clearance move (Move::alongZOnly).
  bool toolChange = false;
  /// A stop for the operator to re-clamp the workpiece (docs/setups.md):
  /// the spindle and coolant stop first.
  bool reclamp = false;
  /// In a program that re-clamps, the work offset (1: the program's first)
  /// its first step and the first step after each re-clamp select.
  int workOffset = 0;
  /// Its setup (the IR's `setup` node), when its moves name one.
  const ir::Node *setup = nullptr;
  /// In a program that turns the rotary axes to each face instead of
  /// re-clamping: the turn before the step.
  std::optional<Index> index;
  /// With the controller's tilted working plane: the plane the turn before
  /// the step selects (set with `index`; the step's moves stay in its
  /// face's frame).
  std::optional<WorkingPlane> plane;
  double spindle = 0;     ///< rev/min, negative clockwise (M3); 0 on a rapid movement: keep
  std::string coolant;    ///< off, flood, mist, through_tool
  double secplane = 0;
  std::vector<Move> moves;
  /// Deposition: the head's state changes made after the last move.
  std::vector<ProcessChange> after;
  /// A deposition step (its moves lay beads with the head's energy on).
  bool deposits = false;
  /// A step that tilts the tool (ir::tiltsTool): its moves carry their tool
  /// axes, and once written as joints (FiveAxis.h) their rotary angles.
  bool tilted = false;
  std::optional<HoleCycle> cycle;
};

struct Program {
  std::string name;  ///< the project's id
  std::vector<ToolCall> tools;
  bool toolsFromTable = false;
  std::vector<Step> steps;
  /// The block raw piece of the (first) workpiece, workpiece coordinates.
  std::optional<std::pair<Vec3, Vec3>> blank;
  /// A program that re-clamps the workpiece (docs/setups.md): each setup's
  /// work offset and what the operator does ("work offset 2: ..."), the
  /// first clamping's first.
  std::vector<std::pair<int, std::string>> clampings;
  /// A program that turns the rotary axes to each face instead
  /// (Indexing.h), or moves them with the tool (FiveAxis.h): what the
  /// header says of it, line by line.
  std::vector<std::string> indexing;
  /// The rotary axes the moves of steps that tilt the tool give angles for
  /// ("A", "C"), once written as joints.
  std::vector<std::string> rotaryAxes;
};

/// How high a step starts when where the tool is cannot be relied on (after
/// a tool change, at the start): its security plane, or its first rapid's
/// height when that is higher.
double clearanceHeight(const Step &s);

/// The program of `module` (toolpath IR). Errors: an executable without
/// moves, a tool missing from the table. Returns nullopt after reporting.
/// `arcs`: how arcs in the ZX and YZ planes come (ir::OutOfPlaneArcs): as
/// arcs for a target that writes them (G18, G19), else as lines along their
/// chords.
/// `deposition`: the target writes deposition steps (Move::before,
/// Step::after); else they are refused.
/// `toolAxes`: Take builds steps that tilt the tool too (Step::tilted, each
/// move's axes), for a target that writes them; else they are refused.
std::optional<Program> buildProgram(const ir::Module &module, const ToolTable *table, DiagnosticEngine &diags,
                                    ir::OutOfPlaneArcs arcs = ir::OutOfPlaneArcs::Chords,
                                    ir::Deposition deposition = ir::Deposition::Refuse,
                                    std::string_view target = "the G-code targets",
                                    ir::ToolAxes toolAxes = ir::ToolAxes::Refuse);

} // namespace stepnc::backends
