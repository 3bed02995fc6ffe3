// Reads a Klartext program block by block as the TNC would, for the forms
// the emitter writes: blocks are numbered lines (a CYCL DEF's parameter lines
// continue its block after a line ending in `~`); words are split at single
// spaces; the position is tracked through the printed numbers (after a CP,
// where the control turns the start to), unknown in X and Y after a TOOL
// CALL or a datum setting until a block sets them. Between FUNCTION TCPM and
// FUNCTION RESET TCPM (tool-centre-point control) an L block may also give
// the rotary axes A, B, C after X Y Z: X Y Z stay the tool tip. For 3+2, a
// datum shift (cycle 7) and PLANE SPATIAL put the coordinates in a face's
// frame; the rotary axes turn (TURN) only after the tool went up in
// machine coordinates (L Z.. R0 FMAX M91), which is no move of the
// program's: where the tool is after it is not known. Problems are
// reported with the 1-based line of the block (of the parameter line, for
// cycle 200's).
#include "backends/heidenhain-tnc/KlartextReader.h"

#include "backends/common/Words.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <vector>

namespace stepnc::backends {

namespace {

constexpr double kPi = std::numbers::pi;
/// The most infeeds a cycle call is expanded into.
constexpr double kMaxInfeeds = 10000;

const double kNaN = std::nan("");

bool known(double v) { return std::isfinite(v); }

/// The M functions the emitter writes.
const std::set<int> kAllowedM = {0, 1, 2, 3, 4, 5, 7, 8, 9, 30, 91, 99};

/// Cycle 200's parameters, in the order the emitter (and the TNC) writes them.
constexpr std::array<int, 8> kCycle200Q = {200, 201, 206, 202, 210, 203, 204, 211};

/// A line of the text and its 1-based number.
struct Line {
  size_t number = 0;
  std::string text;
};

/// A numbered block: its number, the text after it, and the continuation
/// lines (leading spaces taken off).
struct Block {
  long number = 0;
  std::string body;
  std::vector<Line> continuation;
  size_t line = 0;
};

/// Cycle 200 as defined: its Q parameters, and whether they make a cycle
/// that drills (only then is a call expanded).
struct Cycle200 {
  std::map<int, double> q;
  bool drills = true;
};

std::vector<std::string> splitWords(const std::string &body) {
  std::vector<std::string> words;
  size_t start = 0;
  while (true) {
    const size_t space = body.find(' ', start);
    words.push_back(body.substr(start, space - start));
    if (space == std::string::npos)
      return words;
    start = space + 1;
  }
}

bool isDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool startsWith(const std::string &text, std::string_view prefix) { return text.rfind(prefix, 0) == 0; }

/// The words of an arc block after its keyword (C, CP), read in the order
/// the block writes them: each optional word taken when it comes next.
class ArcWords {
public:
  explicit ArcWords(const std::vector<std::string> &words) : w_(words) {}
  /// The value of the next word when it starts with `address` (taken).
  std::optional<std::string> take(std::string_view address) {
    if (k_ < w_.size() && startsWith(w_[k_], address))
      return w_[k_++].substr(address.size());
    return std::nullopt;
  }
  /// DR+ (true, counterclockwise) or DR- (false) when it comes next (taken).
  std::optional<bool> direction() {
    if (k_ < w_.size() && (w_[k_] == "DR+" || w_[k_] == "DR-"))
      return w_[k_++] == "DR+";
    return std::nullopt;
  }
  /// Every word was taken.
  bool done() const { return k_ == w_.size(); }

private:
  const std::vector<std::string> &w_;
  size_t k_ = 1;  // after the keyword
};

std::string withoutTrailingSpaces(std::string text) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r'))
    text.pop_back();
  return text;
}

class KlartextReader {
public:
  KlartextReader(const std::string &text, const TargetDescriptor &d) : text_(text), d_(d) {}

  ProgramReading run() {
    const std::vector<Block> blocks = readBlocks();
    if (blocks.empty()) {
      r_.problem(1, "no blocks: the program is empty");
      return std::move(r_);
    }
    const bool begun = frameLine(blocks.front(), "BEGIN");
    const bool ends = frameLine(blocks.back(), "END");
    if (begun && ends)
      frame(blocks.front(), blocks.back());
    const size_t last = blocks.size() - 1;
    for (size_t i = 0; i < blocks.size(); ++i) {
      if ((i == 0 && begun) || (i == last && ends))
        continue;
      block(blocks, i, i + 1 == last);
    }
    if (tcp_)
      r_.problem(blocks.back().line, "the program ends with FUNCTION TCPM on (FUNCTION RESET TCPM missing)");
    if (tilted_)
      r_.problem(blocks.back().line, "the program ends with the working plane tilted (PLANE RESET missing)");
    if (blocks.size() >= 2 && ends) {
      const std::vector<std::string> before = splitWords(blocks[last - 1].body);
      const bool programEnd =
          before.front() == "L" && std::any_of(before.begin(), before.end(),
                                               [](const std::string &w) { return w == "M30" || w == "M2"; });
      if (!programEnd)
        r_.problem(blocks[last - 1].line, "the block before END PGM is not the program end (M30 or M2)");
    }
    return std::move(r_);
  }

private:
  // --- Lines, blocks, frame ----------------------------------------------------------

