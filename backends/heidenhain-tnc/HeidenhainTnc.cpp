// HEIDENHAIN TNC conversational programs (Klartext, `.h` files): numbered
// blocks from 0 between BEGIN PGM and END PGM, the raw block as BLK FORM,
// `L` lines with signed coordinates, arcs about a modal centre (`CC` then
// `C`, helices as `CP IPA.. IZ..`), drilling as cycle 200 called per hole
// with M99. Klartext is not ISO G-code, so this target has its own emitter
// over the shared program model and word helpers; the facts it relies on,
// and the conservative forms taken where a fact is unverified, are listed
// in backends/heidenhain-tnc/README.md. KlartextReader.cpp reads every
// program back before it is written, as the structural checker
// tests/backends/check-heidenhain-tnc.py does in the tests.
#include "backends/Backend.h"
#include "backends/common/EmitterBackend.h"
#include "backends/common/Indexing.h"
#include "backends/common/IsoEmitter.h"
#include "backends/common/Program.h"
#include "backends/common/Words.h"
#include "backends/heidenhain-tnc/KlartextReader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2 * kPi;
/// Decimals of the incremental polar angle (degrees): 0.0001 deg moves the
/// end of a 100 mm radius by under 0.0002 mm.
constexpr int kAngleDecimals = 4;

TargetDescriptor tncDescriptor() {
  TargetDescriptor d;
  d.name = "heidenhain-tnc";
  d.description = "HEIDENHAIN TNC conversational (Klartext)";
  d.extension = ".h";
  d.arcs = ArcForm::ModalCentre;
  d.helix = true;       // CP with IZ
  d.helixTurns = true;  // CP IPA beyond 360 deg
  // Cycle 200, its Q211 the dwell at the bottom of a hole drilled in one
  // infeed (with infeeds, whether it dwells after each is not among the
  // checked facts).
  d.cycles = {{CycleKind::Drill, {.dwell = true}}, {CycleKind::Peck, {}}};
  d.numbering = Numbering::FromZero;
  // No line limit among the dialect facts; --target-opt max-line-length=N
  // makes the emitter report longer lines.
  d.maxLineLength = 0;
  d.coordDecimals = 3;
  d.feedDecimals = 0;
  d.speedDecimals = 0;
  d.tolerance = 0.01;
  // 5-axis with the control's tool-centre-point control (PROCESSES.md C3):
  // FUNCTION TCPM says in the block each thing the program relies on (the
  // feed along the tip, the rotary words as axis positions, the axes
  // interpolated in proportion), where M128 leaves them to the machine's
  // set-up; README.md, "5-axis".
  d.tcpOn = "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS";
  d.tcpOff = "FUNCTION RESET TCPM";
  // 3+2 with PLANE SPATIAL and a datum shift per face (README.md, "5-axis").
  d.workingPlanes = true;
  return d;
}

bool isAsciiAlnum(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); }

/// The program name as BEGIN PGM and END PGM carry it: letters, digits and
/// underscores (the file name may hold characters the name may not).
std::string sanitizedName(const std::string &wanted) {
  std::string name;
  for (char c : wanted)
    name += isAsciiAlnum(c) ? c : '_';
  return name.empty() ? "PGM" : name;
}

/// Text that stays one comment: printable ASCII only (one `?` for each
/// other character), and no `~`, which at the end of a line would continue
/// the block on the next.
std::string commentText(std::string_view text) {
  std::string t;
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x80) {
      // One mark for a whole UTF-8 sequence: skip its continuation bytes.
      while (i + 1 < text.size() && (static_cast<unsigned char>(text[i + 1]) & 0xC0) == 0x80)
        ++i;
      t += '?';
    } else if (c < 0x20 || c == 0x7F) {
      t += ' ';
    } else {
      t += c == '~' ? '-' : static_cast<char>(c);
    }
  }
  return t;
}

/// `text` without the spaces at its end (a comment may end in one).
std::string trimmed(std::string text) {
  while (!text.empty() && text.back() == ' ')
    text.pop_back();
  return text;
}

