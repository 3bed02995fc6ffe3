// The IR verifier: the sample module verifies clean, and each mutation of it
// gives exactly its one error, naming the node.
#include "SampleModule.h"

#include "ir/Parser.h"
#include "ir/Verifier.h"

#include <catch2/catch.hpp>
#include <algorithm>
#include <limits>

using namespace stepnc;
using namespace stepnc::ir;
using test::find;

namespace {

using Errors = std::vector<std::string>;

Errors verify(const Module &m) {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  const bool ok = verifyModule(m, engine);
  CHECK(ok == c.diags.empty());
  return test::messages(c);
}

void unset(Node &n, std::string_view name) {
  std::erase_if(n.attrs, [&](const Attr &a) { return a.name == name; });
}

} // namespace

TEST_CASE("the sample module verifies clean, built or parsed", "[ir]") {
  const Module m = test::sampleModule();
  CHECK(verify(m).empty());
  test::Parsed p = test::parse("project\n"
                               "  tool %t type=endmill corner_radius=0.0000mm\n");
  REQUIRE(p.module);
  CHECK(verify(*p.module).empty());
}

TEST_CASE("each mutation of a valid module gives its error", "[ir]") {
  Module m = test::sampleModule();
  Node &root = m.root;
  Node &pocket = find(root, "%pocket1");
  Node &milling = find(root, "bottom_and_side_rough_milling");
  Node &drilling = find(root, "drilling");

  SECTION("missing required attribute") {
    unset(pocket, "depth");
    CHECK(verify(m) == Errors{"closed_pocket %pocket1: missing required attribute 'depth'"});
  }
  SECTION("attribute the kind does not list") {
    pocket.attrs.push_back({"colour", Value::string("red")});  // set() refuses it
    CHECK(verify(m) == Errors{"closed_pocket %pocket1: unknown attribute 'colour' for 'closed_pocket'"});
  }
  SECTION("value of the wrong type") {
    pocket.set("depth", Value::angle(3));
    CHECK(verify(m) ==
          Errors{"closed_pocket %pocket1: attribute 'depth' is a length in mm, found a value of type angle"});
  }
  SECTION("word not in the table's list") {
    find(root, "strategy").set("cutmode", Value::word("upcut"));
    CHECK(verify(m) == Errors{"strategy: attribute 'cutmode' is one of (climb, conventional), found 'upcut'"});
  }
  SECTION("dangling reference") {
    milling.set("tool", Value::ref("%nope"));
    CHECK(verify(m) == Errors{"bottom_and_side_rough_milling \"ROUGH POCKET1\": attribute 'tool' refers to "
                              "'%nope', which is not defined"});
  }
  SECTION("tool reference to a feature") {
    milling.set("tool", Value::ref("%pocket1"));
    CHECK(verify(m) == Errors{"bottom_and_side_rough_milling \"ROUGH POCKET1\": attribute 'tool' refers to "
                              "'%pocket1', a closed_pocket, expected a tool"});
  }
  SECTION("feature reference to a tool") {
    find(root, "@ws_drill_hole1").set("feature", Value::ref("%drill_10mm"));
    CHECK(verify(m) == Errors{"workingstep @ws_drill_hole1: attribute 'feature' refers to '%drill_10mm', a tool, "
                              "expected a feature"});
  }
  SECTION("duplicate symbol") {
    root.add(Node(find(root, "%mill_18mm")));
    DiagnosticCollector c;
    DiagnosticEngine engine(c);
    CHECK(!verifyModule(m, engine));
    CHECK(test::messages(c) == Errors{"tool %mill_18mm: symbol '%mill_18mm' is defined twice"});
    CHECK(c.diags.at(0).notes.at(0).message == "first defined by tool %mill_18mm");
  }
  SECTION("direction not of unit length") {
    find(root, "%setup1").set("axis", Value::direction(Vec3(0, 0, 2)));
    CHECK(verify(m) == Errors{"setup %setup1: attribute 'axis' must be a unit vector, found length 2.000000"});
  }
  SECTION("zero depth; a negative radius") {
    pocket.set("depth", Value::length(0));
    find(root, "%mill_18mm").set("corner_radius", Value::length(-1));
    CHECK(verify(m) == Errors{"closed_pocket %pocket1: attribute 'depth' must be positive, found 0.0000mm",
                              "tool %mill_18mm: attribute 'corner_radius' must not be negative, found -1.0000mm"});
  }
  SECTION("number not finite") {
    milling.set("retract_plane", Value::length(std::numeric_limits<double>::quiet_NaN()));
    CHECK(verify(m) == Errors{"bottom_and_side_rough_milling \"ROUGH POCKET1\": attribute 'retract_plane' must be "
                              "a finite number, found nan"});
  }
  SECTION("two operations in a workingstep") {
    find(root, "@ws_rough_pocket1").add(Node(milling));
    CHECK(verify(m) == Errors{"workingstep @ws_rough_pocket1: expected exactly one operation, found 2"});
  }
  SECTION("two technologies, two strategies in an operation") {
    drilling.add(Node(*drilling.child(ir::Kind::Technology)));
    drilling.add(Node(*drilling.child(ir::Kind::DrillingStrategy)));
    CHECK(verify(m) == Errors{"drilling \"DRILL HOLE1\": expected at most one technology, found 2",
                              "drilling \"DRILL HOLE1\": expected at most one strategy, drilling_strategy, "
                              "trochoidal_strategy or plunge_strategy, found 2"});
  }
  SECTION("a pattern strategy without its guide") {
    Node *pattern = nullptr;
    for (Node &op : find(root, "@ws_rough_pocket1").children)
      for (Node &c : op.children)
        if (c.kind == ir::Kind::Strategy)
          pattern = &(c = Node(ir::Kind::TrochoidalStrategy));
    REQUIRE(pattern);
    pattern->set("radius", Value::length(3)).set("step", Value::length(1));
    CHECK(verify(m) == Errors{"trochoidal_strategy: expected exactly one guide 'strategy', found 0"});
    pattern->add(Node(ir::Kind::Strategy)).set("type", Value::word("center_milling"));
    CHECK(verify(m).empty());
  }
  SECTION("child its parent does not take") {
    Node tool = find(root, "%drill_10mm");
    tool.symbol = "%drill_2";
    find(root, "workpiece").add(tool);
    CHECK(verify(m) == Errors{"tool %drill_2: not allowed under 'workpiece', which takes rawpiece, clamp or feature"});
  }
  SECTION("project below the root") {
    find(root, "workplan").add(Node(ir::Kind::Project));
    CHECK(verify(m) == Errors{"project: 'project' is only allowed as the root node"});
  }
  SECTION("symbols: wrong sigil, missing, where none is taken") {
    find(root, "@ws_drill_hole1").symbol = "%ws_drill_hole1";
    find(root, "workplan").symbol.clear();
    find(root, "rawpiece").symbol = "%raw";
    CHECK(verify(m) == Errors{"rawpiece %raw: takes no symbol, found '%raw'",
                              "workplan \"MAIN WORKPLAN\": missing its '@' symbol",
                              "workingstep %ws_drill_hole1: expected a '@' symbol, found '%ws_drill_hole1'"});
  }
  SECTION("comment on two lines") {
    // (An unknown kind cannot be built: kinds are an enum; the parser reports unknown names.)
    find(root, "strategy").comment = "one\ntwo";
    CHECK(verify(m) == Errors{"strategy: the comment has a line break, expected one line"});
  }
}

TEST_CASE("verifier errors on parsed IR are located at the node's line", "[ir]") {
  test::Parsed p = test::parse("project\n"
                               "  tool %t type=endmill diameter=0.0000mm loc(part.stp:5:1 #12)\n"
                               "  workplan @plan setup=%t\n");
  REQUIRE(p.module);
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  CHECK(!verifyModule(*p.module, engine));
  CHECK(test::messages(c) == Errors{"2:3: tool %t: attribute 'diameter' must be positive, found 0.0000mm",
                                    "3:3: workplan @plan: attribute 'setup' refers to '%t', a tool, expected a setup"});
  CHECK(c.diags.at(0).entityId == 12);
}
