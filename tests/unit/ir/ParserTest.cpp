// The IR text parser: it reads back exactly what the printer writes, and
// rejects anything else with an error located at the offending token.
#include "SampleModule.h"

#include "ir/Parser.h"
#include "ir/Printer.h"

#include <catch2/catch.hpp>

using namespace stepnc;
using namespace stepnc::ir;
using test::parse;

namespace {

using Errors = std::vector<std::string>;

/// The errors of parsing `text`, which must not give a module.
Errors errorsOf(std::string_view text) {
  test::Parsed p = parse(text);
  CHECK(!p.module);
  return p.errors;
}

} // namespace

TEST_CASE("print, parse, print gives the same bytes", "[ir]") {
  const std::string text = printModule(test::sampleModule());
  test::Parsed p = parse(text);
  REQUIRE(p.errors.empty());
  REQUIRE(p.module);
  CHECK(printModule(*p.module) == text);
  CHECK(p.module->sourceName == "t.ir");
}

TEST_CASE("a parsed module equals the one printed", "[ir]") {
  const Module original = test::sampleModule();
  test::Parsed p = parse(printModule(original));
  REQUIRE(p.module);
  CHECK(equal(p.module->root, original.root));
  CHECK(test::find(p.module->root, "strategy").comment == "overlap from the tool");
  CHECK(p.module->root.label == original.root.label);
}

TEST_CASE("parsed nodes are located at their kind; loc() gives the entity id", "[ir]") {
  test::Parsed p = parse("; header\n"
                         "project \"P\" loc(part.stp:7:1 #3)\n"
                         "\n"
                         "  tool %t type=endmill loc(part.stp:9:1)  ; a (comment) loc(x:1:1)\n");
  REQUIRE(p.errors.empty());
  const Node &root = p.module->root;
  CHECK(root.origin.entityId == 3);
  CHECK(p.source->lineCol(root.origin.loc.offset).line == 2);
  const Node &tool = root.children.at(0);
  CHECK(tool.origin.entityId == 0);
  LineCol lc = p.source->lineCol(tool.origin.loc.offset);
  CHECK((lc.line == 4 && lc.col == 3));
  CHECK(tool.comment == "a (comment) loc(x:1:1)");
}

