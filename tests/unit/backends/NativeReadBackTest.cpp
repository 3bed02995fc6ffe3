// The native target reads back what it writes, with the checks `stepnc sim`
// runs: a plan whose profile does not cover its segment is never written.
#include "backends/Backend.h"
#include "tests/unit/passes/PassTestSupport.h"

#include <algorithm>

namespace stepnc {
namespace {

/// The pocket block with one straight cut at z=-5, planned on the shipped
/// 3-axis machine.
ir::test::Parsed plannedCut() {
  ir::test::Parsed p = test::parseModule(
      test::blockPocketModule(5, test::oneStep("side_finish_milling \"OP\" tool=%mill10\n"
                                               "        technology feed=600.0mm/min spindle=-3000.0rev/min "
                                               "feed_reference=tcp")));
  test::addStraightCut(*p.module, ir::Vec3(40, 25, -5), ir::Vec3(60, 25, -5), 600);
  std::vector<std::string> errors;
  const bool ok = test::runPipeline(*p.module, "plan-motion<machine=hsc-3axis>", &errors);
  for (const std::string &e : errors)
    FAIL_CHECK(e);
  REQUIRE(ok);
  return p;
}

std::optional<std::string> emitNative(const ir::Module &module, std::vector<std::string> &errors) {
  std::unique_ptr<backends::Backend> native = backends::createBackend("native");
  REQUIRE(native);
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  backends::EmitOptions options;
  options.source = "cut.ir";
  std::optional<std::string> out = native->emit(module, options, diags);
  for (const Diagnostic &d : c.diags)
    if (d.severity == Severity::Error)
      errors.push_back(d.message);
  return out;
}

TEST_CASE("native: a plan is written when it reads back", "[native]") {
  ir::test::Parsed p = plannedCut();
  std::vector<std::string> errors;
  const std::optional<std::string> text = emitNative(*p.module, errors);
  CHECK(errors.empty());
  REQUIRE(text);
  CHECK(text->find("segments ") != std::string::npos);
}

TEST_CASE("native: a profile that does not cover its segment is a bug reported, not a file", "[native]") {
  ir::test::Parsed p = plannedCut();
  ir::Node &ws = ir::test::find(p.module->root, "@ws");
  ir::Node *motion = nullptr;
  for (ir::Node &c : ws.children)
    if (c.kind == ir::Kind::Motion)
      motion = &c;
  REQUIRE(motion);
  REQUIRE(motion->children.size() >= 3);
  // The cut (the third segment: the rapid down, the plunge, the cut) loses
  // half of its longest phase: its profile then stops short of its end, as a
  // planner without its backward pass would leave it.
  ir::Node &cut = motion->children[2];
  bool changed = false;
  for (ir::Attr &a : cut.attrs)
    if (a.name == "phases") {
      std::vector<double> &ph = a.value.numbers;
      size_t longest = 0;
      for (size_t k = 0; k < ph.size(); k += 2)
        if (ph[k] > ph[longest])
          longest = k;
      ph[longest] /= 2;
      changed = true;
    }
  REQUIRE(changed);
  std::vector<std::string> errors;
  CHECK_FALSE(emitNative(*p.module, errors));
  REQUIRE(errors.size() == 1);
  INFO(errors[0]);
  CHECK(errors[0].rfind("workingstep @ws: the native plan stepnc made does not read back (a bug in stepnc): "
                        "segment 3 of the plan: the profile covers ", 0) == 0);
}

} // namespace
} // namespace stepnc
