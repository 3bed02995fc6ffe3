// The G-code words every target shares: numbers, modal state, balanced arc
// centres, arc splitting and sweeps, tool tables, and the canned cycles
// recognised in a hole-making step's moves.
#include "backends/Target.h"
#include "backends/common/Program.h"
#include "backends/common/ToolTable.h"
#include "backends/common/Words.h"

#include "../ir/SampleModule.h"

#include <catch2/catch.hpp>

#include <numbers>

using namespace stepnc;
using namespace stepnc::backends;

TEST_CASE("numbers are written without exponent or -0, with the point", "[backends]") {
  const NumberStyle iso{3, false, true};
  CHECK(formatNumber(10, iso) == "10.");
  CHECK(formatNumber(10.5, iso) == "10.5");
  CHECK(formatNumber(-0.0001, iso) == "0.");  // rounds to -0
  CHECK(formatNumber(-0.0, iso) == "0.");
  CHECK(formatNumber(1e-7, iso) == "0.");
  CHECK(formatNumber(123456789.0, iso) == "123456789.");
  CHECK(formatNumber(0.0005, iso) == "0.001");  // half away from zero
  CHECK(formatNumber(-2.25, {1, false, true}) == "-2.3");
  const NumberStyle tnc{3, true, false};
  CHECK(formatNumber(25, tnc) == "+25");
  CHECK(formatNumber(-7.5, tnc) == "-7.5");
  CHECK(formatNumber(-0.0002, tnc) == "+0");
}

TEST_CASE("modal words are written only when they change", "[backends]") {
  ModalState m;
  CHECK(m.change("G", "G1"));
  CHECK_FALSE(m.change("G", "G1"));
  CHECK(m.change("G", "G0"));
  m.forget("G");
  CHECK(m.change("G", "G0"));
}

TEST_CASE("arc centres are balanced between the endpoints as printed", "[backends]") {
  // A quarter arc of radius 10 about the origin, its end rounded off the circle.
  const geom::Vec2 from(10, 0), to(0.0004, 10.0004), centre(0, 0);
  const geom::Vec2 c = geom::balancedCentre(from, to, centre);
  CHECK(std::abs((c - from).norm() - (c - to).norm()) < 1e-12);
  CHECK((c - centre).norm() < 1e-3);
  // A whole circle keeps its centre.
  CHECK((geom::balancedCentre(from, from, centre) - centre).norm() == 0);
}

TEST_CASE("rounded centre offsets keep start and end radius together", "[backends]") {
  // Random arcs printed with 3 decimals: the printed I J must put the centre
  // as far from the printed start as from the printed end, within 0.001 mm
  // (LinuxCNC's strict tolerance). Rounding the balanced centre alone
  // misses by up to 0.0014 mm on these arcs; 0.001 is what a grid of
  // 0.001 mm allows for a half circle whose chord ends on half a unit.
  uint64_t seed = 12345;
  auto next = [&] {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(seed >> 11) / 9007199254740992.0;
  };
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const geom::Vec2 c(next() * 200 - 100, next() * 200 - 100);
    const double r = 0.1 + next() * 50, a0 = next() * 6.3, a1 = next() * 6.3;
    const geom::Vec2 from(roundTo(c.x() + r * std::cos(a0), 3), roundTo(c.y() + r * std::sin(a0), 3));
    const geom::Vec2 to(roundTo(c.x() + r * std::cos(a1), 3), roundTo(c.y() + r * std::sin(a1), 3));
    const geom::Vec2 ij = roundedCentreOffset(from, to, geom::balancedCentre(from, to, c), 3);
    CHECK(roundTo(ij.x(), 3) == ij.x());
    worst = std::max(worst, std::abs(ij.norm() - (from + ij - to).norm()));
  }
  CHECK(worst <= 0.001);
}

