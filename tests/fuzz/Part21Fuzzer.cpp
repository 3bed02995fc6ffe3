// libFuzzer target for the Part 21 reader, decoder, writer and diagnostic
// printers (see tests/fuzz/README.md).
//
// For every input:
//   1. read it (readPart21 + checkInstances, at most kMaxErrors errors) and
//      render every diagnostic through the text printer (with and without
//      source lines) and the JSON printer; the JSON must be well-formed UTF-8
//      JSON, and every diagnostic must point inside the input; also run the
//      --verify-diagnostics expectation parser over the input;
//   2. if the input read without errors:
//      - it must contain "END-ISO-10303-21" (a file cut short is an error), and
//        cutting it anywhere before the first "END-ISO-10303-21" must give
//        an error;
//      - the canonical text (writePart21) must be produced without error, read
//        back without errors and without new warnings, give the same instance
//        graph (compareGraphs == ""), and writing it again must give the same
//        bytes (write -> read -> write is idempotent).
// Tags for $STEPNC_FUZZ_KNOWN (Oracle.h): json, json-utf8, end-keyword,
// truncation, self-compare, write, reread, new-warnings, graph, idempotence,
// loc, and utf8-lax (see hasLaxUtf8).
// Any violation prints what went wrong and calls abort(), which libFuzzer
// records as a crash. Sanitizer reports (ASan, UBSan, leaks) and timeouts are
// caught by libFuzzer itself.
//
// The same file is linked into part21-fuzz-replay (ReplayMain.cpp) so the
// saved regressions run in the normal test suite without libFuzzer.
#include "frontend/part21/Part21File.h"
#include "frontend/part21/Writer.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"
#include "support/VerifyDiagnostics.h"
#include "tests/fuzz/Oracle.h"

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace {

using namespace stepnc;
using namespace stepnc::fuzz;

constexpr std::string_view kEndKeyword = "END-ISO-10303-21";

/// One read of a text: the source, its diagnostics and the instance table.
struct Parsed {
  std::unique_ptr<SourceFile> source;
  DiagnosticCollector collected;
  DiagnosticEngine diags{collected};
  std::unique_ptr<p21::Part21File> file;

  Parsed(std::string name, std::string_view text) {
    source = SourceFile::fromString(std::move(name), text);
    diags.setMaxErrors(kMaxErrors);
    file = p21::readPart21(*source, diags);
    // stepnc check/convert skip this when the error limit was reached; calling
    // it anyway covers decodeInstance on whatever the scanner kept.
    p21::checkInstances(*file, diags);
  }
};

/// True if `input` has a 3- or 4-byte UTF-8 lead byte followed by a byte that
/// makes the sequence overlong, a surrogate or beyond U+10FFFF, which the
/// decoder used to accept (regressions/utf8-*.p21, fixed in afd253d). With
/// "utf8-lax" in $STEPNC_FUZZ_KNOWN such inputs skip the write/read checks.
bool hasLaxUtf8(std::string_view input) {
  for (size_t i = 0; i + 1 < input.size(); ++i) {
    const auto c = static_cast<unsigned char>(input[i]);
    const auto d = static_cast<unsigned char>(input[i + 1]);
    if ((c == 0xE0 && d < 0xA0) || (c == 0xED && d >= 0xA0) || (c == 0xF0 && d < 0x90) ||
        (c == 0xF4 && d >= 0x90))
      return true;
  }
  return false;
}

/// What `stepnc check --stats` asks of every file, errors or not.
void exerciseQueries(const p21::Part21File &file) {
  size_t total = 0;
  for (const p21::InstanceEntry &e : file.entries()) {
    total += file.describe(e).size();
    total += file.entityName(e).size();
  }
  for (const std::string &s : file.schemaNames())
    total += s.size();
  // Keep the work observable.
  if (total == SIZE_MAX)
    std::abort();
}

/// The canonical text of `file`; false (after a suppressed violation) when
/// the writer failed.
bool writeCanonical(const p21::Part21File &file, const char *which, std::string &text) {
  DiagnosticCollector collected;
  DiagnosticEngine diags(collected);
  bool ok = false;
  text = p21::writePart21ToString(file, diags, &ok);
  renderDiagnostics(collected.diags);
  if (ok && !diags.hasErrors())
    return true;
  violation("write", "writePart21 failed on a file that read without errors",
            std::string("writing the ") + which + " read\n" + textOf(collected.diags));
  return false;
}

void checkInput(std::string_view input) {
  Parsed first("fuzz-input.p21", input);
  checkLocations(first.collected.diags, {first.source.get()}, false);
  renderDiagnostics(first.collected.diags);
  {
    // `stepnc check --verify-diagnostics` parses expectations out of the
    // input's comments: only robustness is checked here.
    std::ostringstream mismatches;
    (void)verifyDiagnostics(*first.source, first.collected.diags, mismatches);
  }
  exerciseQueries(*first.file);
  if (first.diags.hasErrors())
    return;

  // A clean file ends with END-ISO-10303-21; anything cut before its first
  // occurrence has lost the real end keyword and must be an error.
  const size_t endPos = input.find(kEndKeyword);
  if (endPos == std::string_view::npos) {
    violation("end-keyword", "input without 'END-ISO-10303-21' read without errors",
              "--- input ---\n" + clip(input));
  } else {
    const size_t cut = static_cast<size_t>((input.size() * 2654435761u) % (endPos + 1));
    Parsed truncated("fuzz-truncated.p21", input.substr(0, cut));
    renderDiagnostics(truncated.collected.diags);
    if (!truncated.diags.hasErrors())
      violation("truncation", "input cut short read without errors",
                "cut at byte " + std::to_string(cut) + " of " + std::to_string(input.size()) +
                    "\n--- truncated input ---\n" + clip(input.substr(0, cut)));
  }

  if (std::string self = p21::compareGraphs(*first.file, *first.file); !self.empty())
    violation("self-compare", "compareGraphs(file, file) is not empty", self);

  if (suppressed("utf8-lax") && hasLaxUtf8(input))
    return;

  std::string text1;
  if (!writeCanonical(*first.file, "first", text1))
    return;
  Parsed second("fuzz-canonical.p21", text1);
  renderDiagnostics(second.collected.diags);
  if (second.diags.hasErrors()) {
    violation("reread", "the canonical text does not read back without errors",
              textOf(second.collected.diags) + "--- canonical text ---\n" + clip(text1) +
                  "\n--- input ---\n" + clip(input));
    return;
  }
  if (second.diags.warningCount() > first.diags.warningCount())
    violation("new-warnings", "the canonical text reads back with new warnings",
              textOf(second.collected.diags) + "--- canonical text ---\n" + clip(text1));

  if (std::string diff = p21::compareGraphs(*first.file, *second.file); !diff.empty()) {
    violation("graph", "write -> read changed the instance graph",
              diff + "\n--- canonical text ---\n" + clip(text1) + "\n--- input ---\n" +
                  clip(input));
    return;
  }

  std::string text2;
  if (!writeCanonical(*second.file, "second", text2))
    return;
  checkSameText("idempotence", "write -> read -> write is not idempotent", text1, text2);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  setTargetName("part21-fuzzer");
  checkInput(std::string_view(reinterpret_cast<const char *>(data), size));
  return 0;
}
