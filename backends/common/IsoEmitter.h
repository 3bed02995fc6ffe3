// The emitter core for ISO 6983-style dialects (RS274/LinuxCNC, Siemens
// 840D): G0/G1/G2/G3 with axis words, written only when they change, arcs by
// the descriptor's centre form (split where the form cannot take them whole),
// helices, tool calls, spindle, coolant and canned cycles through hooks that
// each dialect fills in with its own words.
#pragma once

#include "backends/Backend.h"
#include "backends/common/Program.h"
#include "backends/common/ReadBack.h"
#include "backends/common/Words.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

/// The comment lines every program starts with: the source, the target and
/// its options, how tools were numbered, and the tools. No dates.
std::vector<std::string> headerLines(const Program &p, const EmitOptions &o, const TargetDescriptor &d);

class IsoEmitter {
public:
  IsoEmitter(const TargetDescriptor &d, const EmitOptions &o, DiagnosticEngine &diags)
      : d_(d), o_(o), diags_(diags), out_(d) {}
  virtual ~IsoEmitter() = default;

  /// The program text; nullopt after reporting errors.
  std::optional<std::string> run(const Program &p);
  /// Where each step of the program run() wrote starts in its text.
  const StepLines &stepLines() const { return stepLines_; }
  /// The lines (1-based) of the deposition head's codes, in order: the
  /// machine's words, which the dialect's reader does not read.
  const std::vector<size_t> &processLines() const { return processLines_; }

protected:
  // --- The dialect's words -----------------------------------------------------
  virtual void header(const Program &p) = 0;
  virtual void footer(const Program &p) = 0;
  /// A comment block.
  virtual std::string comment(const std::string &text) const = 0;
  virtual void toolChange(const ToolCall &t) = 0;
  /// "S.. M3" for a signed speed (negative: clockwise, M3).
  virtual std::string spindle(double rpm) const;
  /// "M8", "M7", "M9"...
  virtual std::string coolant(const std::string &mode) const;
  /// The word that makes an arc block turn `turns` more full turns (toolpath
  /// IR rule), or "" when the target has none (helixTurns false).
  virtual std::string turnsWord(int64_t turns) const = 0;
  /// The radius word of the radius arc form ("R-12.5", "CR=12.5").
  virtual std::string radiusWord(double signedRadius) const;
  /// The block that makes the tool wait `seconds` where it is ("G4 P0.5").
  virtual std::string dwell(double seconds) const = 0;
  /// Writes `c` as the controller's canned cycle; false when the cycle would
  /// not make exactly the planned moves (the moves are written instead).
  virtual bool cycle(const Step &s, const HoleCycle &c) = 0;
  virtual void message(const std::string &text) = 0;
  virtual void stop(bool optional);
  /// Before a re-clamp stop: the spindle and coolant off.
  virtual void beforeReclamp();
  /// The word that selects work offset `n` (1: the program's first); "" and
  /// an error when the controller has no such offset.
  virtual std::string workOffsetWord(int n) const = 0;
  /// 3+2: the turn before a face (Step::index, with the face's frame in
  /// Step::plane for a target that tilts the working plane; none: the axes
  /// back at 0). The rotary axes' positions, written directly (turn()).
  virtual void faceTurn(const Index &index, const std::optional<WorkingPlane> &plane);

  // --- Shared machinery ------------------------------------------------------------
  void move(const Move &m);
  /// Axis words for the coordinates that changed, e.g. "X10.5 Z-2.", and
  /// always those of the plane `force` when given (an arc's end).
  std::string axes(const Vec3 &to, std::optional<geom::ArcPlane> force = std::nullopt);
  std::string num(double v) const { return formatNumber(v, {d_.coordDecimals, false, true}); }
  std::string feedWord(double feed);
  /// Tells the modal state where the tool is after something it did not see
  /// (a cycle), and that the motion word must be written again.
  void assumeAt(const Vec3 &p);
  double tolerance() const { return o_.tolerance.value_or(d_.tolerance); }
  /// Writes the position moves of a cycle step (up to the clearance height
  /// after a tool change, to the hole at the security plane), before the
  /// cycle block.
  void positionFor(const Step &s);

  const TargetDescriptor &d_;
  const EmitOptions &o_;
  DiagnosticEngine &diags_;
  BlockWriter out_;
  ModalState modal_;
  const Program *program_ = nullptr;

private:
  void arc(const Move &m);
  /// 3+2: the tool up to the top of z in machine coordinates, then the
  /// rotary axes to the face's angles (Step::index).
  void turn(const Index &index);
  /// The rotary words of a move of a step that tilts the tool, those that
  /// change (" A-20. C45."), or "".
  std::string rotaryWords(const Move &m);
  /// Inverse-time feeds (G93) or feeds per minute (G94), written when they
  /// change; the feed is written again after.
  void feedMode(bool inverseTime);
  bool inverseTime_ = false;
  /// The head's state changes of step `s` with the machine's codes
  /// (EmitOptions::deposition); errors when there are none, or a value is
  /// beyond what the head gives.
  void process(const Step &s, const std::vector<ProcessChange> &changes);
  std::vector<size_t> processLines_;
  bool saidNoCodes_ = false;
  /// Where the run of smooth lines starting at `i` ends (one past its last
  /// move): lines marked smooth at one height; `i` when the target writes
  /// no splines or moves[i] is no such line.
  size_t smoothRunEnd(const std::vector<Move> &moves, size_t i) const;
  /// moves[begin, end) as a spline through their end points, in the
  /// descriptor's form.
  void spline(const std::vector<Move> &moves, size_t begin, size_t end);
  StepLines stepLines_;
  int tool_ = -1;
  double spindle_ = 0;
  std::string coolant_ = "off";
  /// The plane G17/G18/G19 selects: XY from the header on; an arc in another
  /// plane selects its own, and the step ends back in XY (cycles drill along z).
  geom::ArcPlane plane_ = geom::ArcPlane::xy();
  /// The word that selects `p` when it is not the plane in force ("G18"), else "".
  std::string selectPlane(geom::ArcPlane p);
};

} // namespace stepnc::backends
