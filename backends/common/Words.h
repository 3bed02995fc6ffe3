// What every G-code dialect needs: numbers written the way controllers read
// them, blocks numbered and measured, words written only when they change,
// and arc centres that agree with the endpoints as printed.
#pragma once

#include "backends/Target.h"
#include "geom/Geometry.h"

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::backends {

struct NumberStyle {
  int decimals = 3;
  bool plusSign = false;    ///< "+25" (Heidenhain)
  bool keepPoint = true;    ///< "10." rather than "10" (a bare integer may read as an increment)
};

/// An address letter (or word) and its value: "X" + "10.5". (Also keeps
/// GCC 12 from a false -Wrestrict on one-letter literal concatenations.)
std::string word(std::string_view address, std::string_view value);

/// Fixed point rounded to the style's decimals, trailing zeros dropped, never
/// an exponent, never "-0".
std::string formatNumber(double value, const NumberStyle &style);

/// A value rounded as formatNumber writes it.
double roundTo(double value, int decimals);

/// Blocks of a program: numbered as the target wants, lines over the
/// target's limit recorded for the emitter to report.
class BlockWriter {
public:
  explicit BlockWriter(const TargetDescriptor &d) : d_(d) {}
  /// A numbered block (numbering per the descriptor).
  void block(const std::string &text);
  /// A line outside the numbering (transfer headers such as "%").
  void raw(const std::string &text);
  /// Lines longer than the target allows (1-based line numbers in the text).
  const std::vector<size_t> &overlong() const { return overlong_; }
  const std::string &text() const { return text_; }
  int blocks() const { return blocks_; }
  /// Lines written so far (blocks and raw lines).
  size_t lines() const { return lines_; }

private:
  void put(const std::string &line);
  const TargetDescriptor &d_;
  std::string text_;
  int blocks_ = 0;
  size_t lines_ = 0;
  std::vector<size_t> overlong_;
};

/// The last value written for each modal word, so that a word is written
/// only when it changes.
class ModalState {
public:
  /// True (and remembered) when `value` differs from what `word` last had.
  bool change(const std::string &word, const std::string &value);
  void forget(const std::string &word) { last_.erase(word); }
  void clear() { last_.clear(); }

private:
  std::map<std::string, std::string> last_;
};

/// The ISO 6983 coolant word for a coolant mode: M8 (flood, through the
/// tool), M7 (mist), M9 (off).
std::string coolantWord(const std::string &mode);

/// The centre's offset from `from` (I J), rounded to `decimals`, choosing
/// among the neighbouring rounded values the one whose start and end radius
/// (to the printed `from` and `to`) differ least: rounding I and J alone
/// can leave them about 1.4 units of the last decimal apart, the best
/// neighbour at most 1 unit (a half circle whose chord ends on half a unit).
geom::Vec2 roundedCentreOffset(const geom::Vec2 &from, const geom::Vec2 &to, const geom::Vec2 &centre, int decimals);

/// The angle (radians, in [0, 2 pi)) from direction `a` to direction `b`
/// turning ccw or cw.
double turnAngle(const geom::Vec2 &a, const geom::Vec2 &b, bool ccw);

/// An arc of less than half a turn whose ends print as one point: a
/// controller reads an arc that ends where it starts as a whole circle, so
/// such an arc is written as the straight move it is within a unit of the
/// last decimal.
bool arcPrintsClosed(const geom::Vec2 &from, const geom::Vec2 &to, double sweep, int decimals);

/// Points that cut an arc of `sweep` radians (turning ccw or cw about
/// `centre` from `from`) into `pieces` equal parts: the end of each part.
std::vector<geom::Vec2> arcSplitPoints(const geom::Vec2 &from, const geom::Vec2 &centre, bool ccw, double sweep,
                                       int pieces);

} // namespace stepnc::backends