class KlartextEmitter {
public:
  KlartextEmitter(const TargetDescriptor &d, const EmitOptions &o, DiagnosticEngine &diags)
      : d_(d), o_(o), diags_(diags), out_(d) {}

  /// Where each step of the program starts in its text (ReadBack.h).
  const StepLines &stepLines() const { return stepLines_; }

  /// The program as the TNC reads it back (KlartextReader.h).
  static ProgramReading read(const std::string &text, const TargetDescriptor &d) { return readKlartext(text, d); }

  std::optional<std::string> run(const Program &p) {
    program_ = &p;
    const std::string name = sanitizedName(o_.programName);
    if (name != o_.programName)
      diags_.warning(SourceLoc{}, "the program name '" + o_.programName + "' is written as '" + name +
                                      "' (letters, digits and underscores): name the file " + name + d_.extension +
                                      ", as the TNC expects the file to carry the program's name");
    out_.block("BEGIN PGM " + name + " MM");
    blankForm(p);
    for (const std::string &line : headerLines(p, o_, d_))
      out_.block(comment(line));
    // Cycle 32 is active from its definition on: one contour tolerance for
    // the whole program, reset at the end.
    out_.block("CYCL DEF 32.0 TOLERANCE");
    out_.block("CYCL DEF 32.1 T" + formatNumber(tolerance(), {6, false, false}));
    for (const Step &s : p.steps) {
      stepLines_.push_back(out_.lines() + 1);
      switch (s.kind) {
      case Step::Kind::Message:
        out_.block(comment("MESSAGE: " + s.label));
        continue;
      case Step::Kind::Stop:
      case Step::Kind::OptionalStop:
        if (s.index)
          tilt(*s.index, s.plane);  // (none: the axes back at 0 for the operator)
        if (s.reclamp) {
          // The spindle and coolant stop before the operator re-clamps,
          // whatever the control does at M0.
          flushM();
          if (spindleRunning_)
            mBlock("M5");
          if (coolantCode_ != "M9")
            mBlock("M9");
        }
        stop(s.kind == Step::Kind::OptionalStop);
        continue;
      case Step::Kind::Moves:
        break;
      }
      step(p, s);
    }
    if (tilted_) {
      // The working plane and the datum shift reset, the rotary axes back at 0.
      Index home;
      home.retractZ = *tilted_;
      tilt(home, std::nullopt);
    }
    flushM();
    if (spindleRunning_)
      mBlock("M5");
    if (coolantCode_ != "M9")
      mBlock("M9");
    out_.block("CYCL DEF 32.0 TOLERANCE");
    out_.block("CYCL DEF 32.1");
    mBlock("M30");
    out_.block("END PGM " + name + " MM");
    for (size_t line : out_.overlong())
      diags_.error(SourceLoc{}, "line " + std::to_string(line) + " of the " + d_.name + " program is longer than " +
                                    std::to_string(d_.maxLineLength) + " characters (--target-opt max-line-length)");
    if (!ok_ || !out_.overlong().empty())
      return std::nullopt;
    return out_.text();
  }

private:
  // --- Words ---------------------------------------------------------------------

  /// Coordinates always carry their sign; no trailing point, as the control
  /// writes its own numbers ("X+10", "Z-2.5").
  std::string num(double v) const { return formatNumber(v, {d_.coordDecimals, true, false}); }
  double rounded(double v) const { return roundTo(v, d_.coordDecimals); }
  double unit() const { return std::pow(10.0, -d_.coordDecimals); }
  double tolerance() const { return o_.tolerance.value_or(d_.tolerance); }
  std::string comment(const std::string &text) const { return trimmed("; " + commentText(text)); }

  /// The feed in mm/min as an unsigned number; a feed that would print as 0
  /// keeps more decimals rather than read as no feed.
  std::string feedNumber(double feed) const {
    std::string f = formatNumber(feed, {d_.feedDecimals, false, false});
    if (f == "0")
      f = formatNumber(feed, {3, false, false});
    return f;
  }

