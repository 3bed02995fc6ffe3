// SINUMERIK 840D / 840D sl main programs (.MPF), written on the ISO emitter
// core: the transfer header and program name, G71 metric blocks, tool calls
// whose length comes from the tool's D offset, I/J (or CR=) arcs and TURN=
// helices, the CYCLE832 path settings, and drilling as modal CYCLE81 / CYCLE83
// / CYCLE84 calls. The facts behind each word come from the manuals in
// docs/backends.md ("Sources"); the choices they leave open, and the forms
// taken where a fact is unverified, are in backends/siemens-840d/README.md. The structure of what is written is
// checked by tests/backends/check-siemens-840d.py.
#include "backends/Backend.h"
#include "backends/common/EmitterBackend.h"
#include "backends/common/Indexing.h"
#include "backends/common/IsoEmitter.h"
#include "backends/common/IsoReader.h"
#include "backends/common/LatheEmitter.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

namespace {

TargetDescriptor siemensDescriptor() {
  TargetDescriptor d;
  d.name = "siemens-840d";
  d.deposition = true;  // the machine's codes
  d.description = "Siemens SINUMERIK 840D / 840D sl";
  d.extension = ".mpf";
  d.arcs = ArcForm::IncrementalCentre;
  d.helix = true;
  d.helixTurns = true;  // TURN=
  d.arcPlanes = true;   // G18 (ZX: I, K), G19 (YZ: J, K)
  // CYCLE81/CYCLE82 (dwell DTB), CYCLE83, CYCLE84. CYCLE83's DTB and DTS
  // are left at 0: where it dwells with them is not among the checked facts.
  d.cycles = {{CycleKind::Drill, {.dwell = true}}, {CycleKind::Peck, {}}, {CycleKind::Tap, {}}};
  d.splines = SplineForm::Interpolating;  // CSPLINE
  d.numbering = Numbering::None;
  d.maxLineLength = 512;  // conservative: the controller's own limit is not in the sources
  d.coordDecimals = 3;
  d.feedDecimals = 1;
  d.speedDecimals = 0;
  d.tolerance = 0.01;
  // 5-axis with the controller's transformation (PROCESSES.md C2): the tip
  // programmed in the workpiece, the rotary axes' positions on each block.
  d.tcpOn = "TRAORI";
  d.tcpOff = "TRAFOOF";
  // 3+2 with CYCLE800 (PROCESSES.md C2): the face's frame as the swivel's
  // plane and rotated zero (README.md, "3+2").
  d.workingPlanes = true;
  d.swivelDataSet = "TC1";
  return d;
}

/// CYCLE800's _MODE for swivelling axis by axis, Z first, then Y, then X:
/// bits 7-6 00 (axis by axis), bits 1-0 the first axis (11 Z), 3-2 the
/// second (10 Y), 5-4 the third (01 X) (README.md, "3+2": unverified).
constexpr int kAxisByAxisZyx = 0b011011;

/// Names longer than this are cut: the older 840D limit (unverified, README).
constexpr size_t kMaxNameLength = 24;

/// CYCLE832's machining type: finishing, the mode that keeps to the tolerance
/// rather than favouring speed (README: why one mode for the whole program).
constexpr int kTolmFinishing = 1;

/// A program name as the control files it: letters, digits and underscores,
/// upper case, starting with two letters.
std::string siemensProgramName(const std::string &from) {
  std::string name;
  for (char c : from) {
    const auto u = static_cast<unsigned char>(c);
    if ((u & 0xc0) == 0x80)
      continue;  // the rest of a UTF-8 character: one '_' for the character
    if (u < 0x80 && std::isalnum(u))
      name += static_cast<char>(std::toupper(u));
    else
      name += '_';
  }
  auto letter = [](char c) { return c >= 'A' && c <= 'Z'; };
  if (name.size() < 2 || !letter(name[0]) || !letter(name[1]))
    name = name.empty() ? "NC" : "NC_" + name;
  if (name.size() > kMaxNameLength)
    name.resize(kMaxNameLength);
  return name;
}

/// Text a comment or a message can carry: printable ASCII only (the program
/// is an ASCII file), no double quote (it would end an MSG string).
std::string printable(const std::string &text, size_t most) {
  std::string out;
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u & 0xc0) == 0x80)
      continue;  // the rest of a UTF-8 character: one '_' for the character
    out += u >= 0x20 && u < 0x7f ? (c == '"' ? '\'' : c) : '_';
  }
  if (out.size() > most)
    out.resize(most);
  return out;
}