  /// The blocks of the text, reporting lines that are not printable ASCII,
  /// end in spaces or carry no block number, and numbers out of sequence.
  std::vector<Block> readBlocks() {
    std::vector<Block> blocks;
    long due = 0;
    bool continuing = false;
    size_t n = 0;
    size_t start = 0;
    while (start < text_.size()) {
      size_t end = text_.find('\n', start);
      if (end == std::string::npos) {
        end = text_.size();
        r_.problem(n + 1, "the last line has no line end");
      }
      std::string line = text_.substr(start, end - start);
      start = end + 1;
      ++n;
      if (std::any_of(line.begin(), line.end(), [](char c) { return c < 32 || c > 126; }))
        r_.problem(n, "characters other than printable ASCII");
      if (withoutTrailingSpaces(line) != line) {
        r_.problem(n, "trailing spaces");
        line = withoutTrailingSpaces(line);  // reported: the words are read without them
      }
      if (continuing) {
        if (!blocks.empty())
          blocks.back().continuation.push_back({n, line.substr(std::min(line.find_first_not_of(' '), line.size()))});
        continuing = line.ends_with("~");
        continue;
      }
      const size_t space = line.find(' ');
      const std::string number = line.substr(0, space);
      if (space == std::string::npos || !isDigits(number) || number.size() > 9 || space + 1 == line.size() ||
          line[space + 1] == ' ') {
        r_.problem(n, "no block number: '" + line + "'");
        continue;
      }
      Block b;
      b.number = std::stol(number);
      b.body = line.substr(space + 1);
      b.line = n;
      if (b.number != due)
        r_.problem(n, "block number " + number + " where " + std::to_string(due) + " was due");
      due = b.number + 1;
      continuing = b.body.ends_with("~");
      blocks.push_back(std::move(b));
    }
    if (continuing)
      r_.problem(n, "the last block ends in '~' (continued) but nothing follows");
    return blocks;
  }

  /// `BEGIN PGM NAME MM` (or END): reported when the block is not one.
  bool frameLine(const Block &b, const std::string &keyword) {
    const std::vector<std::string> w = splitWords(b.body);
    if (w.size() == 4 && w[0] == keyword && w[1] == "PGM" && !w[2].empty() && !w[3].empty())
      return true;
    r_.problem(b.line, keyword == "BEGIN" ? "the program does not start with BEGIN PGM NAME MM"
                                          : "the program does not end with END PGM NAME MM");
    return false;
  }

  /// The program's name and units, the same at both ends.
  void frame(const Block &begin, const Block &end) {
    const std::vector<std::string> b = splitWords(begin.body), e = splitWords(end.body);
    if (b[2] != e[2])
      r_.problem(end.line, "END PGM " + e[2] + " does not match BEGIN PGM " + b[2]);
    const bool plain = std::all_of(b[2].begin(), b[2].end(), [](char c) {
      return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    });
    if (!plain)
      r_.problem(begin.line, "program name '" + b[2] + "' has characters other than letters, digits and _");
    if (b[3] != "MM")
      r_.problem(begin.line, "units '" + b[3] + "' where MM was expected");
    if (e[3] != "MM")
      r_.problem(end.line, "units '" + e[3] + "' where MM was expected");
  }

  // --- Numbers -----------------------------------------------------------------------

  /// The value of a number as Klartext writes it: digits with an optional
  /// point and decimals after it, the sign required on coordinates
  /// (`withSign`) and absent elsewhere; nullopt (reported) otherwise.
  std::optional<double> number(size_t line, const std::string &text, bool withSign, const std::string &what) {
    const bool sign = !text.empty() && (text[0] == '+' || text[0] == '-');
    const std::string_view digits = std::string_view(text).substr(sign ? 1 : 0);
    const size_t point = digits.find('.');
    const bool form = isDigits(digits.substr(0, point)) && (point == std::string_view::npos ||
                                                            isDigits(digits.substr(point + 1)));
    if (!form || sign != withSign) {
      // The shared check names the common faults (an exponent, not a number).
      std::string why;
      if (wellFormedNumber(text, false, why))
        why = "'" + text + "' is not " + (withSign ? "a signed decimal number (sign, digits, '.' decimals)"
                                                   : "an unsigned decimal number (digits, '.' decimals)");
      r_.problem(line, what + " " + why);
      return std::nullopt;
    }
    double value = 0;
    std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (text[0] == '-' && value == 0)
      r_.problem(line, what + " '" + text + "' is a negative zero");
    return text[0] == '-' ? -value : value;
  }

  std::optional<double> signedNumber(size_t line, const std::string &text, const std::string &what) {
    return number(line, text, true, what);
  }
  std::optional<double> unsignedNumber(size_t line, const std::string &text, const std::string &what) {
    return number(line, text, false, what);
  }

  // --- Blocks ------------------------------------------------------------------------

  void block(const std::vector<Block> &blocks, size_t i, bool lastBeforeEnd) {
    const Block &b = blocks[i];
    const std::string &body = b.body;
    if (startsWith(body, "BEGIN PGM") || startsWith(body, "END PGM")) {
      r_.problem(b.line, "BEGIN PGM / END PGM inside the program");
      return;
    }
    if (startsWith(body, ";") || startsWith(body, "* - ") || body == "* -") {
      if (body.ends_with("~"))
        r_.problem(b.line, "a comment ending in '~' continues the block");
      return;
    }
    if (!b.continuation.empty() && !startsWith(body, "CYCL DEF 200 ") && !startsWith(body, "CYCL DEF 247 "))
      r_.problem(b.line, "continuation lines after a block that is not a cycle definition");
    if (ended_)
      r_.problem(b.line, "block after the program end (M30/M2)");
    const std::vector<std::string> words = splitWords(body);
    if (words[0] == "BLK") {
      blankForm(b, words, i);
      return;
    }
    if (blk01_)
      r_.problem(b.line, "BLK FORM 0.1 without its BLK FORM 0.2 after it");
    blk01_.reset();
    if (startsWith(body, "TOOL CALL")) {
      if (tcp_)
        r_.problem(b.line, "TOOL CALL with FUNCTION TCPM on");
      toolCall(b, words);
      return;
    }
    if (startsWith(body, "FUNCTION ")) {
      tcpBlock(b);
      return;
    }
    if (startsWith(body, "PLANE ")) {
      planeBlock(b, words);
      return;
    }
    if (startsWith(body, "CYCL DEF 7.")) {
      datumShift(blocks, i);
      return;
    }
    if (twoBlockCycle(blocks, i, words))
      return;
    if (startsWith(body, "CYCL DEF 200")) {
      defineCycle200(b);
      return;
    }
    if (startsWith(body, "CYCL DEF 247")) {
      datumSetting(b);
      return;
    }
    if (words[0] == "L") {
      straightBlock(b, words, lastBeforeEnd);
      return;
    }
    if (words[0] == "CC") {
      poleBlock(b, words);
      return;
    }
    if (words[0] == "C") {
      arcBlock(b, words);
      return;
    }
    if (words[0] == "CP") {
      polarArcBlock(b, words);
      return;
    }
    r_.problem(b.line, "unknown block '" + body + "'");
  }

