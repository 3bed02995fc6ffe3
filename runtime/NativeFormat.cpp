// The native motion format (docs/native-format.md): one header, then one line
// per segment holding its geometry, what the planner knew about it and its
// speed profile. Fields come in a fixed order, each after its keyword, so a
// controller can read them by position or by name.
//
// Numbers are written in the shortest fixed-point text that reads back as the
// same double: a file read and written again is the same bytes, and a player
// plays exactly what the planner planned. The reader rebuilds each segment
// with the same constructors the planner used (the blend's arc-length table
// is not in the file) and checks the written values against the rebuilt ones.
#include "runtime/NativeFormat.h"

#include "support/Format.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <charconv>
#include <cmath>
#include <vector>

namespace stepnc::runtime {

namespace {

/// Version 2 is version 1 with dwells (the `dwell` segment and the stop
/// reason `dwell`); version 3 adds the `axes` line (a lathe's coordinates are
/// z x y) and each segment's spindle. A trajectory is written in the lowest
/// version that holds it, so players of an older version go on reading what
/// they can play: a mill's without dwells as version 1, with them as 2, a
/// lathe's as 3, one that tilts the tool (5-axis: each segment's tool axes
/// and the axis that capped it) as 4, one whose tool axis turns on a cubic
/// somewhere (the planner's orientation smoothing: the axis's rates at each
/// segment's ends) as 5.
constexpr int kVersion = 5;
constexpr int kVersionWithAxisRates = 5;
constexpr int kVersionWithToolAxes = 4;
constexpr int kVersionWithSpindle = 3;
constexpr int kVersionWithDwells = 2;
constexpr int kVersionWithoutDwells = 1;
constexpr std::string_view kMagic = "STEPNC-MOTION";

/// The version a trajectory needs.
int versionFor(const Trajectory &t) {
  bool tilted = false;
  for (const Segment &seg : t.segments) {
    if (seg.axisCubic())
      return kVersionWithAxisRates;
    tilted = tilted || seg.tilted();
  }
  if (tilted)
    return kVersionWithToolAxes;
  // Planned on the joints with the tool upright throughout (a
  // parallel-kinematic machine's sliders): the joints need version 4 too.
  if (!t.joints.empty())
    return kVersionWithToolAxes;
  if (t.frame == Frame::Zxy)
    return kVersionWithSpindle;
  for (size_t i = 0; i < t.segments.size(); ++i)
    if (t.segments[i].kind == SegmentKind::Dwell || t.info[i].stop == StopReason::Dwell)
      return kVersionWithDwells;
  return kVersionWithoutDwells;
}

/// Relative agreement asked of written lengths, radii, angles and profile
/// ends with what the reader recomputes: far above rounding (1e-15), far below
/// anything a machine can follow.
constexpr double kRelTolerance = 1e-6;
/// The same in absolute terms for quantities that should be zero (mm, mm/s,
/// mm/s^2), where a relative bound means nothing.
constexpr double kAbsTolerance = 1e-9;


// ---------------------------------------------------------------------------
// Writing

/// Numbers are written exactly: the shortest fixed-point text that reads
/// back as the same double, no exponent, no -0.
std::string number(double v) { return formatExact(v); }

/// A string in double quotes: `\` and `"` escaped with a backslash, control
/// characters as `\xHH`, so the name stays on its line whatever it holds.
std::string quoted(std::string_view s) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += ch;
    }
  }
  return out + '"';
}

void appendNumbers(std::string &out, std::initializer_list<double> values) {
  for (const double v : values) {
    out += ' ';
    out += number(v);
  }
}

void appendPoint(std::string &out, const Vec3 &p) { appendNumbers(out, {p.x(), p.y(), p.z()}); }

} // namespace

