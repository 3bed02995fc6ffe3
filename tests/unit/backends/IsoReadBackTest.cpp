// The G-code targets read back what they write (backends/common/ReadBack.h):
// the ISO readers find the motions and the problems of hand-written
// programs, and the comparison turns a program that does not make the plan's
// moves into an error at the workingstep.
#include "backends/Backend.h"
#include "backends/common/IsoReader.h"
#include "backends/common/ReadBack.h"
#include "tests/unit/backends/ReadBackTestSupport.h"
#include "tests/unit/passes/PassTestSupport.h"

#include <cmath>
#include <numbers>

namespace stepnc {
namespace {

using backends::Move;
using backends::ProgramReading;
using backends::ReadMove;
using test::descriptorOf;
using test::hasProblem;
using test::problems;

/// An rs274 program: header, tool 1, a rapid up and over, a plunge, an arc,
/// a dwell, a G5 piece and a G81 hole. `body` replaces the moves when given.
std::string rs274Program(const std::string &body = "") {
  const std::string moves = body.empty() ? "G0 Z20.\n"
                                           "X10. Y0.\n"
                                           "Z2.\n"
                                           "G1 Z-1. F200.\n"
                                           "G3 X0. Y10. I-10. J0. F300.\n"
                                           "G4 P0.5\n"
                                           "G5 X-10. Y20. I0. J5. P0. Q-5.\n"
                                           "G0 Z20.\n"
                                           "G98 G81 X30. Y30. Z-5. R2. F100.\n"
                                           "G80\n"
                                         : body;
  return "%\n(header)\nG17 G21 G90 G94 G40 G49 G80\nG64 P0.01\n(WS1)\nT1 M6\nG43 H1\nS1000 M3\n" + moves +
         "M5 M9\nM2\n%\n";
}

TEST_CASE("rs274 reader: motions of a clean program", "[readback]") {
  const ProgramReading r = backends::readRs274(rs274Program(), descriptorOf("rs274"));
  INFO(problems(r));
  REQUIRE(r.problems.empty());
  // Rapids Z, XY, Z; the plunge; the arc; the dwell; the spline; the rapid
  // up; the cycle: rapid over, rapid to R, feed down, rapid back up.
  REQUIRE(r.moves.size() == 12);
  CHECK(r.moves[0].kind == Move::Kind::Rapid);
  CHECK(std::isnan(r.moves[0].to.x()));  // where the tool change left X and Y is the machine's business
  CHECK(r.moves[0].to.z() == 20);
  CHECK(r.moves[0].line == 9);
  const ReadMove &arc = r.moves[4];
  CHECK(arc.kind == Move::Kind::Arc);
  CHECK(arc.ccw);
  CHECK(arc.centre.norm() < 1e-9);
  CHECK(arc.sweep == Approx(std::numbers::pi / 2));
  CHECK(arc.feed == 300);
  CHECK(r.moves[5].kind == Move::Kind::Dwell);
  CHECK(r.moves[5].dwell == 0.5);
  const ReadMove &spline = r.moves[6];
  CHECK(spline.spline);
  REQUIRE(spline.bezier);
  CHECK(spline.bezier->first.isApprox(geom::Vec2(0, 15)));
  CHECK(spline.bezier->second.isApprox(geom::Vec2(-10, 15)));
  const ReadMove &drill = r.moves[10];
  CHECK(drill.cycle);
  CHECK(drill.kind == Move::Kind::Linear);
  CHECK(drill.to.isApprox(ir::Vec3(30, 30, -5)));
  CHECK(drill.feed == 100);
  CHECK(r.moves[11].to.z() == 20);  // G98: back to where the cycle started
}

TEST_CASE("rs274 reader: what LinuxCNC would refuse or do otherwise is a problem on its line", "[readback]") {
  const backends::TargetDescriptor d = descriptorOf("rs274");
  auto read = [&](const std::string &body) { return backends::readRs274(rs274Program(body), d); };
  // Lines 9 on are the body.
  CHECK(hasProblem(read("G0 X1. Z20.\n"), 9, "not G0 with Z alone"));
  CHECK(hasProblem(read("G0 Z20.\nM5\nG1 Z1. F100.\n"), 11, "the spindle off"));
  CHECK(hasProblem(read("G0 Z2.\nG1 Z1.\n"), 10, "no feed F"));
  CHECK(hasProblem(read("G0 Z2.e1\n"), 9, "exponent"));
  CHECK(hasProblem(read("G0 Z-0.\n"), 9, "negative zero"));
  CHECK(hasProblem(read("G0 Z20\n"), 9, "no decimal point"));
  CHECK(hasProblem(read("G0 Z20.\nX10. Y0.\nG1 Z0. F100.\nG2 X0. Y10.002 I-10. J0.\n"), 12, "radius"));
  CHECK(hasProblem(read("G0 Z20.\nG98 G81 X1. Y1. Z-1. R1. F10.\nX2. Y2.\n"), 11, "repeat the canned cycle"));
  CHECK(hasProblem(read("G0 Z20.\nG43 H2\n"), 10, "G43 H2 with tool 1"));
  CHECK(hasProblem(read("G0 Z20.\nG7 X1.\n"), 10, "not a G code"));
  CHECK(hasProblem(read("G0 Z20.\nG4 P0.\n"), 10, "dwell"));
  const ProgramReading unterminated = backends::readRs274("%\nG0 Z1.\n", d);
  CHECK(hasProblem(unterminated, 2, "does not end with M2"));
  CHECK(hasProblem(unterminated, 2, "the last line is not %"));
}

/// An 840D program: tool 1 with D1, a CR= arc, a CYCLE82 hole with its dwell.
std::string siemensProgram(const std::string &body = "") {
  const std::string moves = body.empty() ? "G0 Z20.\n"
                                           "X10. Y0.\n"
                                           "Z2.\n"
                                           "G1 Z-1. F200.\n"
                                           "G2 X0. Y-10. CR=10.\n"
                                           "G0 Z20.\n"
                                           "F50.\n"
                                           "MCALL CYCLE82(20.,0.,2.,-8.,,0.5)\n"
                                           "G0 X30. Y30.\n"
                                           "MCALL\n"
                                         : body;
  return "%_N_PART_MPF\n;$PATH=/_N_MPF_DIR\n; header\nG90 G94 G71 G17 G40\nG642\nCYCLE832(0.01,1,1)\nT1 D1\nM6\n"
         "S1000 M3\n" +
         moves + "M5\nM9\nCYCLE832(0.,0,1)\nM30\n";
}

TEST_CASE("840D reader: motions of a clean program", "[readback]") {
  const ProgramReading r = backends::readSiemens840d(siemensProgram(), descriptorOf("siemens-840d"));
  INFO(problems(r));
  REQUIRE(r.problems.empty());
  REQUIRE(r.moves.size() == 11);
  const ReadMove &arc = r.moves[4];
  CHECK(arc.kind == Move::Kind::Arc);
  CHECK_FALSE(arc.ccw);
  CHECK(arc.centre.norm() < 1e-9);  // CR=10 from (10,0) to (0,-10) clockwise: a quarter about the origin
  CHECK(arc.sweep == Approx(std::numbers::pi / 2));
  // The cycle: over the hole, down to R, the feed to DP at F50, DTB, up to RTP.
  CHECK(r.moves[6].cycle);
  CHECK(r.moves[8].kind == Move::Kind::Linear);
  CHECK(r.moves[8].to.isApprox(ir::Vec3(30, 30, -8)));
  CHECK(r.moves[8].feed == 50);
  CHECK(r.moves[9].kind == Move::Kind::Dwell);
  CHECK(r.moves[9].dwell == 0.5);
  CHECK(r.moves[10].to.z() == 20);
}

TEST_CASE("840D reader: what the controller would refuse is a problem on its line", "[readback]") {
  const backends::TargetDescriptor d = descriptorOf("siemens-840d");
  auto read = [&](const std::string &body) { return backends::readSiemens840d(siemensProgram(body), d); };
  // Lines 10 on are the body.
  CHECK(hasProblem(read("G0 Z20.\nMCALL CYCLE81(20.,0.,2.,-8.,)\nG0 X1. Y1.\n"), 11, "never cancelled"));
  CHECK(hasProblem(read("G0 Z20.\nG4 F1. X2.\n"), 11, "block of its own"));
  CHECK(hasProblem(read("G0 Z20.\nX1. Y1.\nG1 Z1. F100.\nG2 X3. Y1. CR=0.5\n"), 13, "shorter than half the chord"));
  CHECK(hasProblem(read("G0 Z20.\nG43 X1.\n"), 11, "not a G code"));
  CHECK(hasProblem(backends::readSiemens840d("%_N_part_MPF\n;$PATH=/_N_MPF_DIR\nM30\n", d), 1, "upper case"));
}

TEST_CASE("840D reader: a plane swivelled with CYCLE800 (3+2)", "[readback]") {
  const backends::TargetDescriptor d = descriptorOf("siemens-840d");
  auto read = [&](const std::string &body) { return backends::readSiemens840d(siemensProgram(body), d); };
  // Lines 10 on are the body: up, swivel, a face's moves, up, deselect, the
  // rotary axes back at 0.
  const std::string clean = "G0 SUPA Z0.\n"
                            "CYCLE800(0,\"TC1\",0,27,0.,0.,0.,0.,90.,0.,-40.,0.,0.,-1,0.)\n"
                            "G0 Z120.\n"
                            "X20. Y30.\n"
                            "G1 Z90. F120.\n"
                            "G0 Z120.\n"
                            "G0 SUPA Z0.\n"
                            "CYCLE800(0,\"0\",0,27,0.,0.,0.,0.,0.,0.,0.,0.,0.,-1,0.)\n"
                            "G0 A0. C0.\n";
  const ProgramReading r = read(clean);
  INFO(problems(r));
  REQUIRE(r.problems.empty());
  // The SUPA blocks and the swivels are no moves of the program's; up (X and
  // Y unknown), across, down at the feed, up.
  REQUIRE(r.moves.size() == 4);
  CHECK(std::isnan(r.moves[0].to.x()));
  CHECK(r.moves[2].to.isApprox(ir::Vec3(20, 30, 90)));

  auto replaced = [](std::string text, const std::string &from, const std::string &to) {
    const size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
  };
  CHECK(hasProblem(read(replaced(clean, "G0 SUPA Z0.\nCYCLE800(0,\"TC1\"", "CYCLE800(0,\"TC1\"")), 10,
                   "CYCLE800 swivels without the tool first up"));
  CHECK(hasProblem(read(replaced(clean, ",27,0.,0.,0.,0.,90.", ",57,0.,0.,0.,0.,90.")), 11,
                   "CYCLE800 not of the form"));
  // Without the deselection (the last 3 lines of the body): the last line, 19.
  CHECK(hasProblem(read(replaced(clean, "G0 SUPA Z0.\nCYCLE800(0,\"0\",0,27,0.,0.,0.,0.,0.,0.,0.,0.,0.,-1,0.)\nG0 A0. C0.\n", "")),
                   19, "the program ends with the plane swivelled"));
  CHECK(hasProblem(read(replaced(clean, "G0 SUPA Z0.\nCYCLE800(0,\"0\",0,27,0.,0.,0.,0.,0.,0.,0.,0.,0.,-1,0.)\n", "")), 16,
                   "rotary axes turned with the transformation off"));
  CHECK(hasProblem(read(replaced(clean, "G0 SUPA Z0.\nCYCLE800", "G0 SUPA X0. Z0.\nCYCLE800")), 10,
                   "SUPA other than G0 SUPA Z.."));
}

// --- The comparison ----------------------------------------------------------------

/// The pocket module with workingstep @ws's moves written by hand: up, over,
/// down, a line, a quarter arc, a dwell, up.
ir::test::Parsed handMadeModule() {
  return test::parseModule(test::blockPocketModule(5, test::oneStep("side_finish_milling \"OP\" tool=%mill10\n"
                                                                    "        technology feed=600.0mm/min "
                                                                    "spindle=-3000.0rev/min feed_reference=tcp") +
                                                          R"(      moves tool=%mill10 spindle=-3000.0rev/min coolant=flood setup=%s1 secplane=20.0000mm
        rapid to=(40.0000,25.0000,20.0000)mm role=position
        rapid to=(40.0000,25.0000,2.0000)mm role=position
        linear to=(40.0000,25.0000,-5.0000)mm feed=300.0mm/min role=plunge
        linear to=(55.0000,25.0000,-5.0000)mm feed=600.0mm/min role=cut
        arc to=(60.0000,30.0000,-5.0000)mm center=(55.0000,30.0000,-5.0000)mm dir=ccw feed=600.0mm/min role=cut
        dwell time=0.500s
        rapid to=(60.0000,30.0000,20.0000)mm role=retract
)"));
}

struct Written {
  ir::test::Parsed module;
  std::optional<backends::Program> program;
  backends::TargetDescriptor descriptor;
  std::string text;
};

/// The rs274 program of the hand-made module, as the target writes it (which
/// runs the read-back: it must pass).
Written written() {
  Written w{handMadeModule(), std::nullopt, descriptorOf("rs274"), ""};
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  w.program = backends::buildProgram(*w.module.module, nullptr, diags);
  REQUIRE(w.program);
  std::unique_ptr<backends::Backend> rs274 = backends::createBackend("rs274");
  backends::EmitOptions options;
  options.source = "hand.ir";
  options.programName = "hand";
  const std::optional<std::string> text = rs274->emit(*w.module.module, options, diags);
  for (const Diagnostic &d : c.diags)
    FAIL_CHECK(d.message);
  REQUIRE(text);
  w.text = *text;
  return w;
}

/// The errors of comparing `text` (the program with a change) with the plan.
std::vector<std::string> compare(const Written &w, const std::string &text) {
  // One step: it starts at its comment block.
  const size_t at = text.find("\n(WS)\n");
  REQUIRE(at != std::string::npos);
  const size_t line = static_cast<size_t>(std::count(text.begin(), text.begin() + at + 1, '\n')) + 1;
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  const bool ok = backends::checkReadBack(*w.program, w.descriptor, {line}, text,
                                          backends::readRs274(text, w.descriptor), 0.01, diags);
  std::vector<std::string> errors;
  for (const Diagnostic &d : c.diags)
    errors.push_back(d.message);
  CHECK(ok == errors.empty());
  return errors;
}

std::string replaced(std::string text, const std::string &from, const std::string &to) {
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

TEST_CASE("read-back: the program written makes the plan's moves", "[readback]") {
  const Written w = written();
  CHECK(compare(w, w.text).empty());
}

TEST_CASE("read-back: a program that does not make the plan's moves is an error at its workingstep",
          "[readback]") {
  const Written w = written();
  auto error = [&](const std::string &text) {
    const std::vector<std::string> errors = compare(w, text);
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find("workingstep @ws") != std::string::npos);
    CHECK(errors[0].find("does not read back (a bug in stepnc)") != std::string::npos);
    return errors[0];
  };
  CHECK_THAT(error(replaced(w.text, "F600.", "F610.")), Catch::Contains("a feed of 610.000 mm/min"));
  CHECK_THAT(error(replaced(w.text, "Z-5. F300.", "Z-5.002 F300.")), Catch::Contains("a linear to (40.0000, 25.0000, -5.0020)"));
  CHECK_THAT(error(replaced(w.text, "G3 ", "G2 ")), Catch::Contains("cw arc"));
  CHECK_THAT(error(replaced(w.text, "G4 P0.5\n", "")), Catch::Contains("where the plan has a dwell 0.500 s"));
  CHECK_THAT(error(replaced(w.text, "X55.", "X55.002")), Catch::Contains("radius is 5.0000 mm at the start and 4.9980 mm"));
  CHECK_THAT(error(replaced(w.text, "G4 P0.5", "G4 P0.6")), Catch::Contains("a dwell of 0.600 s"));
  CHECK_THAT(error(replaced(w.text, "G0 Z20.\nX40. Y25.", "G0 Z20.\nX40. Y25.1")),
             Catch::Contains("the rapids end at (40.0000, 25.1000"));
  CHECK_THAT(error(replaced(w.text, "S3000 M3", "S3000 M3\nM5")), Catch::Contains("the spindle off"));
}

TEST_CASE("read-back: a sliver arc whose ends print as one point is written as a line, not a whole circle",
          "[readback]") {
  // 0.0004 mm long: two points in the IR's 4 decimals, one in the 840D's 3,
  // where an arc over its start is a whole circle.
  ir::test::Parsed p = test::parseModule(test::blockPocketModule(
      5, test::oneStep("side_finish_milling \"OP\" tool=%mill10\n"
                       "        technology feed=600.0mm/min spindle=-3000.0rev/min feed_reference=tcp") +
             R"(      moves tool=%mill10 spindle=-3000.0rev/min coolant=flood setup=%s1 secplane=20.0000mm
        rapid to=(55.0000,25.0000,20.0000)mm role=position
        linear to=(55.0000,25.0000,-5.0000)mm feed=300.0mm/min role=plunge
        arc to=(55.0004,25.0000,-5.0000)mm center=(55.0002,30.0000,-5.0000)mm dir=ccw feed=600.0mm/min role=cut
        linear to=(60.0000,25.0000,-5.0000)mm feed=600.0mm/min role=cut
        rapid to=(60.0000,25.0000,20.0000)mm role=retract
)"));
  DiagnosticCollector c;
  DiagnosticEngine diags(c);
  backends::EmitOptions options;
  options.source = "sliver.ir";
  options.programName = "SLIVER";
  const std::optional<std::string> text = backends::createBackend("siemens-840d")->emit(*p.module, options, diags);
  for (const Diagnostic &d : c.diags)
    FAIL_CHECK(d.message);
  REQUIRE(text);
  CHECK(text->find("G3") == std::string::npos);
  CHECK(text->find("G2") == std::string::npos);
}

} // namespace
} // namespace stepnc
