#include "backends/common/IsoReader.h"

#include "backends/common/Words.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <set>

namespace stepnc::backends {

namespace {

enum class Dialect { Rs274, Siemens };

/// The longest program name the 840D files (backends/siemens-840d/README.md).
constexpr size_t kMaxSiemensName = 24;

const double kNaN = std::nan("");

bool known(double v) { return std::isfinite(v); }

/// A G code as ten times its value (G59.1: 591), so that decimals compare exactly.
int gKey(double value) { return static_cast<int>(std::lround(value * 10)); }

/// The G codes each dialect's emitter writes (ten times their value).
const std::set<int> &allowedG(Dialect dialect) {
  static const std::set<int> rs274 = [] {
    std::set<int> s;
    for (int g : {0, 1, 2, 3, 4, 5, 17, 18, 19, 21, 40, 43, 49, 53, 54, 55, 56, 57, 58, 59, 64, 74, 80, 81, 82, 83,
                  84, 85, 89, 90, 93, 94, 98, 99})
      s.insert(g * 10);
    s.insert({591, 592, 593});
    return s;
  }();
  static const std::set<int> siemens = [] {
    std::set<int> s;
    for (int g : {0, 1, 2, 3, 4, 17, 18, 19, 40, 64, 71, 90, 94, 642, 54, 55, 56, 57})
      s.insert(g * 10);
    for (int g = 505; g < 600; ++g)
      s.insert(g * 10);
    return s;
  }();
  return dialect == Dialect::Rs274 ? rs274 : siemens;
}

const std::set<int> kAllowedM = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30};

/// A word of a block: an address and its number as written, or a Siemens
/// keyword ("MCALL", "CSPLINE"...) or call ("CALL", its text).
struct Word {
  std::string address;
  std::string text;
  double value = 0;
};

/// A drilling cycle in force: LinuxCNC's G8x of one block, or the 840D's MCALL.
struct HoleCall {
  std::string name;  ///< "G81", "CYCLE83"
  size_t line = 0;
  double r = 0;       ///< where feeding starts
  double depth = 0;
  double rtp = 0;     ///< 840D: where the tool ends
  double rfp = 0;     ///< 840D: the reference plane
  std::vector<std::optional<double>> args;  ///< 840D: the call's arguments
  int holes = 0;
};

class IsoReader {
public:
  IsoReader(Dialect dialect, const std::string &text, const TargetDescriptor &d)
      : dialect_(dialect), text_(text), d_(d) {}

  ProgramReading run() {
    std::vector<std::string> lines;
    size_t start = 0;
    while (start < text_.size()) {
      const size_t end = text_.find('\n', start);
      if (end == std::string::npos) {
        lines.push_back(text_.substr(start));
        r_.problem(lines.size(), "the last line has no newline");
        break;
      }
      lines.push_back(text_.substr(start, end - start));
      start = end + 1;
    }
    if (lines.empty()) {
      r_.problem(1, "an empty program");
      return std::move(r_);
    }
    frame(lines);
    for (size_t n = 1; n <= lines.size(); ++n) {
      if (dialect_ == Dialect::Rs274 ? lines[n - 1] == "%" : n == 1)
        continue;
      std::optional<std::string> code = withoutComment(n, lines[n - 1]);
      if (!code)
        continue;
      block(n, *code);
    }
    if (!ended_)
      r_.problem(lines.size(), dialect_ == Dialect::Rs274 ? "the program does not end with M2 or M30"
                                                          : "the program does not end with M30");
    if (mcall_)
      r_.problem(mcall_->line, "MCALL " + mcall_->name + " never cancelled by a bare MCALL");
    if (swivel_)
      r_.problem(lines.size(), "the program ends with the plane swivelled (CYCLE800 with _TC \"0\" missing)");
    return std::move(r_);
  }

private:
  // --- Frame, comments, words ------------------------------------------------------

  void frame(const std::vector<std::string> &lines) {
    if (dialect_ == Dialect::Rs274) {
      if (lines.front() != "%")
        r_.problem(1, "the first line is not % (the start of the program)");
      if (lines.back() != "%")
        r_.problem(lines.size(), "the last line is not % (the end of the program)");
      return;
    }
    const std::string &first = lines.front();
    if (!first.starts_with("%_N_") || !first.ends_with("_MPF") || first.size() <= 8) {
      r_.problem(1, "the first line is not %_N_NAME_MPF");
    } else {
      const std::string name = first.substr(4, first.size() - 8);
      const bool upper = name.size() >= 2 && std::isupper(static_cast<unsigned char>(name[0])) &&
                         std::isupper(static_cast<unsigned char>(name[1])) &&
                         std::all_of(name.begin(), name.end(), [](char c) {
                           return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
                         });
      if (!upper)
        r_.problem(1, "program name " + name + ": letters, digits and underscores, upper case, two letters first");
      if (name.size() > kMaxSiemensName)
        r_.problem(1, "program name " + name + " is longer than " + std::to_string(kMaxSiemensName) + " characters");
    }
    if (lines.size() < 2 || lines[1] != ";$PATH=/_N_MPF_DIR")
      r_.problem(2, "the second line is not ;$PATH=/_N_MPF_DIR");
  }

  /// The code of line `n` without its comment; nullopt when nothing is left.
  std::optional<std::string> withoutComment(size_t n, const std::string &line) {
    std::string code;
    if (dialect_ == Dialect::Rs274) {
      // ( ... ) anywhere, ; to the end of the line.
      for (size_t i = 0; i < line.size(); ++i) {
        if (line[i] == ';')
          break;
        if (line[i] == '(') {
          const size_t close = line.find(')', i);
          if (close == std::string::npos) {
            r_.problem(n, "a comment that is not closed with ')'");
            return std::nullopt;
          }
          if (line.find('(', i + 1) < close) {
            r_.problem(n, "a comment with '(' inside");
            return std::nullopt;
          }
          i = close;
          continue;
        }
        code += line[i];
      }
    } else {
      bool quoted = false;
      for (char c : line) {
        if (c == '"')
          quoted = !quoted;
        else if (c == ';' && !quoted)
          break;
        code += c;
      }
    }
    const size_t a = code.find_first_not_of(" \t"), b = code.find_last_not_of(" \t");
    if (a == std::string::npos)
      return std::nullopt;
    return code.substr(a, b - a + 1);
  }

