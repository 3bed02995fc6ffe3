// The Klartext reader (backends/heidenhain-tnc/KlartextReader.h): the
// motions of a hand-written program (lines, arcs about a pole, a helix of
// two turns, a dwell, cycle 200 expanded at its call), each structural rule
// reported on its line when a copy breaks it, and the programs the
// heidenhain-tnc emitter writes for the bundled examples read without a
// problem.
#include "backends/Backend.h"
#include "backends/heidenhain-tnc/KlartextReader.h"
#include "driver/Pipeline.h"
#include "tests/unit/backends/ReadBackTestSupport.h"
#include "tests/unit/passes/PassTestSupport.h"

#include <cmath>
#include <numbers>

namespace stepnc {
namespace {

using backends::Move;
using backends::ProgramReading;
using backends::ReadMove;
using test::hasProblem;
using test::problems;

constexpr double kPi = std::numbers::pi;

backends::TargetDescriptor tncDescriptor() { return test::descriptorOf("heidenhain-tnc"); }

ProgramReading read(const std::string &text) { return backends::readKlartext(text, tncDescriptor()); }

/// A program the reader passes: a pocket tool with lines, two half circles
/// about one pole, a helix of two turns down and a dwell; a drill with cycle
/// 200 in three infeeds and a dwell at the bottom. Block n is on line n + 1
/// up to the cycle definition, whose parameter lines follow it (lines
/// 25-32); its call is on line 33.
const std::string kGood = R"(0 BEGIN PGM GOOD MM
1 BLK FORM 0.1 Z X+0 Y+0 Z-20
2 BLK FORM 0.2 X+100 Y+80 Z+0
3 ; a hand-written program the reader passes
4 CYCL DEF 32.0 TOLERANCE
5 CYCL DEF 32.1 T0.01
6 * - POCKET
7 TOOL CALL 1 Z S3000
8 L Z+20 R0 FMAX M3
9 L X+10 Y+40 R0 FMAX M8
10 L Z-2 R0 F200
11 L X+30 R0 F800
12 CC X+40 Y+40
13 C X+50 Y+40 DR+
14 C X+30 Y+40 DR+
15 CP IPA-720 IZ-2 DR-
16 CYCL DEF 9.0 DWELL TIME
17 CYCL DEF 9.1 DWELL 0.5
18 L Z+20 R0 FMAX
19 * - DRILL
20 TOOL CALL 2 Z S2000
21 L Z+20 R0 FMAX M3
22 L X+60 Y+20 R0 FMAX
23 CYCL DEF 200 DRILLING ~
  Q200=+2 ;SET-UP CLEARANCE ~
  Q201=-10 ;DEPTH ~
  Q206=+150 ;FEED RATE FOR PLNGNG ~
  Q202=+4 ;PLUNGING DEPTH ~
  Q210=+0 ;DWELL TIME AT TOP ~
  Q203=+0 ;SURFACE COORDINATE ~
  Q204=+20 ;2ND SET-UP CLEARANCE ~
  Q211=+0.2 ;DWELL TIME AT DEPTH
24 L X+60 Y+20 R0 FMAX M99
25 L Z+20 R0 FMAX M5
26 L Z+20 R0 FMAX M9
27 CYCL DEF 32.0 TOLERANCE
28 CYCL DEF 32.1
29 L Z+20 R0 FMAX M30
30 END PGM GOOD MM
)";

/// `text` with its first `from` replaced by `to`.
std::string replaced(std::string text, const std::string &from, const std::string &to) {
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

void checkEnd(const ReadMove &m, double x, double y, double z) {
  CHECK(m.to.x() == Approx(x).margin(1e-9));
  CHECK(m.to.y() == Approx(y).margin(1e-9));
  CHECK(m.to.z() == Approx(z).margin(1e-9));
}

TEST_CASE("Klartext reader: the motions of a clean program", "[readback][heidenhain-tnc]") {
  const ProgramReading r = read(kGood);
  INFO(problems(r));
  REQUIRE(r.problems.empty());
  // Pocket: 2 rapids, 2 lines, 2 arcs, the helix, the dwell, the rapid up.
  // Drill: 2 rapids; the cycle's 10 moves; the M5/M9/M30 blocks move nothing.
  REQUIRE(r.moves.size() == 21);

  // Where the tool change left X and Y is the machine's business.
  const ReadMove &up = r.moves[0];
  CHECK(up.kind == Move::Kind::Rapid);
  CHECK(std::isnan(up.from.x()));
  CHECK(std::isnan(up.to.x()));
  CHECK(std::isnan(up.to.y()));
  CHECK(up.to.z() == 20);
  CHECK(up.line == 9);
  CHECK(r.moves[1].kind == Move::Kind::Rapid);
  checkEnd(r.moves[1], 10, 40, 20);

  CHECK(r.moves[2].kind == Move::Kind::Linear);
  checkEnd(r.moves[2], 10, 40, -2);
  CHECK(r.moves[2].feed == 200);
  CHECK(r.moves[3].kind == Move::Kind::Linear);
  CHECK(r.moves[3].feed == 800);
  CHECK(r.moves[3].line == 12);

  const ReadMove &half = r.moves[4];
  CHECK(half.kind == Move::Kind::Arc);
  checkEnd(half, 50, 40, -2);
  CHECK((half.centre - geom::Vec2(40, 40)).norm() < 1e-9);
  CHECK(half.ccw);
  CHECK(half.sweep == Approx(kPi));
  CHECK(half.feed == 800);  // modal
  CHECK(half.line == 14);

  // CP IPA-720: two turns clockwise, 2 mm down, back over its start.
  const ReadMove &helix = r.moves[6];
  CHECK(helix.kind == Move::Kind::Arc);
  CHECK_FALSE(helix.ccw);
  CHECK(helix.sweep == Approx(4 * kPi));
  CHECK((helix.centre - geom::Vec2(40, 40)).norm() < 1e-9);
  checkEnd(helix, 30, 40, -4);
  CHECK(helix.from.z() == -2);
  CHECK(helix.line == 16);

  CHECK(r.moves[7].kind == Move::Kind::Dwell);
  CHECK(r.moves[7].dwell == 0.5);
  CHECK(r.moves[7].line == 18);
  CHECK(r.moves[8].kind == Move::Kind::Rapid);
  checkEnd(r.moves[8], 30, 40, 20);
  CHECK_FALSE(r.moves[8].cycle);

  CHECK(std::isnan(r.moves[9].to.x()));
  CHECK(r.moves[9].line == 22);
  checkEnd(r.moves[10], 60, 20, 20);

  // Cycle 200 at X60 Y20: down to the set-up clearance, three infeeds of 4
  // mm from the surface (the last to the depth) with rapids out to Q200 and
  // back down to Q200 above the depth reached, Q211 at the bottom, out to
  // Q204.
  std::vector<const ReadMove *> cycle;
  for (const ReadMove &m : r.moves)
    if (m.cycle)
      cycle.push_back(&m);
  REQUIRE(cycle.size() == 10);
  const Move::Kind R = Move::Kind::Rapid, F = Move::Kind::Linear, D = Move::Kind::Dwell;
  const std::vector<std::pair<Move::Kind, double>> expected = {{R, 2},  {F, -4}, {R, 2},   {R, -2}, {F, -8},
                                                                {R, 2},  {R, -6}, {F, -10}, {D, -10}, {R, 20}};
  for (size_t k = 0; k < cycle.size(); ++k) {
    INFO("cycle move " << k);
    CHECK(cycle[k]->kind == expected[k].first);
    checkEnd(*cycle[k], 60, 20, expected[k].second);
    CHECK(cycle[k]->line == 33);
    if (cycle[k]->kind == F)
      CHECK(cycle[k]->feed == 150);
  }
  CHECK(cycle[8]->dwell == Approx(0.2));
}

TEST_CASE("Klartext reader: each structural rule is a problem on its line", "[readback][heidenhain-tnc]") {
  auto problemsOf = [](const std::string &text) {
    const ProgramReading r = read(text);
    INFO(problems(r));
    CHECK_FALSE(r.problems.empty());
    return r;
  };
  SECTION("the first motion after a TOOL CALL is Z alone") {
    const ProgramReading r = problemsOf(replaced(kGood, "8 L Z+20 R0 FMAX M3", "8 L X+10 Y+40 Z+20 R0 FMAX M3"));
    CHECK(hasProblem(r, 9, "the first motion after the TOOL CALL on line 8 is not Z alone"));
  }
  SECTION("no feed move with the spindle stopped") {
    const ProgramReading r = problemsOf(replaced(kGood, "8 L Z+20 R0 FMAX M3", "8 L Z+20 R0 FMAX"));
    CHECK(hasProblem(r, 11, "feed move with the spindle stopped"));
  }
  SECTION("no feed move without a feed") {
    const ProgramReading r = problemsOf(replaced(kGood, "10 L Z-2 R0 F200", "10 L Z-2 R0"));
    CHECK(hasProblem(r, 11, "feed move without a feed"));
  }
  SECTION("no motion before a TOOL CALL") {
    const ProgramReading r = problemsOf(replaced(kGood, "7 TOOL CALL 1 Z S3000", "7 ; no tool called"));
    CHECK(hasProblem(r, 9, "M3 before any TOOL CALL"));
    CHECK(hasProblem(r, 9, "motion before any TOOL CALL"));
  }
  SECTION("a C needs a CC") {
    const ProgramReading r = problemsOf(replaced(kGood, "12 CC X+40 Y+40", "12 ; no pole"));
    CHECK(hasProblem(r, 14, "C without a CC before it"));
  }
  SECTION("a C ends as far from the pole as it starts, within 0.001 mm") {
    const ProgramReading r = problemsOf(replaced(kGood, "13 C X+50 Y+40 DR+", "13 C X+50.002 Y+40 DR+"));
    CHECK(hasProblem(r, 14, "arc radius from the start 10.0000 and to the end 10.0020 differ by 0.0020 mm"));
    const ProgramReading within = read(replaced(kGood, "13 C X+50 Y+40 DR+", "13 C X+50.001 Y+40 DR+"));
    CHECK(within.problems.empty());
  }
  SECTION("a CP's IPA and DR turn the same way") {
    const ProgramReading r = problemsOf(replaced(kGood, "CP IPA-720 IZ-2 DR-", "CP IPA-720 IZ-2 DR+"));
    CHECK(hasProblem(r, 16, "IPA-720 and DR+ do not turn the same way"));
  }
  SECTION("coordinates: signed, no negative zero, no exponent") {
    const ProgramReading zero = problemsOf(replaced(kGood, "18 L Z+20 R0 FMAX", "18 L Z-0 R0 FMAX"));
    CHECK(hasProblem(zero, 19, "coordinate Z '-0' is a negative zero"));
    const ProgramReading exponent = problemsOf(replaced(kGood, "10 L Z-2 R0 F200", "10 L Z-2e0 R0 F200"));
    CHECK(hasProblem(exponent, 11, "exponent"));
    const ProgramReading unsignedX = problemsOf(replaced(kGood, "22 L X+60", "22 L X60"));
    CHECK(hasProblem(unsignedX, 23, "coordinate X '60' is not a signed decimal number"));
  }
  SECTION("block numbers from 0 in sequence") {
    const ProgramReading r = problemsOf(replaced(kGood, "3 ; a hand-written program the reader passes\n", ""));
    CHECK(hasProblem(r, 4, "block number 4 where 3 was due"));
  }
  SECTION("M99 needs a cycle 200") {
    const size_t from = kGood.find("23 CYCL DEF 200");
    const size_t to = kGood.find("24 L X+60");
    std::string text = kGood;
    text.replace(from, to - from, "23 ; no cycle\n");
    const ProgramReading r = problemsOf(text);
    CHECK(hasProblem(r, 25, "M99 without a CYCL DEF 200 before it"));
  }
  SECTION("M99 at or above the second set-up clearance") {
    const ProgramReading r = problemsOf(replaced(kGood, "22 L X+60 Y+20 R0 FMAX", "22 L X+60 Y+20 Z+5 R0 FMAX"));
    CHECK(hasProblem(r, 33, "cycle called at Z5.0000, below its 2nd set-up clearance Z20.0000"));
  }
  SECTION("cycle 200's parameters, all of them in order") {
    const ProgramReading r = problemsOf(replaced(kGood, "  Q210=+0 ;DWELL TIME AT TOP ~\n", ""));
    CHECK(hasProblem(r, 24, "cycle 200 parameters Q200 Q201 Q206 Q202 Q203 Q204 Q211 where"));
  }
  SECTION("the program ends with M30, then END PGM") {
    const ProgramReading r = problemsOf(replaced(kGood, "30 END PGM GOOD MM\n", ""));
    CHECK(hasProblem(r, 38, "the program does not end with END PGM NAME MM"));
    const ProgramReading noEnd = problemsOf(replaced(kGood, "29 L Z+20 R0 FMAX M30", "29 L Z+20 R0 FMAX"));
    CHECK(hasProblem(noEnd, 38, "the block before END PGM is not the program end (M30 or M2)"));
    const ProgramReading name = problemsOf(replaced(kGood, "30 END PGM GOOD MM", "30 END PGM BAD MM"));
    CHECK(hasProblem(name, 39, "END PGM BAD does not match BEGIN PGM GOOD"));
  }
}

/// A step under tool-centre-point control: rotary words on L blocks between
/// FUNCTION TCPM and FUNCTION RESET TCPM, back at 0 before the reset. Block
/// n is on line n + 1.
const std::string kTcp = R"(0 BEGIN PGM TCP MM
1 TOOL CALL 1 Z S3000
2 L Z+60 R0 FMAX M3
3 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS
4 L X+30 Y+40 A+20 C+0 R0 FMAX
5 L Z+20 R0 F900
6 L X+15 A+20.5 C+2.5 R0
7 L Z+60 R0 FMAX
8 L A+0 C+0 R0 FMAX
9 FUNCTION RESET TCPM
10 L Z+60 R0 FMAX M30
11 END PGM TCP MM
)";

TEST_CASE("Klartext reader: tool-centre-point control", "[readback][heidenhain-tnc]") {
  const ProgramReading r = read(kTcp);
  INFO(problems(r));
  REQUIRE(r.problems.empty());
  // Up, across (A and C turning), down at the feed, along with A and C, up,
  // the rotary axes alone back to 0 (a motion: the tip still).
  REQUIRE(r.moves.size() == 6);
  CHECK(r.moves[1].abc[0] == 20);
  CHECK(r.moves[1].abc[2] == 0);
  CHECK(std::isnan(r.moves[1].abc[1]));
  CHECK(r.moves[3].kind == Move::Kind::Linear);
  checkEnd(r.moves[3], 15, 40, 20);
  CHECK(r.moves[3].abc[0] == 20.5);
  CHECK(r.moves[3].abc[2] == 2.5);
  CHECK(r.moves[3].feed == 900);
  CHECK(r.moves[5].kind == Move::Kind::Rapid);
  checkEnd(r.moves[5], 15, 40, 60);
  CHECK(r.moves[5].abc[0] == 0);

  auto problemsOf = [](const std::string &text) {
    const ProgramReading p = read(text);
    INFO(problems(p));
    CHECK_FALSE(p.problems.empty());
    return p;
  };
  SECTION("rotary words only under FUNCTION TCPM") {
    const ProgramReading p = problemsOf(replaced(kTcp, "3 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS", "3 ; off"));
    CHECK(hasProblem(p, 5, "rotary axis A with FUNCTION TCPM off"));
    CHECK(hasProblem(p, 10, "FUNCTION RESET TCPM while FUNCTION TCPM is off"));
  }
  SECTION("the one form of FUNCTION TCPM") {
    const ProgramReading p = problemsOf(replaced(kTcp, "F TCP AXIS POS", "F CONT AXIS POS"));
    CHECK(hasProblem(p, 4, "FUNCTION block not of the form 'FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS'"));
  }
  SECTION("the rotary axes back at 0 before the reset") {
    const ProgramReading p = problemsOf(replaced(kTcp, "8 L A+0 C+0 R0 FMAX", "8 L A+0 R0 FMAX"));
    CHECK(hasProblem(p, 10, "FUNCTION RESET TCPM with the rotary axis C2.5 turned"));
  }
  SECTION("X Y Z, then A B C") {
    const ProgramReading p = problemsOf(replaced(kTcp, "4 L X+30 Y+40 A+20 C+0", "4 L X+30 A+20 Y+40 C+0"));
    CHECK(hasProblem(p, 5, "axis Y repeated or out of X Y Z order"));
  }
  SECTION("no TOOL CALL, and no end, with it on") {
    const ProgramReading p = problemsOf(replaced(kTcp, "9 FUNCTION RESET TCPM", "9 TOOL CALL 1 Z S3000"));
    CHECK(hasProblem(p, 10, "TOOL CALL with FUNCTION TCPM on"));
    CHECK(hasProblem(p, 12, "the program ends with FUNCTION TCPM on"));
  }
}

/// 3+2: the tool up in machine coordinates, the datum shifted and the plane
/// tilted to a face, its moves in the face's frame, the plane reset at the
/// end. Block n is on line n + 1.
const std::string kPlane = R"(0 BEGIN PGM PLANE MM
1 L Z+0 R0 FMAX M91
2 CYCL DEF 7.0 DATUM SHIFT
3 CYCL DEF 7.1 X+100
4 CYCL DEF 7.2 Y+0
5 CYCL DEF 7.3 Z+0
6 PLANE SPATIAL SPA+0 SPB-90 SPC+0 TURN FMAX
7 TOOL CALL 1 Z S3000
8 L Z+120 R0 FMAX M3
9 L X+25 Y+20 R0 FMAX
10 L Z+90 R0 F120
11 L Z+120 R0 FMAX
12 L Z+0 R0 FMAX M91
13 PLANE RESET TURN FMAX
14 CYCL DEF 7.0 DATUM SHIFT
15 CYCL DEF 7.1 X+0
16 CYCL DEF 7.2 Y+0
17 CYCL DEF 7.3 Z+0
18 L M30
19 END PGM PLANE MM
)";