std::string writeNative(const Trajectory &trajectory, const std::string &source) {
  const Trajectory &t = trajectory;
  assert(t.profiles.size() == t.segments.size() && t.info.size() == t.segments.size());
  std::string out;
  out.reserve(256 + t.segments.size() * 320);
  out += std::string(kMagic) + ' ' + std::to_string(versionFor(t)) + '\n';
  out += "; planned by stepnc from " + quoted(source) + " for machine " + quoted(t.machine) + '\n';
  out += "; " + std::to_string(t.segments.size()) + (t.segments.size() == 1 ? " segment, " : " segments, ") +
         formatFixed(t.duration(), 3) + " s\n";
  out += "; units: mm, s, mm/s, mm/s^2, mm/s^3; angles in radians\n";
  out += "machine " + quoted(t.machine) + '\n';
  out += "cycle_time " + number(t.cycleTime) + '\n';
  out += "tolerance " + number(t.tolerance) + '\n';
  const bool lathe = t.frame == Frame::Zxy;
  const int version = versionFor(t);
  if (version >= kVersionWithSpindle)
    out += lathe ? "axes z x y\n" : "axes x y z\n";
  out += "start";
  appendPoint(out, t.start);
  out += '\n';
  out += "segments " + std::to_string(t.segments.size()) + '\n';
  for (size_t i = 0; i < t.segments.size(); ++i) {
    const Segment &seg = t.segments[i];
    const SegmentInfo &info = t.info[i];
    const Profile &prof = t.profiles[i];
    switch (seg.kind) {
    case SegmentKind::Line:
      out += "line to";
      appendPoint(out, seg.end);
      break;
    case SegmentKind::Arc:
      out += "arc to";
      appendPoint(out, seg.end);
      out += " center";
      appendNumbers(out, {seg.center.x(), seg.center.y()});
      out += " radius " + number(seg.radius);
      out += " start_angle " + number(seg.startAngle);
      out += " sweep " + number(seg.sweep);
      out += seg.ccw ? " dir ccw" : " dir cw";
      break;
    case SegmentKind::Blend:
      // ctrl[0] is the start and ctrl[5] the end: only the inner four are new.
      out += "blend to";
      appendPoint(out, seg.end);
      out += " ctrl";
      for (int k = 1; k <= 4; ++k)
        appendPoint(out, seg.ctrl[k]);
      break;
    case SegmentKind::Dwell:
      out += "dwell to";  // where it stands: the start
      appendPoint(out, seg.end);
      break;
    }
    out += " length " + number(seg.length);
    out += " programmed_feed " + number(info.feed);
    out += " move " + std::to_string(info.move);
    out += " next " + std::to_string(info.nextMove);
    out += " stop " + std::string(stopReasonName(info.stop));
    out += " limits";
    appendNumbers(out, {info.limits.v, info.limits.a, info.limits.j});
    out += " limited_by " + std::string(speedLimitName(info.limitedBy));
    out += " v0 " + number(prof.v0);
    out += " a0 " + number(prof.a0);
    // All seven phases, empty ones too: the profile reads back slot for slot.
    out += " phases " + std::to_string(prof.phases.size());
    for (const Phase &ph : prof.phases)
      appendNumbers(out, {ph.duration, ph.jerk});
    if (version >= kVersionWithSpindle) {
      out += " spindle";
      appendNumbers(out, {info.spindle0, info.spindle1});
      out += info.sync ? " sync index" : " sync none";
    }
    if (version >= kVersionWithToolAxes) {
      out += " tool";
      appendNumbers(out, {seg.axis0.x(), seg.axis0.y(), seg.axis0.z(), seg.axis1.x(), seg.axis1.y(), seg.axis1.z()});
      if (version >= kVersionWithAxisRates) {
        out += " turn";
        appendNumbers(out, {seg.axisRate0.x(), seg.axisRate0.y(), seg.axisRate0.z(), seg.axisRate1.x(),
                            seg.axisRate1.y(), seg.axisRate1.z()});
      }
      out += " limited_axis ";
      out += info.axis >= 0 && size_t(info.axis) < t.axisNames.size() ? t.axisNames[size_t(info.axis)] : "none";
      // The joints at the segment's end, when planned on them.
      const size_t count = t.segments.empty() ? 0 : t.joints.size() / t.segments.size();
      out += " joints " + std::to_string(count);
      for (size_t k = 0; k < count; ++k)
        appendNumbers(out, {t.joints[i * count + k]});
    }
    out += '\n';
  }
  out += "end\n";
  return out;
}

namespace {

// ---------------------------------------------------------------------------
// Reading

struct Word {
  std::string_view text;
  uint64_t offset = 0;  ///< in the file
};

/// A word as shown in messages: long ones are cut.
std::string shown(std::string_view w) {
  constexpr size_t kMax = 40;
  return w.size() <= kMax ? std::string(w) : std::string(w.substr(0, kMax)) + "...";
}

/// Reads the file one significant line at a time. Within a line, the first
/// problem is reported and the rest of the line is skipped (every accessor
/// returns a default once the line has failed), so one mistake gives one
/// message.
class Reader {
public:
  Reader(const SourceFile &file, DiagnosticEngine &diags) : file_(file), diags_(diags), text_(file.text()) {}

  std::optional<Trajectory> read();

private:
  // Lines.
  bool nextLine(bool skipComments = true);
  void fail(uint64_t offset, const std::string &message) {
    if (ok_)
      diags_.error(SourceLoc{&file_, offset}, message);
    ok_ = false;
    anyError_ = true;
  }
  /// Fails at the last word read.
  void failHere(const std::string &message) { fail(last_, message); }
  void endOfLine(std::string_view after);

  // Words.
  const Word *word(std::string_view expected);
  bool keyword(std::string_view kw);
  double real(std::string_view what);
  double nonNegative(std::string_view what);
  double positive(std::string_view what);
  uint32_t integer(std::string_view what);
  Vec3 point(std::string_view what);
  std::string string(std::string_view what);
  template <class Enum, size_t N>
  Enum choice(const Enum (&values)[N], std::string_view (*name)(Enum), std::string_view what);