  /// The words of `code`; nullopt (reported) when something is not a word.
  std::optional<std::vector<Word>> words(size_t n, const std::string &code) {
    std::vector<Word> out;
    size_t i = 0;
    auto number = [&](size_t from) {
      size_t j = from;
      if (j < code.size() && (code[j] == '-' || code[j] == '+'))
        ++j;
      while (j < code.size() && (std::isdigit(static_cast<unsigned char>(code[j])) || code[j] == '.'))
        ++j;
      if (j < code.size() && (code[j] == 'e' || code[j] == 'E') && j + 1 < code.size() &&
          (std::isdigit(static_cast<unsigned char>(code[j + 1])) || code[j + 1] == '-' || code[j + 1] == '+')) {
        j += 2;
        while (j < code.size() && std::isdigit(static_cast<unsigned char>(code[j])))
          ++j;
      }
      return j;
    };
    auto keyword = [&](std::string_view k) {
      return code.compare(i, k.size(), k) == 0 &&
             (i + k.size() == code.size() || !std::isalnum(static_cast<unsigned char>(code[i + k.size()])));
    };
    while (i < code.size()) {
      if (code[i] == ' ' || code[i] == '\t') {
        ++i;
        continue;
      }
      if (dialect_ == Dialect::Siemens) {
        if (code.compare(i, 5, "MSG(\"") == 0) {
          const size_t close = code.find("\")", i + 5);
          if (close == std::string::npos) {
            r_.problem(n, "MSG(\" without its closing \")");
            return std::nullopt;
          }
          out.push_back({"MSG", code.substr(i, close + 2 - i)});
          i = close + 2;
          continue;
        }
        if (code.compare(i, 5, "CYCLE") == 0) {
          const size_t close = code.find(')', i);
          if (close == std::string::npos || code.find('(', i) > close) {
            r_.problem(n, "a cycle call without its arguments in ( )");
            return std::nullopt;
          }
          out.push_back({"CALL", code.substr(i, close + 1 - i)});
          i = close + 1;
          continue;
        }
        bool matched = false;
        for (std::string_view k : {"MCALL", "CSPLINE", "BAUTO", "EAUTO", "TRAORI", "TRAFOOF", "SUPA"})
          if (keyword(k)) {
            out.push_back({std::string(k), ""});
            i += k.size();
            matched = true;
            break;
          }
        if (matched)
          continue;
        for (std::string_view k : {"CR=", "TURN="})
          if (code.compare(i, k.size(), k) == 0) {
            const size_t end = number(i + k.size());
            out.push_back({std::string(k.substr(0, k.size() - 1)), code.substr(i + k.size(), end - i - k.size())});
            i = end;
            matched = true;
            break;
          }
        if (matched)
          continue;
      }
      if (code[i] >= 'A' && code[i] <= 'Z') {
        const size_t end = number(i + 1);
        if (end > i + 1) {
          out.push_back({std::string(1, code[i]), code.substr(i + 1, end - i - 1)});
          i = end;
          continue;
        }
      }
      r_.problem(n, "not a word this target writes: '" + code.substr(i) + "'");
      return std::nullopt;
    }
    return out;
  }

  /// Checks how each word's number is written and takes its value; false
  /// (reported) when one is wrong.
  bool numbers(size_t n, std::vector<Word> &ws) {
    static const std::set<std::string> rs274Words = {"G", "M", "X", "Y", "Z", "I", "J", "K", "P", "Q", "R", "F",
                                                     "S", "T", "H", "A", "B", "C"};
    static const std::set<std::string> siemensWords = {"G", "M", "X", "Y", "Z", "I", "J", "K", "F", "S", "T", "D",
                                                       "CR", "TURN", "A", "B", "C"};
    static const std::set<std::string> lengths = {"X", "Y", "Z", "I", "J", "K", "R", "Q", "F", "CR", "A", "B", "C"};
    static const std::set<std::string> wholes = {"M", "S", "T", "D", "H", "TURN"};
    bool ok = true;
    for (Word &w : ws) {
      if (w.address == "MSG" || w.address == "CALL" || w.address == "MCALL" || w.address == "CSPLINE" ||
          w.address == "BAUTO" || w.address == "EAUTO" || w.address == "TRAORI" || w.address == "TRAFOOF" ||
          w.address == "SUPA")
        continue;
      const auto &allowed = dialect_ == Dialect::Rs274 ? rs274Words : siemensWords;
      if (!allowed.count(w.address)) {
        r_.problem(n, "address " + w.address + " is not one this target writes");
        ok = false;
        continue;
      }
      std::string why;
      if (!wellFormedNumber(w.text, lengths.count(w.address) > 0, why)) {
        r_.problem(n, w.address + ": " + why);
        ok = false;
        continue;
      }
      if (wholes.count(w.address) && w.text.find_first_not_of("0123456789") != std::string::npos) {
        r_.problem(n, w.address + w.text + ": not a whole number");
        ok = false;
        continue;
      }
      w.value = std::strtod(w.text.c_str(), nullptr);
    }
    return ok;
  }

  // --- Blocks ---------------------------------------------------------------------