  /// BLK FORM 0.1 Z with the MIN point, then BLK FORM 0.2 with the MAX point
  /// in the next block.
  void blankForm(const Block &b, const std::vector<std::string> &w, size_t i) {
    auto corner = [&](size_t first) {
      std::array<std::optional<double>, 3> v;
      for (int k = 0; k < 3; ++k)
        v[k] = signedNumber(b.line, w[first + k].substr(1), "BLK FORM coordinate");
      return v;
    };
    auto axesAt = [&](size_t first) {
      return w.size() == first + 3 && startsWith(w[first], "X") && startsWith(w[first + 1], "Y") &&
             startsWith(w[first + 2], "Z");
    };
    if (w.size() > 3 && w[1] == "FORM" && w[2] == "0.1" && w[3] == "Z" && axesAt(4)) {
      blk01_ = {corner(4), i};
      return;
    }
    if (w.size() >= 3 && w[1] == "FORM" && w[2] == "0.2" && axesAt(3)) {
      if (!blk01_ || blk01_->second + 1 != i) {
        r_.problem(b.line, "BLK FORM 0.2 not right after a BLK FORM 0.1");
      } else {
        const std::array<std::optional<double>, 3> hi = corner(3);
        for (int k = 0; k < 3; ++k) {
          const std::optional<double> &lo = blk01_->first[k];
          if (lo && hi[k] && !(*lo < *hi[k]))
            r_.problem(b.line, std::string("BLK FORM MIN ") + "XYZ"[k] + formatTrimmed(*lo, 6) + " is not below MAX " +
                                   "XYZ"[k] + formatTrimmed(*hi[k], 6));
        }
      }
      blk01_.reset();
      return;
    }
    r_.problem(b.line, "BLK FORM block not of the form 'BLK FORM 0.1 Z X.. Y.. Z..' / 'BLK FORM 0.2 X.. Y.. Z..'");
    blk01_.reset();
  }

  /// TOOL CALL n Z S..: the spindle stops, the feed is forgotten, and where
  /// the tool change leaves the tool is the machine's business.
  void toolCall(const Block &b, const std::vector<std::string> &w) {
    const bool form = (w.size() == 4 || (w.size() == 5 && startsWith(w[4], "S") && w[4].size() > 1)) &&
                      w[1] == "CALL" && isDigits(w[2]) && w[2].size() <= 9 && w[3] == "Z";
    if (!form) {
      r_.problem(b.line, "TOOL CALL not of the form 'TOOL CALL n Z S..'");
      return;
    }
    const long tool = std::stol(w[2]);
    if (tool <= 0)
      r_.problem(b.line, "TOOL CALL " + w[2] + ": tool 0 empties the spindle");
    if (w.size() == 5)
      unsignedNumber(b.line, w[4].substr(1), "spindle speed");
    tool_ = tool;
    upFirst_ = "the TOOL CALL on line " + std::to_string(b.line);
    spindle_ = false;
    feed_.reset();
    pos_ = Vec3(kNaN, kNaN, kNaN);
  }

  /// Cycles defined in two blocks: 32 (the contour tolerance) and 9 (a
  /// dwell, effective from its definition on). True when block i is either
  /// block of one, each checked to stand by the other.
  bool twoBlockCycle(const std::vector<Block> &blocks, size_t i, const std::vector<std::string> &w) {
    const Block &b = blocks[i];
    struct Form {
      int number;
      const char *first;       ///< the first block
      const char *second;      ///< the second block's number word ("32.1")
      const char *secondName;  ///< the second block as problems name it
    };
    static const Form forms[] = {{32, "CYCL DEF 32.0 TOLERANCE", "32.1", "CYCL DEF 32.1"},
                                 {9, "CYCL DEF 9.0 DWELL TIME", "9.1", "CYCL DEF 9.1 DWELL"}};
    for (const Form &f : forms) {
      if (b.body == f.first) {
        std::string argument;
        if (i + 1 >= blocks.size() || !secondBlock(f.number, splitWords(blocks[i + 1].body), argument))
          r_.problem(b.line, "CYCL DEF " + std::to_string(f.number) + ".0 not followed by " + f.secondName);
        return true;
      }
      std::string argument;
      if (!secondBlock(f.number, w, argument))
        continue;
      if (i == 0 || blocks[i - 1].body != f.first)
        r_.problem(b.line, std::string("CYCL DEF ") + f.second + " not right after " + f.first);
      if (f.number == 32 && !argument.empty()) {
        const std::optional<double> t = unsignedNumber(b.line, argument, "tolerance");
        if (t && *t <= 0)
          r_.problem(b.line, "tolerance T" + argument + " is not positive");
      } else if (f.number == 9) {
        const std::optional<double> t = unsignedNumber(b.line, argument, "dwell time");
        if (t && *t <= 0) {
          r_.problem(b.line, "dwell time " + argument + " is not positive");
        } else if (t) {
          ReadMove m;
          m.kind = Move::Kind::Dwell;
          m.dwell = *t;
          add(m, b.line, pos_);
        }
      }
      return true;
    }
    return false;
  }

