// The checks every fuzz target shares (Oracle.h).
#include "tests/fuzz/Oracle.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace stepnc::fuzz {

namespace {

const char *g_targetName = "fuzzer";

// --- JSON well-formedness ------------------------------------------------------

/// A strict JSON (RFC 8259) checker: enough to tell whether the diagnostic
/// printer's output is valid JSON text in valid UTF-8.
class JsonChecker {
public:
  explicit JsonChecker(std::string_view s) : s_(s) {}

  /// Set when a string held bytes that are not valid UTF-8 (checking goes on).
  bool badUtf8 = false;
  std::string utf8Error;

  /// Empty when `s` is one valid JSON value (surrounded by white space).
  std::string check() {
    ws();
    if (!value(0))
      return error_;
    ws();
    if (i_ != s_.size()) {
      fail("trailing bytes after the JSON value");
      return error_;
    }
    return {};
  }

private:
  bool fail(const char *why) {
    if (error_.empty())
      error_ = std::string(why) + " at byte " + std::to_string(i_);
    return false;
  }
  void noteBadUtf8() {
    if (!badUtf8)
      utf8Error = "byte " + std::to_string(i_) + " is not valid UTF-8";
    badUtf8 = true;
  }
  void ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\n' || s_[i_] == '\r' || s_[i_] == '\t'))
      ++i_;
  }
  bool lit(std::string_view word) {
    if (s_.substr(i_, word.size()) != word)
      return fail("bad literal");
    i_ += word.size();
    return true;
  }
  bool value(unsigned depth) {
    if (depth > 64)
      return fail("JSON nested too deeply");
    if (i_ >= s_.size())
      return fail("unexpected end of JSON");
    switch (s_[i_]) {
    case '{': return container(depth, '}', true);
    case '[': return container(depth, ']', false);
    case '"': return string();
    case 't': return lit("true");
    case 'f': return lit("false");
    case 'n': return lit("null");
    default: return number();
    }
  }
  bool container(unsigned depth, char close, bool object) {
    ++i_;
    ws();
    if (i_ < s_.size() && s_[i_] == close) {
      ++i_;
      return true;
    }
    for (;;) {
      ws();
      if (object) {
        if (i_ >= s_.size() || s_[i_] != '"')
          return fail("expected a key");
        if (!string())
          return false;
        ws();
        if (i_ >= s_.size() || s_[i_] != ':')
          return fail("expected ':'");
        ++i_;
        ws();
      }
      if (!value(depth + 1))
        return false;
      ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == close) {
        ++i_;
        return true;
      }
      return fail("expected ',' or the end of the container");
    }
  }
  bool string() {
    ++i_;  // '"'
    for (;;) {
      if (i_ >= s_.size())
        return fail("unterminated string");
      const auto c = static_cast<unsigned char>(s_[i_]);
      if (c == '"') {
        ++i_;
        return true;
      }
      if (c < 0x20)
        return fail("unescaped control character in string");
      if (c == '\\') {
        if (i_ + 1 >= s_.size())
          return fail("unterminated escape");
        const char e = s_[i_ + 1];
        if (e == 'u') {
          if (i_ + 6 > s_.size())
            return fail("short \\u escape");
          for (size_t k = i_ + 2; k < i_ + 6; ++k)
            if (!std::isxdigit(static_cast<unsigned char>(s_[k])))
              return fail("bad \\u escape");
          i_ += 6;
        } else if (std::string_view("\"\\/bfnrt").find(e) != std::string_view::npos) {
          i_ += 2;
        } else {
          return fail("bad escape");
        }
        continue;
      }
      if (c < 0x80) {
        ++i_;
        continue;
      }
      // UTF-8: shortest form, no surrogates, at most U+10FFFF.
      size_t n = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
      if (n == 0 || c > 0xF4 || i_ + n > s_.size()) {
        noteBadUtf8();
        ++i_;
        continue;
      }
      uint32_t cp = n == 2 ? (c & 0x1F) : n == 3 ? (c & 0x0F) : (c & 0x07);
      bool ok = true;
      for (size_t k = 1; k < n && ok; ++k) {
        const auto b = static_cast<unsigned char>(s_[i_ + k]);
        ok = (b & 0xC0) == 0x80;
        cp = (cp << 6) | (b & 0x3F);
      }
      if (!ok || (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) || cp > 0x10FFFF ||
          (cp >= 0xD800 && cp < 0xE000)) {
        noteBadUtf8();
        ++i_;
        continue;
      }
      i_ += n;
    }
  }
  bool number() {
    const size_t start = i_;
    if (i_ < s_.size() && s_[i_] == '-')
      ++i_;
    auto digits = [&] {
      size_t d = i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9')
        ++i_;
      return i_ - d;
    };
    const size_t intStart = i_;
    const size_t n = digits();
    if (n == 0 || (n > 1 && s_[intStart] == '0'))
      return fail("bad number");
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      if (digits() == 0)
        return fail("bad number fraction");
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-'))
        ++i_;
      if (digits() == 0)
        return fail("bad number exponent");
    }
    return i_ > start;
  }

  std::string_view s_;
  size_t i_ = 0;
  std::string error_;
};

} // namespace

