// libFuzzer target for the Part 28 XML reader (frontend/part28/Reader.h) and
// what `stepnc compile` does with its translation: read as Part 21, bound to
// the built-in schema and lowered to the feature IR (driver/LoadModule.h).
// See tests/fuzz/README.md.
//
// For every input that looks like XML:
//   1. load it as `stepnc compile` does (at most kMaxErrors errors); the
//      diagnostics must render through every printer, every error must have
//      a place in the XML or its translation, and a module comes back exactly
//      when no error was reported;
//   2. if a module came back, verify it: the verifier's errors are located
//      too (the values lowering refuses point at the XML).
// Tags for $STEPNC_FUZZ_KNOWN: json, json-utf8, loc, unlocated, refusal,
// verifier.
#include "driver/LoadModule.h"
#include "driver/SchemaSelection.h"
#include "frontend/part28/Reader.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"
#include "tests/fuzz/Oracle.h"
#include "tests/fuzz/OracleIr.h"

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace {

using namespace stepnc;
using namespace stepnc::fuzz;

void checkInput(std::string_view input) {
  if (!p28::isXml(input))
    return;  // Part 21 has its own target
  static const driver::SchemaOptions options;
  const driver::SchemaSelection schemas(options);
  std::unique_ptr<SourceFile> source = SourceFile::fromString("fuzz-input.stpx", input);
  const SourceFile *xml = source.get();  // owned by the translation once there is one
  DiagnosticCollector collected;
  DiagnosticEngine diags(collected);
  diags.setMaxErrors(kMaxErrors);
  std::string usageError;
  auto module = driver::loadModule(source, schemas, diags, usageError);
  if (!usageError.empty())
    violation("refusal", "loading XML failed as a usage error", usageError + "\n--- input ---\n" + clip(input));
  checkReaderRun(module != nullptr, diags, collected.diags, {xml, source.get()}, input);
  if (!module)
    return;

  checkVerifies(*module, {xml, source.get()}, input);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  setTargetName("part28-fuzzer");
  checkInput(std::string_view(reinterpret_cast<const char *>(data), size));
  return 0;
}
