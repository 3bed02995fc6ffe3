// RS274NGC as LinuxCNC's interpreter reads it (LinuxCNC 2.9). The program is
// checked in the test suite by LinuxCNC's own `rs274`: it must run without
// error and make the planned moves (backends/rs274/README.md).
#include "backends/Backend.h"
#include "backends/common/EmitterBackend.h"
#include "backends/common/IsoEmitter.h"
#include "backends/common/IsoReader.h"
#include "backends/common/LatheEmitter.h"

#include <cmath>

namespace stepnc::backends {

namespace {

TargetDescriptor rs274Descriptor() {
  TargetDescriptor d;
  d.name = "rs274";
  d.description = "RS274NGC as LinuxCNC reads it";
  d.extension = ".ngc";
  d.arcs = ArcForm::IncrementalCentre;
  d.helix = true;
  d.helixTurns = true;  // P: number of turns
  d.arcPlanes = true;   // G18 (ZX: I, K), G19 (YZ: J, K)
  // G81/G82 (dwell P), G83, G85/G89 (dwell P), G84 and G74 (left hand).
  d.cycles = {{CycleKind::Drill, {.dwell = true}},
              {CycleKind::Peck, {}},
              {CycleKind::Bore, {.dwell = true}},
              {CycleKind::Tap, {}}};
  d.splines = SplineForm::CubicBezier;  // G5
  d.numbering = Numbering::None;
  d.maxLineLength = 254;  // LinuxCNC rejects lines of 255 characters or more
  d.coordDecimals = 4;
  d.feedDecimals = 1;
  d.speedDecimals = 0;
  d.tolerance = 0.01;
  d.latheCompensation = true;  // G41/G42 with the tool table's radius and orientation
  d.deposition = true;         // the machine's codes (M62-M68 on LinuxCNC)
  d.rotaryIndexing = true;     // G53 G0 Z up, G0 A.. C.. (docs/five-axis.md)
  d.jointMoves = true;         // G93 G1 X.. Y.. Z.. A.. C.. F.. (docs/five-axis.md)
  return d;
}

/// A comment block: parentheses end a comment, so the text keeps to what one may hold.
std::string rs274Comment(const std::string &text) {
  std::string t;
  for (char c : text)
    t += c == '(' || c == ')' ? '_' : c;
  return "(" + t + ")";
}

class Rs274Emitter final : public IsoEmitter {
public:
  using IsoEmitter::IsoEmitter;

  static ProgramReading read(const std::string &text, const TargetDescriptor &d) { return readRs274(text, d); }

  static std::optional<std::string> lathe(const ir::Module &module, const TargetDescriptor &d, const EmitOptions &o,
                                          DiagnosticEngine &diags);

private:
  std::string comment(const std::string &text) const override { return rs274Comment(text); }

  void header(const Program &p) override {
    out_.raw("%");
    for (const std::string &line : headerLines(p, o_, d_))
      out_.block(comment(line));
    out_.block("G17 G21 G90 G94 G40 G49 G80");
    out_.block("G64 P" + num(tolerance()));
  }

  void footer(const Program &) override {
    out_.block("M5 M9");
    out_.block("M2");
    out_.raw("%");
  }

  void toolChange(const ToolCall &t) override {
    out_.block(word("T", std::to_string(t.number)) + " M6");
    out_.block("G43 H" + std::to_string(t.number));
  }

  std::string turnsWord(int64_t turns) const override { return word("P", std::to_string(turns + 1)); }

  std::string seconds(double s) const { return formatNumber(s, {3, false, true}); }

  std::string dwell(double s) const override { return "G4 P" + seconds(s); }

  void message(const std::string &text) override { out_.block(comment("MSG," + text)); }

  /// G54..G59, G59.1..G59.3: the nine coordinate systems of LinuxCNC.
  std::string workOffsetWord(int n) const override {
    static constexpr const char *kOffsets[] = {"G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3"};
    return n >= 1 && n <= 9 ? kOffsets[n - 1] : "";
  }

