// The invariants of adapt-feed and compensate-deflection on every corpus file
// that reaches the toolpath IR, and on the bundled example: no adapted feed
// above the programmed one nor above the machine's speed cap on its move, no
// chip above the material's target, the chip within [0.9, 1.0] of it where it
// sets the feed, and after compensation every finishing wall within 2 um of
// its nominal position on the model (DeflectionCheck.h), the verifier
// passing, and no place where the machine runs below half its feed that the
// nominal program does not have.
#include "passes/CuttingModel.h"
#include "ir/motion/MotionIR.h"

#include "tests/unit/TestSupport.h"
#include "tests/unit/passes/DeflectionCheck.h"
#include "tests/unit/passes/PassTestSupport.h"
#include "tests/unit/passes/SlowPlaces.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

using namespace stepnc;
using namespace stepnc::passes;

namespace {

const char *const kFiles[] = {
    "jucsr__sanssouci/OnePocket",
    "jucsr__sanssouci/RanhuraPerfilRoundedU.p21",
    "jucsr__sanssouci/RanhuraPerfilUQuadrado.p21",
    "jucsr__sanssouci/STEP-NC_Slot1 File.p21",
    "jucsr__sanssouci/oneHoleOneSlotOneStepOnePoket.p21",
    "unseenlaser__iso-14649-toolkit/ex1.stp",
    // Not ex1E.stp: its explicit toolpaths are required (its_priority), so
    // the cutting passes leave them as written (ir::runsAsWritten;
    // tests/passes/adapt-feed/required-toolpaths.test checks that).
};

/// How close to the chip target adapt-feed comes where the chip limits the
/// feed, read on the samples it chose the feeds on: the samples of the
/// program before it whose chip sets the lowest feed there (below what the
/// force allows) and whose neighbours want feeds within the pass's feed
/// ratio (not an entry, exit or corner, where feeds step between samples).
/// Each such sample's chip at the feed the adapted program has there,
/// the higher one where two pieces meet on it.
struct ChipFit {
  size_t limited = 0, under = 0, over = 0; ///< samples; below 0.9 of the target; above it
  double lowest = 1;                       ///< lowest chip / target among them
};

ChipFit chipFit(const ir::Module &programmed, const ir::Module &adapted, const cutting::CuttingData &data) {
  const CutAnalysis before = analyseCuts(programmed, {&data, nullptr});
  const CutAnalysis after = analyseCuts(adapted, {&data, nullptr});
  ChipFit fit;
  REQUIRE(before.steps.size() == after.steps.size());
  for (size_t k = 0; k < before.steps.size(); ++k) {
    const CutStep &step = before.steps[k];
    const std::vector<CutMove> &pieces = after.steps[k].moves;
    size_t next = 0;
    for (const CutMove &cm : step.moves) {
      // The pieces of this move, with where each ends along it.
      std::vector<std::pair<double, const CutMove *>> ends;
      for (double run = 0; next < pieces.size() && run < cm.move.length() - 1e-6; ++next) {
        run += pieces[next].move.length();
        ends.push_back({run, &pieces[next]});
      }
      if (!cm.measured || cm.move.turns > 0 || !step.material)
        continue;
      const double target = step.material->chipThickness;
      auto want = [&](const CutSample &s) { return s.chipFactor > 0 ? target / s.chipFactor : 0.0; };
      for (size_t i = 1; i + 1 < cm.samples.size(); ++i) {
        const CutSample &s = cm.samples[i];
        const double w = want(s), w0 = want(cm.samples[i - 1]), w1 = want(cm.samples[i + 1]);
        if (w <= 0 || w > 0.98 * s.fzForce || std::min(w, w0) < kFeedRatio * std::max(w, w0) ||
            std::min(w, w1) < kFeedRatio * std::max(w, w1))
          continue;
        double fz = 0;
        for (const auto &[end, piece] : ends)
          if (end >= s.s - 1e-6 && end - piece->move.length() <= s.s + 1e-6)
            fz = std::max(fz, piece->fz);
        ++fit.limited;
        const double ratio = fz * s.chipFactor / target;
        fit.lowest = std::min(fit.lowest, ratio);
        fit.under += ratio < 0.9;
        fit.over += ratio > 1 + 1e-9;
      }
    }
  }
  return fit;
}

/// The invariants on the program of the STEP-NC file at `path`.
void checkInvariants(const std::string &path, const cutting::CuttingData &data, const runtime::Machine &machine) {
  test::Loaded l = test::loadStepnc(path);
  std::vector<std::string> errors;
  REQUIRE(test::runPipeline(*l.module, "resolve-feeds,expand-strategies", &errors));
  const ir::Module programmed = *l.module;
  REQUIRE(test::runPipeline(*l.module, "adapt-feed<machine=hsc-3axis>", &errors));
  const ir::Module adapted = *l.module;

  // Feeds: every piece of a move at or below its programmed feed, and at
  // most 1 mm/min (feeds are whole mm/min) above the highest speed the
  // machine reaches on it.
  const ir::ProgramPath before = ir::programPath(programmed), after = ir::programPath(adapted);
  const runtime::Trajectory plan = runtime::plan(after.path, machine);
  std::vector<double> cap(after.path.moves.size(), 0);
  for (size_t k = 0; k < plan.segments.size(); ++k)
    cap[plan.info[k].move] = std::max(cap[plan.info[k].move], plan.profiles[k].peak() * 60);
  size_t j = 0, raised = 0, overCap = 0;
  for (size_t i = 0; i < before.nodes.size(); ++i) {
    const double feed = before.nodes[i]->number("feed").value_or(0);
    const ir::Vec3 end = *before.nodes[i]->vec("to");
    for (; j < after.nodes.size(); ++j) {
      const double f = after.nodes[j]->number("feed").value_or(0);
      raised += f > feed;
      overCap += after.nodes[j]->kind != ir::Kind::Rapid && f > cap[j] + 1;
      if ((*after.nodes[j]->vec("to") - end).norm() < 1e-9 && after.nodes[j]->kind == before.nodes[i]->kind)
        break;
    }
    ++j;
  }
  CHECK(j == after.nodes.size());
  CHECK(raised == 0);
  CHECK(overCap == 0);

  // Chips: at every sample of the adapted program, at most the target
  // (2 % for where the samples of the analysis after fall between those
  // the feeds were chosen on).
  const CutAnalysis cuts = analyseCuts(adapted, {&data, &machine});
  size_t samples = 0, overChip = 0;
  for (const CutStep &step : cuts.steps)
    for (const CutMove &cm : step.moves)
      for (const CutSample &s : cm.samples) {
        if (!(s.chipFactor > 0))
          continue;
        ++samples;
        overChip += cm.fz * s.chipFactor > 1.02 * step.material->chipThickness;
      }
  INFO(samples << " samples, " << overChip << " over the chip target");
  CHECK(overChip == 0);

  // Where the chip limits the feed, the chip is within [0.9, 1.0] of the
  // target. The corpus programs feeds below the chip target, so this is
  // checked with increases allowed, and with no machine, so that nothing
  // else caps them.
  {
    ir::Module increased = programmed;
    const bool ran = test::runPipeline(increased, "adapt-feed<allow-increase=true>", &errors);
    INFO((errors.empty() ? std::string() : errors.front()));
    REQUIRE(ran);
    const ChipFit fit = chipFit(programmed, increased, data);
    INFO(fit.limited << " samples limited by the chip, " << fit.under << " below 0.9 of the target, lowest "
                     << fit.lowest << ", " << fit.over << " above it");
    CHECK(fit.limited > 0);
    CHECK(fit.under == 0);
    CHECK(fit.over == 0);
  }

  // Deflection: every finishing wall within 2 um of its nominal position,
  // and the verifier passes on the predicted path.
  REQUIRE(test::runPipeline(*l.module, "compensate-deflection,verify-toolpaths", &errors));
  for (const std::string &e : errors)
    FAIL_CHECK(e);
  const test::DeflectionCheck check = test::checkDeflection(adapted, *l.module, data);
  for (const std::string &f : check.failures)
    FAIL_CHECK(f);
  INFO(check.walls << " wall samples, " << check.offsetWalls << " offset, error before " << check.worstBefore * 1000
                   << " um, after " << check.worstResidual * 1000 << " um");
  CHECK(check.worstResidual <= 0.002);

  // Where the offset changes the path does not step: the machine slows
  // below half the feed nowhere the nominal program does not.
  const std::vector<ir::Vec3> added =
      test::placesAdded(test::slowPlaces(adapted, machine, 0.5), test::slowPlaces(*l.module, machine, 0.5), 0.5);
  INFO(added.size() << " samples below half the feed where the nominal program runs faster, the first at "
                    << (added.empty() ? ir::Vec3::Zero() : added.front()).transpose());
  CHECK(added.empty());
}

} // namespace

TEST_CASE("adapt-feed and compensate-deflection: invariants on the corpus",
          "[adapt-feed][compensate-deflection][corpus]") {
  const std::string corpus = test::corpusDir();
  if (corpus.empty()) {
    WARN("corpus not found (set STEPNC_CORPUS): skipped");
    return;
  }
  const cutting::CuttingData data = cutting::shippedCuttingData();
  const runtime::Machine machine = test::shippedMachine("hsc-3axis");
  for (const char *name : kFiles) {
    const std::string path = corpus + "/" + name;
    if (!std::filesystem::exists(path)) {
      WARN(path << " not found: skipped");
      continue;
    }
    INFO(name);
    checkInvariants(path, data, machine);
  }
}

TEST_CASE("adapt-feed and compensate-deflection: invariants on the bundled example",
          "[adapt-feed][compensate-deflection]") {
  checkInvariants(std::string(STEPNC_SOURCE_DIR) + "/examples/example1.stp", cutting::shippedCuttingData(),
                  test::shippedMachine("hsc-3axis"));
}
