// Facts about a program that every layer asks: the executables in the order
// the machine runs them, a workingstep's operation, the resources a symbol
// names. Passes, backends and the tools ask here instead of walking the tree
// each their own way.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::ir {

/// The executables the machine runs, in program order: every workingstep,
/// rapid movement, program stop, optional stop and display message of the
/// module's workplans, nested workplans flattened where they stand. A control
/// flow executable (if, while, parallel, selective, assignment) is listed
/// itself, its branches not flattened: which of them run is decided when the
/// program runs, so a reader that writes one straight program must refuse it
/// (requireThreeAxisMilling).
std::vector<const Node *> programOrder(const Module &module);

/// Whether the program has a step that moves the tool: a workingstep or a
/// rapid movement among its executables (control flow counts, for what its
/// branches may hold). An empty workplan, or one of stops and messages only,
/// has none: an empty program, which every target writes as one with nothing
/// to move.
bool hasMachiningSteps(const Module &module);

/// Calls `visit(step, setup)` for every workingstep and rapid movement (the
/// executables that get moves) under the module's workplans, in the order
/// written: into nested workplans, and into the bodies and branches of
/// control flow (then, else, branch, a while's body), each of which is a
/// program of its own. `setup` is the setup in force: the step's own (a
/// feature on another face), else the symbol the nearest enclosing workplan
/// names. A straight program is visited in program order.
void forEachMachiningStep(Module &module, const std::function<void(Node &step, const std::string &setup)> &visit);

/// A workingstep's operation (its child of category operation), or null.
const Node *operationOf(const Node &step);
Node *operationOf(Node &step);

/// The resource of `kind` (tool, setup, workpiece) the project lists under
/// `symbol`, or null.
const Node *findResource(const Module &module, Kind kind, std::string_view symbol);
inline const Node *findTool(const Module &module, std::string_view symbol) {
  return findResource(module, Kind::Tool, symbol);
}

/// The feature node a symbol names (features live under their workpiece), or null.
const Node *findFeature(const Module &module, std::string_view symbol);
/// The workpiece that holds `feature`, or null.
const Node *workpieceOf(const Module &module, const Node &feature);

/// Whether `op` has explicit toolpaths and each that moves at feed gives its
/// own feed (a technology with a positive feed; rapids and dwells need
/// none): then the operation's own feed is used by no move (AP238 files
/// from CAM systems give feeds per toolpath).
bool toolpathsGiveFeeds(const Node &op);

/// Whether an executable's moves are its operation's explicit toolpaths,
/// every one of them required (ISO 14649 `its_priority`): they run as the
/// file writes them: no pass changes their path, and adapt-feed changes a
/// feed only to what the machine reaches on the move (which changes nothing
/// the machine does).
bool runsAsWritten(const Node &executable);

/// Whether `exec` is a turning workingstep (its operation has the Turning
/// trait): its moves are a lathe's, in the ZX plane with feeds per
/// revolution, and the milling passes leave them to the turning ones.
bool isTurningStep(const Node &exec);

/// Whether `exec` is a deposition workingstep (its operation has the
/// Additive trait): its moves lay beads with the energy on and off.
bool isAdditiveStep(const Node &exec);

/// Whether `exec` tilts the tool: its `moves`, or one of its moves, has a
/// tool axis other than +z (a 5-axis step, docs/five-axis.md).
bool tiltsTool(const Node &exec);

/// The `moves` of an executable that a 3-axis milling pass reads: null for
/// a step without moves, for a turning or deposition step, and for a step
/// that tilts the tool (each pass that passes one over says so).
const Node *millingMoves(const Node &exec);

/// What a consumer of milling programs does with the steps of other
/// processes (turning, deposition): refuses them (a reader that writes one
/// program) or passes over them (a pass that works step by step and leaves
/// lathe moves to the turning passes, beads to the deposition ones).
enum class OtherProcesses : uint8_t { Refuse, Skip };

/// Whether a reader of the IR takes deposition steps: their operations and
/// the `state` changes of the head (energy, power, powder, wire), written
/// with the machine's codes; the other process state changes (spindle,
/// constant surface speed) stay beyond it.
enum class Deposition : uint8_t { Refuse, Take };

/// Whether a reader of the IR takes steps that tilt the tool (tiltsTool):
/// refuses them, passes over them whole (a pass that says so, or checks
/// them its own way), or takes their moves.
enum class ToolAxes : uint8_t { Refuse, Skip, Take };

/// Which arcs a reader of the IR takes: in the XY plane only, or in any of
/// the principal planes XY, ZX and YZ (an arc `normal` along x, y or z).
enum class ArcPlanes : uint8_t { XYOnly, Principal };

/// A construct that a consumer of straight 3-axis milling programs does not
/// take yet, and the node that has it.
struct Beyond {
  const Node *node = nullptr;
  std::string what;  ///< "control flow ('if')", "a tool axis per move", ...
};

/// The first construct, in tree order, that the readers of today's 3-axis
/// milling programs (the G-code targets, plan-motion, the cutting passes,
/// verify-toolpaths, the STEP-NC writer) cannot take: control flow, an
/// operation of another process than milling and hole making, a tool axis,
/// an arc out of the XY plane, a feed per revolution, a change of process
/// state, a lathe's X mode. (Dwells and canned cycles they all take.) The IR expresses all of them
/// (docs/ir.md); each reader takes them as it learns to.
/// A consumer that takes arcs in the ZX and YZ planes too (`planes`
/// Principal: it walks moves with ir::walkMoves, which gives them as chords,
/// or writes them itself) is not stopped by them; an arc about any other
/// axis stops every consumer.
/// With `others` Skip, turning and deposition workingsteps are passed over
/// whole; with `toolAxes` Skip, so are steps that tilt the tool, and with
/// Take their tool axes are no bar.
std::optional<Beyond> beyondThreeAxisMilling(const Module &module, ArcPlanes planes = ArcPlanes::XYOnly,
                                             OtherProcesses others = OtherProcesses::Refuse,
                                             Deposition deposition = Deposition::Refuse,
                                             ToolAxes toolAxes = ToolAxes::Refuse);

/// Reports the first construct `consumer` cannot take as an error at its
/// node ("<consumer> cannot take <what> yet") and returns false; true when
/// there is none.
bool requireThreeAxisMilling(const Module &module, std::string_view consumer, DiagnosticEngine &diags,
                             ArcPlanes planes = ArcPlanes::XYOnly, OtherProcesses others = OtherProcesses::Refuse,
                             Deposition deposition = Deposition::Refuse, ToolAxes toolAxes = ToolAxes::Refuse);

} // namespace stepnc::ir