TEST_CASE("parse errors name the line, the column of the token, the expectation and the finding", "[ir]") {
  SECTION("unknown kind") {
    CHECK(errorsOf("project\n  workpeice %w\n") == Errors{"2:3: unknown node kind 'workpeice'"});
  }
  SECTION("indentation not a multiple of two") {
    CHECK(errorsOf("project\n   tool %t type=endmill\n") ==
          Errors{"2:4: indentation of 3 spaces is not a multiple of two"});
  }
  SECTION("indentation more than one level deeper") {
    CHECK(errorsOf("project\n    tool %t type=endmill\n") ==
          Errors{"2:5: indentation of 4 spaces is more than one level below the node above, expected at most 2"});
  }
  SECTION("wrong unit") {
    CHECK(errorsOf("project\n  workpiece %w\n    closed_pocket %p depth=3.0000deg\n") ==
          Errors{"3:28: attribute 'depth' of 'closed_pocket' is a length in mm, found '3.0000deg'"});
  }
  SECTION("a word not in the table's list") {
    CHECK(errorsOf("project\n  workpiece %w\n    closed_pocket %p bottom=flat\n") ==
          Errors{"3:29: attribute 'bottom' of 'closed_pocket' is one of (planar, radiused, through, general), "
                 "found 'flat'"});
  }
  SECTION("unknown attribute") {
    CHECK(errorsOf("project\n  tool %t type=endmill colour=\"red\"\n") ==
          Errors{"2:24: unknown attribute 'colour' for 'tool'"});
  }
  SECTION("unterminated string") {
    CHECK(errorsOf("project \"EXAMPLE\n") == Errors{"1:9: unterminated string: no closing '\"' on this line"});
    CHECK(errorsOf("project \"EXAMPLE\\\"\n") == Errors{"1:9: unterminated string: no closing '\"' on this line"});
  }
  SECTION("child not allowed under its parent") {
    CHECK(errorsOf("project\n  workpiece %w\n    tool %t type=endmill\n") ==
          Errors{"3:5: 'tool' is not allowed under 'workpiece', which takes rawpiece, clamp or feature"});
    CHECK(errorsOf("project\n  workpiece %w\n    rawpiece shape=block\n      clamp at=(0.0000,0.0000,0.0000)mm\n") ==
          Errors{"4:7: 'clamp' is not allowed under 'rawpiece', which takes no children"});
  }
  SECTION("a number not spelled as printed") {
    CHECK(errorsOf("project\n  workpiece %w\n    closed_pocket %p depth=3.0mm\n") ==
          Errors{"3:28: attribute 'depth' of 'closed_pocket' must be written '3.0000mm', found '3.0mm'"});
    CHECK(errorsOf("project\n  workpiece %w\n    closed_pocket %p depth=-0.0000mm\n") ==
          Errors{"3:28: attribute 'depth' of 'closed_pocket' must be written '0.0000mm', found '-0.0000mm'"});
    CHECK(errorsOf("project\n  tool %t type=endmill flutes=04\n") ==
          Errors{"2:31: attribute 'flutes' of 'tool' must be written '4', found '04'"});
    CHECK(errorsOf("project\n  tool %t type=endmill flutes=4.0\n") ==
          Errors{"2:31: attribute 'flutes' of 'tool' is a count (an integer), found '4.0'"});
  }
  SECTION("points and directions") {
    CHECK(errorsOf("project\n  setup %s axis=(0.0000,0.0000,1.0000)\n") ==
          Errors{"2:17: attribute 'axis' of 'setup' must be written '(0.000000,0.000000,1.000000)', "
                 "found '(0.0000,0.0000,1.0000)'"});
    CHECK(errorsOf("project\n  setup %s at=(0.0000,0.0000)mm\n") ==
          Errors{"2:15: attribute 'at' of 'setup' is a point (x,y,z)mm, found '(0.0000,0.0000)mm'"});
  }
  SECTION("strings where they do not belong, and bare text where a string belongs") {
    CHECK(errorsOf("project\n  workpiece %w material=ST50\n") ==
          Errors{"2:25: attribute 'material' of 'workpiece' is a quoted string, found 'ST50'"});
    CHECK(errorsOf("project\n  workpiece %w global_tolerance=\"0.1\"\n") ==
          Errors{"2:33: attribute 'global_tolerance' of 'workpiece' is a length in mm, found \"0.1\""});
    CHECK(errorsOf("project \"a\\tb\"\n") ==
          Errors{"1:11: unknown escape '\\t' in a string, expected \\\", \\\\ or \\n"});
  }
  SECTION("symbols and labels the kind does not take") {
    CHECK(errorsOf("project %p\n") == Errors{"1:9: 'project' takes no symbol, found '%p'"});
    CHECK(errorsOf("project\n  tool @t type=endmill\n") == Errors{"2:8: 'tool' takes a '%' symbol, found '@t'"});
    CHECK(errorsOf("project\n  workpiece %w\n    rawpiece \"R\" shape=block\n") ==
          Errors{"3:14: 'rawpiece' takes no label, found \"R\""});
  }
  SECTION("fields out of order, repeated or badly separated") {
    CHECK(errorsOf("project\n  tool %t type=endmill type=endmill\n") ==
          Errors{"2:24: attribute 'type' is given twice"});
    CHECK(errorsOf("project\n  tool type=endmill %t\n") ==
          Errors{"2:21: expected an attribute 'name=value', found '%t'"});
    CHECK(errorsOf("project \n") == Errors{"1:9: expected a field after one space, found the end of the line"});
    CHECK(errorsOf("project  \"P\"\n") == Errors{"1:9: expected a field after one space, found another space"});
    CHECK(errorsOf("project loc(part.stp)\n") ==
          Errors{"1:9: expected 'loc(file:line:col)' or 'loc(file:line:col #id)', found 'loc(part.stp)'"});
    CHECK(errorsOf("project loc(a:1:1) \"P\"\n") ==
          Errors{"1:20: expected a comment after 'loc(...)', found '\"P\"'"});
  }
  SECTION("the root") {
    CHECK(errorsOf("") == Errors{"1:1: expected a 'project' node, found no node"});
    CHECK(errorsOf("  project\n") == Errors{"1:3: expected the root node without indentation, found 2 spaces"});
    CHECK(errorsOf("workpiece %w\n") == Errors{"1:1: expected the root node 'project', found 'workpiece'"});
    CHECK(errorsOf("project\nproject\n") == Errors{"2:1: expected one root node, found a second one: 'project'"});
  }
}

TEST_CASE("the parser reports errors line after line, skipping what it could not place", "[ir]") {
  CHECK(errorsOf("project\n"
                 "  workpeice %w\n"
                 "    rawpiece shape=oval\n"
                 "  tool %t type=drill\n"
                 "    clamp\n"
                 "  tool %u type=endmill flutes=4.0\n") ==
        Errors{"2:3: unknown node kind 'workpeice'",
               "4:16: attribute 'type' of 'tool' is one of (endmill, facemill, ball_endmill, bullnose_endmill, "
               "tapered_endmill, side_mill, t_slot_mill, twist_drill, center_drill, spot_drill, tapered_drill, "
               "reamer, tapered_reamer, tap, boring_tool, countersink, counterbore, cutting_tool, turning_tool, "
               "grooving_tool, threading_tool, knurling_tool, deposition_head), found 'drill'",
               "5:5: 'clamp' is not allowed under 'tool', which takes no children",
               "6:31: attribute 'flutes' of 'tool' is a count (an integer), found '4.0'"});
}
