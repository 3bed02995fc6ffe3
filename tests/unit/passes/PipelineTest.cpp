#include "passes/PassManager.h"
#include "passes/PassRegistry.h"

#include <catch2/catch.hpp>

using namespace stepnc::passes;

TEST_CASE("pass pipelines parse into names and options", "[passes]") {
  std::string error;
  auto p = parsePipeline("resolve-feeds,resolve-feeds", error);
  REQUIRE(p);
  REQUIRE(p->size() == 2);
  CHECK((*p)[0].name == "resolve-feeds");
  CHECK((*p)[1].options.empty());
  CHECK(parsePipeline("", error)->empty());
  CHECK(createPass((*p)[0]) != nullptr);
  CHECK(createPass(PipelineEntry{"nope", {}}) == nullptr);
}

TEST_CASE("pipeline errors say where and what", "[passes]") {
  std::string error;
  CHECK_FALSE(parsePipeline("resolve-feeds;x", error));
  CHECK(error == "in pass pipeline 'resolve-feeds;x' at character 14: expected ',' between passes");
  CHECK_FALSE(parsePipeline("resolve-feeds<k=v>", error));
  CHECK(error.find("pass 'resolve-feeds' has no option 'k'") != std::string::npos);
  CHECK_FALSE(parsePipeline(",", error));
  CHECK(error.find("expected a pass name") != std::string::npos);
  CHECK_FALSE(parsePipeline("unknown", error));
  CHECK(error.find("unknown pass 'unknown'") != std::string::npos);
}

TEST_CASE("every registered pass can be built", "[passes]") {
  for (const PassInfo &info : registeredPasses()) {
    INFO(info.name);
    auto pass = createPass(PipelineEntry{std::string(info.name), {}});
    REQUIRE(pass);
    CHECK(pass->name() == info.name);
  }
}

namespace {

/// A pass with a bug: it gives the first tool a negative diameter.
class BreaksTheIR : public Pass {
public:
  std::string_view name() const override { return "break-the-ir"; }
  PassResult run(stepnc::ir::Module &module, stepnc::DiagnosticEngine &, PassStats &) override {
    for (stepnc::ir::Node &n : module.root.children)
      if (n.kind == stepnc::ir::Kind::Tool) {
        n.set("diameter", stepnc::ir::Value::length(-1));
        break;
      }
    return {true, true};
  }
};

} // namespace

TEST_CASE("a pass that breaks verification is named, and the IR before it printed", "[passes]") {
  using namespace stepnc;
  ir::Module m;
  ir::Node &tool = m.root.add(ir::Node(ir::Kind::Tool));
  tool.symbol = "%t";
  tool.set("type", ir::Value::word("endmill")).set("diameter", ir::Value::length(10));
  std::string printed;
  PassManagerOptions options;
  options.verifyEach = true;
  options.print = [&](std::string_view text) { printed += text; };
  PassManager manager(options);
  manager.add(std::make_unique<BreaksTheIR>());
  DiagnosticCollector sink;
  DiagnosticEngine diags(sink);
  CHECK_FALSE(manager.run(m, diags));
  REQUIRE(sink.diags.size() == 2);  // the verifier's error, then the pass manager's
  CHECK(sink.diags[0].message == "tool %t: attribute 'diameter' must be positive, found -1.0000mm");
  CHECK(sink.diags[1].message == "pass 'break-the-ir' broke verification");
  REQUIRE(sink.diags[1].notes.size() == 1);
  CHECK(sink.diags[1].notes[0].message.find("the IR before it follows") != std::string::npos);
  CHECK(printed == "; *** IR before break-the-ir, which broke verification ***\n"
                   "; stepnc feature IR (lengths mm, angles deg, feeds mm/min, spindle rev/min, times s)\n"
                   "project\n"
                   "  tool %t type=endmill diameter=10.0000mm\n");
}