  /// Whether `w` is the second block of cycle `number`: `CYCL DEF 32.1
  /// [T..]` or `CYCL DEF 9.1 DWELL t`; `argument` the tolerance or time.
  static bool secondBlock(int number, const std::vector<std::string> &w, std::string &argument) {
    if (w.size() < 3 || w[0] != "CYCL" || w[1] != "DEF")
      return false;
    if (number == 32 && w[2] == "32.1") {
      if (w.size() == 3)
        return true;
      if (w.size() == 4 && w[3].size() > 1 && w[3][0] == 'T') {
        argument = w[3].substr(1);
        return true;
      }
      return false;
    }
    if (number == 9 && w[2] == "9.1" && w.size() == 5 && w[3] == "DWELL" && !w[4].empty()) {
      argument = w[4];
      return true;
    }
    return false;
  }

  /// One `Qnnn=value ;TEXT ~` line of a cycle definition: false when it
  /// is not of that form.
  static bool parameterLine(const std::string &line, int &q, std::string &value, bool &continued) {
    if (line.size() < 2 || line[0] != 'Q')
      return false;
    const size_t equals = line.find('=');
    if (equals == std::string::npos || !isDigits(std::string_view(line).substr(1, equals - 1)) || equals > 5)
      return false;
    q = std::stoi(line.substr(1, equals - 1));
    const size_t comment = line.find(" ;", equals);
    if (comment == std::string::npos)
      return false;
    value = line.substr(equals + 1, comment - equals - 1);
    std::string text = line.substr(comment + 2);
    continued = text.ends_with(" ~");
    if (continued)
      text.resize(text.size() - 2);
    return !value.empty() && value.find(' ') == std::string::npos && text.find_first_of("~;") == std::string::npos;
  }

  /// CYCL DEF 200 DRILLING with its eight parameters, in order, each line
  /// but the last continued with `~`.
  void defineCycle200(const Block &b) {
    if (b.body != "CYCL DEF 200 DRILLING ~")
      r_.problem(b.line, "cycle 200 not written as 'CYCL DEF 200 DRILLING ~'");
    Cycle200 c;
    std::vector<int> order;
    for (size_t k = 0; k < b.continuation.size(); ++k) {
      const Line &l = b.continuation[k];
      int q = 0;
      std::string value;
      bool continued = false;
      if (!parameterLine(l.text, q, value, continued)) {
        r_.problem(l.number, "cycle parameter line '" + l.text + "' not of the form 'Qnnn=value ;TEXT ~'");
        continue;
      }
      if (continued == (k + 1 == b.continuation.size()))
        r_.problem(l.number, "cycle parameter Q" + std::to_string(q) + ": '~' must end every line but the last");
      if (const std::optional<double> v = signedNumber(l.number, value, word("Q", std::to_string(q))))
        c.q[q] = *v;
      order.push_back(q);
    }
    if (!std::equal(order.begin(), order.end(), kCycle200Q.begin(), kCycle200Q.end())) {
      std::string found, wanted;
      for (int q : order)
        found += (found.empty() ? "Q" : " Q") + std::to_string(q);
      for (int q : kCycle200Q)
        wanted += (wanted.empty() ? "Q" : " Q") + std::to_string(q);
      r_.problem(b.line, "cycle 200 parameters " + (found.empty() ? "none" : found) + " where " + wanted +
                             " were expected");
      return;
    }
    if (c.q.size() != kCycle200Q.size())
      return;
    auto require = [&](bool ok, const std::string &why) {
      if (!ok) {
        r_.problem(b.line, why);
        c.drills = false;
      }
    };
    require(c.q[200] > 0, "Q200 (set-up clearance) is not positive");
    require(c.q[201] < 0, "Q201 (depth) is not negative: the cycle would not drill");
    require(c.q[202] > 0, "Q202 (plunging depth) is not positive");
    require(c.q[206] > 0, "Q206 (feed) is not positive");
    require(c.q[204] >= c.q[200], "Q204 (2nd set-up clearance) is below Q200: the cycle ends at Q200 instead");
    require(c.q[210] >= 0 && c.q[211] >= 0, "Q210 or Q211 (dwell time) is negative");
    if (c.drills && -c.q[201] / c.q[202] > kMaxInfeeds)
      require(false, "cycle 200 plunges in more than " + formatTrimmed(kMaxInfeeds, 0) + " infeeds");
    cycle_ = c;
  }

  /// CYCL DEF 247 DATUM SETTING: a clamping's datum from the preset table.
  /// Where the axes are after it is not where they were, and the first
  /// motion is Z alone, as after a TOOL CALL.
  void datumSetting(const Block &b) {
    bool form = b.body == "CYCL DEF 247 DATUM SETTING ~" && b.continuation.size() == 1;
    if (form) {
      const std::string &l = b.continuation.front().text;
      const std::string prefix = "Q339=+", suffix = " ;DATUM NUMBER";
      form = startsWith(l, prefix) && l.ends_with(suffix) && l.size() > prefix.size() + suffix.size();
      if (form) {
        const std::string n = l.substr(prefix.size(), l.size() - prefix.size() - suffix.size());
        form = isDigits(n) && n[0] != '0';
      }
    }
    if (!form)
      r_.problem(b.line, "cycle 247 not written as 'CYCL DEF 247 DATUM SETTING ~' and "
                         "'Q339=+n ;DATUM NUMBER' (n >= 1)");
    pos_ = Vec3(kNaN, kNaN, kNaN);
    upFirst_ = "the datum setting (cycle 247) on line " + std::to_string(b.line);
  }