TEST_CASE("arc sweeps count full turns; split points divide them equally", "[backends]") {
  Move m;
  m.kind = Move::Kind::Arc;
  m.from = {10, 0, 0};
  m.to = {0, 10, 0};
  m.centre = {0, 0};
  m.ccw = true;
  CHECK(m.sweep() == Approx(std::numbers::pi / 2));
  m.ccw = false;
  CHECK(m.sweep() == Approx(3 * std::numbers::pi / 2));
  m.to = {10, 0, -5};  // over the start: a whole turn, plus one more
  m.turns = 1;
  CHECK(m.sweep() == Approx(4 * std::numbers::pi));
  const auto ends = arcSplitPoints({10, 0}, {0, 0}, true, std::numbers::pi, 2);
  REQUIRE(ends.size() == 2);
  CHECK((ends[0] - geom::Vec2(0, 10)).norm() < 1e-12);
  CHECK((ends[1] - geom::Vec2(-10, 0)).norm() < 1e-12);
}

TEST_CASE("numbered blocks and overlong lines", "[backends]") {
  TargetDescriptor d;
  d.numbering = Numbering::Every;
  d.numberStep = 10;
  d.maxLineLength = 12;
  BlockWriter w(d);
  w.raw("%");
  w.block("G0 X1.");
  w.block("G1 X123.456 Y7.");
  CHECK(w.text() == "%\nN10 G0 X1.\nN20 G1 X123.456 Y7.\n");
  REQUIRE(w.overlong().size() == 1);
  CHECK(w.overlong()[0] == 3);
  TargetDescriptor z;
  z.numbering = Numbering::FromZero;
  BlockWriter tnc(z);
  tnc.block("BEGIN PGM A MM");
  tnc.block("END PGM A MM");
  CHECK(tnc.text() == "0 BEGIN PGM A MM\n1 END PGM A MM\n");
}

TEST_CASE("capability overrides are checked", "[backends]") {
  TargetDescriptor d;
  d.name = "t";
  d.cycles = {{CycleKind::Drill, {}}};
  CHECK(applyOverrides(d, {"decimals=4", "arcs=radius", "cycles=off", "max-line-length=80"}).empty());
  CHECK(d.coordDecimals == 4);
  CHECK(d.arcs == ArcForm::Radius);
  CHECK(d.cycles.empty());
  CHECK(d.maxLineLength == 80);
  CHECK_FALSE(applyOverrides(d, {"decimals=7"}).empty());
  CHECK_FALSE(applyOverrides(d, {"arcs"}).empty());
  CHECK_FALSE(applyOverrides(d, {"colour=red"}).empty());
  d.numbering = Numbering::FromZero;
  CHECK(applyOverrides(d, {"line-numbers=none"}).find("cannot be changed") != std::string::npos);
}

TEST_CASE("tool tables: entries by id or symbol, errors at line and column", "[backends]") {
  auto file = SourceFile::fromString("tools.txt", "# comment\n\"T2 ENDMILL\"  12  85.5 # the rougher\n"
                                                  "%t3 7\n");
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  auto table = ToolTable::parse(*file, diags);
  REQUIRE(table);
  ir::Node t2(ir::Kind::Tool);
  t2.symbol = "%t2";
  t2.label = "T2 ENDMILL";
  ir::Node t3(ir::Kind::Tool);
  t3.symbol = "%t3";
  ir::Node t4(ir::Kind::Tool);
  t4.symbol = "%t4";
  REQUIRE(table->find(t2));
  CHECK(table->find(t2)->number == 12);
  CHECK(*table->find(t2)->length == 85.5);
  REQUIRE(table->find(t3));
  CHECK(table->find(t3)->number == 7);
  CHECK_FALSE(table->find(t3)->length);
  CHECK(table->find(t4) == nullptr);

  for (const char *bad : {"\"T2 ENDMILL 12\n", "T2 12\n", "%t2 0\n", "%t2 5 -1\n", "%t2 5 1 2\n", "%t2\n"}) {
    DiagnosticCollector badCollector;
    DiagnosticEngine d(badCollector);
    auto f = SourceFile::fromString("bad.txt", bad);
    CHECK_FALSE(ToolTable::parse(*f, d));
    CHECK(d.errorCount() == 1);
  }
}

