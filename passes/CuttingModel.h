// The cutting model of a program (cutting/) read from the IR: each tool as a
// cutter and a beam, each workpiece's material, and the in-process stock,
// cut move by move in program order, so that every horizontal milling move
// knows the engagement, chip, forces and torque along it. Shared by
// adapt-feed and compensate-deflection.
//
// Values STEP-NC does not carry come from the cutting data (shipped or a
// user file) or from documented defaults; each one defaulted is listed in
// the tool's `defaulted` so the passes can say so.
#pragma once

#include "cutting/CuttingData.h"
#include "cutting/Deflection.h"
#include "cutting/Mechanics.h"
#include "ir/Node.h"
#include "ir/geom/MoveWalk.h"
#include "runtime/Machine.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace stepnc::passes {

/// Feeds within this ratio are one feed to adapt-feed, and samples whose
/// chips are within it need no sample between them.
inline constexpr double kFeedRatio = 0.92;

struct CutterSetup {
  std::string symbol;
  bool mill = false; ///< a milling cutter (the model applies); drills and the like are only cut into the stock
  cutting::Cutter cutter;
  cutting::ToolBeam beam;
  std::string toolMaterial;
  double maxForce = 0;                ///< N, peak force the tool may take
  std::vector<std::string> defaulted; ///< "overhang 38 mm (flute length + diameter)", ...
};

/// One place along a horizontal milling move, measured on the stock the
/// moves before it left.
struct CutSample {
  double s = 0; ///< mm from the move's start, along its path
  geom::Vec2 at = geom::Vec2::Zero(), dir = geom::Vec2::UnitX();
  double chipFactor = 0; ///< chip thickness = fz x this
  double ae = 0, ap = 0; ///< mm, radial (equivalent) and axial depth
  int side = 0;          ///< +1 material on the left, -1 right, 0 none or both
  double fzForce = 0;    ///< largest fz whose peak force stays within the tool's limit (mm)
  double fzTorque = 0;   ///< largest fz within the spindle's torque and power (mm; inf without a machine)
  double force = 0;      ///< N, peak at the move's feed
  double torque = 0;     ///< N m, mean at the move's feed

  /// Unit normal from the path towards the material on `side`.
  geom::Vec2 intoWall() const { return side * geom::Vec2(-dir.y(), dir.x()); }
};

struct CutMove {
  ir::Move move;
  bool measured = false; ///< a horizontal feed move of a milling cutter
  double fz = 0;         ///< mm per tooth at the move's feed
  std::vector<CutSample> samples;

  /// Where a piece ending before sample j ends, mm along the move: halfway
  /// to the sample before it; the move's end when j is past the last sample.
  double pieceEnd(size_t j) const { return j < samples.size() ? (samples[j - 1].s + samples[j].s) / 2 : move.length(); }
  /// The feed (mm/min) that gives `perTooth` on this move, in whole mm/min
  /// rounded down, at least 1.
  double feedFor(double perTooth) const { return std::max(1.0, std::floor(perTooth * move.feed / fz)); }
};

struct CutStep {
  const ir::Node *executable = nullptr;
  const ir::Node *movesNode = nullptr;
  std::string setup;
  const CutterSetup *tool = nullptr; ///< null when the tool is unknown
  cutting::Cutter cutter;            ///< the tool's, turning the way the step's spindle does
  const cutting::Material *material = nullptr;
  double spindle = 0; ///< rev/min, unsigned
  /// The step's operation, if it has one.
  std::optional<ir::Kind> operation;
  /// Its moves are the file's required toolpaths (ir::runsAsWritten): cut into
  /// the stock, never measured, so the cutting passes leave them as written.
  bool asWritten = false;
  std::vector<CutMove> moves;

  /// The move of `moves` whose node is `node`, searching on from `cursor`
  /// (moves are met in the order of their nodes); null for other children
  /// (a state, a canned cycle, whose moves the cutting passes leave as they
  /// are), which leave the cursor where it was.
  const CutMove *moveOf(const ir::Node &node, size_t &cursor) const {
    for (size_t k = cursor; k < moves.size(); ++k)
      if (moves[k].move.node == &node) {
        cursor = k;
        return &moves[k];
      }
    return nullptr;
  }
};

struct CutOptions {
  const cutting::CuttingData *data = nullptr;
  const runtime::Machine *machine = nullptr; ///< spindle torque and power limits; none when null
};

struct CutAnalysis {
  std::vector<CutStep> steps;
  std::map<std::string, CutterSetup, std::less<>> tools;
  double cell = 0;                ///< mm, the stock's grid
  std::vector<std::string> notes; ///< assumptions about materials and raw pieces
  /// Per setup, the stock the whole program leaves: the finished part.
  std::map<std::string, cutting::HeightMap, std::less<>> finished;
};

/// How far a tool bends away from a wall (mm) at the tip, at mid-height and
/// at the top of the engaged height.
struct WallBend {
  double tip = 0, mid = 0, top = 0;
  double taper() const { return tip - top; }
};

/// The bend of the step's tool cutting the wall of `sample` as a straight
/// wall taken to its equivalent radial depth plus `offset` mm, at feed per
/// tooth fz: the peak push off the wall over a revolution, spread over the
/// engaged height of the stepped cantilever.
WallBend wallBend(const CutStep &step, const CutSample &sample, double offset, double fz);

/// Whether the step finishes walls: a side or bottom-and-side finish (a
/// plane finish finishes a floor; its side engagement leaves no wall).
bool finishesWalls(const CutStep &step);

/// Whether the material a sample's move engages on its side stays in the
/// finished part: a wall of the part, not stock a later move removes (the
/// inner rings of a floor finish).
bool engagesPartWall(const CutAnalysis &analysis, const CutStep &step, const CutSample &sample, double z);

/// The material of the workpiece a setup holds, and how it was chosen.
struct MaterialChoice {
  const cutting::Material *material = nullptr;
  std::string note; ///< "C45E 1.1191 read as steel_1045 (alias C45E)" or why it was defaulted
};

/// The material a workpiece names, matched in `data`; the default material
/// (with a note saying so) when it names none that the data knows.
MaterialChoice chooseMaterial(const ir::Node *workpiece, const cutting::CuttingData &data);

CutterSetup cutterSetup(const ir::Node &tool, const cutting::CuttingData &data);

/// Cuts the whole program into the stock and measures every horizontal
/// milling move. Feeds are read from the moves as they stand.
CutAnalysis analyseCuts(const ir::Module &module, const CutOptions &options);

/// The spindle torque limit (N m) at `rpm` on `machine`: its torque, and its
/// power over the angular speed, whichever is lower.
double spindleTorqueLimit(const runtime::Machine &machine, double rpm);

} // namespace stepnc::passes
