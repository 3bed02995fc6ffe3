#include "backends/common/Words.h"

#include "support/Format.h"

#include <cmath>
#include <numbers>

namespace stepnc::backends {

std::string word(std::string_view address, std::string_view value) {
  std::string s;
  s.reserve(address.size() + value.size());
  s.append(address).append(value);
  return s;
}

double roundTo(double value, int decimals) {
  const double scale = std::pow(10.0, decimals);
  const double r = std::round(value * scale) / scale;
  return r == 0 ? 0.0 : r;  // no -0
}

std::string formatNumber(double value, const NumberStyle &style) {
  std::string s = formatFixed(roundTo(value, style.decimals), style.decimals);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0')
      s.pop_back();
    if (s.back() == '.' && !style.keepPoint)
      s.pop_back();
  } else if (style.keepPoint) {
    s += '.';
  }
  if (style.plusSign && s.front() != '-')
    s.insert(s.begin(), '+');
  return s;
}

void BlockWriter::block(const std::string &text) {
  switch (d_.numbering) {
  case Numbering::None:
    put(text);
    break;
  case Numbering::Every:
    put(word("N", std::to_string((blocks_ + 1) * d_.numberStep)) + " " + text);
    break;
  case Numbering::FromZero:
    put(std::to_string(blocks_) + " " + text);
    break;
  }
  ++blocks_;
}

void BlockWriter::raw(const std::string &text) { put(text); }

void BlockWriter::put(const std::string &line) {
  ++lines_;
  if (d_.maxLineLength > 0 && line.size() > d_.maxLineLength)
    overlong_.push_back(lines_);
  text_ += line;
  text_ += '\n';
}

bool ModalState::change(const std::string &word, const std::string &value) {
  auto [it, inserted] = last_.try_emplace(word, value);
  if (inserted)
    return true;
  if (it->second == value)
    return false;
  it->second = value;
  return true;
}

geom::Vec2 roundedCentreOffset(const geom::Vec2 &from, const geom::Vec2 &to, const geom::Vec2 &centre, int decimals) {
  const double unit = std::pow(10.0, -decimals);
  const geom::Vec2 nearest(roundTo(centre.x() - from.x(), decimals), roundTo(centre.y() - from.y(), decimals));
  auto mismatch = [&](const geom::Vec2 &ij) { return std::abs(ij.norm() - (from + ij - to).norm()); };
  geom::Vec2 best = nearest;
  double bestMismatch = mismatch(nearest);
  for (int di = -1; di <= 1; ++di)
    for (int dj = -1; dj <= 1; ++dj) {
      const geom::Vec2 ij(roundTo(nearest.x() + di * unit, decimals), roundTo(nearest.y() + dj * unit, decimals));
      if (const double e = mismatch(ij); e < bestMismatch - 1e-12) {
        best = ij;
        bestMismatch = e;
      }
    }
  return best;
}

double turnAngle(const geom::Vec2 &a, const geom::Vec2 &b, bool ccw) {
  double angle = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));  // ccw from a to b, (-pi, pi]
  if (!ccw)
    angle = -angle;
  if (angle < 0)
    angle += 2 * std::numbers::pi;
  return angle;
}

bool arcPrintsClosed(const geom::Vec2 &from, const geom::Vec2 &to, double sweep, int decimals) {
  return sweep < std::numbers::pi && roundTo(from.x(), decimals) == roundTo(to.x(), decimals) &&
         roundTo(from.y(), decimals) == roundTo(to.y(), decimals);
}

std::vector<geom::Vec2> arcSplitPoints(const geom::Vec2 &from, const geom::Vec2 &centre, bool ccw, double sweep,
                                       int pieces) {
  std::vector<geom::Vec2> out;
  const geom::Vec2 r = from - centre;
  for (int k = 1; k <= pieces; ++k) {
    const double a = (ccw ? 1 : -1) * sweep * k / pieces;
    out.emplace_back(centre + geom::Vec2(r.x() * std::cos(a) - r.y() * std::sin(a),
                                         r.x() * std::sin(a) + r.y() * std::cos(a)));
  }
  return out;
}

std::string coolantWord(const std::string &mode) {
  if (mode == "flood" || mode == "through_tool")
    return "M8";
  if (mode == "mist")
    return "M7";
  return "M9";
}

} // namespace stepnc::backends