  /// " F.." when the feed changed since the last feed word.
  std::string feedWord(double feed) {
    const std::string f = feedNumber(feed);
    return modal_.change("F", f) ? " F" + f : "";
  }

  /// Axis words for the coordinates that change as printed ("X+10 Z-2");
  /// records where the control then is.
  std::string axes(const Vec3 &to, bool forceXY = false) {
    std::string words;
    static const char *names[3] = {"X", "Y", "Z"};
    for (int k = 0; k < 3; ++k) {
      const std::string v = num(to[k]);
      if (modal_.change(names[k], v) || (forceXY && k < 2)) {
        if (!words.empty())
          words += ' ';
        words += names[k] + v;
      }
      at_[k] = rounded(to[k]);
    }
    return words;
  }

  /// Forgets where the axes are: the next block writes every axis it names.
  void forgetPosition() {
    for (const char *w : {"X", "Y", "Z"})
      modal_.forget(w);
    at_ = {};
  }

  /// BLK FORM from the raw block: MIN point (with the tool axis), then MAX.
  void blankForm(const Program &p) {
    if (!p.blank) {
      out_.block(comment("no block raw piece in the input: no BLK FORM (the control's graphics need one)"));
      return;
    }
    const auto &[lo, hi] = *p.blank;
    for (int k = 0; k < 3; ++k)
      if (!(rounded(lo[k]) < rounded(hi[k]))) {
        out_.block(comment("the raw piece is flat as printed: no BLK FORM"));
        return;
      }
    out_.block("BLK FORM 0.1 Z X" + num(lo.x()) + " Y" + num(lo.y()) + " Z" + num(lo.z()));
    out_.block("BLK FORM 0.2 X" + num(hi.x()) + " Y" + num(hi.y()) + " Z" + num(hi.z()));
  }

  // --- M functions ------------------------------------------------------------------
  // M functions ride on L blocks, one per block (the form every TNC reads).
  // Spindle and coolant starts wait for the next L block; where no motion
  // comes to carry one, a block repeats the current height.

  std::string takeM() {
    if (pendingM_.empty())
      return "";
    const std::string m = " " + pendingM_.front();
    pendingM_.erase(pendingM_.begin());
    return m;
  }

  void mBlock(const std::string &m) {
    if (at_[2]) {
      out_.block("L Z" + num(*at_[2]) + " R0 FMAX " + m);
      modal_.forget("F");  // as after every FMAX block
    } else {
      out_.block("L " + m);  // no height known yet: only before the first motion
    }
  }

  void flushM() {
    while (!pendingM_.empty())
      mBlock(takeM().substr(1));
  }

  void stop(bool optional) {
    flushM();
    mBlock(optional ? "M1" : "M0");
    // M0 (and M1 where it stops) switch the spindle and the coolant off: the
    // next step starts them again.
    spindleRunning_ = false;
    coolantCode_.clear();
  }

  // --- Steps --------------------------------------------------------------------