  // Parts of the file.
  bool header(Trajectory &t);
  void segment(Trajectory &t, bool first);
  void recoverEnd();
  void checkProfile(const Profile &prof, double length, bool first, uint64_t v0At, uint64_t a0At, uint64_t phasesAt);

  const SourceFile &file_;
  DiagnosticEngine &diags_;
  std::string_view text_;
  uint64_t next_ = 0;     ///< where the next line starts
  uint64_t lineEnd_ = 0;  ///< end of the current line's text
  std::vector<Word> words_;
  size_t pos_ = 0;
  uint64_t last_ = 0;  ///< offset of the last word read
  bool ok_ = true;
  bool anyError_ = false;

  uint32_t version_ = kVersion;  ///< the file's format version
  uint32_t announced_ = 0;  ///< the header's segment count
  Vec3 at_ = Vec3::Zero();  ///< where the next segment starts
  std::vector<double> jointsHere_;  ///< the joints the segment being read gives
  /// The speed and acceleration the previous segment ends with; NaN after a
  /// segment that could not be read (they are not compared).
  double v1_ = 0;
  double a1_ = 0;
  uint64_t lastPhasesAt_ = 0;  ///< the last segment's `phases`, for the end-at-rest check
};

/// Moves to the next line that is not blank (nor a comment, unless asked);
/// false at the end of the file. Words are runs of characters other than
/// space, tab and carriage return; a word that starts with `"` runs to the
/// closing quote, spaces included.
bool Reader::nextLine(bool skipComments) {
  while (next_ < text_.size()) {
    const uint64_t begin = next_;
    uint64_t end = text_.find('\n', begin);
    if (end == std::string_view::npos)
      end = text_.size();
    next_ = end + 1;
    lineEnd_ = end;
    if (lineEnd_ > begin && text_[lineEnd_ - 1] == '\r')
      --lineEnd_;
    words_.clear();
    pos_ = 0;
    ok_ = true;
    last_ = begin;
    auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    for (uint64_t i = begin; i < end;) {
      if (space(text_[i])) {
        ++i;
        continue;
      }
      const uint64_t from = i;
      if (text_[i] == '"') {
        for (++i; i < end && text_[i] != '"'; ++i)
          if (text_[i] == '\\')
            ++i;
        i = std::min(i + 1, end);
      } else {
        while (i < end && !space(text_[i]))
          ++i;
      }
      words_.push_back({text_.substr(from, i - from), from});
    }
    if (words_.empty() || (skipComments && words_[0].text[0] == ';'))
      continue;
    return true;
  }
  lineEnd_ = text_.size();
  last_ = text_.size();
  words_.clear();
  pos_ = 0;
  return false;
}

void Reader::endOfLine(std::string_view after) {
  if (ok_ && pos_ < words_.size())
    fail(words_[pos_].offset, "unexpected '" + shown(words_[pos_].text) + "' after " + std::string(after));
}

/// The next word; `expected` says what should have been there if the line ends.
const Word *Reader::word(std::string_view expected) {
  if (!ok_)
    return nullptr;
  if (pos_ >= words_.size()) {
    fail(lineEnd_, "the line ends where " + std::string(expected) + " should follow");
    return nullptr;
  }
  last_ = words_[pos_].offset;
  return &words_[pos_++];
}

bool Reader::keyword(std::string_view kw) {
  const Word *w = word("'" + std::string(kw) + "'");
  if (w && w->text != kw)
    fail(w->offset, "expected '" + std::string(kw) + "', found '" + shown(w->text) + "'");
  return ok_;
}

/// A number as the writer spells it: an optional minus, digits, and an
/// optional point followed by digits. No exponent, no "inf" or "nan": every
/// number read is finite.
double Reader::real(std::string_view what) {
  const Word *w = word(what);
  if (!w)
    return 0;
  const std::string_view s = w->text;
  size_t i = s.size() > 0 && s[0] == '-' ? 1 : 0;
  const size_t intFrom = i;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9')
    ++i;
  bool good = i > intFrom;
  if (good && i < s.size() && s[i] == '.') {
    const size_t fracFrom = ++i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9')
      ++i;
    good = i > fracFrom;
  }
  good = good && i == s.size();
  double v = 0;
  if (good) {
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::fixed);
    if (r.ec == std::errc::result_out_of_range) {
      fail(w->offset, std::string(what) + " '" + shown(s) + "' is out of the range of numbers");
      return 0;
    }
    good = r.ec == std::errc() && r.ptr == s.data() + s.size();
  }
  if (!good)
    fail(w->offset, "expected " + std::string(what) + " (a decimal number such as -12.5, without exponent), found '" +
                        shown(s) + "'");
  return v;
}

double Reader::nonNegative(std::string_view what) {
  const double v = real(what);
  if (ok_ && v < 0)
    failHere(std::string(what) + " must not be negative (found " + number(v) + ")");
  return v;
}

