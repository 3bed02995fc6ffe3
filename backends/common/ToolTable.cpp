#include "backends/common/ToolTable.h"

#include <cctype>
#include <charconv>

namespace stepnc::backends {

std::optional<ToolTable> ToolTable::parse(const SourceFile &file, DiagnosticEngine &diags) {
  ToolTable table;
  table.name_ = std::string(file.name());
  const std::string_view text = file.text();
  bool ok = true;
  size_t lineStart = 0;
  while (lineStart < text.size()) {
    size_t lineEnd = text.find('\n', lineStart);
    if (lineEnd == std::string_view::npos)
      lineEnd = text.size();
    std::string_view line = text.substr(lineStart, lineEnd - lineStart);
    // A '#' outside quotes starts a comment.
    bool quoted = false;
    for (size_t k = 0; k < line.size(); ++k) {
      if (line[k] == '"')
        quoted = !quoted;
      else if (line[k] == '#' && !quoted) {
        line = line.substr(0, k);
        break;
      }
    }
    // Split into fields; a quoted field may hold spaces.
    std::vector<std::pair<std::string, size_t>> fields;  // text, offset in the file
    size_t i = 0;
    bool bad = false;
    while (i < line.size()) {
      if (std::isspace(static_cast<unsigned char>(line[i]))) {
        ++i;
        continue;
      }
      const size_t start = i;
      if (line[i] == '"') {
        const size_t close = line.find('"', i + 1);
        if (close == std::string_view::npos) {
          diags.error(SourceLoc{&file, lineStart + i}, "unterminated quoted tool id in the tool table");
          bad = true;
          break;
        }
        fields.emplace_back(std::string(line.substr(i, close + 1 - i)), lineStart + start);
        i = close + 1;
      } else {
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i])))
          ++i;
        fields.emplace_back(std::string(line.substr(start, i - start)), lineStart + start);
      }
    }
    if (!bad && !fields.empty()) {
      Entry e;
      e.loc = SourceLoc{&file, fields[0].second};
      const std::string &key = fields[0].first;
      if (key.front() == '"') {
        e.key = key.substr(1, key.size() - 2);
      } else if (key.front() == '%') {
        e.key = key;
        e.bySymbol = true;
      } else {
        diags.error(e.loc, "tool table: '" + key + "' is neither a quoted STEP-NC tool id nor a %symbol");
        bad = true;
      }
      long number = 0;
      if (!bad && fields.size() >= 2) {
        const std::string &n = fields[1].first;
        auto [p, ec] = std::from_chars(n.data(), n.data() + n.size(), number);
        if (ec != std::errc() || p != n.data() + n.size() || number < 1 || number > 99999) {
          diags.error(SourceLoc{&file, fields[1].second}, "tool table: '" + n + "' is not a tool number (1 to 99999)");
          bad = true;
        }
        e.number = static_cast<int>(number);
      } else if (!bad) {
        diags.error(e.loc, "tool table: " + key + " has no tool number");
        bad = true;
      }
      if (!bad && fields.size() >= 3) {
        const std::string &l = fields[2].first;
        double length = 0;
        auto [p, ec] = std::from_chars(l.data(), l.data() + l.size(), length);
        if (ec != std::errc() || p != l.data() + l.size() || !(length >= 0)) {
          diags.error(SourceLoc{&file, fields[2].second}, "tool table: '" + l + "' is not a length in mm");
          bad = true;
        }
        e.length = length;
      }
      if (!bad && fields.size() > 3) {
        diags.error(SourceLoc{&file, fields[3].second}, "tool table: more than three fields (tool, number, length)");
        bad = true;
      }
      if (!bad)
        table.entries_.push_back(std::move(e));
    }
    ok = ok && !bad;
    lineStart = lineEnd + 1;
  }
  if (!ok)
    return std::nullopt;
  return table;
}

const ToolTable::Entry *ToolTable::find(const ir::Node &tool) const {
  for (const Entry &e : entries_)
    if (e.bySymbol ? e.key == tool.symbol : (!tool.label.empty() && e.key == tool.label))
      return &e;
  return nullptr;
}

} // namespace stepnc::backends
