// The IR text printer: value spellings, attribute order, locations, comments,
// and the whole sample module as golden text.
#include "SampleModule.h"

#include "ir/Printer.h"

#include <catch2/catch.hpp>

using namespace stepnc;
using namespace stepnc::ir;

namespace {

std::string printed(const Value &v) {
  std::string out;
  printValue(v, out);
  return out;
}

std::string printed(const Node &n, const PrintOptions &o = {}) {
  std::string out;
  printNode(n, out, o);
  return out;
}

const std::string kFrame = " axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000)";

} // namespace

TEST_CASE("each value type has one spelling: fixed decimals, unit suffix, no -0", "[ir]") {
  CHECK(printed(Value::length(12.5)) == "12.5000mm");
  CHECK(printed(Value::length(-0.0)) == "0.0000mm");
  CHECK(printed(Value::length(-0.00001)) == "0.0000mm");
  CHECK(printed(Value::length(1e-9)) == "0.0000mm");
  CHECK(printed(Value::angle(90)) == "90.0000deg");
  CHECK(printed(Value::feed(2400)) == "2400.0mm/min");
  CHECK(printed(Value::spindle(-720)) == "-720.0rev/min");
  CHECK(printed(Value::time(1.5)) == "1.500s");
  CHECK(printed(Value::ratio(0.05)) == "0.0500");
  CHECK(printed(Value::integer(-3)) == "-3");
  CHECK(printed(Value::boolean(false)) == "false");
  CHECK(printed(Value::word("climb")) == "climb");
  CHECK(printed(Value::string("a\"b\\c\nd é")) == "\"a\\\"b\\\\c\\nd é\"");
  CHECK(printed(Value::ref("%mill_18mm")) == "%mill_18mm");
  CHECK(printed(Value::point(Vec3(1, -0.0, 2.5))) == "(1.0000,0.0000,2.5000)mm");
  CHECK(printed(Value::direction(Vec3(0, 0, -1))) == "(0.000000,0.000000,-1.000000)");
}

TEST_CASE("a node prints on one line, attributes in the kind table's order", "[ir]") {
  Node strategy(ir::Kind::Strategy);
  strategy.set("cutmode", Value::word("conventional"))
      .set("rotation", Value::word("cw"))
      .set("overlap", Value::ratio(0.05))
      .set("type", Value::word("contour_parallel"));
  strategy.comment = "overlap from the tool";
  CHECK(printed(strategy) ==
        "strategy type=contour_parallel overlap=0.0500 rotation=cw cutmode=conventional  ; overlap from the tool\n");
}

TEST_CASE("attributes the table does not list follow, in insertion order", "[ir]") {
  // Node::set refuses them (an internal error); a node whose attribute list
  // was filled directly still prints all of it, for the verifier to report.
  Node pocket(ir::Kind::ClosedPocket);
  pocket.symbol = "%p";
  pocket.attrs.push_back({"zeta", Value::integer(1)});
  pocket.set("depth", Value::length(3));
  pocket.attrs.push_back({"alpha", Value::boolean(true)});
  CHECK(printed(pocket) == "closed_pocket %p depth=3.0000mm zeta=1 alpha=true\n");
}

TEST_CASE("kinds are declared once: names, categories, traits and attributes", "[ir]") {
  for (const KindSpec &k : allKinds()) {
    CHECK(kindNamed(k.name) == k.id);
    CHECK(&specOf(k.id) == &k);
  }
  CHECK(kindNamed("mystery") == std::nullopt);
  CHECK(attrIndex(specOf(Kind::ClosedPocket), "zeta") == SIZE_MAX);
  CHECK(attrIndex(specOf(Kind::ClosedPocket), "at") == 0);
  CHECK(categoryOf(Kind::Drilling) == Category::Operation);
  CHECK(categoryName(Category::MotionSegment) == "motion_segment");
  // Hole making is one trait: every operation that takes a drilling strategy has it.
  for (const KindSpec &k : allKinds())
    if (k.category == Category::Operation)
      CHECK(k.is(Trait::HoleMaking) == inList(k.children, "drilling_strategy"));
  CHECK(hasTraits(Kind::SideFinishMilling, Trait::Milling | Trait::Finishing | Trait::SideOnly));
  CHECK_FALSE(hasTraits(Kind::PlaneFinishMilling, Trait::WallFinishing));
  CHECK(childAllowed(specOf(Kind::Workingstep), specOf(Kind::Drilling)));
  CHECK_FALSE(childAllowed(specOf(Kind::Workingstep), specOf(Kind::Tool)));
}