TEST_CASE("Klartext reader: 3+2 with a tilted working plane", "[readback][heidenhain-tnc]") {
  const ProgramReading r = read(kPlane);
  INFO(problems(r));
  REQUIRE(r.problems.empty());
  // The M91 blocks are no moves of the program's: up, across, in, out.
  REQUIRE(r.moves.size() == 4);
  CHECK(std::isnan(r.moves[0].to.x()));
  checkEnd(r.moves[2], 25, 20, 90);

  auto problemsOf = [](const std::string &text) {
    const ProgramReading p = read(text);
    INFO(problems(p));
    CHECK_FALSE(p.problems.empty());
    return p;
  };
  SECTION("the rotary axes turn only right after the tool went up") {
    const ProgramReading p = problemsOf(replaced(kPlane, "12 L Z+0 R0 FMAX M91", "12 L Z+130 R0 FMAX"));
    CHECK(hasProblem(p, 14, "the rotary axes turn (TURN) without the tool first up in machine coordinates"));
  }
  SECTION("Z alone first after a PLANE") {
    const ProgramReading p = problemsOf(replaced(kPlane, "8 L Z+120 R0 FMAX M3", "8 L X+25 Z+120 R0 FMAX M3"));
    CHECK(hasProblem(p, 9, "is not Z alone"));
  }
  SECTION("M91 only on a Z block at rapid") {
    const ProgramReading p = problemsOf(replaced(kPlane, "1 L Z+0 R0 FMAX M91", "1 L X+0 Z+0 R0 FMAX M91"));
    CHECK(hasProblem(p, 2, "M91 on a block other than 'L Z.. R0 FMAX M91'"));
  }
  SECTION("a datum shift gives X, Y and Z") {
    const ProgramReading p = problemsOf(replaced(kPlane, "4 CYCL DEF 7.2 Y+0", "4 CYCL DEF 7.2 Z+0"));
    CHECK(hasProblem(p, 3, "CYCL DEF 7.0 DATUM SHIFT not followed by CYCL DEF 7.1 X.., 7.2 Y.. and 7.3 Z.."));
  }
  SECTION("no plane left tilted at the end") {
    const ProgramReading p = problemsOf(replaced(kPlane, "13 PLANE RESET TURN FMAX", "13 ; no reset"));
    CHECK(hasProblem(p, 20, "the program ends with the working plane tilted (PLANE RESET missing)"));
  }
}