void setTargetName(const char *name) { g_targetName = name; }

std::string clip(std::string_view s, size_t max) {
  if (s.size() <= max)
    return std::string(s);
  return std::string(s.substr(0, max)) + "\n[... " + std::to_string(s.size() - max) +
         " more bytes]";
}

std::string textOf(const std::vector<Diagnostic> &diags) {
  std::ostringstream os;
  TextDiagnosticPrinter printer(os, true);
  for (const Diagnostic &d : diags)
    printer.handle(d);
  return os.str();
}

bool suppressed(std::string_view tag) {
  static const std::string known = [] {
    const char *env = std::getenv("STEPNC_FUZZ_KNOWN");
    return "," + std::string(env ? env : "") + ",";
  }();
  return known.find("," + std::string(tag) + ",") != std::string::npos;
}

void violation(std::string_view tag, const char *what, const std::string &detail) {
  if (suppressed(tag))
    return;
  std::fprintf(stderr, "\n==== %s oracle violation [%.*s]: %s ====\n%s\n", g_targetName,
               static_cast<int>(tag.size()), tag.data(), what, detail.c_str());
  std::fflush(stderr);
  std::abort();
}

void renderDiagnostics(const std::vector<Diagnostic> &diags) {
  std::ostringstream text, brief, json;
  TextDiagnosticPrinter withSource(text, true);
  TextDiagnosticPrinter withoutSource(brief, false);
  JsonDiagnosticPrinter jsonPrinter(json);
  for (const Diagnostic &d : diags) {
    withSource.handle(d);
    withoutSource.handle(d);
    jsonPrinter.handle(d);
  }
  jsonPrinter.finish();
  const std::string out = json.str();
  JsonChecker checker(out);
  std::string why = checker.check();
  if (!why.empty())
    violation("json", "JsonDiagnosticPrinter wrote invalid JSON",
              why + "\n--- JSON output ---\n" + clip(out) + "\n--- text output ---\n" +
                  clip(text.str()));
  if (checker.badUtf8)
    violation("json-utf8", "JsonDiagnosticPrinter wrote bytes that are not UTF-8",
              checker.utf8Error + "\n--- JSON output ---\n" + clip(out) +
                  "\n--- text output ---\n" + clip(text.str()));
}

namespace {

bool pointsInto(const SourceLoc &loc, std::initializer_list<const SourceFile *> sources) {
  for (const SourceFile *s : sources)
    if (s && loc.file == s)
      return loc.offset <= s->text().size();
  return false;
}

} // namespace

void checkLocations(const std::vector<Diagnostic> &diags, std::initializer_list<const SourceFile *> sources,
                    bool errorsLocated) {
  for (const Diagnostic &d : diags) {
    if (d.loc.valid() && !pointsInto(d.loc, sources))
      violation("loc", "a diagnostic points outside the files read",
                "offset " + std::to_string(d.loc.offset) + ": " + d.message);
    if (errorsLocated && d.severity == Severity::Error && !d.loc.valid())
      violation("unlocated", "an error without a place in the input", textOf({d}));
    checkLocations(d.notes, sources, false);
  }
}

void checkRefusal(bool accepted, const DiagnosticEngine &diags, const std::vector<Diagnostic> &collected,
                  std::string_view input) {
  if (!accepted && !diags.hasErrors())
    violation("refusal", "the reader refused the input without an error",
              textOf(collected) + "--- input ---\n" + clip(input));
  if (accepted && diags.hasErrors())
    violation("refusal", "the reader accepted the input and reported an error",
              textOf(collected) + "--- input ---\n" + clip(input));
}

void checkSameText(std::string_view tag, const char *what, const std::string &first, const std::string &second) {
  if (first == second)
    return;
  size_t at = 0;
  while (at < first.size() && at < second.size() && first[at] == second[at])
    ++at;
  violation(tag, what,
            "texts differ from byte " + std::to_string(at) + "\n--- first ---\n" + clip(first) +
                "\n--- second ---\n" + clip(second));
}

void checkReaderRun(bool accepted, const DiagnosticEngine &diags, const std::vector<Diagnostic> &collected,
                    std::initializer_list<const SourceFile *> sources, std::string_view input) {
  renderDiagnostics(collected);
  checkLocations(collected, sources, true);
  checkRefusal(accepted, diags, collected, input);
}

} // namespace stepnc::fuzz