  void step(const Program &p, const Step &s) {
    out_.block(trimmed("* - " + commentText(s.label)));
    if (s.workOffset > 0) {
      // The setup's datum: a line of the preset table, activated by cycle 247.
      flushM();
      out_.block("CYCL DEF 247 DATUM SETTING ~");
      out_.raw("  Q339=+" + std::to_string(s.workOffset) + " ;DATUM NUMBER");
      forgetPosition();
    }
    if (s.index)
      tilt(*s.index, s.plane);
    if (s.taps()) {
      // Plain moves would feed the tap out with the spindle still turning
      // forward: it would break. Cycle 207 is left out until its facts are
      // checked (README.md).
      diags_.error(s.exec->origin.loc, "workingstep " + s.exec->symbol + " (" + s.operationName() + "): " + d_.name +
                                           " writes no tapping cycle (cycle 207's parameters are not among the "
                                           "checked dialect facts), and as plain moves the tap would be fed out "
                                           "with the spindle still turning forward and break")
          .entity(s.exec->origin.entityId);
      ok_ = false;
      return;
    }
    const bool newTool = s.tool >= 0 && s.tool != tool_;
    if (newTool || (s.spindle != 0 && s.spindle != spindle_)) {
      if (s.tool >= 0)
        toolCall(p.tools[static_cast<size_t>(s.tool)], s);
    } else if (s.spindle != 0 && !spindleRunning_) {
      pendingM_.push_back(s.spindle < 0 ? "M3" : "M4");
      spindleRunning_ = true;
    }
    const std::string coolant = coolantCode(s.coolant);
    if (coolant != coolantCode_) {
      pendingM_.push_back(coolant);
      coolantCode_ = coolant;
    }
    if (s.cycle && whyNotCycle(d_, *s.cycle).empty() && cycle(s, *s.cycle)) {
      flushM();
      return;
    }
    // A step that tilts the tool runs under the control's tool-centre-point
    // control from its first move that gives the rotary axes (the clearance
    // move before is along Z as after any tool call) to its end, where the
    // rotary axes are back at 0 (FiveAxis.h, tcpMoves).
    bool tcp = false;
    for (const Move &m : s.moves) {
      if (s.tilted && !tcp && !m.rotary.empty()) {
        out_.block(d_.tcpOn);
        tcp = true;
      }
      move(m);
    }
    if (tcp)
      out_.block(d_.tcpOff);
    flushM();
  }

  static std::string coolantCode(const std::string &mode) {
    if (mode == "flood" || mode == "through_tool")
      return "M8";
    if (mode == "mist")
      return "M7";
    return "M9";
  }

  /// TOOL CALL with the speed; the spindle starts on the next L block. After
  /// a tool change that is the step's clearance move, up along the tool axis
  /// (the program model puts it there, Move::alongZOnly); a TOOL CALL that
  /// only changes the speed may move the axes as well, so it is followed by
  /// the same move here.
  void toolCall(const ToolCall &t, const Step &s) {
    std::string text = "TOOL CALL " + std::to_string(t.number) + " Z";
    if (s.spindle != 0)
      text += " S" + formatNumber(std::abs(s.spindle), {d_.speedDecimals, false, false});
    out_.block(text);
    tool_ = s.tool;
    spindle_ = s.spindle;
    // The control may move the axes and change the feed in the tool change;
    // a pole set before it is not relied on.
    forgetPosition();
    modal_.forget("F");
    modal_.forget("CC");
    cc_.reset();
    spindleRunning_ = s.spindle != 0;
    if (spindleRunning_)
      pendingM_.push_back(s.spindle < 0 ? "M3" : "M4");
    if (!s.toolChange)
      upAlongZ(clearanceHeight(s));
  }

  /// An FMAX block along Z alone, carrying the next M function.
  void upAlongZ(double z) {
    modal_.forget("Z");
    modal_.change("Z", num(z));
    at_[2] = rounded(z);
    out_.block("L Z" + num(z) + " R0 FMAX" + takeM());
    modal_.forget("F");
  }

  // --- 3+2: the working plane tilted to each face --------------------------------