  void block(size_t n, std::string code) {
    if (code.size() > 1 && code[0] == 'N' && std::isdigit(static_cast<unsigned char>(code[1]))) {
      size_t end = 1;
      while (end < code.size() && std::isdigit(static_cast<unsigned char>(code[end])))
        ++end;
      const long number = std::strtol(code.c_str() + 1, nullptr, 10);
      if (lastNumber_ && number <= *lastNumber_)
        r_.problem(n, "block number N" + std::to_string(number) + " after N" + std::to_string(*lastNumber_));
      lastNumber_ = number;
      code = code.substr(std::min(code.size(), code.find_first_not_of(' ', end)));
      if (code.empty())
        return;
    } else if (lastNumber_) {
      r_.problem(n, "a block without a number among numbered blocks");
    }
    if (ended_)
      r_.problem(n, "a block after the program's end (line " + std::to_string(*ended_) + ")");
    std::optional<std::vector<Word>> ws = words(n, code);
    if (!ws || !numbers(n, *ws))
      return;
    std::vector<int> gs, ms;
    std::map<std::string, double> seen;
    std::vector<std::string> keywords;
    std::vector<std::string> calls;
    for (const Word &w : *ws) {
      if (w.address == "G") {
        if (!allowedG(dialect_).count(gKey(w.value))) {
          r_.problem(n, "G" + w.text + " is not a G code this target writes");
          return;
        }
        gs.push_back(gKey(w.value));
      } else if (w.address == "M") {
        if (!kAllowedM.count(static_cast<int>(w.value))) {
          r_.problem(n, "M" + w.text + " is not an M code this target writes");
          return;
        }
        ms.push_back(static_cast<int>(w.value));
      } else if (w.address == "CALL") {
        calls.push_back(w.text);
      } else if (w.address == "TRAORI" || w.address == "TRAFOOF") {
        // The 840D's transformation on or off: alone in its block; the
        // rotary words are taken with it on (the tip stays the program's).
        if (ws->size() != 1)
          r_.problem(n, w.address + " shares its block");
        if (dialect_ != Dialect::Siemens)
          r_.problem(n, w.address + " is the 840D's");
        if ((w.address == "TRAORI") == traori_)
          r_.problem(n, w.address + (traori_ ? " while the transformation is on" : " while it is off"));
        if (swivel_)
          r_.problem(n, w.address + " with the plane swivelled (CYCLE800)");
        traori_ = w.address == "TRAORI";
        return;
      } else if (w.address == "MSG" || w.address == "MCALL" || w.address == "CSPLINE" || w.address == "BAUTO" ||
                 w.address == "EAUTO" || w.address == "SUPA") {
        keywords.push_back(w.address);
      } else if (!seen.emplace(w.address, w.value).second) {
        r_.problem(n, w.address + " written twice in one block");
        return;
      }
    }
    auto has = [&](int g) { return std::find(gs.begin(), gs.end(), g * 10) != gs.end(); };
    const auto motionCount = std::count_if(gs.begin(), gs.end(), [](int g) {
      return g == 0 || g == 10 || g == 20 || g == 30 || g == 50 || (g >= 810 && g <= 890) || g == 740;
    });
    if (motionCount > 1) {
      r_.problem(n, "two motion G codes in one block");
      return;
    }
    if (std::count(keywords.begin(), keywords.end(), "MSG") && ws->size() > 1)
      r_.problem(n, "MSG shares its block");
    if (has(4)) {
      dwell(n, *ws, seen);
      return;
    }
    // 3+2 (backends/common/Indexing.h): the tool up in machine coordinates
    // (G53 G0 Z..), then the rotary axes turned (G0 A.. C..): no move of the
    // program's, and where the axes are in it is not known after either.
    if (has(53)) {
      if (!has(0) || seen.size() != 1 || !seen.count("Z"))
        r_.problem(n, "G53 other than G53 G0 Z.. (the tool up before the table turns)");
      pos_ = Vec3(kNaN, kNaN, kNaN);
      up_ = true;
      return;
    }
    // The 840D's: up with every frame suppressed (G0 SUPA Z..) before a swivel.
    if (std::count(keywords.begin(), keywords.end(), "SUPA")) {
      if (!has(0) || seen.size() != 1 || !seen.count("Z") || gs.size() != 1)
        r_.problem(n, "SUPA other than G0 SUPA Z.. (the tool up before the plane swivels)");
      pos_ = Vec3(kNaN, kNaN, kNaN);
      up_ = true;
      return;
    }
    const bool rotaryWords = seen.count("A") || seen.count("B") || seen.count("C");
    const bool rotaryAlone = rotaryWords && std::all_of(seen.begin(), seen.end(), [](const auto &w) {
      return w.first == "A" || w.first == "B" || w.first == "C";
    });
    // (On the 840D the rotary axes turn alone at rapid only back to 0 after
    // a swivel is deselected, with the tool up.)
    if (rotaryWords && dialect_ == Dialect::Siemens && !traori_ && !(rotaryAlone && has(0) && up_ && !swivel_)) {
      r_.problem(n, "rotary axes turned with the transformation off (TRAORI first)");
      return;
    }
    if (rotaryAlone && has(0) && !traori_) {
      // A turn (3+2, or before a step that tilts the tool): where the tool
      // is over the workpiece is not known after it.
      rotate(seen);
      pos_ = Vec3(kNaN, kNaN, kNaN);
      return;
    }
    if (rotaryWords && !rotaryAlone && !has(0) && !has(1) && motion_ != 0 && motion_ != 1) {
      r_.problem(n, "rotary axes turned other than alone at rapid (G0 A.. C..) or on a straight move");
      return;
    }
    if (seen.count("X") || seen.count("Y") || seen.count("Z"))
      up_ = false;
    if (std::count(keywords.begin(), keywords.end(), "MCALL")) {
      mcallBlock(n, *ws, calls);
      return;
    }
    for (const std::string &call : calls)
      directCall(n, call, ws->size());
    if (!keywords.empty() && keywords.front() == "CSPLINE") {
      if (keywords != std::vector<std::string>{"CSPLINE", "BAUTO", "EAUTO"})
        r_.problem(n, "a spline starts with CSPLINE BAUTO EAUTO");
      if (motionCount)
        r_.problem(n, "CSPLINE and a motion G code in one block");
      motion_ = kCspline;
    }

    // In the order LinuxCNC executes a block: feed mode, feed, speed, tool,
    // M6, spindle, modal codes, length offset, then the motion. Leaving
    // inverse time (G94) leaves no feed in force.
    if (has(93))
      inverseTime_ = true;
    if (has(94)) {
      if (inverseTime_)
        feed_ = 0;
      inverseTime_ = false;
    }
    if (seen.count("F")) {
      if (seen["F"] <= 0)
        r_.problem(n, "a feed F" + formatFixed(seen["F"], 3));
      feed_ = seen["F"];
    }
    if (seen.count("S"))
      speed_ = seen["S"];
    if (seen.count("T"))
      selected_ = static_cast<int>(seen["T"]);
    for (int m : ms)
      mCode(n, m);
    for (int g : gs)
      modalCode(n, g, seen);
    if (seen.count("D")) {
      // D before the M6 that changes in the selected tool is that tool's
      // offset, taken on by the M6; otherwise it applies at once.
      if (selected_ && selected_ != inSpindle_)
        pendingOffset_ = static_cast<int>(seen["D"]);
      else
        offset_ = static_cast<int>(seen["D"]);
    }
    if (dialect_ == Dialect::Rs274 && cycleCode_ && seen.count("P"))
      stickyP_ = seen["P"];
    const bool axes = seen.count("X") || seen.count("Y") || seen.count("Z") || seen.count("I") || seen.count("J") ||
                      seen.count("K") || seen.count("CR") || (seen.count("R") && !has(43)) || rotaryWords;
    if (!axes) {
      if (seen.count("TURN") || (seen.count("Q") && !cycleCode_))
        r_.problem(n, "TURN=, K or Q without a move");
      return;
    }
    if (cycleCode_ && std::any_of(gs.begin(), gs.end(), [](int g) { return (g >= 810 && g <= 890) || g == 740; })) {
      holeCycle(n, seen);
      return;
    }
    if (cycleCode_) {
      r_.problem(n, "axis words while G" + std::to_string(*cycleCode_ / 10) +
                        " is in force repeat the canned cycle (the program cancels it with G80 first)");
      return;
    }
    move(n, seen);
  }

