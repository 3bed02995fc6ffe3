// libFuzzer target for the native motion format's reader and writer
// (runtime/NativeFormat.h) and the reference player that `stepnc sim` runs
// on what it read (see tests/fuzz/README.md).
//
// For every input:
//   1. read it (at most kMaxErrors errors); the diagnostics must render
//      through every printer, every error must have a place in the input,
//      and the reader returns a trajectory exactly when it reported no error;
//   2. if it read, write it again: that text must read without errors and
//      write to the same bytes (write -> read -> write is the identity);
//   3. play it on the shipped hsc-3axis machine, as `stepnc sim` would, at a
//      sampling period long enough for at most kMaxSamples samples; the report
//      must be finite.
// Tags for $STEPNC_FUZZ_KNOWN: json, json-utf8, loc, unlocated, refusal,
// reread, roundtrip, report.
#include "runtime/Machine.h"
#include "runtime/NativeFormat.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"
#include "tests/fuzz/Oracle.h"
#include "tests/fuzz/OracleRuntime.h"

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

namespace {

using namespace stepnc;
using namespace stepnc::fuzz;

const runtime::Machine &machine() {
  static const runtime::Machine m = [] {
    std::unique_ptr<SourceFile> file;
    DiagnosticCollector collected;
    DiagnosticEngine diags(collected);
    auto loaded = runtime::loadMachine("hsc-3axis", file, diags);
    if (!loaded) {
      std::fprintf(stderr, "native-fuzzer: the shipped machine hsc-3axis does not load\n");
      std::abort();
    }
    return *loaded;
  }();
  return m;
}

void checkInput(std::string_view input) {
  auto source = SourceFile::fromString("fuzz-input.motion", input);
  auto trajectory = readChecked(*source, input, runtime::readNative);
  if (!trajectory)
    return;
  const std::string written = runtime::writeNative(*trajectory, "fuzz-input.motion");
  if (auto second = rereadClean(written, input, runtime::readNative))
    checkSameText("roundtrip", "write -> read -> write changed the text", written,
                  runtime::writeNative(*second, "fuzz-input.motion"));
  checkPlays(*trajectory, machine(), "report", input);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  setTargetName("native-fuzzer");
  checkInput(std::string_view(reinterpret_cast<const char *>(data), size));
  return 0;
}