double Reader::positive(std::string_view what) {
  const double v = real(what);
  if (ok_ && !(v > 0))
    failHere(std::string(what) + " must be positive (found " + number(v) + ")");
  return v;
}

uint32_t Reader::integer(std::string_view what) {
  const Word *w = word(what);
  if (!w)
    return 0;
  uint32_t v = 0;
  const std::string_view s = w->text;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range && s.find_first_not_of("0123456789") == std::string_view::npos)
    fail(w->offset, std::string(what) + " '" + shown(s) + "' is too large (at most 4294967295)");
  else if (r.ec != std::errc() || r.ptr != s.data() + s.size())
    fail(w->offset, "expected " + std::string(what) + " (a whole number), found '" + shown(s) + "'");
  return v;
}

Vec3 Reader::point(std::string_view what) {
  const std::string w(what);
  const double x = real("the x of " + w);
  const double y = real("the y of " + w);
  const double z = real("the z of " + w);
  return Vec3(x, y, z);
}

/// A quoted string with `\\`, `\"` and `\xHH` escapes.
std::string Reader::string(std::string_view what) {
  const Word *w = word(what);
  if (!w)
    return {};
  const std::string_view s = w->text;
  if (s[0] != '"') {
    fail(w->offset, "expected " + std::string(what) + " in double quotes, found '" + shown(s) + "'");
    return {};
  }
  auto hex = [](char c) {
    if (c >= '0' && c <= '9')
      return c - '0';
    if (c >= 'A' && c <= 'F')
      return c - 'A' + 10;
    return c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
  };
  std::string out;
  for (size_t i = 1; i < s.size(); ++i) {
    const char c = s[i];
    const uint64_t at = w->offset + i;
    if (c == '"') {
      if (i + 1 != s.size())
        fail(at + 1, "unexpected text after the closing quote");
      return out;
    }
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      fail(at, "a control character in a string must be written as \\xHH");
      return {};
    }
    if (c != '\\') {
      out += c;
      continue;
    }
    const char e = i + 1 < s.size() ? s[i + 1] : '\0';
    if (e == '\\' || e == '"') {
      out += e;
      ++i;
    } else if (e == 'x' && i + 3 < s.size() && hex(s[i + 2]) >= 0 && hex(s[i + 3]) >= 0) {
      out += static_cast<char>(hex(s[i + 2]) * 16 + hex(s[i + 3]));
      i += 3;
    } else {
      fail(at, "unknown escape in a string (known: \\\\, \\\", \\xHH)");
      return {};
    }
  }
  fail(w->offset, "the string has no closing quote");
  return {};
}

/// One of the words `name` gives for `values`.
template <class Enum, size_t N>
Enum Reader::choice(const Enum (&values)[N], std::string_view (*name)(Enum), std::string_view what) {
  const Word *w = word(what);
  if (!w)
    return values[0];
  std::string known;
  for (const Enum v : values) {
    if (w->text == name(v))
      return v;
    known += (known.empty() ? "" : ", ") + std::string(name(v));
  }
  fail(w->offset, "unknown " + std::string(what) + " '" + shown(w->text) + "' (known: " + known + ")");
  return values[0];
}

/// The header: magic and version, machine, cycle time, tolerance, start and
/// the segment count, in that order. A broken header stops the reading: what
/// follows cannot be trusted.
bool Reader::header(Trajectory &t) {
  // The very first line, before any comment or blank, must name the format.
  if (!nextLine(false) || words_[0].offset != 0 || words_[0].text != kMagic) {
    fail(words_.empty() ? 0 : words_[0].offset,
         "not a stepnc native motion file: the first line must be '" + std::string(kMagic) + " N', N the format "
         "version (" + std::to_string(kVersionWithoutDwells) + " to " + std::to_string(kVersion) + ")");
    return false;
  }
  ++pos_;
  const uint32_t version = integer("the format version");
  if (!ok_)
    return false;
  if (version < kVersionWithoutDwells || version > kVersion) {
    failHere("unsupported native format version " + std::to_string(version) + "; this stepnc reads versions " +
             std::to_string(kVersionWithoutDwells) + " to " + std::to_string(kVersion));
    return false;
  }
  version_ = version;
  endOfLine("the format version");

  auto line = [&](std::string_view kw) {
    if (!ok_)
      return false;
    if (!nextLine()) {
      fail(text_.size(), "the file ends before the '" + std::string(kw) + "' line of the header");
      return false;
    }
    return keyword(kw);
  };
  if (line("machine"))
    t.machine = string("the machine's name");
  endOfLine("the machine's name");
  if (line("cycle_time"))
    t.cycleTime = positive("the cycle time");
  endOfLine("the cycle time");
  if (line("tolerance"))
    t.tolerance = nonNegative("the tolerance");
  endOfLine("the tolerance");
  if (version_ >= kVersionWithSpindle) {
    // Which machine axes the three coordinates are: a mill's x y z, a lathe's z x y.
    if (line("axes")) {
      const Word *a = word("the first axis"), *b = word("the second axis"), *c = word("the third axis");
      if (a && b && c) {
        const std::string axes = std::string(a->text) + " " + std::string(b->text) + " " + std::string(c->text);
        if (axes == "z x y")
          t.frame = Frame::Zxy;
        else if (axes != "x y z")
          fail(a->offset, "the axes are 'x y z' (a mill) or 'z x y' (a lathe), not '" + shown(axes) + "'");
      }
    }
    endOfLine("the axes");
  }
  if (line("start"))
    t.start = point("the start point");
  endOfLine("the start point");
  if (line("segments")) {
    const uint32_t n = integer("the number of segments");
    // Reserve only what a file of this size can hold (a segment line has
    // well over 64 characters), whatever the count says.
    const size_t room = std::min<size_t>(n, text_.size() / 64 + 1);
    t.segments.reserve(room);
    t.profiles.reserve(room);
    t.info.reserve(room);
    announced_ = n;
  }
  endOfLine("the number of segments");
  return ok_;
}

