#include "passes/PassManager.h"
#include "passes/PassRegistry.h"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <string_view>

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

TEST_CASE("every registered pass can be built, its declared defaults taken", "[passes]") {
  for (const PassInfo &info : registeredPasses()) {
    INFO(info.name);
    // The required options given, the others left to their defaults (which
    // must be values of their type: a declaration's mistake fails here).
    std::string text(info.name), required;
    for (const OptionInfo &o : info.options)
      if (o.fallback.kind == OptionDefault::Kind::Required)
        required += (required.empty() ? "<" : ",") + std::string(o.name) + "=" +
                    (o.type == OptionType::Machine ? "hsc-3axis" : "x");
    std::string error;
    auto p = parsePipeline(text + required + (required.empty() ? "" : ">"), error);
    INFO(error);
    REQUIRE(p);
    auto pass = createPass(p->front());
    REQUIRE(pass);
    CHECK(pass->name() == info.name);
  }
}

TEST_CASE("pass options take their declared defaults", "[passes]") {
  std::string error;
  auto p = parsePipeline("expand-strategies,compensate-deflection,verify-toolpaths,adapt-feed", error);
  REQUIRE(p);
  CHECK((*p)[0].options.number("max-engagement") == 90.0);
  CHECK((*p)[0].options.number("chord-tolerance") == 0.005);
  CHECK((*p)[1].options.number("max-offset") == 0.05);
  CHECK_FALSE((*p)[1].options.has("data"));        // no default: the shipped data
  CHECK_FALSE((*p)[2].options.has("tolerance"));   // no default: the workpiece's
  CHECK((*p)[3].options.has("allow-increase"));
  CHECK_FALSE((*p)[3].options.flag("allow-increase"));
  // A value given replaces the default, converted to the option's type.
  p = parsePipeline("expand-strategies<max-engagement=60deg,chord-tolerance=0.01mm>,adapt-feed<allow-increase=true>",
                    error);
  REQUIRE(p);
  CHECK((*p)[0].options.number("max-engagement") == 60.0);
  CHECK((*p)[0].options.number("chord-tolerance") == 0.01);
  CHECK((*p)[1].options.flag("allow-increase"));
  CHECK_FALSE((*p)[1].options.has("machine"));
}

TEST_CASE("an option value not of its type is refused where it stands", "[passes]") {
  std::string error;
  CHECK_FALSE(parsePipeline("adapt-feed<allow-increase=maybe>", error));
  CHECK(error == "in pass pipeline 'adapt-feed<allow-increase=maybe>' at character 27: pass 'adapt-feed' option "
                 "'allow-increase' expects true or false, got 'maybe'");
  CHECK_FALSE(parsePipeline("resolve-feeds,compensate-deflection<max-offset=far>", error));
  CHECK(error == "in pass pipeline 'resolve-feeds,compensate-deflection<max-offset=far>' at character 48: pass "
                 "'compensate-deflection' option 'max-offset' expects a positive length in mm, such as 0.05 or "
                 "0.05mm, got 'far'");
  for (const char *bad : {"abc", "-1", "0", "1e400", "0.1mm2", "0.01in", "nan", "inf", ""}) {
    INFO(bad);
    CHECK_FALSE(parsePipeline(std::string("verify-toolpaths<tolerance=") + bad + ">", error));
    CHECK(error.find("option 'tolerance' expects a positive length in mm") != std::string::npos);
  }
  for (const char *bad : {"wide", "0", "-30", "181", "60rad", "deg"}) {
    INFO(bad);
    CHECK_FALSE(parsePipeline(std::string("expand-strategies<max-engagement=") + bad + ">", error));
    CHECK(error.find("option 'max-engagement' expects an angle in degrees above 0 and at most 180") !=
          std::string::npos);
  }
  CHECK(parsePipeline("expand-strategies<max-engagement=180>", error));
  CHECK_FALSE(parsePipeline("compensate-deflection<data=>", error));
  CHECK(error.find("option 'data' expects a file path, got ''") != std::string::npos);
  CHECK_FALSE(parsePipeline("plan-motion<machine=>", error));
  CHECK(error.find("option 'machine' expects a machine description (a TOML file) or a shipped machine (") !=
        std::string::npos);
}

TEST_CASE("an unknown option and a missing required option are refused", "[passes]") {
  std::string error;
  CHECK_FALSE(parsePipeline("adapt-feed<allow-increas=true>", error));
  CHECK(error == "in pass pipeline 'adapt-feed<allow-increas=true>' at character 25: pass 'adapt-feed' has no "
                 "option 'allow-increas'");
  CHECK_FALSE(parsePipeline("plan-motion<tolerance=0.01>", error));
  CHECK(error.starts_with("in pass pipeline 'plan-motion<tolerance=0.01>' at character 28: pass 'plan-motion' "
                          "needs option 'machine', a machine description (a TOML file) or a shipped machine ("));
  CHECK(parsePipeline("plan-motion<machine=hsc-3axis>", error));
}

TEST_CASE("the pass list describes each option from its declaration", "[passes]") {
  const PassInfo *adapt = nullptr;
  for (const PassInfo &info : registeredPasses())
    if (info.name == "adapt-feed")
      adapt = &info;
  REQUIRE(adapt);
  const std::string text = describePass(*adapt);
  CHECK(text.starts_with("adapt-feed\n    Set each milling move's feed"));
  CHECK(text.find("\n    options:\n      machine=<machine>  ") != std::string::npos);
  CHECK(text.find("\n      allow-increase=true|false  let feeds rise above the programmed ones (default false)\n") !=
        std::string::npos);
  CHECK(text.find("data=<file>  cutting-data TOML file on top of the shipped one (without it: the shipped cutting "
                  "data only)") != std::string::npos);
  CHECK(describeOptionTypes().find("<mm>: a positive length in mm") != std::string::npos);
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

/// A module of one 10 mm end mill, %t: what BreaksTheIR breaks.
stepnc::ir::Module oneToolModule() {
  using namespace stepnc;
  ir::Module m;
  ir::Node &tool = m.root.add(ir::Node(ir::Kind::Tool));
  tool.symbol = "%t";
  tool.set("type", ir::Value::word("endmill")).set("diameter", ir::Value::length(10));
  return m;
}

} // namespace

TEST_CASE("a pass that breaks verification is named, and the IR before it printed", "[passes]") {
  using namespace stepnc;
  ir::Module m = oneToolModule();
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

TEST_CASE("without verify-each, the pipeline's result is verified once", "[passes]") {
  using namespace stepnc;
  ir::Module m = oneToolModule();
  PassManagerOptions options;
  options.verifyEach = false;
  PassManager manager(options);
  manager.add(std::make_unique<BreaksTheIR>());
  DiagnosticCollector sink;
  DiagnosticEngine diags(sink);
  if (const char *env = std::getenv("STEPNC_VERIFY_EACH"); env && std::string_view(env) == "1") {
    WARN("STEPNC_VERIFY_EACH=1 is set: every pass is verified, the single final check is not tested");
    return;
  }
  CHECK_FALSE(manager.run(m, diags));
  REQUIRE(sink.diags.size() == 2);
  CHECK(sink.diags[0].message == "tool %t: attribute 'diameter' must be positive, found -1.0000mm");
  CHECK(sink.diags[1].message.find("the IR the pass pipeline produced does not verify (a bug in stepnc)") == 0);
}
