// What the files of expand-strategies share (private to passes/expand/).
//
// The pass (Expand.cpp) walks the workingsteps, builds a Plan from the
// operation, its tool and its feature, and hands the step to the family of
// code that expands its strategy, found in a registry keyed by the kind of
// the strategy node (ir::Kind): explicit toolpaths, hole making, the 2.5D
// milling strategies and the pattern strategies. The families write their
// moves through an Emitter and report through the Expander, which holds
// the state of one run of the pass. Geometry helpers that several families
// use (centre areas, contour rings, zigzag strokes, cutting a path with its
// approach) are declared here and defined in the file of their family.
#pragma once

#include "geom/Boolean.h"
#include "ir/Kinds.h"
#include "ir/Program.h"
#include "ir/geom/Curves.h"
#include "ir/geom/FeatureShape.h"
#include "passes/Pass.h"
#include "passes/expand/Emitter.h"

#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::passes::expand {

using geom::Loop;
using geom::Region;
using geom::Seg;
using geom::Vec2;
using ir::Node;
using ir::Value;
using ir::Vec3;

/// A path in the plane: segments, each starting where the one before ends.
using Path2D = std::vector<Seg>;

inline constexpr double kPi = std::numbers::pi;
/// Height above a feature's top where plunges start when the operation gives no retract plane (mm).
inline constexpr double kDefaultClearance = 2.0;
/// Largest engagement angle of a trochoid's tool (deg) when the pass is not given max-engagement.
inline constexpr double kDefaultMaxEngagement = 90.0;
/// How far the line segments of a curve the strategy makes (trochoids,
/// rounded links) may stray from it (mm) when the pass is not given chord-tolerance.
inline constexpr double kDefaultChordTolerance = 0.005;
/// Overlap of neighbouring guide paths of a pattern strategy that gives none:
/// a share of the width one pass of the motif cuts.
inline constexpr double kPatternOverlap = 0.2;
/// Largest ridge left between finishing levels on a slanted wall (mm) when
/// neither the pass nor the workpiece gives one.
inline constexpr double kDefaultScallopHeight = 0.01;
/// Extra depth past the floor of a through hole, beyond the tool's point, when
/// the operation's overcut is smaller (mm).
inline constexpr double kBreakthrough = 1.0;

/// The most depth levels and radial passes (rings or strokes per level) a
/// step is planned with: more come only from a depth of cut or stepover far
/// too small for the feature (a micrometre on a pocket), and would plan for
/// hours; such a step is a located error instead.
inline constexpr int kMaxLevels = 2000;
inline constexpr int kMaxRadialPasses = 2000;
/// The most points a pattern strategy samples for one step (a trochoid's
/// points, plunges): as for levels, more come only from a step far too
/// small for the feature (a trochoid advancing a nanometre per loop), and
/// such a step is a located error, before the points are made.
inline constexpr double kMaxPatternPoints = 5e6;

/// A plane point at height z.
inline Vec3 at(const Vec2 &p, double z) { return {p.x(), p.y(), z}; }

/// What the operation, its tool and its feature fix for every move of a step.
struct Plan {
  const Node *feature = nullptr;
  const Node *op = nullptr;
  const Node *tool = nullptr;
  double radius = 0;
  double feed = 0;
  double plungeFeed = 0;
  double spindle = 0;
  double allowanceSide = 0;
  double allowanceBottom = 0;
  double clearanceZ = 0;  ///< where axial approaches start
};

/// The state of one run of the pass, and the ways it reports: every family
/// reads its options and module and reports through it.
/// What expanding a path the file gives (an operation's explicit toolpaths,
/// a rapid movement) left on its moves, for linking consecutive paths and
/// settling their rapids on the in-process stock (linkExplicitPaths,
/// settleExplicitRapids). Indices are into the executable's `moves`.
struct ExplicitRun {
  Node *exec = nullptr;
  size_t leadIn = 0;                 ///< moves made to reach the path's start
  bool retract = false;              ///< the last move is the retract made after the path
  ir::Vec3 start = ir::Vec3::Zero(); ///< the path's first point
  ir::Vec3 end = ir::Vec3::Zero();   ///< and its last
  /// The file's own moves that the stock decides: rapids it asks for
  /// (`connect` false), and lines of `connect` toolpaths that give no speed,
  /// each with the place of its toolpath in the file (for messages: the
  /// toolpath node itself may move as the step gets its moves).
  struct Decided {
    size_t index;
    bool connect;
    ir::Origin toolpath;
  };
  std::vector<Decided> decided;
};