/// One segment line. The segment starts where the previous one ended; it is
/// rebuilt from what the file gives with the constructor the planner used
/// (which also makes a blend's arc-length table), and the written values
/// that follow from the geometry must agree with it: the length, and for arcs
/// the radius, the start angle and the end reached after the sweep. The
/// written values are kept: they are what was planned and what players use.
void Reader::segment(Trajectory &t, bool first) {
  const Word &kindWord = words_[pos_++];
  last_ = kindWord.offset;
  SegmentKind kind = SegmentKind::Line;
  if (kindWord.text == "arc")
    kind = SegmentKind::Arc;
  else if (kindWord.text == "blend")
    kind = SegmentKind::Blend;
  else if (kindWord.text == "dwell")
    kind = SegmentKind::Dwell;
  else if (kindWord.text != "line")
    fail(kindWord.offset, "unknown segment kind '" + shown(kindWord.text) + "' (known: line, arc, blend, dwell)");
  if (kind == SegmentKind::Dwell && version_ < kVersionWithDwells)
    fail(kindWord.offset, "a dwell segment needs format version " + std::to_string(kVersionWithDwells) +
                              "; this file is version " + std::to_string(version_));
  const Vec3 from = at_;
  keyword("to");
  const uint64_t toAt = last_;
  const Vec3 to = point("the end point");
  if (ok_)
    at_ = to;  // the next segment starts here even when this line has a mistake further on

  double cx = 0, cy = 0, radius = 0, startAngle = 0, sweep = 0;
  uint64_t centerAt = 0, radiusAt = 0, angleAt = 0, sweepAt = 0;
  bool ccw = true;
  std::array<Vec3, 6> ctrl{};
  if (kind == SegmentKind::Arc) {
    keyword("center");
    cx = real("the x of the centre");
    centerAt = last_;
    cy = real("the y of the centre");
    keyword("radius");
    radius = positive("the radius");
    radiusAt = last_;
    keyword("start_angle");
    startAngle = real("the start angle");
    angleAt = last_;
    keyword("sweep");
    sweep = positive("the sweep");
    sweepAt = last_;
    keyword("dir");
    if (const Word *w = word("the direction (ccw or cw)"); w && w->text != "ccw" && w->text != "cw")
      fail(w->offset, "unknown direction '" + shown(w->text) + "' (known: ccw, cw)");
    else
      ccw = w && w->text == "ccw";
  } else if (kind == SegmentKind::Blend) {
    keyword("ctrl");
    ctrl[0] = from;
    ctrl[1] = point("the second control point");
    ctrl[2] = point("the third control point");
    ctrl[3] = point("the fourth control point");
    ctrl[4] = point("the fifth control point");
    ctrl[5] = to;
  }
  keyword("length");
  // A dwell waits where the tool is: no length. Every other segment moves.
  const double length = kind == SegmentKind::Dwell ? nonNegative("the length") : positive("the length");
  const uint64_t lengthAt = last_;
  if (ok_ && kind == SegmentKind::Dwell && length != 0)
    failHere("a dwell has no length (the tool waits where it is): length 0, not " + number(length));

  SegmentInfo info;
  keyword("programmed_feed");
  info.feed = nonNegative("the programmed feed");
  keyword("move");
  info.move = integer("the move index");
  keyword("next");
  info.nextMove = integer("the next move index");
  keyword("stop");
  info.stop = choice(kStopReasons, stopReasonName, "stop reason");
  if (ok_ && info.stop == StopReason::Dwell && version_ < kVersionWithDwells)
    failHere("the stop reason 'dwell' needs format version " + std::to_string(kVersionWithDwells) + "; this file is version " +
             std::to_string(version_));
  if (ok_ && kind == SegmentKind::Dwell && info.stop != StopReason::Dwell)
    failHere("a dwell segment stops for its dwell: 'stop dwell', not 'stop " + std::string(stopReasonName(info.stop)) +
             "'");
  keyword("limits");
  info.limits.v = nonNegative("the speed limit");
  info.limits.a = nonNegative("the acceleration limit");
  info.limits.j = nonNegative("the jerk limit");
  keyword("limited_by");
  info.limitedBy = choice(kSpeedLimits, speedLimitName, "speed limit");

  Profile prof;
  keyword("v0");
  prof.v0 = nonNegative("the start speed v0");
  const uint64_t v0At = last_;
  keyword("a0");
  prof.a0 = real("the start acceleration a0");
  const uint64_t a0At = last_;
  keyword("phases");
  const uint64_t phasesAt = last_;
  const uint32_t phases = integer("the number of phases");
  if (ok_ && phases > prof.phases.size())
    failHere("a profile has at most " + std::to_string(prof.phases.size()) + " phases, not " +
             std::to_string(phases));
  // Fewer than seven phases fill the first slots; the rest stay empty
  // (duration 0), which plays the same.
  for (uint32_t k = 0; k < phases && ok_; ++k) {
    prof.phases[k].duration = nonNegative("a phase's duration");
    prof.phases[k].jerk = real("a phase's jerk");
  }
  Vec3 axis0 = Vec3::UnitZ(), axis1 = Vec3::UnitZ(), rate0 = Vec3::Zero(), rate1 = Vec3::Zero();
  if (version_ >= kVersionWithSpindle) {
    // The spindle: its speed at both ends; a thread pass keeps it.
    keyword("spindle");
    info.spindle0 = real("the spindle speed at the start");
    const uint64_t spindleAt = last_;
    info.spindle1 = real("the spindle speed at the end");
    keyword("sync");
    if (const Word *w = word("the synchronisation (index or none)"); w && w->text != "index" && w->text != "none")
      fail(w->offset, "unknown synchronisation '" + shown(w->text) + "' (known: index, none)");
    else
      info.sync = w && w->text == "index";
    if (ok_ && info.sync && (info.spindle0 == 0 || std::abs(info.spindle1 - info.spindle0) >
                                                      kRelTolerance * std::abs(info.spindle0)))
      fail(spindleAt, "a segment synchronised with the spindle (a thread pass) needs it turning at one speed, not " +
                          number(info.spindle0) + " to " + number(info.spindle1) + " rev/min");
    if (version_ >= kVersionWithToolAxes) {
      // The tool axis at the segment's start and end (unit vectors), and
      // the machine axis whose limit capped its speed (none: no axis's).
      keyword("tool");
      const uint64_t toolAt = last_;
      axis0 = point("the tool axis at the start");
      axis1 = point("the tool axis at the end");
      if (ok_ && !(std::abs(axis0.norm() - 1) <= kRelTolerance && std::abs(axis1.norm() - 1) <= kRelTolerance))
        fail(toolAt, "the tool axes are unit vectors, not of lengths " + number(axis0.norm()) + " and " +
                         number(axis1.norm()));
      if (version_ >= kVersionWithAxisRates) {
        // The axis's rates at the ends (per unit of the fraction along the
        // segment), across the axis there: zero for an even turn.
        keyword("turn");
        const uint64_t turnAt = last_;
        rate0 = point("the tool axis's rate at the start");
        rate1 = point("the tool axis's rate at the end");
        const double across = std::max(std::abs(rate0.dot(axis0)), std::abs(rate1.dot(axis1)));
        if (ok_ && !(across <= kRelTolerance * (1 + rate0.norm() + rate1.norm())))
          fail(turnAt, "the tool axis's rates at the ends are across the axis there, not along it by " +
                           number(across));
      }
      keyword("limited_axis");
      if (const Word *w = word("the limiting axis (a name, or none)"); w && w->text != "none") {
        auto it = std::find(t.axisNames.begin(), t.axisNames.end(), std::string(w->text));
        if (it == t.axisNames.end())
          it = t.axisNames.insert(t.axisNames.end(), std::string(w->text));
        info.axis = static_cast<int8_t>(it - t.axisNames.begin());
      }
      keyword("joints");
      const uint32_t count = integer("the number of joints");
      if (ok_ && count > 16)
        failHere("a machine has at most 16 joints here, not " + std::to_string(count));
      for (uint32_t k = 0; k < count && ok_; ++k)
        jointsHere_.push_back(real("a joint's position"));
      endOfLine("the joints");
    } else {
      endOfLine("the synchronisation");
    }
  } else {
    endOfLine("the last phase");
  }

  // The geometry, rebuilt.
  Segment seg;
  const char *what = "line";
  if (ok_ && kind == SegmentKind::Line) {
    seg = Segment::line(from, to);
  } else if (ok_ && kind == SegmentKind::Arc) {
    what = "arc";
    // Checked against the written centre: what a player uses.
    const double rFrom = std::hypot(from.x() - cx, from.y() - cy), rTo = std::hypot(to.x() - cx, to.y() - cy);
    const double endAngle = startAngle + (ccw ? sweep : -sweep);
    const double endOff =
        std::hypot(cx + radius * std::cos(endAngle) - to.x(), cy + radius * std::sin(endAngle) - to.y());
    constexpr double kTurn = 6.283185307179586476925;
    const double fromAngle = std::atan2(from.y() - cy, from.x() - cx);
    const double angleOff = std::abs(std::remainder(startAngle - fromAngle, kTurn));
    if (std::abs(rFrom - rTo) > kRelTolerance * radius)
      fail(centerAt, "the centre " + formatTuple({cx, cy}, 6) + " is not equally far from the arc's start and end (" +
                         formatFixed(rFrom, 9) + " and " + formatFixed(rTo, 9) + " mm)");
    else if (std::abs(rFrom - radius) > kRelTolerance * radius)
      fail(radiusAt, "radius " + number(radius) + " does not match the distance from the centre to the arc's start (" +
                         formatFixed(rFrom, 9) + " mm)");
    else if (angleOff > kRelTolerance)
      fail(angleAt, "start_angle " + number(startAngle) + " does not point at the arc's start (at " +
                        formatFixed(fromAngle, 9) + " rad)");
    else if (endOff > kRelTolerance * radius)
      fail(sweepAt, "turning " + number(sweep) + " rad " + (ccw ? "ccw" : "cw") + " from start_angle ends " +
                        formatFixed(endOff, 9) + " mm from the end point");
    // Rebuilt for its length; the written centre, radius and angle are kept
    // (Segment::arc may move the centre by a rounding's worth).
    seg = Segment::arc(from, to, Vec3(cx, cy, 0), ccw, sweep);
    seg.center = Vec3(cx, cy, 0);
    seg.radius = radius;
    seg.startAngle = startAngle;
  } else if (ok_ && kind == SegmentKind::Blend) {
    what = "blend";
    seg = Segment::blend(ctrl);
  } else if (ok_) {
    what = "dwell";
    const double off = (to - from).norm();
    if (off > kAbsTolerance)
      fail(toAt, "a dwell waits where the tool is: its end point is " + formatFixed(off, 9) +
                     " mm from where the previous segment ends");
    seg = Segment::dwell(from);
  }
  if (ok_ && std::abs(seg.length - length) > kRelTolerance * std::max(seg.length, length))
    fail(lengthAt, "length " + number(length) + " does not match the " + what + "'s geometry (" +
                       formatFixed(seg.length, 9) + " mm)");
  seg.length = length;

  // The profile: continuous speed and acceleration, the whole length; a
  // dwell's at rest throughout, for some time.
  if (ok_)
    checkProfile(prof, length, first, v0At, a0At, phasesAt);
  if (ok_ && kind == SegmentKind::Dwell) {
    for (const Phase &ph : prof.phases)
      if (ph.jerk != 0) {
        fail(phasesAt, "a dwell's phases have jerk 0 (the tool stays at rest), not " + number(ph.jerk));
        break;
      }
    if (ok_ && !(prof.duration() > 0))
      fail(phasesAt, "a dwell waits for the duration of its phases, which must be more than 0 s");
  }
  if (ok_ && info.stop != StopReason::None && prof.v0 > kAbsTolerance)
    fail(v0At, "a segment that stops first (stop " + std::string(stopReasonName(info.stop)) +
                   ") must start at rest, not at v0 " + number(prof.v0));
  if (ok_ && info.stop != StopReason::None && std::abs(prof.a0) > kAbsTolerance)
    fail(a0At, "a segment that stops first (stop " + std::string(stopReasonName(info.stop)) +
                   ") must start at rest, not with acceleration a0 " + number(prof.a0));
  lastPhasesAt_ = phasesAt;
  if (!ok_) {
    recoverEnd();
    v1_ = std::nan("");
    a1_ = std::nan("");
    return;
  }
  v1_ = prof.v1();
  a1_ = prof.a1();
  seg.axis0 = unitAsWritten(axis0);
  seg.axis1 = unitAsWritten(axis1);
  seg.axisRate0 = rate0;
  seg.axisRate1 = rate1;
  t.joints.insert(t.joints.end(), jointsHere_.begin(), jointsHere_.end());
  jointsHere_.clear();
  t.segments.push_back(seg);
  t.profiles.push_back(prof);
  t.info.push_back(info);
}

