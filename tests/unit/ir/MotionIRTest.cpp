// The motion IR (ir/motion/MotionIR.h) with dwells: the program's dwells
// reach the planner where the tool is (one before the first move at the
// point where the tool starts), the motion planned with them prints, parses
// and prints to the same bytes and reads back as the same trajectory, and a
// dwell segment that does not wait at rest where the tool is is refused.
#include "SampleModule.h"

#include "ir/Printer.h"
#include "ir/Verifier.h"
#include "ir/motion/MotionIR.h"
#include "tests/unit/runtime/ShippedMachine.h"

#include <catch2/catch.hpp>

#include <functional>

using namespace stepnc;
using namespace stepnc::ir;
namespace irtest = stepnc::ir::test;

namespace {

/// Spot drilling of one hole: a dwell before the first move, half a second
/// at the bottom of the hole, and a dwell at the top after the retract.
constexpr std::string_view kProgram =
    "project \"DWELLS\"\n"
    "  workpiece %block \"BLOCK\"\n"
    "    round_hole %hole \"HOLE\" at=(20.0000,40.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) "
    "ref=(1.000000,0.000000,0.000000) depth=40.0000mm diameter=12.0000mm bottom=through\n"
    "  tool %spot \"SPOT DRILL\" type=center_drill diameter=16.0000mm tip_half_angle=45.0000deg\n"
    "  setup %vise \"VISE\" at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) "
    "ref=(1.000000,0.000000,0.000000) secplane=20.0000mm\n"
    "  workplan @main \"MAIN\" setup=%vise\n"
    "    workingstep @ws_spot \"SPOT\" feature=%hole secplane=20.0000mm\n"
    "      center_drilling \"SPOT\" tool=%spot retract_plane=5.0000mm cutting_depth=6.5000mm dwell_bottom=0.500s\n"
    "        technology feed=124.8mm/min spindle=-1560.0rev/min feed_reference=tcp\n"
    "      moves tool=%spot spindle=-1560.0rev/min coolant=flood setup=%vise secplane=20.0000mm\n"
    "        dwell time=0.100s\n"
    "        cycle type=drill at=(20.0000,40.0000,0.0000)mm clearance=5.0000mm bottom=-6.5000mm "
    "feed=124.8mm/min dwell=0.500s\n"
    "          rapid to=(20.0000,40.0000,20.0000)mm role=position\n"
    "          rapid to=(20.0000,40.0000,5.0000)mm role=approach\n"
    "          linear to=(20.0000,40.0000,-6.5000)mm feed=124.8mm/min role=plunge\n"
    "          dwell time=0.500s\n"
    "          rapid to=(20.0000,40.0000,20.0000)mm role=retract\n"
    "        dwell time=0.200s\n";

std::vector<std::string> verify(const Module &m) {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  verifyModule(m, engine);
  return irtest::messages(c);
}

/// The trajectory read back from `m`, and the errors of reading it.
struct ReadBack {
  std::optional<runtime::Trajectory> trajectory;
  std::vector<std::string> errors;
};
ReadBack readBack(const Module &m) {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  ReadBack r;
  r.trajectory = readMotion(m, engine);
  r.errors = irtest::messages(c);
  return r;
}

/// The module with its motion planned on the high-dynamics machine.
struct Planned {
  irtest::Parsed parsed;
  ProgramPath program;
  runtime::Trajectory trajectory;
};
Planned planned() {
  Planned p;
  p.parsed = irtest::parse(kProgram);
  REQUIRE(p.parsed.errors.empty());
  REQUIRE(p.parsed.module);
  REQUIRE(verify(*p.parsed.module).empty());
  p.program = programPath(*p.parsed.module);
  p.trajectory = runtime::plan(p.program.path, stepnc::test::shippedMachine("hsc-3axis"));
  attachMotion(*p.parsed.module, p.program, p.trajectory);
  return p;
}

} // namespace

TEST_CASE("the program's dwells reach the planner where the tool is", "[motion-ir][dwell]") {
  irtest::Parsed p = irtest::parse(kProgram);
  REQUIRE(p.module);
  const ProgramPath program = programPath(*p.module);
  using Kind = runtime::PathMove::Kind;
  const runtime::Vec3 top(20, 40, 20), bottom(20, 40, -6.5);
  CHECK(program.path.start == top);
  const std::vector<runtime::PathMove> &moves = program.path.moves;
  REQUIRE(moves.size() == 7);
  REQUIRE(program.nodes.size() == 7);
  // The first dwell waits where the tool starts, before the move that names it.
  CHECK(moves[0].kind == Kind::Dwell);
  CHECK(moves[0].to == top);
  CHECK(moves[0].dwellS == 0.1);
  CHECK(program.nodes[0]->kind == ir::Kind::Dwell);
  CHECK(moves[1].to == top);
  CHECK(moves[3].kind == Kind::Line);
  CHECK(moves[3].to == bottom);
  CHECK(moves[4].kind == Kind::Dwell);
  CHECK(moves[4].to == bottom);
  CHECK(moves[4].dwellS == 0.5);
  CHECK(program.nodes[4]->kind == ir::Kind::Dwell);
  CHECK(moves[6].kind == Kind::Dwell);
  CHECK(moves[6].to == top);
  CHECK(moves[6].dwellS == 0.2);
  for (const ir::Node *owner : program.owners)
    CHECK(owner->symbol == "@ws_spot");
}