  /// CYCL DEF 7.0 DATUM SHIFT, then 7.1 X.., 7.2 Y.., 7.3 Z.. in the next
  /// three blocks: the datum moved (in the untilted coordinates); where the
  /// tool is in the new coordinates is not known.
  void datumShift(const std::vector<Block> &blocks, size_t i) {
    static const char *kParts[] = {"CYCL DEF 7.1 X", "CYCL DEF 7.2 Y", "CYCL DEF 7.3 Z"};
    const Block &b = blocks[i];
    if (b.body == "CYCL DEF 7.0 DATUM SHIFT") {
      for (size_t k = 0; k < 3; ++k)
        if (i + 1 + k >= blocks.size() || !startsWith(blocks[i + 1 + k].body, kParts[k])) {
          r_.problem(b.line, "CYCL DEF 7.0 DATUM SHIFT not followed by CYCL DEF 7.1 X.., 7.2 Y.. and 7.3 Z..");
          break;
        }
      pos_ = Vec3(kNaN, kNaN, kNaN);
      return;
    }
    for (size_t k = 0; k < 3; ++k)
      if (startsWith(b.body, kParts[k])) {
        if (i < k + 1 || blocks[i - k - 1].body != "CYCL DEF 7.0 DATUM SHIFT")
          r_.problem(b.line, std::string(kParts[k]).substr(0, 12) + " not in its place after CYCL DEF 7.0 DATUM SHIFT");
        signedNumber(b.line, b.body.substr(std::string(kParts[k]).size()), "datum shift");
        return;
      }
    r_.problem(b.line, "unknown block '" + b.body + "'");
  }

  /// PLANE SPATIAL SPA.. SPB.. SPC.. TURN FMAX, PLANE RESET STAY, PLANE
  /// RESET TURN FMAX. TURN turns the rotary axes: the tool must have gone up
  /// out of the way (M91) with nothing moved since; the first motion after
  /// is Z alone, as after a TOOL CALL.
  void planeBlock(const Block &b, const std::vector<std::string> &w) {
    const bool spatial = w.size() == 7 && w[1] == "SPATIAL" && startsWith(w[2], "SPA") && startsWith(w[3], "SPB") &&
                         startsWith(w[4], "SPC") && w[5] == "TURN" && w[6] == "FMAX";
    const bool resetTurn = b.body == "PLANE RESET TURN FMAX", resetStay = b.body == "PLANE RESET STAY";
    if (!spatial && !resetTurn && !resetStay) {
      r_.problem(b.line, "PLANE not of the form 'PLANE SPATIAL SPA.. SPB.. SPC.. TURN FMAX', 'PLANE RESET STAY' or "
                         "'PLANE RESET TURN FMAX'");
      return;
    }
    if (spatial)
      for (size_t k = 2; k <= 4; ++k)
        signedNumber(b.line, w[k].substr(3), "spatial angle " + w[k].substr(0, 3));
    if (tcp_)
      r_.problem(b.line, "PLANE with FUNCTION TCPM on");
    if (resetStay) {
      if (!tilted_)
        r_.problem(b.line, "PLANE RESET STAY with no working plane tilted");
      tilted_ = false;
      return;
    }
    if (!retracted_)
      r_.problem(b.line, "the rotary axes turn (TURN) without the tool first up in machine coordinates "
                         "(L Z.. R0 FMAX M91) and nothing moved since");
    tilted_ = spatial;
    pos_ = Vec3(kNaN, kNaN, kNaN);
    upFirst_ = "the PLANE on line " + std::to_string(b.line);
  }

  /// FUNCTION TCPM in the one form the emitter writes (the descriptor's: the
  /// feed along the tip, the rotary words as axis positions, the axes
  /// interpolated in proportion), and FUNCTION RESET TCPM with the rotary
  /// axes back at 0.
  void tcpBlock(const Block &b) {
    if (!d_.tcpOn.empty() && b.body == d_.tcpOn) {
      if (tcp_)
        r_.problem(b.line, "FUNCTION TCPM while it is on");
      tcp_ = true;
      return;
    }
    if (!d_.tcpOff.empty() && b.body == d_.tcpOff) {
      if (!tcp_)
        r_.problem(b.line, "FUNCTION RESET TCPM while FUNCTION TCPM is off");
      for (int k = 0; k < 3; ++k)
        if (known(abc_[k]) && abc_[k] != 0)
          r_.problem(b.line, std::string("FUNCTION RESET TCPM with the rotary axis ") + "ABC"[k] +
                                 formatTrimmed(abc_[k], 4) + " turned (the steps after run with it at 0)");
      tcp_ = false;
      return;
    }
    r_.problem(b.line, "FUNCTION block not of the form '" + d_.tcpOn + "' or '" + d_.tcpOff + "'");
  }

