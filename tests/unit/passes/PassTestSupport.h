// Helpers shared by the unit tests of the passes that work on moves:
// running a pipeline on a module, and writing a straight cut by hand.
#pragma once

#include "passes/PassManager.h"
#include "tests/unit/ir/SampleModule.h"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

namespace stepnc::test {

/// Runs the pipeline `text` on `module`; its error messages go to `errors`
/// when given. False when a pass failed.
inline bool runPipeline(ir::Module &module, const std::string &text, std::vector<std::string> *errors = nullptr) {
  std::string error;
  auto entries = passes::parsePipeline(text, error);
  INFO(error);
  REQUIRE(entries);
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  passes::PassManager pm({});
  pm.add(*entries);
  const bool ok = pm.run(module, diags);
  for (const Diagnostic &d : c.diags)
    if (d.severity == Severity::Error && errors)
      errors->push_back(d.message);
  return ok;
}

/// A `moves` node under workingstep @ws of a module with tool %mill10 and
/// setup %s1 (security plane 20): a rapid above `from`, down to it at
/// `feed`, a line to `to` at `feed`, a rapid up.
inline void addStraightCut(ir::Module &module, const ir::Vec3 &from, const ir::Vec3 &to, double feed,
                           double spindle = -3000) {
  using ir::Value;
  ir::Node &ws = ir::test::find(module.root, "@ws");
  ir::Node moves("moves");
  moves.set("tool", Value::ref("%mill10"))
      .set("spindle", Value::spindle(spindle))
      .set("coolant", Value::word("flood"))
      .set("setup", Value::ref("%s1"))
      .set("secplane", Value::length(20));
  auto add = [&](const char *kind, const ir::Vec3 &p, double f) {
    ir::Node &n = moves.add(ir::Node(kind));
    n.set("to", Value::point(p));
    if (f > 0)
      n.set("feed", Value::feed(f));
  };
  add("rapid", ir::Vec3(from.x(), from.y(), 20), 0);
  add("linear", from, feed);
  add("linear", to, feed);
  add("rapid", ir::Vec3(to.x(), to.y(), 20), 0);
  ws.add(std::move(moves));
}

} // namespace stepnc::test
