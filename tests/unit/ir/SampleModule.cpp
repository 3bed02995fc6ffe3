// The sample module and helpers declared in SampleModule.h.
#include "SampleModule.h"

#include "ir/Parser.h"

#include <catch2/catch.hpp>

namespace stepnc::ir::test {

namespace {

Node node(Kind kind, std::string symbol = {}, std::string label = {}) {
  Node n(kind);
  n.symbol = std::move(symbol);
  n.label = std::move(label);
  return n;
}

/// The at/axis/ref placement of many kinds: origin `at`, z up, x along x.
Node &place(Node &n, const Vec3 &at) {
  return n.set("at", Value::point(at))
      .set("axis", Value::direction(Vec3::UnitZ()))
      .set("ref", Value::direction(Vec3::UnitX()));
}

Node workpiece() {
  Node wp = node(Kind::Workpiece, "%simple_workpiece", "SIMPLE WORKPIECE");
  wp.set("material", Value::string("ST-50 \\ STEEL")).set("global_tolerance", Value::length(0.01));

  Node &raw = wp.add(node(Kind::Rawpiece));
  raw.set("shape", Value::word("block")).set("size", Value::point(Vec3(110, 110, 80)));
  place(raw, Vec3(-5, -5, -5));

  Node &pocket = wp.add(node(Kind::ClosedPocket, "%pocket1", "POCKET1"));
  place(pocket, Vec3(50, 50, 0));
  pocket.set("depth", Value::length(15))
      .set("bottom", Value::word("planar"))
      .set("orthogonal_radius", Value::length(10));
  pocket.add(node(Kind::RectangularProfile)).set("width", Value::length(60)).set("length", Value::length(40));

  Node &hole = wp.add(node(Kind::RoundHole, "%hole1", "HOLE1"));
  place(hole, Vec3(20, 20, 0));
  hole.set("depth", Value::length(12.5))
      .set("diameter", Value::length(10))
      .set("bottom", Value::word("conical"))
      .set("tip_angle", Value::angle(118));
  return wp;
}

Node millingWorkingstep() {
  Node ws = node(Kind::Workingstep, "@ws_rough_pocket1", "ROUGH POCKET1");
  ws.set("feature", Value::ref("%pocket1")).set("secplane", Value::length(20));
  Node &op = ws.add(node(Kind::BottomAndSideRoughMilling, {}, "ROUGH POCKET1"));
  op.set("tool", Value::ref("%mill_18mm"))
      .set("retract_plane", Value::length(20))
      .set("axial_depth", Value::length(6.5))
      .set("radial_depth", Value::length(5))
      .set("allowance_side", Value::length(1))
      .set("allowance_bottom", Value::length(0.5));
  op.add(node(Kind::Technology))
      .set("feed", Value::feed(2400))
      .set("spindle", Value::spindle(-720))
      .set("feed_reference", Value::word("tcp"));
  op.add(node(Kind::MachineFunctions)).set("coolant", Value::boolean(true));
  Node &strategy = op.add(node(Kind::Strategy));
  strategy.set("type", Value::word("contour_parallel"))
      .set("overlap", Value::ratio(0.05))
      .set("rotation", Value::word("cw"))
      .set("cutmode", Value::word("conventional"));
  strategy.comment = "overlap from the tool";
  op.add(node(Kind::Approach)).set("type", Value::word("plunge_toolaxis"));
  return ws;
}

Node drillingWorkingstep() {
  Node ws = node(Kind::Workingstep, "@ws_drill_hole1", "DRILL HOLE1");
  ws.set("feature", Value::ref("%hole1")).set("secplane", Value::length(20));
  Node &op = ws.add(node(Kind::Drilling, {}, "DRILL HOLE1"));
  op.set("tool", Value::ref("%drill_10mm"))
      .set("retract_plane", Value::length(20))
      .set("cutting_depth", Value::length(12.5))
      .set("dwell_bottom", Value::time(1.5))
      .set("feed_on_retract", Value::ratio(1));
  op.add(node(Kind::Technology))
      .set("feed", Value::feed(300))
      .set("spindle", Value::spindle(-1200))
      .set("feed_reference", Value::word("tcp"));
  op.add(node(Kind::DrillingStrategy))
      .set("reduced_cut_at_start", Value::ratio(0.5))
      .set("reduced_feed_at_start", Value::ratio(0.5))
      .set("depth_of_start", Value::length(2));
  return ws;
}

void collect(Node &n, std::string_view symbolOrKind, Node *&found) {
  if (found)
    return;
  if (n.symbol == symbolOrKind || n.kindName() == symbolOrKind) {
    found = &n;
    return;
  }
  for (Node &c : n.children)
    collect(c, symbolOrKind, found);
}

} // namespace

Module sampleModule() {
  Module m;
  m.root.label = "EXECUTE \"EXAMPLE1\" Fräsen";
  m.root.add(workpiece());
  m.root.add(node(Kind::Tool, "%mill_18mm", "MILL 18MM"))
      .set("type", Value::word("endmill"))
      .set("diameter", Value::length(18))
      .set("corner_radius", Value::length(0))
      .set("flutes", Value::integer(4))
      .set("hand", Value::word("right"));
  m.root.add(node(Kind::Tool, "%drill_10mm", "DRILL 10MM"))
      .set("type", Value::word("twist_drill"))
      .set("diameter", Value::length(10))
      .set("tip_half_angle", Value::angle(59));
  Node &setup = m.root.add(node(Kind::Setup, "%setup1", "SETUP1"));
  place(setup, Vec3(0, 0, 0)).set("secplane", Value::length(20));
  Node &wpSetup = setup.add(node(Kind::WorkpieceSetup));
  wpSetup.set("workpiece", Value::ref("%simple_workpiece"));
  place(wpSetup, Vec3(-0.0, 0, -0.0));
  Node &plan = m.root.add(node(Kind::Workplan, "@main_workplan", "MAIN WORKPLAN"));
  plan.set("setup", Value::ref("%setup1"));
  plan.add(millingWorkingstep());
  plan.add(drillingWorkingstep());
  return m;
}

Node &find(Node &root, std::string_view symbolOrKind) {
  Node *found = nullptr;
  collect(root, symbolOrKind, found);
  REQUIRE(found);
  return *found;
}

std::vector<std::string> messages(const DiagnosticCollector &c) {
  std::vector<std::string> out;
  for (const Diagnostic &d : c.diags) {
    std::string prefix;
    if (d.loc.valid()) {
      LineCol lc = d.loc.file->lineCol(d.loc.offset);
      prefix = std::to_string(lc.line) + ":" + std::to_string(lc.col) + ": ";
    }
    out.push_back(prefix + d.message);
  }
  return out;
}

Parsed parse(std::string_view text) {
  Parsed p;
  p.source = SourceFile::fromString("t.ir", text);
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  p.module = parseModule(*p.source, engine);
  p.errors = messages(c);
  return p;
}

} // namespace stepnc::ir::test