/// After a mistake on a segment line before its end point: the end point
/// still, if it can be found, so that the next segment starts where it should
/// and one mistake does not bring errors on the lines after it.
void Reader::recoverEnd() {
  for (size_t i = 0; i + 3 < words_.size(); ++i) {
    if (words_[i].text != "to")
      continue;
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      const std::string_view w = words_[i + 1 + k].text;
      const auto r = std::from_chars(w.data(), w.data() + w.size(), p[k], std::chars_format::fixed);
      if (r.ec != std::errc() || r.ptr != w.data() + w.size())
        return;
    }
    at_ = p;
    return;
  }
}

/// The highest |acceleration| a profile reaches (at a phase boundary: it is
/// linear within a phase), the scale of what rounding leaves of a difference
/// in acceleration that should be zero.
double accelScale(const Profile &prof) {
  double a = prof.a0, scale = std::abs(a);
  for (const Phase &ph : prof.phases) {
    a += ph.jerk * ph.duration;
    scale = std::max(scale, std::abs(a));
  }
  return scale;
}

/// A profile must pick up the speed and the acceleration the previous
/// segment ends with (the first starts at rest) and cover the segment's
/// length: a player that trusts it then never jumps in position, speed or
/// acceleration. Only the last must end with zero acceleration (read()): a
/// profile planned over a run of short segments is cut into slices that end
/// where the next one starts.
void Reader::checkProfile(const Profile &prof, double length, bool first, uint64_t v0At, uint64_t a0At,
                          uint64_t phasesAt) {
  const double before = std::isnan(v1_) ? 0 : v1_;
  // What rounding may leave of a difference that should be zero, at this
  // profile's scale of speed and of acceleration.
  const double speedSlack = kRelTolerance * std::max(prof.peak(), before) + kAbsTolerance;
  if (!std::isnan(v1_) && std::abs(prof.v0 - v1_) > speedSlack) {
    fail(v0At, first ? "v0 " + number(prof.v0) + " mm/s: the first segment starts at rest"
                     : "v0 " + number(prof.v0) + " mm/s does not continue the previous segment, which ends at " +
                           formatFixed(v1_, 9) + " mm/s");
    return;
  }
  const double accelBefore = std::isnan(a1_) ? 0 : std::abs(a1_);
  const double accelSlack = kRelTolerance * std::max(accelScale(prof), accelBefore) + kAbsTolerance;
  if (!std::isnan(a1_) && std::abs(prof.a0 - a1_) > accelSlack) {
    fail(a0At, first ? "a0 " + number(prof.a0) + " mm/s^2: the first segment starts at rest, with zero acceleration"
                     : "a0 " + number(prof.a0) +
                           " mm/s^2 does not continue the previous segment, which ends with acceleration " +
                           formatFixed(a1_, 9) + " mm/s^2");
    return;
  }
  const double covered = prof.at(prof.duration()).s;
  if (std::abs(covered - length) > kRelTolerance * length + kAbsTolerance)
    fail(phasesAt, "the profile covers " + formatFixed(covered, 9) + " mm, not the segment's length " +
                       number(length) + " mm");
}

