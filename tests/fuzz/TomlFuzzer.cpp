// libFuzzer target for the TOML descriptions stepnc reads: machines
// (runtime/Machine.h, --machine) and cutting data (cutting/CuttingData.h,
// --cutting-data). Targets are compiled in (backends/Targets.def), so they
// have no file to fuzz. See tests/fuzz/README.md.
//
// For every input, read as a machine and as cutting data (at most
// kMaxErrors errors each):
//   1. the diagnostics must render through every printer, every error must
//      have a place in the input, and each reader returns a result exactly
//      when it reported no error;
//   2. a machine that was accepted and can run a 3-axis program plans a small
//      fixed path (lines, an arc, a dwell, a rapid) into a trajectory that is
//      finite everywhere and that the player replays to a finite report.
// Tags for $STEPNC_FUZZ_KNOWN: json, json-utf8, loc, unlocated, refusal, plan.
#include "cutting/CuttingData.h"
#include "runtime/Machine.h"
#include "runtime/Planner.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"
#include "tests/fuzz/Oracle.h"
#include "tests/fuzz/OracleRuntime.h"

#include <cstdint>
#include <string>
#include <string_view>

namespace {

using namespace stepnc;
using namespace stepnc::fuzz;


/// A few moves of the kinds a program has, 10 to 40 mm long.
runtime::PathInput smallPath() {
  using Move = runtime::PathMove;
  runtime::PathInput path;
  path.start = runtime::Vec3(0, 0, 10);
  auto add = [&](Move::Kind kind, runtime::Vec3 to, double feed) {
    Move m;
    m.kind = kind;
    m.to = to;
    m.feed = feed;
    path.moves.push_back(m);
    return &path.moves.back();
  };
  add(Move::Kind::Line, {20, 0, 10}, 0);
  add(Move::Kind::Line, {20, 0, -2}, 300);
  add(Move::Kind::Line, {40, 0, -2}, 1200);
  Move *arc = add(Move::Kind::Arc, {40, 20, -2}, 1200);
  arc->center = runtime::Vec3(40, 10, -2);
  arc->ccw = true;
  add(Move::Kind::Line, {20, 20, -2}, 1200)->stopBefore = true;
  Move *dwell = add(Move::Kind::Dwell, {20, 20, -2}, 0);
  dwell->dwellS = 0.5;
  add(Move::Kind::Line, {20, 20, 10}, 0);
  return path;
}

void checkMachinePlans(const runtime::Machine &machine, std::string_view input) {
  if (!machine.whyNotThreeAxis().empty())
    return;
  checkPlays(runtime::plan(smallPath(), machine), machine, "plan", input);
}

void checkInput(std::string_view input) {
  auto source = SourceFile::fromString("fuzz-input.toml", input);
  if (auto machine = readChecked(*source, input, runtime::readMachine))
    checkMachinePlans(*machine, input);
  (void)readChecked(*source, input, [](const SourceFile &file, DiagnosticEngine &diags) {
    return cutting::readCuttingData(file, cutting::shippedCuttingData(), diags);
  });
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  setTargetName("toml-fuzzer");
  checkInput(std::string_view(reinterpret_cast<const char *>(data), size));
  return 0;
}