  void modalCode(size_t n, int g, const std::map<std::string, double> &seen) {
    switch (g) {
    case 0:
    case 10:
    case 20:
    case 30:
    case 50:
      motion_ = g / 10;
      return;
    case 170:
      plane_ = geom::ArcPlane{2};
      return;
    case 180:
      plane_ = geom::ArcPlane{1};
      return;
    case 190:
      plane_ = geom::ArcPlane{0};
      return;
    case 210:
    case 710:
      metric_ = true;
      return;
    case 900:
      absolute_ = true;
      return;
    case 800:
      cycleCode_.reset();
      return;
    case 980:
      retractToStart_ = true;
      return;
    case 990:
      retractToStart_ = false;
      return;
    case 430: {
      const auto h = seen.find("H");
      if (h == seen.end()) {
        r_.problem(n, "G43 without H (the tool's length offset)");
        return;
      }
      if (inSpindle_ && static_cast<int>(h->second) != *inSpindle_)
        r_.problem(n, "G43 H" + std::to_string(static_cast<int>(h->second)) + " with tool " +
                          std::to_string(*inSpindle_) + " in the spindle");
      offset_ = static_cast<int>(h->second);
      return;
    }
    case 490:
      offset_.reset();
      return;
    default:
      break;
    }
    if ((g >= 810 && g <= 890) || g == 740) {
      cycleCode_ = g;
      return;
    }
    if ((g >= 540 && g <= 593) || (g >= 5050 && g <= 5990)) {
      // Another work offset: where the axes are in it is not known.
      pos_ = Vec3(kNaN, kNaN, kNaN);
    }
  }

  void mCode(size_t n, int m) {
    switch (m) {
    case 3:
    case 4:
      if (speed_ <= 0)
        r_.problem(n, "the spindle on (M" + std::to_string(m) + ") without a speed S");
      spindleOn_ = true;
      return;
    case 5:
      spindleOn_ = false;
      return;
    case 6:
      if (mcall_)
        r_.problem(n, "a tool change while MCALL " + mcall_->name + " is active");
      if (!selected_)
        r_.problem(n, "M6 without a tool selected by T");
      inSpindle_ = selected_;
      offset_ = dialect_ == Dialect::Siemens ? pendingOffset_ : std::nullopt;
      pendingOffset_.reset();
      // The tool change position is the machine's: the axes are unknown
      // until written again, and the spindle is stopped.
      pos_ = Vec3(kNaN, kNaN, kNaN);
      spindleOn_ = false;
      upFirst_ = "the tool change on line " + std::to_string(n);
      return;
    case 2:
    case 30:
      if (mcall_)
        r_.problem(n, "the program ends while MCALL " + mcall_->name + " is active");
      ended_ = n;
      return;
    default:
      return;
    }
  }

  // --- Moves ----------------------------------------------------------------------

  /// Reports what a move lacks.
  void ready(size_t n, bool feedMove, bool needFeed = true) {
    if (!absolute_)
      r_.problem(n, "a move before G90 (absolute positions)");
    if (!metric_)
      r_.problem(n, dialect_ == Dialect::Rs274 ? "a move before G21 (mm)" : "a move before G71 (mm)");
    if (!inSpindle_)
      r_.problem(n, "a move with no tool changed in (T.. M6)");
    else if (!offset_)
      r_.problem(n, dialect_ == Dialect::Rs274 ? "a move without the tool's length offset (G43 H..)"
                                               : "a move without the tool's D offset (its length)");
    if (feedMove && needFeed && feed_ <= 0)
      r_.problem(n, "a feed move with no feed F");
    if (feedMove && !spindleOn_ && !d_.feedsWithoutSpindle)
      r_.problem(n, "a feed move with the spindle off");
  }

  /// The first move of the program and after each tool change goes up along Z alone.
  void upFirst(size_t n, bool zAlone) {
    if (upFirst_.empty())
      return;
    if (!zAlone)
      r_.problem(n, "the first move after " + upFirst_ +
                        " is not G0 with Z alone (up to the clearance height before X and Y move)");
    upFirst_.clear();
  }

  void make(size_t n, Move::Kind kind, const Vec3 &to, bool cycle = false, bool rotated = false) {
    ReadMove m;
    m.kind = kind;
    m.from = pos_;
    m.to = to;
    m.feed = kind == Move::Kind::Rapid ? 0 : feed_;
    m.inverseTime = kind != Move::Kind::Rapid && inverseTime_;
    m.abc = abc_;
    m.cycle = cycle;
    m.line = n;
    pos_ = to;
    // A move that goes nowhere is none (the emitter leaves such moves out).
    if (kind != Move::Kind::Arc && !rotated && m.from.allFinite() && m.to.allFinite() && m.from == m.to)
      return;
    r_.moves.push_back(m);
  }

  /// The rotary axes the block's A, B, C words turn; whether any changes.
  bool rotate(const std::map<std::string, double> &seen) {
    bool changed = false;
    for (int k = 0; k < 3; ++k)
      if (const auto v = seen.find(std::string(1, "ABC"[k])); v != seen.end()) {
        changed = changed || !(abc_[static_cast<size_t>(k)] == v->second);
        abc_[static_cast<size_t>(k)] = v->second;
      }
    return changed;
  }

