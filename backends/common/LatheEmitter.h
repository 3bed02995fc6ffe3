// The emitter core for lathe programs (docs/turning.md, Programs): turning
// workingsteps' moves in the XZ plane, X written as a diameter or a radius,
// feeds per revolution, constant surface speed with its spindle limit. A
// dialect fills in its words through the hooks; what to do was decided by
// the passes (the moves are the insert's programmed point, nose radius
// compensated: the program stays G40). With nose-compensation=controller a
// finishing step's pass along the surface is written as the surface itself
// under the controller's compensation (G41/G42), the same path for a tool
// whose table radius is the insert's.
#pragma once

#include "backends/Backend.h"
#include "backends/common/Words.h"
#include "ir/Node.h"
#include "ir/geom/MoveWalk.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

/// Whether `module` has a turning workingstep: then a target writes a lathe program.
bool hasTurningSteps(const ir::Module &module);

class LatheEmitter {
public:
  LatheEmitter(const TargetDescriptor &d, const EmitOptions &o, DiagnosticEngine &diags)
      : d_(d), o_(o), diags_(diags), out_(d) {}
  virtual ~LatheEmitter() = default;

  /// The program text; nullopt after reporting errors (a milling step among
  /// the turning ones, a tool the table lacks).
  std::optional<std::string> run(const ir::Module &module);

protected:
  // --- The dialect's words -------------------------------------------------------
  virtual std::string comment(const std::string &text) const = 0;
  /// What comes before the header comments ("%", a program name) and after the end.
  virtual void opening() = 0;
  virtual void closing() {}
  /// The words of an arc's centre: its offset from the start as the
  /// controller reads it (x the radius, z), or its radius and whether it
  /// sweeps more than half a turn (all given).
  virtual std::string arcCentre(const geom::Vec2 &offsetXZ, double radius, bool moreThanHalf) const;
  /// After the header comments: plane, X mode, units, absolute, no compensation.
  virtual void preamble() = 0;
  /// The end: spindle and coolant off, program end.
  virtual void postamble() = 0;
  virtual void toolChange(int number) = 0;
  /// Constant surface speed `metresPerMinute`, the spindle no faster than
  /// `maxRpm`, turning clockwise (M3) or not.
  virtual std::string surfaceSpeed(double metresPerMinute, double maxRpm, bool clockwise) const = 0;
  /// A constant spindle speed (negative: clockwise).
  virtual std::string spindleSpeed(double rpm) const = 0;
  /// The word that makes F a feed per revolution, or per minute.
  virtual std::string feedMode(bool perRevolution) const = 0;
  virtual std::string dwell(double seconds) const = 0;
  virtual std::string coolant(const std::string &mode) const;
  virtual void message(const std::string &text) = 0;
  virtual std::string stop(bool optional) const { return optional ? "M1" : "M0"; }
  /// How the controller's tool table says where a turning or grooving
  /// insert's imaginary tip is ("" when the dialect does not say).
  virtual std::string toolOrientation(bool /*inside*/) const { return ""; }
  /// The words that turn the controller's nose radius compensation on, the
  /// tool left of the path (else right), and off.
  virtual std::string compensation(bool /*left*/) const { return ""; }
  virtual std::string compensationOff() const { return "G40"; }

  /// X as written: the diameter (twice the radius) or the radius.
  virtual bool diameterMode() const { return true; }

  std::string num(double v) const { return formatNumber(v, {d_.coordDecimals, false, true}); }

  const TargetDescriptor &d_;
  const EmitOptions &o_;
  DiagnosticEngine &diags_;
  BlockWriter out_;

private:
  /// `onAxis`: a drill on the spindle axis (ir::drillsOnTurningAxis).
  void step(const ir::Module &module, const ir::Node &ws, const ir::Node &moves, bool onAxis = false);
  void move(const ir::Move &m);
  /// The moves of a finishing step with its pass along the surface written
  /// as the surface under the controller's compensation; false (nothing
  /// written) when the pass is not an offset of a surface by the nose.
  bool compensated(const ir::Node &ws, const ir::Node &moves, const std::vector<ir::Move> &all, const ir::Node &tool);
  /// A coordinate as the controller reads it back (X halved in diameter mode).
  double readX(double radius) const;
  std::string xWord(double radius) const;
  int toolNumber(const ir::Node &tool);
  /// ", " and the tool table's orientation of a turning or grooving insert, or "".
  std::string orientationNote(const ir::Node &tool, bool inside, bool axial) const;

  ModalState modal_;
  std::map<std::string, int> numbers_;
  int nextNumber_ = 1;
  std::string tool_;
  std::string spindleWords_;
  std::string coolant_ = "off";
  std::optional<bool> perRev_;
  double feed_ = -1;
  bool ok_ = true;
  std::string prefix_;  ///< words the next move's block starts with (G41/G42, G40)
};

} // namespace stepnc::backends