  /// An L block: X Y Z (signed, in that order), under FUNCTION TCPM also A B
  /// C, R0, F<n> or FMAX, one M function. M3/M4 act before the motion, the
  /// stops after it, M99 calls cycle 200 where the block ends.
  void straightBlock(const Block &b, const std::vector<std::string> &words, bool lastBeforeEnd) {
    std::array<std::optional<double>, 3> axes;
    std::array<std::optional<double>, 3> rotary;
    int lastAxis = -1;
    int state = 0;  // 0 axes, 1 after R, 2 after F or FMAX, 3 after M
    bool rapid = false;
    std::optional<double> feed;
    std::vector<int> ms;
    for (size_t k = 1; k < words.size(); ++k) {
      const std::string &w = words[k];
      if (state == 0 && !w.empty() && (w[0] == 'X' || w[0] == 'Y' || w[0] == 'Z')) {
        const int axis = w[0] - 'X';
        if (axis <= lastAxis)
          r_.problem(b.line, std::string("axis ") + w[0] + " repeated or out of X Y Z order");
        lastAxis = std::max(lastAxis, axis);
        if (const std::optional<double> v = signedNumber(b.line, w.substr(1), std::string("coordinate ") + w[0]))
          axes[axis] = v;
        continue;
      }
      if (state == 0 && !w.empty() && (w[0] == 'A' || w[0] == 'B' || w[0] == 'C')) {
        const int axis = 3 + (w[0] - 'A');
        if (axis <= lastAxis)
          r_.problem(b.line, std::string("axis ") + w[0] + " repeated or out of X Y Z A B C order");
        lastAxis = std::max(lastAxis, axis);
        if (!tcp_)
          r_.problem(b.line, std::string("rotary axis ") + w[0] + " with FUNCTION TCPM off");
        if (const std::optional<double> v = signedNumber(b.line, w.substr(1), std::string("rotary axis ") + w[0]))
          rotary[axis - 3] = v;
        continue;
      }
      if ((w == "R0" || w == "RL" || w == "RR") && state < 1) {
        state = 1;
        if (w != "R0")
          r_.problem(b.line, "radius compensation " + w + ": stepnc writes tool-centre paths (R0)");
        continue;
      }
      if (w == "FMAX" && state < 2) {
        rapid = true;
        state = 2;
        continue;
      }
      if (!w.empty() && w[0] == 'F' && state < 2) {
        feed = unsignedNumber(b.line, w.substr(1), "feed");
        if (feed && *feed <= 0) {
          r_.problem(b.line, "feed " + w + " is not positive");
          feed.reset();
        }
        state = 2;
        continue;
      }
      if (w.size() > 1 && w[0] == 'M' && isDigits(std::string_view(w).substr(1)) && w.size() <= 4) {
        state = 3;
        const int m = std::stoi(w.substr(1));
        if (!kAllowedM.contains(m))
          r_.problem(b.line, "M" + std::to_string(m) + " is not among the M functions stepnc writes");
        ms.push_back(m);
        continue;
      }
      r_.problem(b.line, "word '" + w + "' is not valid here in an L block");
    }
    if (ms.size() > 1)
      r_.problem(b.line, std::to_string(ms.size()) + " M functions in one block (stepnc writes one)");
    if (std::find(ms.begin(), ms.end(), 91) != ms.end()) {
      // Up along Z in machine coordinates: the only M91 move stepnc writes.
      if (!rapid || axes[0] || axes[1] || !axes[2] || rotary[0] || rotary[1] || rotary[2])
        r_.problem(b.line, "M91 on a block other than 'L Z.. R0 FMAX M91'");
      pos_ = Vec3(kNaN, kNaN, kNaN);
      retracted_ = true;
      return;
    }
    for (int m : ms)
      mFunction(b.line, m, /*beforeMotion=*/true);
    straight(b.line, axes, rotary, rapid, feed);
    for (int m : ms) {
      mFunction(b.line, m, /*beforeMotion=*/false);
      if (m == 99)
        callCycle(b.line);
      if (m == 2 || m == 30) {
        if (!lastBeforeEnd)
          r_.problem(b.line, "program end M" + std::to_string(m) + " before the block before END PGM");
        ended_ = true;
      }
    }
  }

  /// CC X.. Y..: the pole of the arcs that follow.
  void poleBlock(const Block &b, const std::vector<std::string> &w) {
    if (w.size() != 3 || !startsWith(w[1], "X") || !startsWith(w[2], "Y")) {
      r_.problem(b.line, "CC not of the form 'CC X.. Y..'");
      return;
    }
    const std::optional<double> x = signedNumber(b.line, w[1].substr(1), "pole coordinate");
    const std::optional<double> y = signedNumber(b.line, w[2].substr(1), "pole coordinate");
    if (x && y)
      cc_ = geom::Vec2(*x, *y);
  }

  /// C [X..] [Y..] DR+/- [F..]: an arc about the pole to the end point.
  void arcBlock(const Block &b, const std::vector<std::string> &w) {
    ArcWords a(w);
    const std::optional<std::string> x = a.take("X"), y = a.take("Y");
    const std::optional<bool> ccw = a.direction();
    const std::optional<std::string> f = a.take("F");
    if (!ccw || !a.done() || (!x && !y) || (x && x->empty()) || (y && y->empty()) || (f && f->empty())) {
      r_.problem(b.line, "C not of the form 'C X.. Y.. DR+/- [F..]'");
      return;
    }
    std::optional<double> endX, endY, feed;
    if (x)
      endX = signedNumber(b.line, *x, "coordinate X");
    if (y)
      endY = signedNumber(b.line, *y, "coordinate Y");
    if (f)
      feed = positiveFeed(b.line, *f);
    arc(b.line, endX, endY, *ccw, feed);
  }