TEST_CASE("motion with dwells prints, parses and prints the same and reads back", "[motion-ir][dwell]") {
  Planned p = planned();
  const runtime::Trajectory &t = p.trajectory;
  // A segment per dwell, each at rest where the tool is.
  size_t dwells = 0;
  for (size_t k = 0; k < t.segments.size(); ++k)
    if (t.segments[k].kind == runtime::SegmentKind::Dwell) {
      ++dwells;
      CHECK(t.info[k].stop == runtime::StopReason::Dwell);
    }
  CHECK(dwells == 3);
  CHECK(t.segments.front().kind == runtime::SegmentKind::Dwell);
  CHECK(t.segments.back().kind == runtime::SegmentKind::Dwell);

  const std::string text = printModule(*p.parsed.module);
  INFO(text);
  CHECK(text.find("motion_segment shape=dwell to=(20,40,-6.5) length=0 move=4 stop=dwell limited_by=feed "
                  "limits=(0,0,0) v0=0 phases=(0,0,0,0,0,0,0.5,0,0,0,0,0,0,0)\n") != std::string::npos);
  irtest::Parsed again = irtest::parse(text);
  REQUIRE(again.errors.empty());
  REQUIRE(again.module);
  CHECK(verify(*again.module).empty());
  CHECK(printModule(*again.module) == text);

  const ReadBack r = readBack(*again.module);
  REQUIRE(r.errors.empty());
  REQUIRE(r.trajectory);
  const runtime::Trajectory &u = *r.trajectory;
  REQUIRE(u.segments.size() == t.segments.size());
  for (size_t k = 0; k < t.segments.size(); ++k) {
    INFO("segment " << k);
    CHECK(u.segments[k].kind == t.segments[k].kind);
    CHECK(u.segments[k].start == t.segments[k].start);
    CHECK(u.segments[k].end == t.segments[k].end);
    CHECK(u.segments[k].length == t.segments[k].length);
    CHECK(u.info[k].stop == t.info[k].stop);
    CHECK(u.info[k].move == t.info[k].move);
    CHECK(u.profiles[k].v0 == t.profiles[k].v0);
    for (size_t i = 0; i < t.profiles[k].phases.size(); ++i) {
      CHECK(u.profiles[k].phases[i].duration == t.profiles[k].phases[i].duration);
      CHECK(u.profiles[k].phases[i].jerk == t.profiles[k].phases[i].jerk);
    }
  }
  CHECK(u.duration() == t.duration());
  // The step's motion time holds the dwells: 0.8 s of it.
  const Node &motion = irtest::find(again.module->root, "motion");
  CHECK(motion.number("time").value_or(0) == Approx(t.duration()).margin(0.0005));
}

TEST_CASE("a dwell segment that does not wait at rest where the tool is is refused", "[motion-ir][dwell]") {
  Planned p = planned();
  REQUIRE(readBack(*p.parsed.module).errors.empty());
  const std::string rest = "a dwell segment waits at rest: stop=dwell, v0 and a0 0, phases of jerk 0 that last more "
                           "than 0 s";
  auto refused = [&](const std::function<void(Node &)> &change) {
    Planned q = planned();
    Node &m = irtest::find(q.parsed.module->root, "motion");
    for (Node &s : m.children)
      if (s.text("shape") == "dwell" && s.count("move") == 4)
        change(s);
    const ReadBack r = readBack(*q.parsed.module);
    CHECK_FALSE(r.trajectory);
    REQUIRE(r.errors.size() == 1);
    return r.errors[0];
  };
  CHECK(refused([](Node &s) { s.set("phases", Value::reals(std::vector<double>(14, 0.0))); }) == rest);
  CHECK(refused([](Node &s) {
          s.set("phases", Value::reals({0, 0, 0, 0, 0, 0, -0.5, 0, 0, 0, 0, 0, 0, 0}));
        }) == rest);
  CHECK(refused([](Node &s) {
          s.set("phases", Value::reals({0, 0, 0, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 0, 0}));
        }) == rest);
  CHECK(refused([](Node &s) { s.set("stop", Value::word("program")); }) == rest);
  CHECK(refused([](Node &s) { s.set("v0", Value::real(1)); }) == rest);
  CHECK(refused([](Node &s) { s.set("length", Value::real(0.5)); }) ==
        "segment length 0.5 mm does not match its geometry (0 mm)");
  CHECK(refused([](Node &s) { s.set("to", Value::reals({20, 40, -6})); }) ==
        "a dwell waits where the tool is: 'to' (20.000000, 40.000000, -6.000000) is not where the previous segment "
        "ends, (20.000000, 40.000000, -6.500000)");
}