  /// The turn before a face (`plane`), or back to the untilted plane with
  /// the rotary axes at 0 (none): up along Z to the top of its travel in
  /// machine coordinates (M91), the plane in force reset without moving
  /// (STAY; or with TURN back to 0), the datum shifted to the face's origin
  /// in the untilted coordinates (cycle 7; 0 for none), then PLANE SPATIAL
  /// about it with TURN: the control turns the rotary axes alone, the tool
  /// where it is. The face's moves follow in its frame, starting with Z
  /// alone as after a tool call.
  void tilt(const Index &index, const std::optional<WorkingPlane> &plane) {
    flushM();
    out_.block("L Z" + num(index.retractZ) + " R0 FMAX M91");
    modal_.forget("F");
    // The shift is given in the untilted coordinates: the plane in force
    // is reset first (without moving, when another face follows).
    if (tilted_ || !plane)
      out_.block(plane ? "PLANE RESET STAY" : "PLANE RESET TURN FMAX");
    const Vec3 origin = plane ? plane->origin : Vec3::Zero();
    out_.block("CYCL DEF 7.0 DATUM SHIFT");
    out_.block("CYCL DEF 7.1 X" + num(origin.x()));
    out_.block("CYCL DEF 7.2 Y" + num(origin.y()));
    out_.block("CYCL DEF 7.3 Z" + num(origin.z()));
    if (plane) {
      // SPA SPB SPC: rotations about the fixed X, Y, Z (PROCESSES.md C3).
      const std::array<double, 3> a = fixedAxisAngles(plane->turn);
      const auto angle = [](double v) { return formatNumber(v, {kAngleDecimals, true, false}); };
      out_.block("PLANE SPATIAL SPA" + angle(a[0]) + " SPB" + angle(a[1]) + " SPC" + angle(a[2]) + " TURN FMAX");
      tilted_ = index.retractZ;
    } else {
      tilted_.reset();
    }
    forgetPosition();
    modal_.forget("CC");
    cc_.reset();
  }

  // --- Moves -------------------------------------------------------------------

  void move(const Move &m) {
    if (m.kind == Move::Kind::Arc) {
      arc(m);
      return;
    }
    if (m.kind == Move::Kind::Dwell) {
      // Cycle 9 waits where the tool is, from its definition on.
      out_.block("CYCL DEF 9.0 DWELL TIME");
      out_.block("CYCL DEF 9.1 DWELL " + seconds(m.dwell));
      return;
    }
    if (m.alongZOnly) {
      upAlongZ(m.to.z());
      return;
    }
    line(m.to, m.kind == Move::Kind::Rapid, m.feed, rotaryWords(m));
  }

  /// The rotary axes' words of a move under tool-centre-point control, for
  /// the angles that change as printed, in the order A B C after X Y Z
  /// (" A+20 C+2.479"; a head-head machine's C comes first in its chain).
  std::string rotaryWords(const Move &m) {
    std::vector<std::pair<std::string, std::string>> changed;
    for (size_t k = 0; k < m.rotary.size() && k < program_->rotaryAxes.size(); ++k) {
      const std::string &name = program_->rotaryAxes[k];
      const std::string v = num(m.rotary[k]);
      if (modal_.change(name, v))
        changed.emplace_back(name, v);
    }
    std::sort(changed.begin(), changed.end());
    std::string words;
    for (const auto &[name, v] : changed)
      words += " " + name + v;
    return words;
  }

  static std::string seconds(double s) { return formatNumber(s, {3, false, false}); }

  void line(const Vec3 &to, bool rapid, double feed, const std::string &rotary = "") {
    std::string words = axes(to) + rotary;
    if (!words.empty() && words.front() == ' ')
      words.erase(0, 1);
    if (words.empty())
      return;  // no motion as printed
    std::string text = "L " + words + " R0";
    if (rapid) {
      text += " FMAX";
      // FMAX holds for its block only; the next feed block states its feed
      // again so that no reader has to look back across a rapid.
      modal_.forget("F");
    } else {
      text += feedWord(feed);
    }
    out_.block(text + takeM());
  }