std::optional<Trajectory> Reader::read() {
  Trajectory t;
  if (!header(t))
    return std::nullopt;
  at_ = t.start;
  v1_ = 0;  // the trajectory starts at rest
  a1_ = 0;
  uint32_t seen = 0;
  for (;;) {
    if (diags_.limitReached())
      return std::nullopt;
    if (!nextLine()) {
      fail(text_.size(), seen < announced_ ? "the file ends after " + std::to_string(seen) + " of the " +
                                                 std::to_string(announced_) + " segments announced"
                                           : std::string("the file ends without 'end'"));
      return std::nullopt;
    }
    if (words_[0].text == "end") {
      if (seen < announced_)
        fail(words_[0].offset, "'end' after " + std::to_string(seen) + " of the " + std::to_string(announced_) +
                                   " segments announced");
      ++pos_;
      endOfLine("'end'");
      break;
    }
    if (seen == announced_) {
      fail(words_[0].offset, "expected 'end' after the " + std::to_string(announced_) +
                                 " segments announced, found '" + shown(words_[0].text) + "'");
      return std::nullopt;
    }
    segment(t, seen == 0);
    ++seen;
  }
  if (nextLine())
    fail(words_[0].offset, "unexpected '" + shown(words_[0].text) + "' after 'end'");
  if (!anyError_ && !std::isnan(v1_) && seen > 0) {
    // At rest: zero speed and zero acceleration.
    const Profile &last = t.profiles.back();
    if (std::abs(v1_) > kRelTolerance * last.peak() + kAbsTolerance)
      fail(lastPhasesAt_, "the last segment ends at " + formatFixed(v1_, 9) + " mm/s; a trajectory ends at rest");
    else if (std::abs(a1_) > kRelTolerance * accelScale(last) + kAbsTolerance)
      fail(lastPhasesAt_, "the last segment ends with acceleration " + formatFixed(a1_, 9) +
                              " mm/s^2; a trajectory ends at rest");
  }
  if (anyError_)
    return std::nullopt;
  return t;
}

} // namespace

std::optional<Trajectory> readNative(const SourceFile &file, DiagnosticEngine &diags) {
  return Reader(file, diags).read();
}

} // namespace stepnc::runtime
