// A minimal streaming JSON writer: enough for diagnostics and reports, with
// correct string escaping and deterministic number formatting.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::json {

/// Appends `s` to `out` as a quoted JSON string.
void appendQuoted(std::string &out, std::string_view s);

class Writer {
public:
  explicit Writer(std::ostream &os) : os_(os) {}
  Writer &beginObject();
  Writer &endObject();
  Writer &beginArray();
  Writer &endArray();
  Writer &key(std::string_view k);
  Writer &value(std::string_view s);
  Writer &value(const char *s) { return value(std::string_view(s)); }
  Writer &value(uint64_t n);
  Writer &value(int64_t n);
  Writer &value(double d);
  Writer &value(bool b);

private:
  void separate();
  std::ostream &os_;
  std::vector<bool> first_;  // per open container: no element written yet
  bool afterKey_ = false;
};

} // namespace stepnc::json
