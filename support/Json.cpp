#include "support/Json.h"

#include "support/Format.h"
#include "support/Utf8.h"

#include <ostream>
#include <string>

namespace stepnc::json {

void appendQuoted(std::string &out, std::string_view s) {
  static const char *hex = "0123456789abcdef";
  out.push_back('"');
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x80) {
      // JSON must be valid UTF-8: bytes that are not become U+FFFD.
      size_t n = utf8::sequenceLength(s, i);
      if (n == 0) {
        out += "\\ufffd";
        ++i;
      } else {
        out.append(s.substr(i, n));
        i += n;
      }
      continue;
    }
    ++i;
    switch (c) {
    case '"': out += "\\\""; break;
    case '\\': out += "\\\\"; break;
    case '\n': out += "\\n"; break;
    case '\r': out += "\\r"; break;
    case '\t': out += "\\t"; break;
    default:
      if (c < 0x20 || c == 0x7F) {
        out += "\\u00";
        out.push_back(hex[c >> 4]);
        out.push_back(hex[c & 15]);
      } else {
        out.push_back(static_cast<char>(c));
      }
    }
  }
  out.push_back('"');
}

void Writer::separate() {
  if (afterKey_) {
    afterKey_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back())
      os_ << ',';
    first_.back() = false;
  }
}

Writer &Writer::beginObject() {
  separate();
  os_ << '{';
  first_.push_back(true);
  return *this;
}
Writer &Writer::endObject() {
  os_ << '}';
  first_.pop_back();
  return *this;
}
Writer &Writer::beginArray() {
  separate();
  os_ << '[';
  first_.push_back(true);
  return *this;
}
Writer &Writer::endArray() {
  os_ << ']';
  first_.pop_back();
  return *this;
}
Writer &Writer::key(std::string_view k) {
  separate();
  std::string s;
  appendQuoted(s, k);
  os_ << s << ':';
  afterKey_ = true;
  return *this;
}
Writer &Writer::value(std::string_view v) {
  separate();
  std::string s;
  appendQuoted(s, v);
  os_ << s;
  return *this;
}
Writer &Writer::value(uint64_t n) {
  separate();
  os_ << n;
  return *this;
}
Writer &Writer::value(int64_t n) {
  separate();
  os_ << n;
  return *this;
}
Writer &Writer::value(double d) {
  separate();
  os_ << formatShortest(d);
  return *this;
}
Writer &Writer::value(bool b) {
  separate();
  os_ << (b ? "true" : "false");
  return *this;
}

} // namespace stepnc::json