/// The longest message text written: the display line is short (its length
/// is not in the sources), and a longer text says no more at the machine.
constexpr size_t kMaxMessage = 120;


/// A cycle call for a hole, or why the cycle would not make the planned moves.
struct CycleCall {
  std::string text;    ///< "CYCLE81(...)"; empty when not possible
  std::string whyNot;  ///< when text is empty
  bool usesFeed = true;  ///< F is the feed in (CYCLE84 feeds by the pitch)
};

/// The cycle for `c` in step `s`, by the documented parameters.
CycleCall cycleCall(const Program &p, const Step &s, const HoleCycle &c, const TargetDescriptor &d) {
  const auto num = [&](double v) { return formatNumber(v, {d.coordDecimals, false, true}); };
  CycleCall call;
  auto no = [&](std::string why) {
    call.whyNot = std::move(why);
    return call;
  };
  // RTP, RFP, SDIS, DP, DPR: the cycle starts at RTP (the security plane),
  // goes at rapid to RFP + SDIS (the plan's R), feeds to DP and leaves back
  // to RTP. SDIS is unsigned: R must be on or above the surface.
  const double sdis = c.retractZ - c.surfaceZ;
  if (sdis < -1e-9)
    return no("its reference plane R (z=" + num(c.retractZ) + ") is below the top of the hole (z=" +
              num(c.surfaceZ) + "), and SDIS is unsigned");
  if (c.initialZ < c.retractZ - 1e-9)
    return no("its security plane is below its reference plane R");
  if (c.depthZ >= c.retractZ)
    return no("its depth is not below its reference plane R");
  const std::string common = num(c.initialZ) + "," + num(c.surfaceZ) + "," + num(std::max(sdis, 0.0)) + "," +
                             num(c.depthZ) + ",";  // DPR empty: the depth is DP
  switch (c.kind) {
  case CycleKind::Drill:
    // CYCLE82 waits DTB seconds at the bottom.
    call.text = c.dwell > 0 ? "CYCLE82(" + common + "," + formatNumber(c.dwell, {3, false, true}) + ")"
                            : "CYCLE81(" + common + ")";
    return call;
  case CycleKind::Peck: {
    if (c.pecks.size() == 1) {
      // One feed down and out at rapid: exactly what CYCLE81 does.
      call.text = "CYCLE81(" + common + ")";
      return call;
    }
    // CYCLE83 with no degression (DAM 0) makes strokes as long as the
    // first, measured from RFP, the last one shorter; VARI 1 leaves each
    // time at rapid to RFP + SDIS. Only a plan that pecks so is written so.
    const double stroke = c.surfaceZ - c.pecks.front();
    if (stroke <= 1e-6)
      return no("its first peck does not go below the top of the hole");
    for (size_t k = 1; k < c.pecks.size(); ++k) {
      const double expected = std::max(c.pecks.front() - stroke * static_cast<double>(k), c.depthZ);
      if (std::abs(expected - c.pecks[k]) > 1e-6)
        return no("its pecks are not equal strokes from the top of the hole, the only pecking CYCLE83 "
                  "makes without degression");
    }
    // FDEP, FDPR (empty), DAM 0, DTB 0, DTS 0, FRF 1, VARI 1.
    call.text = "CYCLE83(" + common + "," + num(c.pecks.front()) + ",,0.,0.,0.,1.,1)";
    return call;
  }
  case CycleKind::Tap: {
    // Rigid tapping: the feed follows from the pitch and the speed, and
    // the spindle reverses at the bottom; out at SST1.
    const ToolCall *tool = s.tool >= 0 ? &p.tools[static_cast<size_t>(s.tool)] : nullptr;
    const std::optional<double> pitch = tool && tool->node ? tool->node->number("thread_pitch") : std::nullopt;
    if (!pitch || *pitch <= 0)
      return no("its tool has no thread_pitch, which CYCLE84 needs");
    if (s.spindle == 0)
      return no("it has no spindle speed");
    const double rpm = std::abs(s.spindle);
    if (std::abs(c.feed - *pitch * rpm) > 0.01 * c.feed)
      return no("its feed " + formatNumber(c.feed, {1, false, false}) + " mm/min is not the thread pitch " +
                num(*pitch) + " mm times the spindle speed " + formatNumber(rpm, {0, false, false}) + " rev/min");
    const double rpmOut = rpm * c.feedOut / c.feed;
    // DTB 0, SDAC: the spindle turns on as before (3 = M3, 4 = M4); MPIT
    // empty; PIT signed, positive for a right-hand thread cut with M3;
    // POSS 0; SST, SST1.
    const bool clockwise = s.spindle < 0;
    const auto rpmText = [&](double v) { return formatNumber(v, {d.speedDecimals, false, false}); };
    call.text = "CYCLE84(" + common + ",0.," + std::string(clockwise ? "3" : "4") + ",," +
                num(clockwise ? *pitch : -*pitch) + ",0.," + rpmText(rpm) + "," + rpmText(rpmOut) + ")";
    call.usesFeed = false;
    return call;
  }
  case CycleKind::Bore:
    return no("boring cycles are not written for this target");
  }
  return no("unknown cycle");
}