  void arc(const Move &m) {
    flushM();
    const double u = unit();
    const double sweep = m.sweep();
    const double radius = (m.from.head<2>() - m.centre).norm();
    // An arc that keeps within half a unit of its chord is its chord as
    // printed, and one of a radius under three units cannot be placed on
    // the printed grid (as a line it strays less than the contour
    // tolerance): both are written as lines.
    if (m.turns == 0 && (radius < 3 * u || radius * (1 - std::cos(std::min(sweep, kPi) / 2)) <= u / 2)) {
      line(m.to, false, m.feed);
      return;
    }
    // Arcs start on the printed grid: after a CP the control stands where
    // the turned start landed, a little off it, and a whole circle must end
    // exactly where it starts.
    auto offGrid = [&](const std::optional<double> &v) { return v && std::abs(*v - rounded(*v)) > 1e-9; };
    if (offGrid(at_[0]) || offGrid(at_[1])) {
      modal_.forget("X");
      modal_.forget("Y");
      line(m.from, false, m.feed);
    }
    const geom::Vec2 from = at_[0] && at_[1] ? geom::Vec2(*at_[0], *at_[1])
                                             : geom::Vec2(rounded(m.from.x()), rounded(m.from.y()));
    const double fromZ = at_[2] ? *at_[2] : rounded(m.from.z());
    if (num(m.to.z()) != num(fromZ) || m.turns > 0)
      helix(m, from, fromZ);
    else
      flatArc(from, m.from.head<2>(), m.to.head<2>(), m, sweep, 0);
  }

  /// The printed centre for an arc from `from` to `to` (both as the control
  /// has them), near `around`: on the grid of printed numbers within `reach`
  /// units, the nearest point whose start and end radius differ by at most
  /// half a unit of the last decimal (else the point where they differ
  /// least). The pole in force is kept when it does as well and lies within
  /// a unit.
  geom::Vec2 gridCentre(const geom::Vec2 &from, const geom::Vec2 &to, const geom::Vec2 &around, int reach) const {
    const double u = unit();
    const double enough = u / 2 + 1e-12;
    auto mismatch = [&](const geom::Vec2 &c) { return std::abs((from - c).norm() - (to - c).norm()); };
    const geom::Vec2 base(rounded(around.x()), rounded(around.y()));
    geom::Vec2 best = base;
    double bestMismatch = mismatch(base), bestDistance = (base - around).norm();
    for (int i = -reach; i <= reach; ++i)
      for (int j = -reach; j <= reach; ++j) {
        const geom::Vec2 c(rounded(base.x() + i * u), rounded(base.y() + j * u));
        const double e = mismatch(c), dist = (c - around).norm();
        const bool better = bestMismatch > enough
                                ? e < bestMismatch - 1e-12 || (e <= bestMismatch + 1e-12 && dist < bestDistance)
                                : e <= enough && dist < bestDistance - 1e-12;
        if (better) {
          best = c;
          bestMismatch = e;
          bestDistance = dist;
        }
      }
    if (cc_ && (*cc_ - around).norm() <= u && mismatch(*cc_) <= std::max(bestMismatch, enough))
      return *cc_;
    return best;
  }

  void centreBlock(const geom::Vec2 &c) {
    const std::string text = "CC X" + num(c.x()) + " Y" + num(c.y());
    if (modal_.change("CC", text))
      out_.block(text);
    cc_ = c;
  }

  /// The farthest the arc the control makes (from `from` about `c` through
  /// `printedSweep`) strays from the planned one (from `plannedFrom` about
  /// `centre` through `sweep`), at its quarter points.
  static double arcGap(const geom::Vec2 &from, const geom::Vec2 &c, double printedSweep,
                       const geom::Vec2 &plannedFrom, const geom::Vec2 &centre, double sweep, bool ccw) {
    double gap = 0;
    for (int k = 1; k <= 3; ++k) {
      const geom::Vec2 p = arcSplitPoints(from, c, ccw, printedSweep * k / 4, 1).front();
      const geom::Vec2 q = arcSplitPoints(plannedFrom, centre, ccw, sweep * k / 4, 1).front();
      gap = std::max(gap, (p - q).norm());
    }
    return gap;
  }