  void move(size_t n, const std::map<std::string, double> &seen) {
    if (!motion_) {
      r_.problem(n, "axis words with no motion G code (G0 G1 G2 G3)");
      return;
    }
    const bool xyMoves = seen.count("X") || seen.count("Y") || seen.count("I") || seen.count("J") ||
                         seen.count("K") || seen.count("CR") || seen.count("R") || seen.count("TURN");
    upFirst(n, *motion_ == 0 && !xyMoves);
    if (mcall_) {
      cyclePosition(n, seen);
      return;
    }
    ready(n, *motion_ != 0);
    if (*motion_ == 2 || *motion_ == 3) {
      arc(n, seen);
      return;
    }
    Vec3 to = pos_;
    for (int k = 0; k < 3; ++k)
      if (const auto v = seen.find(std::string(1, "XYZ"[k])); v != seen.end())
        to[k] = v->second;
    if (*motion_ == 5 || *motion_ == kCspline) {
      spline(n, seen, to);
      return;
    }
    for (const char *bad : {"I", "J", "K", "R", "CR", "TURN", "P", "Q"})
      if (seen.count(bad)) {
        r_.problem(n, std::string(bad) + " on a straight move");
        return;
      }
    // LinuxCNC refuses a G1 in inverse time without its F.
    if (*motion_ == 1 && inverseTime_ && !seen.count("F"))
      r_.problem(n, "a G1 in inverse time (G93) without F");
    const bool rotated = rotate(seen);
    make(n, *motion_ == 0 ? Move::Kind::Rapid : Move::Kind::Linear, to, false, rotated);
  }

  void spline(size_t n, const std::map<std::string, double> &seen, const Vec3 &to) {
    if (seen.count("Z")) {
      r_.problem(n, "a spline point with Z (the splines are in the XY plane)");
      return;
    }
    if (!known(pos_.x()) || !known(pos_.y())) {
      r_.problem(n, "a spline from an unknown position");
      return;
    }
    const bool bezier = *motion_ == 5;
    for (const auto &[address, value] : seen)
      if (address != "X" && address != "Y" && address != "F" &&
          !(bezier && (address == "I" || address == "J" || address == "P" || address == "Q"))) {
        r_.problem(n, "a spline point with " + address);
        return;
      }
    if (bezier && !(seen.count("X") && seen.count("Y") && seen.count("I") && seen.count("J") && seen.count("P") &&
                    seen.count("Q"))) {
      r_.problem(n, "G5 without all of X Y I J P Q");
      return;
    }
    const Vec3 from = pos_;
    make(n, Move::Kind::Linear, to);
    ReadMove &m = r_.moves.back();
    m.spline = true;
    if (bezier)
      m.bezier = std::pair(geom::Vec2(from.x() + seen.at("I"), from.y() + seen.at("J")),
                           geom::Vec2(to.x() + seen.at("P"), to.y() + seen.at("Q")));
  }

  void arc(size_t n, const std::map<std::string, double> &seen) {
    if (!plane_)
      r_.problem(n, "an arc before G17, G18 or G19 (its plane)");
    // In the plane's coordinates (geom/ArcPlane.h): the first and second
    // axes' words, the centre offsets of the same axes (I J K).
    const geom::ArcPlane plane = plane_.value_or(geom::ArcPlane::xy());
    Vec3 to = pos_;
    for (int k = 0; k < 3; ++k)
      if (const auto v = seen.find(std::string(1, "XYZ"[k])); v != seen.end())
        to[k] = v->second;
    const std::string firstOffset(1, "IJK"[plane.first()]), secondOffset(1, "IJK"[plane.second()]);
    const std::string normalOffset(1, "IJK"[plane.normal]);
    if (seen.count(normalOffset)) {
      r_.problem(n, "an arc in the " + std::string(plane.name()) + " plane with " + normalOffset);
      return;
    }
    const geom::Vec2 start = plane.local(pos_).head<2>();
    const geom::Vec2 end = plane.local(to).head<2>();
    const bool ccw = *motion_ == 3;
    const char *radiusWord = dialect_ == Dialect::Rs274 ? "R" : "CR";
    const char *turnsWord = dialect_ == Dialect::Rs274 ? "P" : "TURN";
    if (!start.allFinite() || !end.allFinite()) {
      r_.problem(n, "an arc from an unknown position");
      return;
    }
    geom::Vec2 centre;
    int64_t turns = 0;
    if (seen.count(radiusWord)) {
      if (seen.count(firstOffset) || seen.count(secondOffset) || seen.count(turnsWord)) {
        r_.problem(n, std::string("an arc with ") + radiusWord + " and " + firstOffset + ", " + secondOffset +
                          " or turns");
        return;
      }
      const double cr = seen.at(radiusWord), r = std::abs(cr), chord = (end - start).norm();
      if (chord < 1e-9) {
        r_.problem(n, std::string("a whole circle with ") + radiusWord + " (it needs " + firstOffset + " and " +
                          secondOffset + ")");
        return;
      }
      if (r == 0 || r < chord / 2 - arcRadiusTolerance(d_)) {
        r_.problem(n, std::string(radiusWord) + formatFixed(cr, 4) + " is shorter than half the chord (" +
                          formatFixed(chord / 2, 4) + " mm)");
        return;
      }
      // The centre on the side the direction and the sign say: left of the
      // chord for a ccw arc under half a turn.
      const double h = std::sqrt(std::max(r * r - chord * chord / 4, 0.0));
      const geom::Vec2 left(-(end.y() - start.y()) / chord, (end.x() - start.x()) / chord);
      const double side = (ccw ? 1 : -1) * (cr > 0 ? 1 : -1);
      centre = (start + end) / 2 + side * h * left;
    } else if (seen.count(firstOffset) || seen.count(secondOffset)) {
      centre = start + geom::Vec2(seen.count(firstOffset) ? seen.at(firstOffset) : 0,
                                  seen.count(secondOffset) ? seen.at(secondOffset) : 0);
      const double r0 = (start - centre).norm(), r1 = (end - centre).norm();
      if (r0 < 1e-9) {
        r_.problem(n, "an arc of radius 0");
        return;
      }
      if (std::abs(r0 - r1) > arcRadiusTolerance(d_)) {
        r_.problem(n, "the arc's radius is " + formatFixed(r0, 4) + " mm at the start and " + formatFixed(r1, 4) +
                          " mm at the end (more than " + formatFixed(arcRadiusTolerance(d_), 3) + " mm apart)");
        return;
      }
      if (const auto t = seen.find(turnsWord); t != seen.end()) {
        // LinuxCNC's P counts the turns with the last (P1: the arc alone); TURN= the full turns before it.
        turns = static_cast<int64_t>(t->second) - (dialect_ == Dialect::Rs274 ? 1 : 0);
        if (turns < 0 || t->second != std::floor(t->second)) {
          r_.problem(n, std::string(turnsWord) + " must be a whole number of turns" +
                            (dialect_ == Dialect::Rs274 ? ", at least 1" : ""));
          return;
        }
      }
    } else {
      r_.problem(n, "an arc with neither " + firstOffset + ", " + secondOffset + " nor " + radiusWord);
      return;
    }
    Move planned;  // Move::sweep() is the arc rule of the toolpath IR
    planned.from = pos_;
    planned.to = to;
    planned.centre = centre;
    planned.ccw = ccw;
    planned.turns = turns;
    planned.plane = plane;
    make(n, Move::Kind::Arc, to);
    ReadMove &m = r_.moves.back();
    m.centre = centre;
    m.plane = plane;
    m.ccw = ccw;
    m.sweep = planned.sweep();
  }