class Expander {
public:
  double maxEngagement = kDefaultMaxEngagement;   ///< deg
  double chordTolerance = kDefaultChordTolerance; ///< mm
  /// Largest ridge left between finishing levels on a slanted wall (mm);
  /// absent: the workpiece's global tolerance, else kDefaultScallopHeight.
  std::optional<double> scallopHeight;
  ir::Module *module = nullptr;
  DiagnosticEngine *diags = nullptr;
  PassStats *stats = nullptr;
  PassResult result;
  /// The tool of the last step expanded, its spindle and coolant: a rapid
  /// movement keeps them.
  std::string lastTool;
  double lastSpindle = 0;
  std::string lastCoolant = "off";
  /// The paths the file gives, by executable.
  std::map<const Node *, ExplicitRun> explicitRuns;
  /// The stock of each turned workpiece (by symbol) in the half plane of
  /// its turning axis, as the lathe steps so far left it (Turning.cpp).
  std::map<std::string, Region> turnedStock;

  /// Gives executable `ws` its moves and counts them.
  void attach(Node &ws, Node moves);

  /// An error about workingstep `ws`, located at it; the pass fails.
  void report(const Node &ws, const std::string &message) { report(ws, ws, message); }
  /// An error about workingstep `ws` located at `at` (a part of it the file gives, such as its strategy).
  void report(const Node &ws, const Node &at, const std::string &message);
  /// A warning about workingstep `ws`, located at it: what its moves leave
  /// undone (the moves are made).
  void warning(const Node &ws, const std::string &message);
  /// A warning that workingstep `ws` gets no moves, and why.
  void unsupported(const Node &ws, const std::string &reason);
  /// A warning at `at` (what the file gives and stepnc does not follow, such
  /// as the operation's approach) that workingstep `ws` is expanded on an
  /// assumption: "workingstep @w: approach plunge_zigzag is not supported:
  /// plunging along the tool axis". The moves are those the message names;
  /// the warning only says so (--strict makes it an error).
  void assumed(const Node &ws, const Node &at, const std::string &message);
};

/// Joins consecutive paths the file gives (same tool, setup, spindle and
/// coolant) where one starts where the one before ends: no retract and no
/// approach between them; over the same point in the plane, straight along
/// the axis. (Where the next starts elsewhere, the tool retracts to the
/// security plane and travels, as before.)
void linkExplicitPaths(Expander &x);

/// Reads the rapids the file's paths ask for below the security plane on
/// the in-process stock: kept where their path is clear, lifted (up to the
/// security plane, across, down) with a warning where it is not; a rapid
/// whose end lies in the stock is an error. Lines of `connect` toolpaths
/// that give no speed are moved at rapid where their path is clear (as
/// NIST's ISO 14649 interpreter reads them), at feed where it is not.
void settleExplicitRapids(Expander &x);

/// An empty `moves` for the executable `exec`, with the state in force.
Node makeMoves(const Node &exec, const std::string &tool, double spindle, const std::string &coolant,
               const std::string &setup);

/// One workingstep as a family expands it.
struct Step {
  const Node &ws;                          ///< the workingstep
  const Node &op;                          ///< its operation
  const Node *strategy;                    ///< the node the family was found by (may be null)
  const ir::FeatureShape *shape;           ///< null for families that need no shape
  const ir::PlaneFrame *frame;             ///< the feature's frame (explicit toolpaths only)
  const Plan &plan;
  Node &moves;                             ///< the `moves` node the family fills
};

/// Expands one step into `step.moves`; false (after a diagnostic) when the
/// step gets no moves.
using ExpandFn = bool (*)(Expander &, const Step &);

/// A family of strategies, as the registry holds it.
struct Family {
  ir::Kind key;                              ///< the kind of the node that selects it
  std::string_view name;                     ///< for messages: "2.5D milling"
  bool needsShape;                           ///< the feature's shape, not only its frame
  /// The approach types the family follows; any other is reported.
  std::span<const std::string_view> approaches;
  /// What the family does instead of an approach it does not follow.
  std::string_view otherApproach;
  ExpandFn expand;
};

/// The family registered for strategy kind `key`; null when none is.
const Family *findFamily(ir::Kind key);

// --- The families' entry points (one file each) ---------------------------------