class SiemensEmitter final : public IsoEmitter {
public:
  using IsoEmitter::IsoEmitter;

  /// The program, once every tap is known to be a CYCLE84 (all reported
  /// together, before anything is written).
  std::optional<std::string> run(const Program &p) {
    if (!tapsAsCycles(p))
      return std::nullopt;
    return IsoEmitter::run(p);
  }

  static ProgramReading read(const std::string &text, const TargetDescriptor &d) {
    return readSiemens840d(text, d);
  }

  static std::optional<std::string> lathe(const ir::Module &module, const TargetDescriptor &d, const EmitOptions &o,
                                          DiagnosticEngine &diags);

private:
  /// A tap written as moves would feed out without reversing the spindle and
  /// break: every tapping step must be a CYCLE84, else nothing is written.
  bool tapsAsCycles(const Program &p) {
    bool ok = true;
    for (const Step &s : p.steps) {
      if (s.kind != Step::Kind::Moves || !s.taps())
        continue;
      std::string why;
      if (!s.cycle)
        why = "its moves are not one tapping cycle";
      else if (why = whyNotCycle(d_, *s.cycle); why.empty())
        why = cycleCall(p, s, *s.cycle, d_).whyNot;
      if (why.empty())
        continue;
      diags_.error(s.exec->origin.loc, "workingstep " + s.exec->symbol + " (" + s.operationName() +
                                           ") cannot be written as CYCLE84: " + why +
                                           "; as plain moves the spindle would not reverse at the bottom")
          .entity(s.exec->origin.entityId);
      ok = false;
    }
    return ok;
  }

  std::string comment(const std::string &text) const override {
    // Room for a block number and "; " within the line limit.
    const size_t room = d_.maxLineLength > 32 ? d_.maxLineLength - 16 : std::string::npos;
    return "; " + printable(text, room);
  }

  void header(const Program &p) override {
    const std::string name = siemensProgramName(o_.programName);
    out_.raw(word("%_N_", name) + "_MPF");
    out_.raw(";$PATH=/_N_MPF_DIR");
    for (const std::string &line : headerLines(p, o_, d_))
      out_.block(comment(line));
    // Tool-centre paths: radius compensation off.
    out_.block("G90 G94 G71 G17 G40");
    // Continuous path with the contour tolerance, finishing settings.
    out_.block("G642");
    out_.block("CYCLE832(" + formatNumber(tolerance(), {6, false, true}) + "," + std::to_string(kTolmFinishing) +
               ",1)");
  }