  void dwell(size_t n, const std::vector<Word> &ws, const std::map<std::string, double> &seen) {
    const char *time = dialect_ == Dialect::Rs274 ? "P" : "F";
    if (ws.size() != 2 || !seen.count(time)) {
      r_.problem(n, std::string("G4 takes ") + time + " (seconds) in a block of its own");
      return;
    }
    if (seen.at(time) <= 0) {
      r_.problem(n, std::string("a dwell of G4 ") + time + formatFixed(seen.at(time), 3));
      return;
    }
    wait(n, seen.at(time), false);
  }

  /// A dwell of `seconds` where the tool is (none when not above 0).
  void wait(size_t n, double seconds, bool cycle) {
    if (seconds <= 0)
      return;
    ReadMove m;
    m.kind = Move::Kind::Dwell;
    m.from = m.to = pos_;
    m.dwell = seconds;
    m.cycle = cycle;
    m.line = n;
    r_.moves.push_back(m);
  }

  // --- Canned cycles ----------------------------------------------------------------

  /// LinuxCNC's G74 G81 G82 G83 G84 G85 G89 at X Y, from Z R (G98: back to
  /// where it started, when above R; G99: to R), as the LinuxCNC manual
  /// describes their motions.
  void holeCycle(size_t n, const std::map<std::string, double> &seen) {
    const int g = *cycleCode_;
    const std::string name = word("G", std::to_string(g / 10));
    for (const char *w : {"X", "Y", "Z", "R"})
      if (!seen.count(w)) {
        r_.problem(n, name + " without X, Y, Z and R");
        return;
      }
    upFirst(n, false);
    ready(n, true);
    if (!plane_ || !plane_->isXY())
      r_.problem(n, name + " outside G17 (the XY plane)");
    if (!known(pos_.z())) {
      r_.problem(n, name + " from an unknown height");
      return;
    }
    const double x = seen.at("X"), y = seen.at("Y"), bottom = seen.at("Z"), r = seen.at("R");
    if (bottom >= r) {
      r_.problem(n, name + ": the bottom Z is not below R");
      return;
    }
    const double clear = retractToStart_ ? std::max(pos_.z(), r) : r;
    if (pos_.z() < r)
      make(n, Move::Kind::Rapid, Vec3(pos_.x(), pos_.y(), r), true);
    make(n, Move::Kind::Rapid, Vec3(x, y, pos_.z()), true);
    make(n, Move::Kind::Rapid, Vec3(x, y, r), true);
    auto at = [&](double z) { return Vec3(x, y, z); };
    switch (g) {
    case 810:
      make(n, Move::Kind::Linear, at(bottom), true);
      break;
    case 820:
      make(n, Move::Kind::Linear, at(bottom), true);
      wait(n, stickyP_, true);
      break;
    case 830: {
      const double q = seen.count("Q") ? seen.at("Q") : 0;
      if (q <= 0) {
        r_.problem(n, "G83 without a peck depth Q above 0");
        return;
      }
      double reached = r;
      while (reached > bottom) {
        const double next = std::max(reached - q, bottom);
        if (reached < r)
          make(n, Move::Kind::Rapid, at(reached + kLinuxCncG83Backoff), true);
        make(n, Move::Kind::Linear, at(next), true);
        make(n, Move::Kind::Rapid, at(r), true);
        reached = next;
      }
      break;
    }
    case 840:
    case 740:
      // Feed in, the spindle reversed at the bottom (after a dwell P), feed out to R.
      if (!spindleOn_)
        r_.problem(n, name + " with the spindle off");
      make(n, Move::Kind::Linear, at(bottom), true);
      wait(n, stickyP_, true);
      make(n, Move::Kind::Linear, at(r), true);
      break;
    case 850:
      make(n, Move::Kind::Linear, at(bottom), true);
      make(n, Move::Kind::Linear, at(r), true);
      break;
    case 890:
      make(n, Move::Kind::Linear, at(bottom), true);
      wait(n, stickyP_, true);
      make(n, Move::Kind::Linear, at(r), true);
      break;
    default:
      r_.problem(n, name + ": its moves are not modelled");
      return;
    }
    make(n, Move::Kind::Rapid, at(clear), true);
  }

  /// The arguments of an 840D cycle call ("CYCLE81(20.,0.,2.,-10.,)").
  static std::pair<std::string, std::vector<std::string>> callArgs(const std::string &call) {
    const size_t open = call.find('(');
    std::vector<std::string> args;
    std::string inside = call.substr(open + 1, call.size() - open - 2), arg;
    for (char c : inside) {
      if (c == ',') {
        args.push_back(arg);
        arg.clear();
      } else if (c != ' ') {
        arg += c;
      }
    }
    args.push_back(arg);
    return {call.substr(0, open), args};
  }