/// ExplicitToolpaths.cpp: an operation's `toolpath` children, lowered exactly.
bool expandExplicitToolpaths(Expander &x, const Step &step);
/// ExplicitToolpaths.cpp: a `rapid_movement`'s points as rapids.
void expandRapidMovement(Expander &x, Node &rm, const std::string &setup);
/// HoleMaking.cpp: axial moves on a round hole's axis.
bool expandHoleMaking(Expander &x, const Step &step);
/// Milling2D.cpp: levels, the strategy's paths at each, approaches and links.
bool expandMilling2D(Expander &x, const Step &step);
/// FlankMilling.cpp: a side finishing operation whose tool direction varies
/// (ISO 14649-11 five_axes_var_tilt_yaw): the walls of the bosses on a planar
/// face, each in one pass with the side of a flat end mill along its
/// rulings (moves with a tool axis). Other tool directions are refused.
bool expandFlankMilling(Expander &x, const Step &step);
/// SlotLevels.cpp: a slot with slanted or curved walls, level by level from
/// the top down, each level cut as a slot with vertical walls as wide as the
/// tool fits at that height (2.5D milling hands such slots over).
bool expandSlotLevels(Expander &x, const Step &step);
/// PatternStrategies.cpp: trochoids along the guide strategy's paths.
bool expandTrochoidal(Expander &x, const Step &step);
/// Turning.cpp: the lathe moves of a turning workingstep, from its turned
/// feature and the stock the steps before left; false after a diagnostic.
bool expandTurning(Expander &x, Node &ws, const Node &op, const std::string &setup);
/// Deposition.cpp: the beads of an additive workingstep, layer by layer,
/// with the energy switched on and off along them; false after a diagnostic.
bool expandDeposition(Expander &x, Node &ws, const Node &op, const std::string &setup);
/// Turning.cpp: after a hole-making step drilled on the turning axis
/// (ir::drillsOnTurningAxis), its workpiece's lathe stock loses what the
/// drill's point and body swept, so that a boring step after it finds the hole.
void noteAxialDrilling(Expander &x, const Node &ws);
/// Expand.cpp: true when every point and length of the expanded moves is
/// one a machine tool can go to, else an error at the workingstep naming the
/// first coordinate beyond (a feature whose dimensions run past it).
bool withinMachine(Expander &x, const Node &ws, const Node &feature, const Node &moves);
/// Expand.cpp: the coolant an operation's machine functions ask for (off,
/// flood, mist, through_tool).
std::string coolant(const Node &op);
/// PatternStrategies.cpp: plunges along the guide strategy's paths.
bool expandPlunging(Expander &x, const Step &step);

// --- Shared by the milling families ---------------------------------------------

/// Milling2D.cpp: the heights a milling operation cuts at, from the top down
/// to the floor plus its allowance, in equal steps no deeper than the axial
/// depth of cut; none (after a warning) when the allowance leaves nothing.
std::vector<double> levelsOf(Expander &x, const Node &ws, const Node &op, const ir::FeatureShape &s, const Plan &p);

/// How a step's strategy cuts a level, fixed once per step, and what has
/// been said about it (each warning once per step).
struct LevelStrategy {
  std::string type;  ///< the strategy's type, or the default for the feature
  bool face = false;
  bool sideOnly = false;  ///< one contour along the walls (side milling)
  bool followOrientation = true;
  bool linkAtDepth = false;
  double stepover = 0;
  Vec2 strokeDir = Vec2::UnitX();
  bool saidSlotLine = false, saidSideMilling = false;
};

/// The centre area of one level and the strategy's paths in it.
struct LevelPaths {
  Region centres;
  std::vector<Path2D> paths;
};

/// Milling2D.cpp: the strategy of `step` as its levels follow it: its type,
/// the stepover, the cut direction, the stroke direction.
LevelStrategy levelStrategy(const Step &step, const ir::FeatureShape &s, const Plan &p);

/// Milling2D.cpp: the centre area of shape `s` less the islands' `keepOut`
/// areas (keepOutAt) and the strategy's paths in it (along the course of
/// travel for center milling and slots no wider than the tool); false after
/// a diagnostic.
bool planLevel(Expander &x, const Step &step, const ir::FeatureShape &s, const Plan &p,
               const std::vector<Region> &keepOut, LevelStrategy &ls, LevelPaths &out);

