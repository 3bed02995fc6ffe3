// libFuzzer target for the IR text reader (ir/Parser.h), the verifier and
// the printer (see tests/fuzz/README.md).
//
// For every input:
//   1. parse it (at most kMaxErrors errors); the diagnostics must render
//      through every printer, every error must have a place in the input,
//      and the parser returns a module exactly when it reported no error;
//   2. if it parsed, verify it: every verifier error is located too (each
//      node remembers where its kind was written);
//   3. print the module; the text must parse again without errors and print
//      to the same bytes (print -> parse -> print is the identity).
// Tags for $STEPNC_FUZZ_KNOWN: json, json-utf8, loc, unlocated, refusal,
// verifier, reread, roundtrip.
#include "ir/Parser.h"
#include "ir/Printer.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"
#include "tests/fuzz/Oracle.h"
#include "tests/fuzz/OracleIr.h"

#include <cstdint>
#include <string>
#include <string_view>

namespace {

using namespace stepnc;
using namespace stepnc::fuzz;

void checkInput(std::string_view input) {
  auto source = SourceFile::fromString("fuzz-input.ir", input);
  auto module = readChecked(*source, input, ir::parseModule);
  if (!module)
    return;
  checkVerifies(*module, {source.get()}, input);
  const std::string printed = ir::printModule(*module);
  if (auto second = rereadClean(printed, input, ir::parseModule))
    checkSameText("roundtrip", "print -> parse -> print changed the text", printed, ir::printModule(*second));
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  setTargetName("ir-fuzzer");
  checkInput(std::string_view(reinterpret_cast<const char *>(data), size));
  return 0;
}
