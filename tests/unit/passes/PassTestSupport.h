// Helpers shared by the unit tests of the passes that work on moves:
// a block with a pocket to cut, a STEP-NC file read into the IR, running a
// pipeline on a module, and writing a straight cut by hand.
#pragma once

#include "driver/LoadModule.h"
#include "passes/PassManager.h"
#include "support/Format.h"
#include "tests/unit/ir/SampleModule.h"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

namespace stepnc::test {

/// The IR text of a 100 x 50 x 20 block of SAE 1020 (steel_1020: h* = 0.10
/// mm), its top at z = 0, with a closed pocket %pocket 40 x 30 x 10 deep of
/// corner radius `cornerRadius` mm centred at (50, 25); a D10 four-flute end
/// mill %mill10 with 20 mm of flutes; setup %s1 (security plane 20); and
/// `workingsteps`, the workplan's lines (see oneStep).
inline std::string blockPocketModule(double cornerRadius, const std::string &workingsteps) {
  return R"(project "CUT"
  workpiece %wp "WP" material="id" material_standard="SAE 1020" global_tolerance=0.0100mm
    rawpiece shape=block size=(100.0000,50.0000,20.0000)mm at=(0.0000,0.0000,-20.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)
    closed_pocket %pocket "POCKET" at=(50.0000,25.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=10.0000mm bottom=planar orthogonal_radius=)" +
         formatFixed(cornerRadius, 4) + R"(mm
      rectangular_profile width=30.0000mm length=40.0000mm
  tool %mill10 "MILL 10" type=endmill diameter=10.0000mm cutting_edge_length=20.0000mm flutes=4
  setup %s1 "S1" at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) secplane=20.0000mm
    workpiece_setup workpiece=%wp at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)
  workplan @plan "PLAN" setup=%s1
)" + workingsteps;
}

/// One workingstep @ws on the pocket whose operation is `operation` (its
/// IR line, such as `side_finish_milling "OP" tool=%mill10`).
inline std::string oneStep(const std::string &operation) {
  return "    workingstep @ws \"WS\" feature=%pocket secplane=20.0000mm\n      " + operation + "\n";
}

/// A STEP-NC file read, checked and lowered as `stepnc compile` does; the
/// source stays alive with the module (diagnostics point into it).
struct Loaded {
  std::unique_ptr<SourceFile> source;
  std::unique_ptr<ir::Module> module;
};

inline Loaded loadStepnc(const std::string &path) {
  Loaded l;
  std::string error;
  l.source = SourceFile::open(path, error);
  INFO(error);
  REQUIRE(l.source);
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  const driver::SchemaOptions options;
  driver::SchemaSelection schemas(options);
  REQUIRE(schemas.load(diags, error));
  l.module = driver::loadModule(l.source, schemas, diags, error);
  INFO(error);
  REQUIRE(l.module);
  return l;
}

/// `text` parsed, failing the test on any error.
inline ir::test::Parsed parseModule(const std::string &text) {
  ir::test::Parsed p = ir::test::parse(text);
  for (const std::string &e : p.errors)
    FAIL(e);
  REQUIRE(p.module);
  return p;
}

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
  ir::Node moves(ir::Kind::Moves);
  moves.set("tool", Value::ref("%mill10"))
      .set("spindle", Value::spindle(spindle))
      .set("coolant", Value::word("flood"))
      .set("setup", Value::ref("%s1"))
      .set("secplane", Value::length(20));
  auto add = [&](ir::Kind kind, const ir::Vec3 &p, double f) {
    ir::Node &n = moves.add(ir::Node(kind));
    n.set("to", Value::point(p));
    if (f > 0)
      n.set("feed", Value::feed(f));
  };
  add(ir::Kind::Rapid, ir::Vec3(from.x(), from.y(), 20), 0);
  add(ir::Kind::Linear, from, feed);
  add(ir::Kind::Linear, to, feed);
  add(ir::Kind::Rapid, ir::Vec3(to.x(), to.y(), 20), 0);
  ws.add(std::move(moves));
}

} // namespace stepnc::test
