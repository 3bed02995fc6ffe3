// What every fuzz target of stepnc checks of a reader's diagnostics, and how
// a target reports a broken check (tests/fuzz/README.md): each diagnostic is
// rendered by every printer (the JSON must be valid JSON in valid UTF-8),
// points inside a source the target read, and, where the reader promises
// it, every error has a place; a reader that refuses its input says why.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::fuzz {

/// The name a violation banner starts with ("part21-fuzzer").
void setTargetName(const char *name);

/// `s`, cut to `max` bytes with a note of how many more there were.
std::string clip(std::string_view s, size_t max = 4000);

/// The diagnostics as the text printer writes them.
std::string textOf(const std::vector<Diagnostic> &diags);

/// True when `tag` is listed (comma-separated) in $STEPNC_FUZZ_KNOWN: a long
/// run can get past a known, reported bug. Each target lists its tags.
bool suppressed(std::string_view tag);

/// Reports a broken check and aborts, which libFuzzer records as a crash;
/// returns only when `tag` is suppressed.
void violation(std::string_view tag, const char *what, const std::string &detail);

/// Renders the diagnostics through every printer (so the printers are fuzzed
/// too) and checks that the JSON rendering is valid JSON in valid UTF-8
/// (tags json, json-utf8).
void renderDiagnostics(const std::vector<Diagnostic> &diags);

/// Every located diagnostic (and note) points into one of `sources` (tag
/// loc); with `errorsLocated`, every error has a place (tag unlocated).
void checkLocations(const std::vector<Diagnostic> &diags, std::initializer_list<const SourceFile *> sources,
                    bool errorsLocated);

/// A reader that returned nothing reported an error, and one that returned
/// a result reported none (tag refusal).
void checkRefusal(bool accepted, const DiagnosticEngine &diags, const std::vector<Diagnostic> &collected,
                  std::string_view input);

/// `second` is `first` byte for byte (tag `tag`); else the banner says
/// where they part.
void checkSameText(std::string_view tag, const char *what, const std::string &first, const std::string &second);

/// All of the above for one reader's run over `input`: the diagnostics are
/// rendered, located inside `sources` (errors with a place), and agree with
/// whether the reader accepted the input.
void checkReaderRun(bool accepted, const DiagnosticEngine &diags, const std::vector<Diagnostic> &collected,
                    std::initializer_list<const SourceFile *> sources, std::string_view input);

/// At most this many errors per read, as `stepnc` stops at its default.
inline constexpr unsigned kMaxErrors = 20;

/// Runs `read(source, diags)` (a reader returning a pointer or an optional)
/// and checks the run (checkReaderRun against `source` alone).
template <class Read>
auto readChecked(const SourceFile &source, std::string_view input, Read read) {
  DiagnosticCollector collected;
  DiagnosticEngine diags(collected);
  diags.setMaxErrors(kMaxErrors);
  auto result = read(source, diags);
  checkReaderRun(static_cast<bool>(result), diags, collected.diags, {&source}, input);
  return result;
}

/// Reads `written`, what a writer made of `input`, again with `read`: it
/// must read without errors (tag reread); empty when it did not.
template <class Read>
auto rereadClean(const std::string &written, std::string_view input, Read read) {
  auto source = SourceFile::fromString("fuzz-written", written);
  DiagnosticCollector collected;
  DiagnosticEngine diags(collected);
  auto result = read(*source, diags);
  if (!result || diags.hasErrors()) {
    violation("reread", "what the writer wrote does not read again",
              textOf(collected.diags) + "--- written ---\n" + clip(written) + "\n--- input ---\n" + clip(input));
    return decltype(result){};
  }
  return result;
}

} // namespace stepnc::fuzz