TEST_CASE("LinuxCNC tool tables: numbers, diameters, lengths, comments", "[backends]") {
  auto file = SourceFile::fromString("tool.tbl", "; a comment line first\n"
                                                 "T1 P1 D10.000 Z+50.000 ;SPOT D10\n"
                                                 "t2 p5 x0 z-1.5 d8 i0 j0 q0\r\n"
                                                 "\n"
                                                 "T12 P12 ;   REAMER D10  \n");
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  auto table = ToolTable::parse(*file, diags);
  REQUIRE(table);
  CHECK(table->format() == ToolTable::Format::LinuxCnc);
  REQUIRE(table->entries().size() == 3);
  const ToolTable::Entry &t1 = table->entries()[0];
  CHECK(t1.number == 1);
  CHECK(*t1.diameter == 10);
  CHECK(*t1.length == 50);
  CHECK(t1.key == "SPOT D10");
  CHECK(t1.loc.offset == 23);
  CHECK(t1.diameterLoc.offset == 29);
  CHECK(*table->entries()[1].diameter == 8);
  CHECK(*table->entries()[1].length == -1.5);
  CHECK(table->entries()[1].key.empty());
  CHECK_FALSE(table->entries()[2].diameter);
  CHECK(table->entries()[2].key == "REAMER D10");
  // Tools are found by number, and by a comment that is their STEP-NC id.
  CHECK(table->findNumber(2) == &table->entries()[1]);
  CHECK(table->findNumber(3) == nullptr);
  ir::Node reamer(ir::Kind::Tool);
  reamer.symbol = "%reamer";
  reamer.label = "REAMER D10";
  CHECK(table->find(reamer) == &table->entries()[2]);

  for (const char *bad : {"T0 P1\n", "T1 P1 D-3\n", "T1 P1 D\n", "T1 P1 R3\n", "T1 P1\nT1 P2\n", "T1\nP2 D3\n",
                          "T1 T2\n"}) {
    DiagnosticCollector badCollector;
    DiagnosticEngine d(badCollector);
    auto f = SourceFile::fromString("bad.tbl", bad);
    CHECK_FALSE(ToolTable::parse(*f, d));
    CHECK(d.errorCount() == 1);
  }
}

namespace {

/// A drilled hole's workingstep with the given moves, in IR text.
std::optional<Program> holeProgram(const std::string &op, const std::string &moves) {
  auto parsed = ir::test::parse(
      "project \"P\"\n"
      "  workpiece %wp \"WP\"\n"
      "    round_hole %h \"H\" at=(10.0000,10.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) "
      "ref=(1.000000,0.000000,0.000000) depth=12.0000mm diameter=8.0000mm bottom=flat\n"
      "  tool %d \"DRILL\" type=twist_drill diameter=8.0000mm\n"
      "  workplan @plan \"PLAN\"\n"
      "    workingstep @ws \"WS\" feature=%h secplane=20.0000mm\n"
      "      " + op + " \"OP\" tool=%d\n"
      "      moves tool=%d spindle=-1000.0rev/min coolant=off secplane=20.0000mm\n" + moves);
  REQUIRE(parsed.errors.empty());
  static std::unique_ptr<ir::Module> keep;
  keep = std::move(parsed.module);
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  return buildProgram(*keep, nullptr, diags);
}

/// The moves of a drill from the security plane z=20 to R z=2, down to
/// z=-12 and back up, indented for a cycle (or, with `moveIndent` 8, for
/// `moves` itself).
std::string drillMoves(int moveIndent) {
  const std::string in(static_cast<size_t>(moveIndent), ' ');
  return in + "rapid to=(10.0000,10.0000,20.0000)mm role=position\n" + in +
         "rapid to=(10.0000,10.0000,2.0000)mm role=approach\n" + in +
         "linear to=(10.0000,10.0000,-12.0000)mm feed=100.0mm/min role=plunge\n" + in +
         "rapid to=(10.0000,10.0000,20.0000)mm role=retract\n";
}

} // namespace