/// Milling2D.cpp: the paths of one level cut at height z, each reached by a
/// link at depth or by the approach; an open path along a slot is cut from
/// the end nearer to the tool.
void cutLevel(Emitter &e, const Step &step, const ir::FeatureShape &s, const Plan &p, LevelPaths &level, double z,
              const LevelStrategy &ls, int &fallbacks);

/// Milling2D.cpp: where the tool centre may be at one level: away from walls
/// by the radius plus the side allowance, out of the islands' `keepOut`
/// areas; for faces, over the face and past it.
Region centreArea(const ir::FeatureShape &s, const Region &area, const std::vector<Region> &keepOut, const Plan &p);

/// Milling2D.cpp: the scallop height finishing leaves on walls that are not
/// vertical: --scallop-height, else the workpiece's global_tolerance, else
/// kDefaultScallopHeight.
double scallopHeight(const Expander &x, const Node &feature);

/// Milling2D.cpp: where the tool's centre may not be, its tip at height z,
/// for each island standing there: the island grown by the side allowance
/// and the radius; a boss whose walls lean in, its sections met by the
/// tool's body (corner and side) grown by the allowance.
std::vector<Region> keepOutAt(const ir::FeatureShape &s, double z, const Plan &p);

/// Milling2D.cpp: the tool centre's path along a slot: its course of travel,
/// stopped the tool radius (and side allowance) short of flat ends, short of
/// radiused ends as far as the tool is narrower than the slot, and run a
/// radius past open ends. None when the tool is wider than the slot less its
/// allowances.
std::optional<Path2D> slotCentreline(const ir::FeatureShape::SlotPath &slot, const Plan &p);

/// Milling2D.cpp: the plane paths of strategy `type` in the centre area;
/// none for a strategy not expanded yet.
std::optional<std::vector<Path2D>> strategyPaths(const std::string &type, bool face, bool unbounded, bool sideOnly,
                                                 const Region &centres, const Vec2 &strokeDir, double stepover,
                                                 bool followOrientation, double radius);

/// Milling2D.cpp: one plane path at height z, reached by a link at depth when
/// allowed and inside the centre area (anywhere when `anywhere`: see
/// linkAnywhere), else from the security plane by the operation's approach.
/// `fallbacks` counts the paths whose helix or ramp did not fit and that
/// were entered along the tool axis instead.
/// Milling2D.cpp: whether links at depth may leave the centre area: on a face
/// with nothing standing in it (the tool passes its edges in the air).
bool linkAnywhere(const ir::FeatureShape &s);

void cutPath(Emitter &e, const Path2D &path, double z, const Plan &p, const Node &op, const Region &centres,
             bool mayLink, bool anywhere, int &fallbacks);

/// Milling2D.cpp: the warning, once per step, that `fallbacks` paths were
/// entered along the tool axis because the operation's helix or ramp did
/// not fit there.
void reportApproachFallbacks(Expander &x, const Step &step, int fallbacks);

/// Milling2D.cpp: whether a strategy's paths turn counter-clockwise (the
/// orientation of a Region's outer loops): climb keeps the wall on the
/// tool's right for a clockwise (M3) spindle, conventional on its left;
/// without a cut mode, the rotation it names; else counter-clockwise.
bool counterClockwise(const Node *strategy, double spindle);

/// Contour.cpp: a loop started at the point nearest to p (the segment there is split).
Loop startNearest(const Loop &l, const Vec2 &p);

/// Contour.cpp: the widest stepover between rings of a tool of radius
/// `radius` that leaves no material at the target's sharpest convex corner
/// (R (1 + sin(theta / 2)), REFERENCES), with 2 % to spare.
double ringCoverLimit(const ir::FeatureShape &s, double radius);

/// Contour.cpp: contour-parallel rings, the boundaries of the centre area
/// shrunk by 0, s, 2s, ... innermost first (all) or the outermost ring only.
std::vector<Path2D> rings(const Region &centres, double stepover, bool followOrientation, bool all, double radius);

/// Zigzag.cpp: the stroke direction: the strategy's feed direction, else
/// the face's course of travel, else the feature's x axis.
Vec2 strokeDirection(const Node &feature, const ir::FeatureShape &s, const Node *strategy);

/// Zigzag.cpp: parallel strokes across the area in direction `dir`,
/// `stepover` apart, each clipped to the area; alternate strokes reversed
/// when bidirectional.
std::vector<Path2D> strokes(const Region &area, const Vec2 &dir, double stepover, bool bidirectional,
                            double overtravel);

} // namespace stepnc::passes::expand