TEST_CASE("locations print only on request and only when the origin has one", "[ir]") {
  auto part = SourceFile::fromString("part.stp", "#1=A();\n#12=CLOSED_POCKET();\n");
  Node pocket(ir::Kind::ClosedPocket);
  pocket.symbol = "%pocket1";
  pocket.comment = "lowered";
  pocket.origin = {12, {part.get(), 8}};
  CHECK(printed(pocket) == "closed_pocket %pocket1  ; lowered\n");
  CHECK(printed(pocket, {true}) == "closed_pocket %pocket1 loc(part.stp:2:1 #12)  ; lowered\n");
  pocket.origin.entityId = 0;
  CHECK(printed(pocket, {true}) == "closed_pocket %pocket1 loc(part.stp:2:1)  ; lowered\n");
  pocket.origin = {12, {}};
  CHECK(printed(pocket, {true}) == "closed_pocket %pocket1  ; lowered\n");
}

TEST_CASE("the sample module prints as golden text", "[ir]") {
  const std::string expected =
      "; stepnc feature IR (lengths mm, angles deg, feeds mm/min, spindle rev/min, times s)\n"
      "project \"EXECUTE \\\"EXAMPLE1\\\" Fräsen\"\n"
      "  workpiece %simple_workpiece \"SIMPLE WORKPIECE\" material=\"ST-50 \\\\ STEEL\" global_tolerance=0.0100mm\n"
      "    rawpiece shape=block size=(110.0000,110.0000,80.0000)mm at=(-5.0000,-5.0000,-5.0000)mm" + kFrame + "\n"
      "    closed_pocket %pocket1 \"POCKET1\" at=(50.0000,50.0000,0.0000)mm" + kFrame +
      " depth=15.0000mm bottom=planar orthogonal_radius=10.0000mm\n"
      "      rectangular_profile width=60.0000mm length=40.0000mm\n"
      "    round_hole %hole1 \"HOLE1\" at=(20.0000,20.0000,0.0000)mm" + kFrame +
      " depth=12.5000mm diameter=10.0000mm bottom=conical tip_angle=118.0000deg\n"
      "  tool %mill_18mm \"MILL 18MM\" type=endmill diameter=18.0000mm corner_radius=0.0000mm flutes=4 hand=right\n"
      "  tool %drill_10mm \"DRILL 10MM\" type=twist_drill diameter=10.0000mm tip_half_angle=59.0000deg\n"
      "  setup %setup1 \"SETUP1\" at=(0.0000,0.0000,0.0000)mm" + kFrame + " secplane=20.0000mm\n"
      "    workpiece_setup workpiece=%simple_workpiece at=(0.0000,0.0000,0.0000)mm" + kFrame + "\n"
      "  workplan @main_workplan \"MAIN WORKPLAN\" setup=%setup1\n"
      "    workingstep @ws_rough_pocket1 \"ROUGH POCKET1\" feature=%pocket1 secplane=20.0000mm\n"
      "      bottom_and_side_rough_milling \"ROUGH POCKET1\" tool=%mill_18mm retract_plane=20.0000mm "
      "axial_depth=6.5000mm radial_depth=5.0000mm allowance_side=1.0000mm allowance_bottom=0.5000mm\n"
      "        technology feed=2400.0mm/min spindle=-720.0rev/min feed_reference=tcp\n"
      "        machine_functions coolant=true\n"
      "        strategy type=contour_parallel overlap=0.0500 rotation=cw cutmode=conventional"
      "  ; overlap from the tool\n"
      "        approach type=plunge_toolaxis\n"
      "    workingstep @ws_drill_hole1 \"DRILL HOLE1\" feature=%hole1 secplane=20.0000mm\n"
      "      drilling \"DRILL HOLE1\" tool=%drill_10mm retract_plane=20.0000mm cutting_depth=12.5000mm "
      "dwell_bottom=1.500s feed_on_retract=1.0000\n"
      "        technology feed=300.0mm/min spindle=-1200.0rev/min feed_reference=tcp\n"
      "        drilling_strategy reduced_cut_at_start=0.5000 reduced_feed_at_start=0.5000 depth_of_start=2.0000mm\n";
  CHECK(printModule(test::sampleModule()) == expected);
}

TEST_CASE("attributes keep the kind table's order whatever the order they are set in", "[ir]") {
  ir::Node a(ir::Kind::RoundHole);
  a.set("diameter", ir::Value::length(12));
  a.set("depth", ir::Value::length(30));
  a.set("at", ir::Value::point(ir::Vec3(1, 2, 3)));
  ir::Node b(ir::Kind::RoundHole);
  b.set("at", ir::Value::point(ir::Vec3(1, 2, 3)));
  b.set("depth", ir::Value::length(30));
  b.set("diameter", ir::Value::length(12));
  CHECK(ir::equal(a, b));
  REQUIRE(a.attrs.size() == 3);
  CHECK(a.attrs[0].name == "at");
  CHECK(a.attrs[1].name == "depth");
  CHECK(a.attrs[2].name == "diameter");
}