TEST_CASE("hole cycles come from the IR's cycle, never from the moves", "[backends]") {
  // The moves of a drilling cycle, but no `cycle` says so: moves.
  auto bare = holeProgram("drilling", drillMoves(8));
  REQUIRE(bare);
  REQUIRE(bare->steps.size() == 1);
  CHECK_FALSE(bare->steps[0].cycle);
  // The program's first step starts with its clearance move, then the four.
  CHECK(bare->steps[0].moves.size() == 5);
  CHECK(bare->steps[0].moves[0].alongZOnly);

  // The same moves inside a cycle: what it says, read from its attributes.
  auto drill = holeProgram("drilling", "        cycle type=drill at=(10.0000,10.0000,0.0000)mm clearance=2.0000mm "
                                       "bottom=-12.0000mm feed=100.0mm/min dwell=0.500s end_feed=50.0mm/min "
                                       "end_depth=2.0000mm\n" +
                                           drillMoves(10));
  REQUIRE(drill);
  REQUIRE(drill->steps[0].cycle);
  const HoleCycle &c = *drill->steps[0].cycle;
  CHECK(c.kind == CycleKind::Drill);
  CHECK(c.initialZ == 20);
  CHECK(c.retractZ == 2);
  CHECK(c.surfaceZ == 0);
  CHECK(c.depthZ == -12);
  CHECK(c.pecks == std::vector<double>{-12});
  CHECK(c.feed == 100);
  CHECK(c.feedOut == 0);
  CHECK(c.dwell == 0.5);
  CHECK(c.endFeed == 50);
  CHECK(c.endDepth == 2);
  // The cycle's moves are the step's moves all the same (after the clearance move).
  CHECK(drill->steps[0].moves.size() == 5);

  auto peck = holeProgram("multistep_drilling",
                          "        cycle type=peck at=(10.0000,10.0000,0.0000)mm clearance=2.0000mm bottom=-12.0000mm "
                          "feed=100.0mm/min pecks=(-5,-12) reapproach=0.5000mm dwell_step=0.200s\n"
                          "          rapid to=(10.0000,10.0000,20.0000)mm role=position\n"
                          "          rapid to=(10.0000,10.0000,2.0000)mm role=approach\n"
                          "          linear to=(10.0000,10.0000,-5.0000)mm feed=100.0mm/min role=plunge\n"
                          "          dwell time=0.200s\n"
                          "          rapid to=(10.0000,10.0000,2.0000)mm role=retract\n"
                          "          rapid to=(10.0000,10.0000,-4.5000)mm role=approach\n"
                          "          linear to=(10.0000,10.0000,-12.0000)mm feed=100.0mm/min role=plunge\n"
                          "          rapid to=(10.0000,10.0000,20.0000)mm role=retract\n");
  REQUIRE(peck);
  REQUIRE(peck->steps[0].cycle);
  CHECK(peck->steps[0].cycle->kind == CycleKind::Peck);
  CHECK(peck->steps[0].cycle->pecks == std::vector<double>{-5, -12});
  CHECK(peck->steps[0].cycle->reapproach == 0.5);
  CHECK(peck->steps[0].cycle->dwellStep == 0.2);
  // The dwell is a move of the step, where the tool stands.
  REQUIRE(peck->steps[0].moves.size() == 9);
  CHECK(peck->steps[0].moves[4].kind == Move::Kind::Dwell);
  CHECK(peck->steps[0].moves[4].dwell == 0.2);
  CHECK(peck->steps[0].moves[4].to == ir::Vec3(10, 10, -5));

  // What a target's descriptor lacks to write the cycle.
  TargetDescriptor d;
  d.name = "t";
  CHECK(whyNotCycle(d, c) == "cycles are off (--no-cycles or cycles=off)");
  d.cycles = {{CycleKind::Peck, {}}};
  CHECK(whyNotCycle(d, c) == "t writes no drill cycle");
  d.cycles = {{CycleKind::Drill, {}}};
  CHECK(whyNotCycle(d, c) == "its drill cycle has no dwell at the bottom");
  d.cycles = {{CycleKind::Drill, {.dwell = true}}};
  CHECK(whyNotCycle(d, c) == "its drill cycle has no reduced feeds near the top or bottom");
  d.cycles = {{CycleKind::Drill, {.dwell = true, .reducedFeeds = true}}};
  CHECK(whyNotCycle(d, c).empty());
}