  void footer(const Program &) override {
    if (swivelled_) {
      // The swivel deselected, the rotary axes back at 0.
      Index home;
      home.retractZ = *swivelled_;
      home.axes = homeAxes_;
      faceTurn(home, std::nullopt);
    }
    out_.block("M5");
    out_.block("M9");
    out_.block("CYCLE832(0.,0,1)");  // _TOLM 0: the high speed settings off again
    out_.block("M30");
  }

  void toolChange(const ToolCall &t) override {
    // The length is the controller's: offset D1 of the tool, taken on with
    // the tool at M6; there is no G43/H on this controller.
    out_.block(word("T", std::to_string(t.number)) + " D1");
    out_.block("M6");
  }

  /// 3+2 (Step::plane): up to the top of z with every frame suppressed
  /// (G0 SUPA Z..), then CYCLE800 swivels to the face: no retraction of its
  /// own (_FR 0, the tool is up), the swivel data set, a new plane (_ST 0),
  /// axis by axis in the order Z, Y, X (_MODE 27) about the workpiece's
  /// origin (X0 Y0 Z0 at 0) by the angles that turn the coordinates to the
  /// face's frame, the rotated zero X1 Y1 Z1 the face frame's origin in the
  /// turned coordinates, the control's preferred direction minus (_DIR -1).
  /// Back (none): the same retract, the swivel deselected (_TC "0") and
  /// the rotary axes to 0 at rapid (G0 A0. C0.).
  void faceTurn(const Index &index, const std::optional<WorkingPlane> &plane) override {
    out_.block("G0 SUPA " + word("Z", num(index.retractZ)));
    const auto n = [&](double v) { return num(v); };
    if (plane) {
      const std::array<double, 3> a = fixedAxisAngles(plane->turn);  // {about X, about Y, about Z}
      const Vec3 zero = plane->turn.transpose() * plane->origin;    // the origin in the turned coordinates
      out_.block("CYCLE800(0,\"" + d_.swivelDataSet + "\",0," + std::to_string(kAxisByAxisZyx) + ",0.,0.,0.," + n(a[2]) +
                 "," + n(a[1]) + "," + n(a[0]) + "," + n(zero.x()) + "," + n(zero.y()) + "," + n(zero.z()) +
                 ",-1,0.)");
      swivelled_ = index.retractZ;
      homeAxes_.clear();
      for (const auto &[axis, deg] : index.axes)
        homeAxes_.emplace_back(axis, 0.0);
    } else {
      out_.block("CYCLE800(0,\"0\",0," + std::to_string(kAxisByAxisZyx) + ",0.,0.,0.,0.,0.,0.,0.,0.,0.,-1,0.)");
      std::string words = "G0";
      for (const auto &[axis, deg] : index.axes)
        words += " " + axis + num(deg);
      out_.block(words);
      swivelled_.reset();
    }
    // Where the axes are in the new coordinates is not where they were.
    for (const char *w : {"G", "X", "Y", "Z"})
      modal_.forget(w);
  }

  /// A swivel is in force: the top of z the tool goes up to before it is
  /// deselected; the rotary axes to put back at 0.
  std::optional<double> swivelled_;
  std::vector<std::pair<std::string, double>> homeAxes_;

  std::string turnsWord(int64_t turns) const override { return word("TURN=", std::to_string(turns)); }

  std::string radiusWord(double signedRadius) const override { return word("CR=", num(signedRadius)); }

  // G4 F: seconds (G4 S would count spindle revolutions), in a block of its own.
  std::string dwell(double seconds) const override { return "G4 F" + formatNumber(seconds, {3, false, true}); }

  void message(const std::string &text) override { out_.block("MSG(\"" + printable(text, kMaxMessage) + "\")"); }

