#include "backends/common/ToolTable.h"

#include "ir/Plausible.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

namespace stepnc::backends {

namespace {

bool isSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && isSpace(s.front()))
    s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back()))
    s.remove_suffix(1);
  return s;
}

/// The first word of the first line that has one, outside comments of
/// either format: `T<digits>` says the table is LinuxCNC's.
bool looksLikeLinuxCnc(std::string_view text) {
  size_t i = 0;
  while (i < text.size()) {
    if (isSpace(text[i])) {
      ++i;
      continue;
    }
    if (text[i] == '#' || text[i] == ';') {
      i = text.find('\n', i);
      if (i == std::string_view::npos)
        return false;
      continue;
    }
    if (text[i] != 'T' && text[i] != 't')
      return false;
    size_t j = i + 1;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])))
      ++j;
    return j > i + 1 && (j == text.size() || isSpace(text[j]) || text[j] == ';');
  }
  return false;
}

} // namespace

bool ToolTable::parseLinuxCncLine(const SourceFile &file, size_t lineStart, std::string_view line,
                                  std::string_view comment, DiagnosticEngine &diags) {
  Entry e;
  bool hasNumber = false;
  size_t i = 0;
  while (i < line.size()) {
    if (isSpace(line[i])) {
      ++i;
      continue;
    }
    const size_t start = i;
    while (i < line.size() && !isSpace(line[i]))
      ++i;
    const std::string_view word = line.substr(start, i - start);
    const SourceLoc loc{&file, lineStart + start};
    const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(word.front())));
    const std::string_view value = word.substr(1);
    if (letter == 'T' || letter == 'P') {
      long n = 0;
      auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
      if (ec != std::errc() || p != value.data() + value.size() || n < (letter == 'T' ? 1 : 0) || n > 99999) {
        diags.error(loc, "tool table: '" + std::string(word) + "' is not a " +
                             (letter == 'T' ? "tool number (T1 to T99999)" : "pocket number (P0 to P99999)"));
        return false;
      }
      if (letter == 'T') {
        if (hasNumber) {
          diags.error(loc, "tool table: a second tool number on the line");
          return false;
        }
        e.number = static_cast<int>(n);
        e.loc = loc;
        hasNumber = true;
      }
      continue;
    }
    if (std::string_view("XYZABCUVWDIJQ").find(letter) == std::string_view::npos) {
      diags.error(loc, "tool table: '" + std::string(word) +
                           "' is not a word of a LinuxCNC tool table (T, P, X Y Z A B C U V W, D, I, J, Q)");
      return false;
    }
    // strtod reads '+' signs, which LinuxCNC writes on its offsets.
    const std::string number(value);
    char *end = nullptr;
    const double v = std::strtod(number.c_str(), &end);
    if (number.empty() || *end != '\0' || !std::isfinite(v)) {
      diags.error(loc, "tool table: '" + std::string(word) + "' is not a number after " + std::string(1, letter));
      return false;
    }
    if (letter == 'Z')
      e.length = v;
    else if (letter == 'D') {
      if (v < 0) {
        diags.error(loc, "tool table: diameter " + std::string(word) + " is negative");
        return false;
      }
      e.diameter = v;
      e.diameterLoc = loc;
    }
  }
  if (!hasNumber) {
    diags.error(SourceLoc{&file, lineStart}, "tool table: a line without its tool number T<n>");
    return false;
  }
  for (const Entry &other : entries_)
    if (other.number == e.number) {
      diags.error(e.loc, "tool table: T" + std::to_string(e.number) + " is listed twice")
          .note(other.loc, "first listed here");
      return false;
    }
  e.key = std::string(trim(comment));
  entries_.push_back(std::move(e));
  return true;
}

std::optional<ToolTable> ToolTable::parse(const SourceFile &file, DiagnosticEngine &diags) {
  ToolTable table;
  table.name_ = std::string(file.name());
  const std::string_view text = file.text();
  bool ok = true;
  size_t lineStart = 0;
  if (looksLikeLinuxCnc(text)) {
    table.format_ = Format::LinuxCnc;
    while (lineStart < text.size()) {
      size_t lineEnd = text.find('\n', lineStart);
      if (lineEnd == std::string_view::npos)
        lineEnd = text.size();
      std::string_view line = text.substr(lineStart, lineEnd - lineStart);
      std::string_view comment;
      if (const size_t semi = line.find(';'); semi != std::string_view::npos) {
        comment = line.substr(semi + 1);
        line = line.substr(0, semi);
      }
      if (!trim(line).empty())
        ok = table.parseLinuxCncLine(file, lineStart, line, comment, diags) && ok;
      lineStart = lineEnd + 1;
    }
    if (!ok)
      return std::nullopt;
    return table;
  }
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
      size_t next = 2;
      if (!bad && fields.size() > next && fields[next].first.find('=') == std::string::npos) {
        const std::string &l = fields[next].first;
        double length = 0;
        auto [p, ec] = std::from_chars(l.data(), l.data() + l.size(), length);
        if (ec != std::errc() || p != l.data() + l.size() || !(length >= 0)) {
          diags.error(SourceLoc{&file, fields[next].second}, "tool table: '" + l + "' is not a length in mm");
          bad = true;
        }
        e.length = length;
        ++next;
      }
      // The holder's geometry, as key=value fields.
      for (; !bad && next < fields.size(); ++next) {
        const std::string &f = fields[next].first;
        const size_t eq = f.find('=');
        const SourceLoc at{&file, fields[next].second};
        const std::string name = eq == std::string::npos ? f : f.substr(0, eq);
        std::optional<double> *slot =
            name == "holder" ? &e.holderDiameter : name == "stickout" ? &e.stickout : nullptr;
        if (eq == std::string::npos || !slot) {
          diags.error(at, "tool table: '" + f + "' is not a field of a tool's line (tool, number, length, then " +
                              "holder=<diameter mm>, stickout=<mm from the tip to the holder>)");
          bad = true;
          break;
        }
        const std::string v = f.substr(eq + 1);
        double value = 0;
        auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
        if (ec != std::errc() || p != v.data() + v.size() || !(value > 0) || value > ir::kMaxLengthMm) {
          diags.error(at.advanced(eq + 1), "tool table: '" + v + "' is not a positive length in mm for " + name);
          bad = true;
          break;
        }
        if (slot->has_value()) {
          diags.error(at, "tool table: " + name + "= is given twice");
          bad = true;
          break;
        }
        *slot = value;
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

void ToolTable::applyGeometry(ir::Module &module) const {
  for (ir::Node &n : module.root.children) {
    if (n.kind != ir::Kind::Tool)
      continue;
    const Entry *e = find(n);
    if (!e)
      continue;
    if (e->holderDiameter)
      n.set("holder_diameter", ir::Value::length(*e->holderDiameter));
    if (e->stickout)
      n.set("overall_length", ir::Value::length(*e->stickout));
  }
}

const ToolTable::Entry *ToolTable::find(const ir::Node &tool) const {
  for (const Entry &e : entries_)
    if (e.bySymbol ? e.key == tool.symbol : (!tool.label.empty() && e.key == tool.label))
      return &e;
  return nullptr;
}

const ToolTable::Entry *ToolTable::findNumber(int number) const {
  for (const Entry &e : entries_)
    if (e.number == number)
      return &e;
  return nullptr;
}

} // namespace stepnc::backends