  /// RTP, RFP, SDIS, DP of a drilling cycle call, after checking its arguments; nullopt when wrong.
  std::optional<HoleCall> cycleParameters(size_t n, const std::string &call) {
    static const std::map<std::string, std::pair<size_t, size_t>> counts = {
        {"CYCLE81", {5, 5}}, {"CYCLE82", {6, 6}}, {"CYCLE83", {12, 99}}, {"CYCLE84", {12, 99}}};
    auto [name, args] = callArgs(call);
    const auto count = counts.find(name);
    if (count == counts.end()) {
      r_.problem(n, name + " is not a drilling cycle this target writes");
      return std::nullopt;
    }
    if (args.size() < count->second.first || args.size() > count->second.second) {
      r_.problem(n, name + " with " + std::to_string(args.size()) + " arguments");
      return std::nullopt;
    }
    HoleCall c;
    c.name = name;
    c.line = n;
    for (const std::string &a : args) {
      std::string why;
      if (a.empty()) {
        c.args.emplace_back();
      } else if (!wellFormedNumber(a, false, why)) {
        r_.problem(n, name + ": argument " + why);
        return std::nullopt;
      } else {
        c.args.emplace_back(std::strtod(a.c_str(), nullptr));
      }
    }
    const auto &v = c.args;
    if (!v[0] || !v[1] || !v[2] || (!v[3] && !v[4])) {
      r_.problem(n, name + " without RTP, RFP, SDIS and a depth");
      return std::nullopt;
    }
    if (*v[2] < 0 || (v[4] && *v[4] < 0))
      r_.problem(n, name + ": SDIS and DPR are unsigned");
    c.rtp = *v[0];
    c.rfp = *v[1];
    c.r = c.rfp + *v[2];
    c.depth = v[3] ? *v[3] : c.rfp - *v[4];
    if (c.depth >= c.r)
      r_.problem(n, name + ": the depth " + formatFixed(c.depth, 3) + " is not below the reference plane RFP + SDIS = " +
                        formatFixed(c.r, 3));
    if (c.rtp < c.r)
      r_.problem(n, name + ": the retract plane RTP " + formatFixed(c.rtp, 3) + " is below RFP + SDIS = " +
                        formatFixed(c.r, 3));
    if (name != "CYCLE84" && feed_ <= 0)
      r_.problem(n, name + " with no feed F set");
    if (name == "CYCLE83") {
      if (!v[5] && !v[6])
        r_.problem(n, "CYCLE83 without a first depth (FDEP or FDPR)");
      else if (v[5] && !(c.depth <= *v[5] && *v[5] < c.r))
        r_.problem(n, "CYCLE83: the first depth FDEP is not between the depth and RFP + SDIS");
      if (v[11] != 0.0 && v[11] != 1.0)
        r_.problem(n, "CYCLE83: VARI is 0 (chip breaking) or 1 (full retract)");
    }
    if (name == "CYCLE84") {
      if (v[6] != 3.0 && v[6] != 4.0 && v[6] != 5.0)
        r_.problem(n, "CYCLE84: SDAC (the spindle after the cycle) is 3, 4 or 5");
      if (!v[7].value_or(0) && !v[8].value_or(0))
        r_.problem(n, "CYCLE84 without a thread pitch (MPIT or PIT)");
      if (v[10].value_or(0) <= 0)
        r_.problem(n, "CYCLE84 without a tapping speed SST");
    }
    return c;
  }

  void mcallBlock(size_t n, const std::vector<Word> &ws, const std::vector<std::string> &calls) {
    if (ws.size() == 1) {
      if (!mcall_)
        r_.problem(n, "a bare MCALL with no modal call active");
      else if (mcall_->holes == 0)
        r_.problem(n, "MCALL " + mcall_->name + " (line " + std::to_string(mcall_->line) +
                          ") cancelled before any position");
      mcall_.reset();
      return;
    }
    if (ws.size() != 2 || calls.size() != 1) {
      r_.problem(n, "MCALL takes one cycle call and nothing else");
      return;
    }
    if (mcall_)
      r_.problem(n, "MCALL while MCALL " + mcall_->name + " (line " + std::to_string(mcall_->line) + ") is active");
    mcall_ = cycleParameters(n, calls.front());
  }

  /// A position block under MCALL: to X Y, then the cycle there.
  void cyclePosition(size_t n, const std::map<std::string, double> &seen) {
    HoleCall &c = *mcall_;
    if (*motion_ != 0 && *motion_ != 1) {
      r_.problem(n, "an arc or spline while MCALL " + c.name + " is active");
      return;
    }
    for (const auto &[address, value] : seen)
      if (address != "X" && address != "Y") {
        r_.problem(n, "a position block under MCALL with more than X and Y");
        return;
      }
    if (!known(pos_.z()) || pos_.z() < c.r - 1e-9) {
      r_.problem(n, "a position under MCALL " + c.name + " from " +
                        (known(pos_.z()) ? "z=" + formatFixed(pos_.z(), 3) : std::string("an unknown height")) +
                        ", below the reference plane " + formatFixed(c.r, 3));
      return;
    }
    ready(n, true, c.name != "CYCLE84");
    Vec3 to = pos_;
    if (seen.count("X"))
      to.x() = seen.at("X");
    if (seen.count("Y"))
      to.y() = seen.at("Y");
    make(n, Move::Kind::Rapid, to, true);
    if (!known(pos_.x()) || !known(pos_.y())) {
      r_.problem(n, "a hole at an unknown position");
      return;
    }
    drill(n, c);
    ++c.holes;
  }

  /// The moves an 840D drilling cycle makes where the tool is, as its
  /// documented parameters say (backends/siemens-840d/README.md); the tool
  /// ends at RTP.
  void drill(size_t n, const HoleCall &c) {
    const double x = pos_.x(), y = pos_.y();
    auto at = [&](double z) { return Vec3(x, y, z); };
    const auto &v = c.args;
    make(n, Move::Kind::Rapid, at(c.r), true);
    if (c.name == "CYCLE83") {
      // Full retract (VARI 1) after each stroke; strokes as long as the first
      // (no degression, DAM 0), the last one shorter. The way back down is
      // the controller's: only the feed moves are compared.
      const double first = v[5] ? *v[5] : c.rfp - v[6].value_or(0);
      const double stroke = c.rfp - first;
      if (v[11] != 1.0 || v[7].value_or(0) != 0 || stroke <= 0) {
        r_.problem(n, "CYCLE83 with chip breaking, degression or no first stroke: its moves are not modelled");
        return;
      }
      for (double bottom = first;; bottom -= stroke) {
        bottom = std::max(bottom, c.depth);
        make(n, Move::Kind::Linear, at(bottom), true);
        if (bottom <= c.depth + 1e-9)
          break;
        make(n, Move::Kind::Rapid, at(c.r), true);
      }
    } else if (c.name == "CYCLE84") {
      const double pitch = std::abs(v[8].value_or(0)), sst = v[10].value_or(0), sst1 = v[11].value_or(sst);
      const double keep = feed_;
      feed_ = pitch * sst;
      make(n, Move::Kind::Linear, at(c.depth), true);
      feed_ = pitch * (sst1 > 0 ? sst1 : sst);
      make(n, Move::Kind::Linear, at(c.r), true);
      feed_ = keep;
    } else {
      make(n, Move::Kind::Linear, at(c.depth), true);
      if (c.name == "CYCLE82")
        wait(n, v[5].value_or(0), true);
    }
    make(n, Move::Kind::Rapid, at(c.rtp), true);
  }