/// `path` (a STEP-NC file) through the toolpath passes, as `stepnc compile` runs them.
test::Loaded toolpaths(const std::string &path) {
  test::Loaded l = test::loadStepnc(path);
  std::vector<std::string> errors;
  const bool ok = test::runPipeline(*l.module, driver::toolpathPipeline({}), &errors);
  for (const std::string &e : errors)
    FAIL_CHECK(e);
  REQUIRE(ok);
  return l;
}

/// The heidenhain-tnc program for `l`, written with the target options
/// `overrides` (which reads it back: it must pass); the reader finds no
/// problem in it.
std::string written(const test::Loaded &l, const std::vector<std::string> &overrides) {
  INFO("target options:" << [&] {
    std::string all;
    for (const std::string &o : overrides)
      all += " " + o;
    return all;
  }());
  std::unique_ptr<backends::Backend> tnc = backends::createBackend("heidenhain-tnc");
  REQUIRE(backends::applyOverrides(tnc->descriptor(), overrides).empty());
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  backends::EmitOptions options;
  options.source = "example.stp";
  options.programName = "PGM";
  const std::optional<std::string> text = tnc->emit(*l.module, options, diags);
  for (const Diagnostic &d : c.diags)
    if (d.severity == Severity::Error)
      FAIL_CHECK(d.message);
  REQUIRE(text);
  const ProgramReading r = backends::readKlartext(*text, tnc->descriptor());
  INFO(problems(r));
  CHECK(r.problems.empty());
  CHECK_FALSE(r.moves.empty());
  return *text;
}

const std::string kExamples = std::string(STEPNC_SOURCE_DIR) + "/examples/";

TEST_CASE("Klartext reader: the emitter's programs for example1 read without a problem",
          "[readback][heidenhain-tnc]") {
  const test::Loaded l = toolpaths(kExamples + "example1.stp");
  CHECK(written(l, {}).find("M99") != std::string::npos);  // cycle 200
  CHECK(written(l, {"cycles=off"}).find("M99") == std::string::npos);
  written(l, {"decimals=4"});
}

TEST_CASE("Klartext reader: the emitter's programs for the milling patterns read without a problem",
          "[readback][heidenhain-tnc]") {
  written(toolpaths(kExamples + "patterns/contour-pocket.stp"), {});
  written(toolpaths(kExamples + "patterns/plunge-slot.stp"), {});
  // Helices as CP: the position after each is where the control turns the start to.
  CHECK(written(toolpaths(kExamples + "patterns/trochoidal-slot.stp"), {}).find("CP IPA") != std::string::npos);
}

} // namespace
} // namespace stepnc