  /// CP IPA.. [IZ..] DR+/- [F..]: the start turned about the pole by the
  /// incremental angle (full turns included), rising by IZ.
  void polarArcBlock(const Block &b, const std::vector<std::string> &w) {
    ArcWords a(w);
    const std::optional<std::string> ipa = a.take("IPA"), iz = a.take("IZ");
    const std::optional<bool> direction = a.direction();
    const std::optional<std::string> f = a.take("F");
    if (!ipa || !direction || !a.done() || ipa->empty() || (iz && iz->empty()) || (f && f->empty())) {
      r_.problem(b.line, "CP not of the form 'CP IPA.. [IZ..] DR+/- [F..]' (IPA and DR are needed)");
      return;
    }
    const bool ccw = *direction;
    const std::optional<double> angle = signedNumber(b.line, *ipa, "IPA");
    const std::optional<double> rise = iz ? signedNumber(b.line, *iz, "IZ") : std::optional<double>(0.0);
    std::optional<double> feed;
    if (f)
      feed = positiveFeed(b.line, *f);
    if (!angle || !rise)
      return;
    if (*angle == 0 || (*angle > 0) != ccw)
      r_.problem(b.line, "IPA" + *ipa + " and DR" + (ccw ? "+" : "-") + " do not turn the same way");
    polarArc(b.line, *angle, *rise, ccw, feed);
  }

  std::optional<double> positiveFeed(size_t line, const std::string &text) {
    std::optional<double> feed = unsignedNumber(line, text, "feed");
    if (feed && *feed <= 0) {
      r_.problem(line, "feed F" + text + " is not positive");
      feed.reset();
    }
    return feed;
  }

  // --- The control's state, and the motions -------------------------------------------

  /// A motion needs a tool, and the first after a TOOL CALL (or a datum
  /// setting) is Z alone, up to the clearance height before X and Y move.
  void needTool(size_t line, bool zAlone) {
    if (!tool_)
      r_.problem(line, "motion before any TOOL CALL");
    if (upFirst_ && !zAlone)
      r_.problem(line, "the first motion after " + *upFirst_ +
                           " is not Z alone (up to the clearance height before X and Y move)");
    upFirst_.reset();
  }

  /// A feed move needs a feed and the spindle turning.
  void feedMove(size_t line, const std::optional<double> &feed) {
    if (feed)
      feed_ = feed;
    if (!feed_)
      r_.problem(line, "feed move without a feed programmed since the TOOL CALL (or the last cycle call)");
    if (!spindle_)
      r_.problem(line, "feed move with the spindle stopped (no M3/M4 since the TOOL CALL or a stop)");
  }

  /// M functions effective at the start of the block (spindle on) or at its
  /// end (stops, the program end, spindle off).
  void mFunction(size_t line, int m, bool beforeMotion) {
    if (beforeMotion && (m == 3 || m == 4)) {
      if (!tool_)
        r_.problem(line, "M" + std::to_string(m) + " before any TOOL CALL");
      spindle_ = true;
    }
    if (!beforeMotion && (m == 0 || m == 1 || m == 2 || m == 5 || m == 30))
      spindle_ = false;
  }

  /// Records `m`, a move from where the tool is to `to` (a dwell stays), on
  /// the block at `line`.
  void add(ReadMove m, size_t line, const Vec3 &to) {
    m.from = pos_;
    m.to = to;
    m.line = line;
    r_.moves.push_back(m);
    retracted_ = false;
    if (m.kind != Move::Kind::Dwell)
      pos_ = to;
  }

  /// Whether a move to `to` prints as no motion: an L block repeating the
  /// height to carry an M function, or one that puts the tool back on the
  /// printed grid after a CP (as expectedMoves leaves such moves out).
  bool printsAsNoMotion(const Vec3 &to) const {
    for (int k = 0; k < 3; ++k)
      if (known(to[k]) && (!known(pos_[k]) || roundTo(to[k], d_.coordDecimals) != roundTo(pos_[k], d_.coordDecimals)))
        return false;
    return true;
  }

  void straight(size_t line, const std::array<std::optional<double>, 3> &axes,
                const std::array<std::optional<double>, 3> &rotary, bool rapid, const std::optional<double> &feed) {
    // An L block without coordinates ("L M30" in a program with no motion)
    // moves nothing: it needs no tool.
    const bool turns = rotary[0] || rotary[1] || rotary[2];
    if (!axes[0] && !axes[1] && !axes[2] && !turns)
      return;
    needTool(line, rapid && !axes[0] && !axes[1] && !turns);
    if (!rapid)
      feedMove(line, feed);
    Vec3 to = pos_;
    for (int k = 0; k < 3; ++k)
      if (axes[k])
        to[k] = *axes[k];
    bool rotates = false;
    for (int k = 0; k < 3; ++k)
      if (rotary[k]) {
        rotates = rotates || !(abc_[k] == *rotary[k]);
        abc_[k] = *rotary[k];
      }
    if (printsAsNoMotion(to) && !rotates) {
      pos_ = to;
      return;
    }
    ReadMove m;
    m.kind = rapid ? Move::Kind::Rapid : Move::Kind::Linear;
    m.feed = rapid ? 0 : feed_.value_or(0);
    m.abc = abc_;
    add(m, line, to);
  }

  void arc(size_t line, const std::optional<double> &x, const std::optional<double> &y, bool ccw,
           const std::optional<double> &feed) {
    needTool(line, false);
    feedMove(line, feed);
    if (!cc_) {
      r_.problem(line, "C without a CC before it");
      return;
    }
    if (!known(pos_.x()) || !known(pos_.y())) {
      r_.problem(line, "C from an unknown position");
      return;
    }
    const geom::Vec2 from = pos_.head<2>();
    const geom::Vec2 to(x.value_or(from.x()), y.value_or(from.y()));
    const double r1 = (from - *cc_).norm(), r2 = (to - *cc_).norm();
    // How much farther from the pole a C may end than it starts.
    if (std::abs(r1 - r2) > arcRadiusTolerance(d_))
      r_.problem(line, "arc radius from the start " + formatFixed(r1, 4) + " and to the end " + formatFixed(r2, 4) +
                           " differ by " + formatFixed(std::abs(r1 - r2), 4) + " mm (more than " +
                           formatTrimmed(arcRadiusTolerance(d_), 4) + ")");
    if (r1 < 1e-9)
      r_.problem(line, "arc of zero radius");
    ReadMove m;
    m.kind = Move::Kind::Arc;
    m.centre = *cc_;
    m.ccw = ccw;
    // A C that ends where it starts is a whole circle.
    m.sweep = (to - from).norm() < 1e-9 ? 2 * kPi : turnAngle(from - *cc_, to - *cc_, ccw);
    m.feed = feed_.value_or(0);
    add(m, line, Vec3(to.x(), to.y(), pos_.z()));
  }