  /// G54..G57, then the user frames G505..G599 (as many as the machine
  /// data MD28080 sets up).
  std::string workOffsetWord(int n) const override {
    if (n >= 1 && n <= 4)
      return word("G", std::to_string(53 + n));
    if (n >= 5 && n <= 99)
      return word("G", std::to_string(500 + n));
    return "";
  }

  bool cycle(const Step &s, const HoleCycle &c) override {
    const CycleCall call = cycleCall(*program_, s, c, d_);
    if (call.text.empty())
      return false;
    positionFor(s);
    if (call.usesFeed) {
      modal_.forget("F");
      const std::string f = feedWord(c.feed);
      out_.block(f.substr(1));  // " F..": the feed the cycle drills at
    }
    out_.block("MCALL " + call.text);
    // The position block: the modal cycle runs after it, at the hole.
    const std::string g = modal_.change("G", "G0") ? "G0 " : "";
    out_.block(g + word("X", num(c.at.x())) + word(" Y", num(c.at.y())));
    out_.block("MCALL");
    assumeAt(Vec3(c.at.x(), c.at.y(), c.initialZ));
    // Whether a cycle leaves the feed as it found it is the cycle's
    // business (CYCLE83 scales it by FRF): the next feed move writes F again.
    modal_.forget("F");
    return true;
  }
};

/// SINUMERIK 840D lathe programs (docs/turning.md): G18, DIAMON, G96 S
/// LIMS= with G95 feeds per revolution (the words as the 840D manuals give
/// them); arcs by their radius (CR=), which DIAMON leaves as it is.
class SiemensLatheEmitter final : public LatheEmitter {
public:
  using LatheEmitter::LatheEmitter;

private:
  std::string comment(const std::string &text) const override {
    const size_t room = d_.maxLineLength > 32 ? d_.maxLineLength - 16 : std::string::npos;
    return "; " + printable(text, room);
  }
  void opening() override {
    out_.raw(word("%_N_", siemensProgramName(o_.programName)) + "_MPF");
    out_.raw(";$PATH=/_N_MPF_DIR");
  }
  void preamble() override {
    out_.block("G18 G90 G71 DIAMON G40");
    out_.block("G64");
  }
  void postamble() override {
    out_.block("M5");
    out_.block("M9");
    out_.block("M30");
  }
  void toolChange(int number) override {
    out_.block(word("T", std::to_string(number)) + " D1");
    out_.block("M6");
  }
  std::string surfaceSpeed(double metresPerMinute, double maxRpm, bool clockwise) const override {
    return "G96 " + word("S", formatNumber(metresPerMinute, {0, false, false})) + " " +
           word("LIMS=", formatNumber(maxRpm, {0, false, false})) + (clockwise ? " M3" : " M4");
  }
  std::string spindleSpeed(double rpm) const override {
    return "G97 " + word("S", formatNumber(std::abs(rpm), {0, false, false})) + (rpm < 0 ? " M3" : " M4");
  }
  std::string feedMode(bool perRevolution) const override { return perRevolution ? "G95" : "G94"; }
  std::string dwell(double seconds) const override { return "G4 F" + formatNumber(seconds, {3, false, true}); }
  void message(const std::string &text) override { out_.block("MSG(\"" + printable(text, kMaxMessage) + "\")"); }
  std::string arcCentre(const geom::Vec2 &, double radius, bool moreThanHalf) const override {
    return word("CR=", num(moreThanHalf ? -radius : radius));
  }
};

std::optional<std::string> SiemensEmitter::lathe(const ir::Module &module, const TargetDescriptor &d,
                                                 const EmitOptions &o, DiagnosticEngine &diags) {
  return SiemensLatheEmitter(d, o, diags).run(module);
}

} // namespace

std::unique_ptr<Backend> createSiemens840dBackend() {
  return std::make_unique<EmitterBackend<SiemensEmitter>>(siemensDescriptor());
}

} // namespace stepnc::backends
