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