  /// An arc in the plane: CC (when it changes), then C to the end point,
  /// with the centre balanced for the printed endpoints. Where that would
  /// take the path more than three units of the last decimal off the plan
  /// (a near-whole circle whose endpoints lie too close to fix the centre,
  /// or whose end rounds past its start), the arc is written in halves.
  void flatArc(const geom::Vec2 &from, const geom::Vec2 &plannedFrom, const geom::Vec2 &plannedTo, const Move &m,
               double sweep, int depth) {
    const double u = unit();
    const geom::Vec2 to(rounded(plannedTo.x()), rounded(plannedTo.y()));
    const double fromZ = at_[2] ? *at_[2] : m.to.z();
    const bool whole = (to - from).norm() < u / 2;
    const geom::Vec2 c = gridCentre(from, to, whole ? m.centre : geom::balancedCentre(from, to, m.centre), 2);
    const double printedSweep = whole ? kTwoPi : turnAngle(from - c, to - c, m.ccw);
    if (depth < 4 && arcGap(from, c, printedSweep, plannedFrom, m.centre, sweep, m.ccw) > 3 * u) {
      const geom::Vec2 mid = arcSplitPoints(plannedFrom, m.centre, m.ccw, sweep / 2, 1).front();
      flatArc(from, plannedFrom, mid, m, sweep / 2, depth + 1);
      const geom::Vec2 next = at_[0] && at_[1] ? geom::Vec2(*at_[0], *at_[1]) : mid;
      flatArc(next, mid, plannedTo, m, sweep / 2, depth + 1);
      return;
    }
    centreBlock(c);
    const std::string text = "C " + axes(Vec3(to.x(), to.y(), fromZ), /*forceXY=*/true) + " DR" +
                             (m.ccw ? "+" : "-") + feedWord(m.feed);
    out_.block(text);
  }

  /// A helix (or an arc of more than one turn): CC, then CP with the whole
  /// incremental angle (full turns included) and the incremental height.
  /// The control ends where the start turned by that angle lands, which
  /// the next block's coordinates then take as the position.
  void helix(const Move &m, const geom::Vec2 &from, double fromZ) {
    // The pole within a unit of the planned centre: the radius comes from
    // the start, the next block puts the tool on the planned end, and
    // balancing for endpoints a turn apart could move the pole anywhere.
    const geom::Vec2 to(rounded(m.to.x()), rounded(m.to.y()));
    const geom::Vec2 c = gridCentre(from, to, m.centre, 1);
    centreBlock(c);
    const double sweep = m.sweep();
    // The printed angle, with as many whole turns as brings it nearest the
    // planned sweep.
    double angle = (to - from).norm() < unit() / 2 ? 0.0 : turnAngle(from - c, to - c, m.ccw);
    angle += kTwoPi * std::round((sweep - angle) / kTwoPi);
    const double degrees = roundTo((m.ccw ? 1 : -1) * angle * 180 / kPi, kAngleDecimals);
    const std::string ipa = formatNumber(degrees, {kAngleDecimals, true, false});
    const double toZ = rounded(m.to.z());
    const double dz = rounded(toZ - fromZ);
    std::string text = "CP IPA" + ipa;
    if (dz != 0)
      text += " IZ" + num(dz);
    text += std::string(" DR") + (m.ccw ? "+" : "-") + feedWord(m.feed);
    out_.block(text);
    // Where the control is: the start turned by the printed angle.
    const double a = degrees * kPi / 180;
    const geom::Vec2 r = from - c;
    at_[0] = c.x() + r.x() * std::cos(a) - r.y() * std::sin(a);
    at_[1] = c.y() + r.x() * std::sin(a) + r.y() * std::cos(a);
    at_[2] = toZ;
    modal_.forget("X");
    modal_.forget("Y");
    modal_.forget("Z");
    modal_.change("Z", num(toZ));
  }

  // --- Cycle 200 ------------------------------------------------------------------