  bool cycle(const Step &s, const HoleCycle &c) override {
    // G98: back to the height before the cycle, the security plane.
    std::string words;
    const std::string xyzr = word("X", num(c.at.x())) + " Y" + num(c.at.y()) + " Z" + num(c.depthZ) + " R" +
                             num(c.retractZ);
    // G82 and G89 wait P seconds at the bottom.
    const std::string dwellWord = c.dwell > 0 ? " P" + seconds(c.dwell) : "";
    switch (c.kind) {
    case CycleKind::Drill:
      words = (c.dwell > 0 ? "G98 G82 " : "G98 G81 ") + xyzr + dwellWord;
      break;
    case CycleKind::Bore:
      // G85 and G89 feed out at the feed in.
      if (std::abs(c.feedOut - c.feed) > 1e-9)
        return false;
      // LinuxCNC's G89 under G98 feeds out all the way to the first height
      // (G85 only to R): G99 stops it at R, and the plan's rapid up follows.
      words = (c.dwell > 0 ? "G99 G89 " : "G98 G85 ") + xyzr + dwellWord;
      break;
    case CycleKind::Peck: {
      // G83 pecks Q deep from R, each time out to R and back to just above
      // the last depth: only when the plan pecks the same way.
      if (c.pecks.size() < 2)
        return false;
      const double q = c.retractZ - c.pecks.front();
      for (size_t k = 0; k < c.pecks.size(); ++k) {
        const double expected = std::max(c.retractZ - q * static_cast<double>(k + 1), c.depthZ);
        if (std::abs(expected - c.pecks[k]) > 1e-6)
          return false;
      }
      if (std::abs(c.reapproach - kLinuxCncG83Backoff) > 1e-6)
        return false;
      words = "G98 G83 " + xyzr + " Q" + num(q);
      break;
    }
    case CycleKind::Tap:
      // G84 feeds in, reverses the spindle and feeds out at the same feed
      // (which must be the pitch times the speed: the plan's feed is).
      if (std::abs(c.feedOut - c.feed) > 1e-9)
        return false;
      // LinuxCNC's G84 under G98 feeds out all the way to the first height:
      // G99 stops at R, and the plan's rapid up follows the cycle. G84
      // taps a right-hand thread and needs the spindle clockwise (M3); a
      // tap turning counterclockwise (M4) cuts a left-hand thread: G74.
      words = std::string(s.spindle > 0 ? "G99 G74 " : "G99 G84 ") + xyzr;
      // LinuxCNC keeps P from an earlier cycle (G80 does not clear it), and
      // its G84 and G74 dwell P at the bottom: a tap must not wait there.
      if (stickyDwell_)
        words += " P0";
      stickyDwell_ = false;
      break;
    }
    if (c.dwell > 0)
      stickyDwell_ = true;
    positionFor(s);
    modal_.forget("F");
    out_.block(words + feedWord(c.feed));
    out_.block("G80");
    if (words.starts_with("G99")) {
      assumeAt(Vec3(c.at.x(), c.at.y(), c.retractZ));
      move(s.moves.back());
    } else {
      assumeAt(Vec3(c.at.x(), c.at.y(), c.initialZ));
    }
    return true;
  }

  bool stickyDwell_ = false;  ///< an earlier cycle set P, which LinuxCNC keeps
};

/// LinuxCNC lathe programs (docs/turning.md): G18, diameter mode G7,
/// G96 D S with G95 feeds per revolution (LinuxCNC's lathe words, as its
/// g-code reference gives them).
class Rs274LatheEmitter final : public LatheEmitter {
public:
  using LatheEmitter::LatheEmitter;

private:
  std::string comment(const std::string &text) const override { return rs274Comment(text); }
  void opening() override { out_.raw("%"); }
  void closing() override { out_.raw("%"); }
  void preamble() override {
    out_.block("G18 G7 G21 G90 G40 G80");
    out_.block("G64 " + word("P", num(o_.tolerance.value_or(d_.tolerance))));
  }
  void postamble() override {
    out_.block("M5 M9");
    out_.block("M2");
  }
  void toolChange(int number) override {
    out_.block(word("T", std::to_string(number)) + " M6");
    out_.block("G43 H" + std::to_string(number));
  }
  std::string surfaceSpeed(double metresPerMinute, double maxRpm, bool clockwise) const override {
    return "G96 " + word("D", formatNumber(maxRpm, {0, false, false})) + " " +
           word("S", formatNumber(metresPerMinute, {1, false, false})) + (clockwise ? " M3" : " M4");
  }
  std::string spindleSpeed(double rpm) const override {
    return "G97 " + word("S", formatNumber(std::abs(rpm), {0, false, false})) + (rpm < 0 ? " M3" : " M4");
  }
  std::string feedMode(bool perRevolution) const override { return perRevolution ? "G95" : "G94"; }
  std::string dwell(double seconds) const override { return "G4 " + word("P", formatNumber(seconds, {3, false, true})); }
  void message(const std::string &text) override { out_.block(comment("MSG," + text)); }
  // LinuxCNC's tool table orientations (Q): the imaginary tip towards -X
  // and -Z of the nose's centre is 2, towards +X and -Z is 3 (read back
  // from its interpreter with G42 on a shoulder).
  std::string toolOrientation(bool inside) const override {
    return inside ? "tool table orientation Q3" : "tool table orientation Q2";
  }
  std::string compensation(bool left) const override { return left ? "G41" : "G42"; }
};

std::optional<std::string> Rs274Emitter::lathe(const ir::Module &module, const TargetDescriptor &d,
                                               const EmitOptions &o, DiagnosticEngine &diags) {
  return Rs274LatheEmitter(d, o, diags).run(module);
}

} // namespace

std::unique_ptr<Backend> createRs274Backend() {
  return std::make_unique<EmitterBackend<Rs274Emitter>>(rs274Descriptor());
}

} // namespace stepnc::backends