  void polarArc(size_t line, double degrees, double rise, bool ccw, const std::optional<double> &feed) {
    needTool(line, false);
    feedMove(line, feed);
    if (!cc_) {
      r_.problem(line, "CP without a CC before it");
      return;
    }
    if (!known(pos_.x()) || !known(pos_.y()) || !known(pos_.z())) {
      r_.problem(line, "CP from an unknown position");
      return;
    }
    const double a = degrees * kPi / 180;
    const geom::Vec2 r = pos_.head<2>() - *cc_;
    const geom::Vec2 to(cc_->x() + r.x() * std::cos(a) - r.y() * std::sin(a),
                        cc_->y() + r.x() * std::sin(a) + r.y() * std::cos(a));
    ReadMove m;
    m.kind = Move::Kind::Arc;
    m.centre = *cc_;
    m.ccw = ccw;
    m.sweep = std::abs(a);
    m.feed = feed_.value_or(0);
    add(m, line, Vec3(to.x(), to.y(), pos_.z() + rise));
  }

  /// M99: cycle 200 where the tool is, as the TNC manual describes it (the
  /// emitter's README): at rapid to the set-up clearance over the surface;
  /// in at Q206 to the surface less Q202 per infeed (the last to the
  /// depth), between infeeds out at rapid to the set-up clearance, a wait
  /// of Q210 there, and back down at rapid to the set-up clearance above
  /// the depth reached; the wait of Q211 at the bottom; out at rapid to the
  /// second set-up clearance. The feed it used is not the program's.
  void callCycle(size_t line) {
    if (!cycle_) {
      r_.problem(line, "M99 without a CYCL DEF 200 before it");
      return;
    }
    if (!known(pos_.x()) || !known(pos_.y()) || !known(pos_.z())) {
      r_.problem(line, "M99 at an unknown position");
      return;
    }
    if (!spindle_)
      r_.problem(line, "cycle called with the spindle stopped");
    std::map<int, double> q = cycle_->q;
    const double surface = q[203], clearance = q[200], bottom = surface + q[201];
    if (pos_.z() < surface + q[204] - 1e-6)
      r_.problem(line, "cycle called at Z" + formatFixed(pos_.z(), 4) + ", below its 2nd set-up clearance Z" +
                           formatFixed(surface + q[204], 4) +
                           " (the security plane): the move to the hole is not safe");
    if (!cycle_->drills)
      return;  // reported with its definition
    const double x = pos_.x(), y = pos_.y();
    auto rapidTo = [&](double z) {
      ReadMove m;
      m.cycle = true;
      add(m, line, Vec3(x, y, z));
    };
    auto dwell = [&](double s) {
      ReadMove m;
      m.kind = Move::Kind::Dwell;
      m.dwell = s;
      m.cycle = true;
      add(m, line, pos_);
    };
    rapidTo(surface + clearance);
    double reached = surface;
    for (int k = 1;; ++k) {
      const double target = q[202] < -q[201] ? std::max(surface - q[202] * k, bottom) : bottom;
      if (reached < surface) {
        rapidTo(surface + clearance);
        if (q[210] > 0)
          dwell(q[210]);
        rapidTo(reached + clearance);
      }
      ReadMove in;
      in.kind = Move::Kind::Linear;
      in.feed = q[206];
      in.cycle = true;
      add(in, line, Vec3(x, y, target));
      reached = target;
      if (target <= bottom + 1e-9)
        break;
    }
    if (q[211] > 0)
      dwell(q[211]);
    rapidTo(surface + std::max(q[204], clearance));
    feed_.reset();
  }

  const std::string &text_;
  const TargetDescriptor &d_;
  ProgramReading r_;
  /// Where the tool is, as the control has it; NaN where the program has
  /// not said.
  Vec3 pos_ = Vec3(kNaN, kNaN, kNaN);
  std::optional<geom::Vec2> cc_;
  /// The rotary axes A, B, C as the program last wrote them (NaN: never).
  std::array<double, 3> abc_ = {kNaN, kNaN, kNaN};
  bool tcp_ = false;  ///< FUNCTION TCPM on
  bool tilted_ = false;  ///< a PLANE SPATIAL in force
  bool retracted_ = false;  ///< up in machine coordinates (M91), nothing moved since
  std::optional<double> feed_;  ///< mm/min, modal
  std::optional<long> tool_;
  bool spindle_ = false;
  std::optional<Cycle200> cycle_;
  /// The TOOL CALL (or datum setting) whose first motion is still to come.
  std::optional<std::string> upFirst_;
  /// The MIN point of a BLK FORM 0.1 and the index of its block.
  std::optional<std::pair<std::array<std::optional<double>, 3>, size_t>> blk01_;
  bool ended_ = false;
};

} // namespace

ProgramReading readKlartext(const std::string &text, const TargetDescriptor &d) {
  return KlartextReader(text, d).run();
}

} // namespace stepnc::backends
