#include "support/Format.h"

#include <charconv>
#include <cmath>

namespace stepnc {

std::string formatShortest(double value) {
  if (value == 0.0)
    value = 0.0;  // folds -0
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, r.ptr);
}

std::string formatExact(double value) {
  if (value == 0.0)
    value = 0.0;  // folds -0
  char buf[400];
  auto r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed);
  return std::string(buf, r.ptr);
}

std::string formatFixed(double value, int decimals) {
  char buf[400];
  auto r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed, decimals);
  std::string s(buf, r.ptr);
  if (!s.empty() && s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos)
    s.erase(0, 1);
  return s;
}

std::string formatTrimmed(double value, int decimals) {
  std::string s = formatFixed(value, decimals);
  if (s.find('.') == std::string::npos)
    return s;
  while (s.back() == '0')
    s.pop_back();
  if (s.back() == '.')
    s.pop_back();
  return s;
}

std::string formatTuple(std::initializer_list<double> values, int decimals) {
  std::string s = "(";
  for (double v : values) {
    if (s.size() > 1)
      s += ", ";
    s += formatFixed(v, decimals);
  }
  s += ')';
  return s;
}

std::string hashId(uint64_t id) {
  std::string s(1, '#');
  s += std::to_string(id);
  return s;
}

} // namespace stepnc
