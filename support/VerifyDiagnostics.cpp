#include "support/VerifyDiagnostics.h"

#include <ostream>
#include <string>

namespace stepnc {

namespace {

struct Expectation {
  Severity severity;
  uint32_t line;
  uint32_t col;  // 0: any column
  std::string text;
  uint32_t writtenAt;  // line of the annotation, for messages
  bool met = false;
};

bool parseUint(std::string_view s, size_t &i, uint32_t &out) {
  size_t start = i;
  uint64_t v = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9' && v < UINT32_MAX)
    v = v * 10 + static_cast<uint64_t>(s[i++] - '0');
  out = static_cast<uint32_t>(v);
  return i > start;
}

std::vector<Expectation> parseExpectations(const SourceFile &file, std::ostream &os, bool &ok) {
  std::vector<Expectation> out;
  std::string_view text = file.text();
  static constexpr std::string_view kTag = "expected-";
  for (size_t pos = text.find(kTag); pos != std::string_view::npos; pos = text.find(kTag, pos + 1)) {
    size_t i = pos + kTag.size();
    Severity sev;
    std::string_view rest = text.substr(i);
    if (rest.starts_with("error")) {
      sev = Severity::Error;
      i += 5;
    } else if (rest.starts_with("warning")) {
      sev = Severity::Warning;
      i += 7;
    } else if (rest.starts_with("note")) {
      sev = Severity::Note;
      i += 4;
    } else if (rest.starts_with("remark")) {
      sev = Severity::Remark;
      i += 6;
    } else {
      continue;
    }
    const uint32_t here = file.lineCol(pos).line;
    Expectation e{sev, here, 0, {}, here};
    if (i < text.size() && text[i] == '@') {
      ++i;
      uint32_t n = 0;
      if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
        bool minus = text[i++] == '-';
        if (!parseUint(text, i, n)) {
          os << file.name() << ':' << here << ": bad line offset in expectation\n";
          ok = false;
          continue;
        }
        e.line = minus ? here - n : here + n;
      } else if (parseUint(text, i, n)) {
        e.line = n;
      }
      if (i < text.size() && text[i] == ':') {
        ++i;
        parseUint(text, i, e.col);
      }
    }
    while (i < text.size() && text[i] == ' ')
      ++i;
    if (text.substr(i, 2) != "{{") {
      os << file.name() << ':' << here << ": expected '{{' in diagnostic expectation\n";
      ok = false;
      continue;
    }
    size_t close = text.find("}}", i + 2);
    if (close == std::string_view::npos) {
      os << file.name() << ':' << here << ": expected '}}' in diagnostic expectation\n";
      ok = false;
      continue;
    }
    e.text = std::string(text.substr(i + 2, close - i - 2));
    out.push_back(std::move(e));
  }
  return out;
}

void flatten(const Diagnostic &d, std::vector<const Diagnostic *> &out) {
  out.push_back(&d);
  for (const Diagnostic &n : d.notes)
    flatten(n, out);
}

} // namespace

bool verifyDiagnostics(const SourceFile &file, const std::vector<Diagnostic> &diags, std::ostream &os) {
  bool ok = true;
  std::vector<Expectation> expected = parseExpectations(file, os, ok);
  std::vector<const Diagnostic *> actual;
  for (const Diagnostic &d : diags)
    flatten(d, actual);
  for (const Diagnostic *d : actual) {
    if (!d->loc.valid() || d->loc.file != &file)
      continue;
    LineCol lc = file.lineCol(d->loc.offset);
    bool matched = false;
    for (Expectation &e : expected) {
      if (e.met || e.severity != d->severity || e.line != lc.line || (e.col && e.col != lc.col))
        continue;
      if (d->message.find(e.text) == std::string::npos)
        continue;
      e.met = matched = true;
      break;
    }
    if (!matched) {
      ok = false;
      os << file.name() << ':' << lc.line << ':' << lc.col << ": unexpected "
         << severityName(d->severity) << ": " << d->message << '\n';
    }
  }
  for (const Expectation &e : expected) {
    if (e.met)
      continue;
    ok = false;
    os << file.name() << ':' << e.writtenAt << ": expected " << severityName(e.severity)
       << " at line " << e.line;
    if (e.col)
      os << ", column " << e.col;
    os << " was not produced: {{" << e.text << "}}\n";
  }
  return ok;
}

} // namespace stepnc