  void directCall(size_t n, const std::string &call, size_t words) {
    auto [name, args] = callArgs(call);
    if (name == "CYCLE800") {
      swivel(n, args, words);
      return;
    }
    if (name == "CYCLE832") {
      if (words != 1)
        r_.problem(n, "CYCLE832 shares its block");
      if (args.size() != 3) {
        r_.problem(n, "CYCLE832 with " + std::to_string(args.size()) + " arguments (it takes 3: _TOL, _TOLM, _OTOL)");
        return;
      }
      std::vector<double> v;
      for (const std::string &a : args) {
        std::string why;
        if (!wellFormedNumber(a, false, why)) {
          r_.problem(n, "CYCLE832: argument " + why);
          return;
        }
        v.push_back(std::strtod(a.c_str(), nullptr));
      }
      if (v[1] != 0 && v[1] != 1 && v[1] != 2 && v[1] != 3)
        r_.problem(n, "CYCLE832: _TOLM is 0 (off), 1, 2 or 3");
      else if (v[1] != 0 && v[0] <= 0)
        r_.problem(n, "CYCLE832: a tolerance above 0 is needed with _TOLM " + args[1]);
      if (v[2] != 1)
        r_.problem(n, "CYCLE832: _OTOL is 1 on a 3-axis machine");
      return;
    }
    // A direct (not modal) drilling cycle runs once where the tool is.
    std::optional<HoleCall> c = cycleParameters(n, call);
    if (!c)
      return;
    if (words != 1)
      r_.problem(n, name + " shares its block");
    if (!pos_.allFinite() || pos_.z() < c->r - 1e-9) {
      r_.problem(n, name + " called from an unknown position or below its reference plane");
      return;
    }
    ready(n, true, name != "CYCLE84");
    drill(n, *c);
  }

  /// CYCLE800 in the one form the emitter writes (README.md, "3+2"): _FR 0,
  /// _TC the swivel data set (or "0": deselect, every value 0), _ST 0,
  /// _MODE 27 (axis by axis, Z Y X), X0 Y0 Z0 0, the three angles, the
  /// rotated zero X1 Y1 Z1, _DIR -1, _FR_I 0; alone in its block, right
  /// after the tool went up (G0 SUPA Z..) with nothing moved since. Where the
  /// tool is in the new coordinates is not known after it.
  void swivel(size_t n, const std::vector<std::string> &args, size_t words) {
    if (words != 1)
      r_.problem(n, "CYCLE800 shares its block");
    if (args.size() != 15) {
      r_.problem(n, "CYCLE800 with " + std::to_string(args.size()) +
                        " arguments (it takes 15: _FR, _TC, _ST, _MODE, _X0, _Y0, _Z0, _A, _B, _C, _X1, _Y1, _Z1, "
                        "_DIR, _FR_I)");
      return;
    }
    const std::string &tc = args[1];
    if (tc.size() < 3 || tc.front() != '"' || tc.back() != '"') {
      r_.problem(n, "CYCLE800: _TC " + tc + " is not a name in double quotes");
      return;
    }
    const bool deselect = tc == "\"0\"";
    std::vector<double> v;
    for (size_t k = 0; k < args.size(); ++k) {
      if (k == 1)
        continue;
      std::string why;
      if (!wellFormedNumber(args[k], false, why)) {
        r_.problem(n, "CYCLE800: argument " + std::to_string(k + 1) + " " + why);
        return;
      }
      v.push_back(std::strtod(args[k].c_str(), nullptr));
    }
    // v: _FR, _ST, _MODE, X0, Y0, Z0, A, B, C, X1, Y1, Z1, _DIR, _FR_I.
    if (v[0] != 0 || v[1] != 0 || v[2] != 27 || v[3] != 0 || v[4] != 0 || v[5] != 0 || v[12] != -1 || v[13] != 0)
      r_.problem(n, "CYCLE800 not of the form CYCLE800(0,\"..\",0,27,0.,0.,0.,A,B,C,X1,Y1,Z1,-1,0.)");
    if (deselect && std::any_of(v.begin() + 6, v.begin() + 12, [](double x) { return x != 0; }))
      r_.problem(n, "CYCLE800: a deselection (_TC \"0\") with angles or a zero point");
    if (traori_)
      r_.problem(n, "CYCLE800 with TRAORI on");
    if (!up_)
      r_.problem(n, "CYCLE800 swivels without the tool first up (G0 SUPA Z..) and nothing moved since");
    swivel_ = !deselect;
    pos_ = Vec3(kNaN, kNaN, kNaN);
  }

  static constexpr int kCspline = -1;  ///< motion_: the 840D's CSPLINE

  Dialect dialect_;
  const std::string &text_;
  const TargetDescriptor &d_;
  ProgramReading r_;
  Vec3 pos_ = Vec3(kNaN, kNaN, kNaN);
  std::optional<int> motion_;  ///< 0 1 2 3, 5 (G5), kCspline
  bool absolute_ = false, metric_ = false;
  std::optional<geom::ArcPlane> plane_;  ///< G17, G18, G19; none before the program selects one
  double feed_ = 0, speed_ = 0;
  bool inverseTime_ = false;  ///< G93: F is 1 / the block's minutes
  bool traori_ = false;       ///< the 840D's TRAORI on
  bool swivel_ = false;       ///< the 840D's plane swivelled (CYCLE800)
  bool up_ = false;           ///< the tool up in machine coordinates (G53, SUPA), nothing moved since
  std::array<double, 3> abc_ = {kNaN, kNaN, kNaN};  ///< A, B, C as last written
  bool spindleOn_ = false;
  std::optional<int> selected_, inSpindle_, offset_, pendingOffset_;
  std::optional<long> lastNumber_;
  std::optional<size_t> ended_;
  std::string upFirst_ = "the program start";
  // LinuxCNC's canned cycles: the cycle in force (ten times its G code), its
  // retract mode, and P, which LinuxCNC keeps from one cycle to the next.
  std::optional<int> cycleCode_;
  bool retractToStart_ = true;
  double stickyP_ = 0;
  std::optional<HoleCall> mcall_;  ///< the 840D's modal call
};

} // namespace

ProgramReading readRs274(const std::string &text, const TargetDescriptor &d) {
  return IsoReader(Dialect::Rs274, text, d).run();
}

ProgramReading readSiemens840d(const std::string &text, const TargetDescriptor &d) {
  return IsoReader(Dialect::Siemens, text, d).run();
}

} // namespace stepnc::backends