  /// Drilling as cycle 200 when it makes the planned moves: down at rapid to
  /// the set-up clearance, in at the feed (one infeed, or equal infeeds from
  /// the surface with rapids out to the set-up clearance and back down to
  /// the set-up clearance above the last depth), out at rapid to the second
  /// set-up clearance, the security plane. False: the moves are written.
  bool cycle(const Step &s, const HoleCycle &c) {
    if (c.kind != CycleKind::Drill && c.kind != CycleKind::Peck)
      return false;
    const double surface = rounded(c.surfaceZ), retract = rounded(c.retractZ), depth = rounded(c.depthZ),
                 initial = rounded(c.initialZ);
    const double clearance = retract - surface, depthQ = depth - surface, second = initial - surface;
    if (clearance < unit() / 2 || depthQ > -unit() / 2 || initial < retract || c.feed <= 0)
      return false;
    double plunging = -depthQ;
    if (c.pecks.size() > 1) {
      // Unverified beyond the sources: infeeds counted from the surface, and
      // the return down to the set-up clearance above the last depth
      // (README.md). Only a plan that does exactly this is written as one.
      const double q = c.surfaceZ - c.pecks.front();
      for (size_t k = 0; k < c.pecks.size(); ++k)
        if (std::abs(std::max(c.surfaceZ - q * static_cast<double>(k + 1), c.depthZ) - c.pecks[k]) > 1e-6)
          return false;
      if (std::abs(c.reapproach - (c.retractZ - c.surfaceZ)) > 1e-6)
        return false;
      plunging = rounded(q);
    }
    // To the hole at the security plane, as planned.
    for (const Move &m : s.moves) {
      if (!m.positions())
        break;
      move(m);
    }
    flushM();
    if (!at_[2] || *at_[2] < initial) {
      // Up along the tool axis first: the call moves in the plane.
      out_.block("L Z" + num(initial) + " R0 FMAX");
      modal_.forget("F");
      modal_.forget("Z");
      modal_.change("Z", num(initial));
      at_[2] = initial;
    }
    out_.block("CYCL DEF 200 DRILLING ~");
    const std::vector<std::pair<std::string, std::string>> q = {
        {"Q200=" + num(clearance), "SET-UP CLEARANCE"},
        {"Q201=" + num(depthQ), "DEPTH"},
        {"Q206=+" + feedNumber(c.feed), "FEED RATE FOR PLNGNG"},
        {"Q202=" + num(plunging), "PLUNGING DEPTH"},
        {"Q210=+0", "DWELL TIME AT TOP"},
        {"Q203=" + num(surface), "SURFACE COORDINATE"},
        {"Q204=" + num(second), "2ND SET-UP CLEARANCE"},
        {"Q211=+" + seconds(c.dwell), "DWELL TIME AT DEPTH"},
    };
    for (size_t i = 0; i < q.size(); ++i)
      out_.raw("  " + q[i].first + " ;" + q[i].second + (i + 1 < q.size() ? " ~" : ""));
    // The call moves in the plane at the security plane, then the cycle runs.
    out_.block("L " + axes(Vec3(c.at.x(), c.at.y(), *at_[2]), /*forceXY=*/true) + " R0 FMAX M99");
    // The cycle ends at the second set-up clearance; the feed it used and
    // the pole are not relied on.
    at_[2] = initial;
    modal_.forget("Z");
    modal_.change("Z", num(initial));
    modal_.forget("F");
    modal_.forget("CC");
    cc_.reset();
    return true;
  }

  const TargetDescriptor &d_;
  const EmitOptions &o_;
  DiagnosticEngine &diags_;
  const Program *program_ = nullptr;
  BlockWriter out_;
  StepLines stepLines_;
  ModalState modal_;
  /// Where the control has the tool, per axis, when known.
  std::array<std::optional<double>, 3> at_;
  std::optional<geom::Vec2> cc_;  ///< the pole in force, as printed
  /// A working plane tilted to a face is in force: the top of z travel the
  /// tool goes up to before the turn back.
  std::optional<double> tilted_;
  std::vector<std::string> pendingM_;
  int tool_ = -1;
  double spindle_ = 0;
  bool spindleRunning_ = false;
  std::string coolantCode_ = "M9";  ///< assumed off at the start
  bool ok_ = true;
};

} // namespace

std::unique_ptr<Backend> createHeidenhainTncBackend() {
  return std::make_unique<EmitterBackend<KlartextEmitter>>(tncDescriptor());
}

} // namespace stepnc::backends
