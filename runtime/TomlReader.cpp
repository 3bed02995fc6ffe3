#include "runtime/TomlReader.h"

#include "support/Format.h"

#include <set>

namespace stepnc::runtime {

namespace {

std::string join(std::initializer_list<std::string_view> names) {
  std::string out;
  for (std::string_view n : names)
    out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

} // namespace

std::optional<toml::table> TomlReader::parse() {
  try {
    return toml::parse(file_.text(), std::string(file_.name()));
  } catch (const toml::parse_error &e) {
    error(e.source(), what_ + " is not valid TOML: " + std::string(e.description()));
    return std::nullopt;
  }
}

void TomlReader::error(const toml::source_region &where, const std::string &message) {
  diags_.error(locate(where.begin), message);
  ok_ = false;
}

void TomlReader::onlyKnown(const toml::table &table, std::initializer_list<std::string_view> known,
                           const std::string &where) {
  const std::set<std::string_view> names(known);
  for (const auto &[key, value] : table)
    if (!names.count(key.str()))
      error(key.source(), "unknown key '" + std::string(key.str()) + "' in " + where + " (known: " + join(known) + ")");
}

std::optional<double> TomlReader::number(const toml::table &table, std::string_view key, const std::string &where,
                                         const char *unit, double lo, double hi, bool required) {
  const toml::node *n = table.get(key);
  if (!n) {
    if (required)
      error(table.source(), where + " needs '" + std::string(key) + "' (" + unit + ")");
    return std::nullopt;
  }
  std::optional<double> v = n->value<double>();
  if (!v || !(*v >= lo && *v <= hi)) {
    error(n->source(), where + "." + std::string(key) + " must be a number of " + unit + " from " + formatTrimmed(lo, 6) +
                           " to " + formatTrimmed(hi, 6));
    return std::nullopt;
  }
  return v;
}

std::optional<std::string> TomlReader::text(const toml::table &table, std::string_view key, const std::string &where,
                                            bool required) {
  const toml::node *n = table.get(key);
  if (!n) {
    if (required)
      error(table.source(), where + " needs '" + std::string(key) + "' (a string)");
    return std::nullopt;
  }
  if (auto s = n->value<std::string>())
    return s;
  error(n->source(), where + "." + std::string(key) + " must be a string");
  return std::nullopt;
}

const toml::table *TomlReader::table(const toml::table &parent, std::string_view key, const std::string &where,
                                     bool required) {
  const toml::node *n = parent.get(key);
  if (!n) {
    if (required)
      error(parent.source(), what_ + " needs a [" + where + "] table");
    return nullptr;
  }
  if (!n->is_table()) {
    error(n->source(), "'" + where + "' must be a table ([" + where + "])");
    return nullptr;
  }
  return n->as_table();
}

SourceLoc TomlReader::locate(const toml::source_position &p) const {
  // Line and column (1-based) back to a byte offset, so the engine prints the
  // line.
  const std::string_view text = file_.text();
  uint64_t offset = 0;
  for (uint32_t line = 1; line < p.line && offset < text.size(); ++offset)
    if (text[offset] == '\n')
      ++line;
  if (p.line == 0)
    offset = 0;
  else
    offset = std::min<uint64_t>(offset + (p.column > 0 ? p.column - 1 : 0), text.size());
  return SourceLoc{&file_, offset};
}

} // namespace stepnc::runtime