TEST_CASE("the program and every tool change start up along Z alone", "[backends]") {
  // Three steps: T1, T1 again, T2; the last one's first rapid goes across
  // and down at once (to z=5, under its security plane 20).
  auto parsed = ir::test::parse(
      "project \"P\"\n"
      "  workpiece %wp \"WP\"\n"
      "    round_hole %h \"H\" at=(10.0000,10.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) "
      "ref=(1.000000,0.000000,0.000000) depth=12.0000mm diameter=8.0000mm bottom=flat\n"
      "  tool %a \"A\" type=twist_drill diameter=8.0000mm\n"
      "  tool %b \"B\" type=twist_drill diameter=6.0000mm\n"
      "  workplan @plan \"PLAN\"\n"
      "    workingstep @ws1 \"WS1\" feature=%h secplane=20.0000mm\n"
      "      drilling \"OP\" tool=%a\n"
      "      moves tool=%a spindle=-1000.0rev/min coolant=off secplane=20.0000mm\n" +
      drillMoves(8) +
      "    workingstep @ws2 \"WS2\" feature=%h secplane=20.0000mm\n"
      "      drilling \"OP\" tool=%a\n"
      "      moves tool=%a spindle=-1000.0rev/min coolant=off secplane=20.0000mm\n" +
      drillMoves(8) +
      "    workingstep @ws3 \"WS3\" feature=%h secplane=20.0000mm\n"
      "      drilling \"OP\" tool=%b\n"
      "      moves tool=%b spindle=-1000.0rev/min coolant=off secplane=20.0000mm\n"
      "        rapid to=(30.0000,10.0000,5.0000)mm role=position\n"
      "        linear to=(30.0000,10.0000,-12.0000)mm feed=100.0mm/min role=plunge\n"
      "        rapid to=(30.0000,10.0000,20.0000)mm role=retract\n");
  REQUIRE(parsed.errors.empty());
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  auto p = buildProgram(*parsed.module, nullptr, diags);
  REQUIRE(p);
  REQUIRE(p->steps.size() == 3);

  // The start: up to the security plane, Z alone, then the planned moves.
  const Step &first = p->steps[0];
  CHECK(first.toolChange);
  REQUIRE(first.moves.size() == 5);
  CHECK(first.moves[0].alongZOnly);
  CHECK(first.moves[0].role == "clearance");
  CHECK(first.moves[0].kind == Move::Kind::Rapid);
  CHECK(first.moves[0].to.z() == 20);
  CHECK(first.moves[1].to == ir::Vec3(10, 10, 20));
  CHECK(first.moves[1].from.z() == 20);

  // The same tool again: its moves as planned.
  CHECK_FALSE(p->steps[1].toolChange);
  CHECK(p->steps[1].moves.size() == 4);
  CHECK_FALSE(p->steps[1].moves[0].alongZOnly);

  // A new tool: up, across at the security plane, then down.
  const Step &third = p->steps[2];
  CHECK(third.toolChange);
  REQUIRE(third.moves.size() == 5);
  CHECK(third.moves[0].alongZOnly);
  CHECK(third.moves[0].to.z() == 20);
  CHECK(third.moves[1].kind == Move::Kind::Rapid);
  CHECK(third.moves[1].to == ir::Vec3(30, 10, 20));
  CHECK(third.moves[2].kind == Move::Kind::Rapid);
  CHECK(third.moves[2].from == ir::Vec3(30, 10, 20));
  CHECK(third.moves[2].to == ir::Vec3(30, 10, 5));
  CHECK(clearanceHeight(third) == 20);
}
