// The native motion format: a trajectory written and read back is the same,
// value for value and byte for byte, and each kind of mistake in a file is
// reported at its line and column.
#include "runtime/NativeFormat.h"

#include "support/Format.h"

#include "../TestSupport.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <regex>
#include <sstream>

using namespace stepnc;
using namespace stepnc::runtime;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Read {
  std::unique_ptr<SourceFile> file;
  std::optional<Trajectory> trajectory;
  std::vector<std::string> errors;  ///< "line:col: message"
};

Read read(const std::string &text) {
  Read r;
  r.file = SourceFile::fromString("t.motion", text);
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  r.trajectory = readNative(*r.file, diags);
  r.errors = test::locatedMessages(collector, *r.file);
  return r;
}

/// Appends a segment with its profile from v0 to v1 and some planner facts.
void add(Trajectory &t, const Segment &seg, double v0, double v1, SpeedLimit by, StopReason stop, uint32_t move) {
  SegmentInfo info;
  info.limits = {25.0 / 3, 1500.5, 20000.25};
  info.limitedBy = by;
  info.feed = 1000.0 / 60;
  info.move = move;
  info.nextMove = seg.kind == SegmentKind::Blend ? move + 1 : move;
  info.stop = stop;
  t.segments.push_back(seg);
  t.profiles.push_back(planProfile(v0, v1, seg.length, info.limits));
  t.info.push_back(info);
}

/// A line, a quarter arc, a helix of one whole turn and a blend, with
/// numbers that have no short decimal form.
Trajectory sample() {
  Trajectory t;
  t.machine = "M \"fast\" \\ 1\t";
  t.tolerance = 0.01;
  t.cycleTime = 0.0005;
  t.start = Vec3(0.1, -0.0, 1.0 / 3);
  const Segment line = Segment::line(t.start, Vec3(10.1, 0.2, 1.0 / 3));
  const Vec3 center(10.1, 5.2, 0);
  const Segment quarter = Segment::arc(line.end, Vec3(15.1, 5.2, 1.0 / 3), center, true, kPi / 2);
  const Segment helix = Segment::arc(quarter.end, Vec3(15.1, 5.2, -2.0 / 3), center, false, 2 * kPi);
  const Vec3 p = helix.end;
  const Segment blend = Segment::blend({p, p + Vec3(0, 0.4, 0), p + Vec3(0.05, 0.8, 0.01), p + Vec3(0.2, 1.1, 0.02),
                                        p + Vec3(0.5, 1.3, 0.03), p + Vec3(0.9, 1.4, 0.04)});
  add(t, line, 0, 7.5, SpeedLimit::Feed, StopReason::Start, 3);
  add(t, quarter, 7.5, 5, SpeedLimit::Acceleration, StopReason::None, 4);
  add(t, helix, 5, 1.0 / 7, SpeedLimit::Jerk, StopReason::None, 5);
  add(t, blend, 1.0 / 7, 0, SpeedLimit::AxisVelocity, StopReason::None, 5);
  t.info[2].feed = 0;  // a rapid
  t.info[2].limitedBy = SpeedLimit::MachineFeed;
  // An empty phase keeps its jerk: the profile reads back slot for slot.
  t.profiles[1].phases[1].jerk = -1.25e-20;
  return t;
}

/// Three lines along one direction that share one profile planned over
/// their whole length, cut into slices: the first two end, and the last two
/// start, with the acceleration the whole has at the cuts (positive while
/// speeding up, negative while slowing down).
Trajectory sliced() {
  Trajectory t;
  t.machine = "M";
  t.tolerance = 0.01;
  t.cycleTime = 0.001;
  t.start = Vec3(0.1, -0.2, 1.0 / 3);
  const PathLimits limits{25.0 / 3, 1500.5, 20000.25};
  const Profile whole = planProfile(0, 0, 12.3, limits);
  // Within the first phase (acceleration rising from zero) and the last
  // (acceleration returning to zero from below): neither cut is at zero.
  const double tc = whole.phases[0].duration / 3, tc2 = whole.duration() - whole.phases[6].duration / 3;
  const Vec3 dir = Vec3(3, 4, 1.0 / 7).normalized();
  Vec3 at = t.start;
  const Profile slices[] = {whole.slice(0, tc), whole.slice(tc, tc2), whole.slice(tc2, whole.duration())};
  for (size_t i = 0; i < 3; ++i) {
    const Profile &p = slices[i];
    const Vec3 end = at + dir * p.at(p.duration()).s;
    t.segments.push_back(Segment::line(at, end));
    t.profiles.push_back(p);
    SegmentInfo info;
    info.limits = limits;
    info.limitedBy = SpeedLimit::Acceleration;
    info.feed = 1000.0 / 60;
    info.move = 2;
    info.nextMove = 2;
    info.stop = i == 0 ? StopReason::Start : StopReason::None;
    t.info.push_back(info);
    at = end;
  }
  return t;
}

/// A feed line rest to rest, half a second's dwell at its end, and a rapid
/// up from there.
Trajectory dwelling() {
  Trajectory t;
  t.machine = "M";
  t.tolerance = 0.01;
  t.cycleTime = 0.001;
  t.start = Vec3(0.1, 0.2, 1.0 / 3);
  const Segment feed = Segment::line(t.start, t.start + Vec3(10.1, 0, 0));
  add(t, feed, 0, 0, SpeedLimit::Feed, StopReason::Start, 0);
  SegmentInfo wait;
  wait.move = wait.nextMove = 1;
  wait.stop = StopReason::Dwell;
  t.segments.push_back(Segment::dwell(feed.end));
  t.profiles.push_back(dwellProfile(0.5));
  t.info.push_back(wait);
  add(t, Segment::line(feed.end, feed.end + Vec3(0, 0, 5)), 0, 0, SpeedLimit::AxisVelocity, StopReason::Dwell, 2);
  t.info[2].feed = 0;  // a rapid
  return t;
}

void requireSame(const Trajectory &a, const Trajectory &b) {
  CHECK(a.machine == b.machine);
  CHECK(a.tolerance == b.tolerance);
  CHECK(a.cycleTime == b.cycleTime);
  CHECK(a.start == b.start);
  REQUIRE(a.segments.size() == b.segments.size());
  REQUIRE(a.profiles.size() == b.profiles.size());
  REQUIRE(a.info.size() == b.info.size());
  for (size_t i = 0; i < a.segments.size(); ++i) {
    INFO("segment " << i);
    const Segment &s = a.segments[i], &r = b.segments[i];
    CHECK(s.kind == r.kind);
    CHECK(s.start == r.start);
    CHECK(s.end == r.end);
    CHECK(s.length == r.length);
    CHECK(s.center == r.center);
    CHECK(s.radius == r.radius);
    CHECK(s.startAngle == r.startAngle);
    CHECK(s.sweep == r.sweep);
    CHECK(s.ccw == r.ccw);
    CHECK(s.axis0 == r.axis0);
    CHECK(s.axis1 == r.axis1);
    CHECK(s.axisRate0 == r.axisRate0);
    CHECK(s.axisRate1 == r.axisRate1);
    if (s.kind == SegmentKind::Blend) {  // lines and arcs leave ctrl uninitialised (Eigen)
      CHECK(s.ctrl == r.ctrl);
      CHECK(s.arcTable == r.arcTable);
    }
    const Profile &p = a.profiles[i], &q = b.profiles[i];
    CHECK(p.v0 == q.v0);
    CHECK(p.a0 == q.a0);
    for (size_t k = 0; k < p.phases.size(); ++k) {
      CHECK(p.phases[k].duration == q.phases[k].duration);
      CHECK(p.phases[k].jerk == q.phases[k].jerk);
    }
    const SegmentInfo &m = a.info[i], &n = b.info[i];
    CHECK(m.limits.v == n.limits.v);
    CHECK(m.limits.a == n.limits.a);
    CHECK(m.limits.j == n.limits.j);
    CHECK(m.limitedBy == n.limitedBy);
    CHECK(m.feed == n.feed);
    CHECK(m.move == n.move);
    CHECK(m.nextMove == n.nextMove);
    CHECK(m.stop == n.stop);
    CHECK(m.spindle0 == n.spindle0);
    CHECK(m.spindle1 == n.spindle1);
    CHECK(m.sync == n.sync);
  }
  CHECK(a.frame == b.frame);
}

/// One straight segment of 5 mm at up to 2 mm/s with a jerk of 2 mm/s^3:
/// each number has a short exact form, so the text is easy to check.
const std::string kSmall = "STEPNC-MOTION 1\n"
                           "; planned by stepnc from \"part.stpnc\" for machine \"M\"\n"
                           "; 1 segment, 4.500 s\n"
                           "; units: mm, s, mm/s, mm/s^2, mm/s^3; angles in radians\n"
                           "machine \"M\"\n"
                           "cycle_time 0.001\n"
                           "tolerance 0.01\n"
                           "start 0 0 0\n"
                           "segments 1\n"
                           "line to 3 4 0 length 5 programmed_feed 2.5 move 0 next 0 stop start limits 2 4 2 "
                           "limited_by acceleration v0 0 a0 0 phases 7 1 2 0 0 1 -2 0.5 0 1 -2 0 0 1 2\n"
                           "end\n";

std::string replaced(const std::string &text, const std::string &from, const std::string &to) {
  std::string t = text;
  const size_t at = t.find(from);
  REQUIRE(at != std::string::npos);
  t.replace(at, from.size(), to);
  return t;
}

/// The single error of reading `text`.
std::string error(const std::string &text) {
  Read r = read(text);
  CHECK_FALSE(r.trajectory);
  REQUIRE(r.errors.size() == 1);
  return r.errors[0];
}

} // namespace

TEST_CASE("a trajectory reads back value for value and byte for byte", "[native]") {
  const Trajectory t = sample();
  const std::string text = writeNative(t, "dir/part 1.stpnc");
  Read r = read(text);
  INFO(text);
  REQUIRE(r.errors.empty());
  REQUIRE(r.trajectory);
  requireSame(t, *r.trajectory);
  CHECK(writeNative(*r.trajectory, "dir/part 1.stpnc") == text);
  // The helix makes a whole turn; the blend was rebuilt with its arc table.
  CHECK(r.trajectory->segments[2].sweep == 2 * kPi);
  CHECK_FALSE(r.trajectory->segments[2].ccw);
  CHECK(r.trajectory->segments[3].arcTable.back() > 0);
  CHECK(r.trajectory->profiles[1].phases[1].jerk == -1.25e-20);
}

TEST_CASE("a dwell reads back value for value and byte for byte, as version 2", "[native][dwell]") {
  const Trajectory t = dwelling();
  const std::string text = writeNative(t, "holes");
  INFO(text);
  CHECK(text.rfind("STEPNC-MOTION 2\n", 0) == 0);
  CHECK(text.find("\ndwell to 10.2 0.2 0.3333333333333333 length 0 programmed_feed 0 move 1 next 1 stop dwell limits "
                  "0 0 0 limited_by feed v0 0 a0 0 phases 7 0 0 0 0 0 0 0.5 0 0 0 0 0 0 0\nline to ") !=
        std::string::npos);
  CHECK(text.find(" move 2 next 2 stop dwell limits ") != std::string::npos);
  CHECK(text.find("; 3 segments, " + formatFixed(t.duration(), 3) + " s\n") != std::string::npos);
  Read r = read(text);
  REQUIRE(r.errors.empty());
  REQUIRE(r.trajectory);
  requireSame(t, *r.trajectory);
  CHECK(r.trajectory->segments[1].kind == SegmentKind::Dwell);
  CHECK(r.trajectory->duration() == t.duration());
  CHECK(writeNative(*r.trajectory, "holes") == text);
  // Without a dwell the same writer writes version 1, which version 1
  // players read.
  CHECK(writeNative(sample(), "p").rfind("STEPNC-MOTION 1\n", 0) == 0);
}

TEST_CASE("a lathe's trajectory is version 3: its axes and each segment's spindle", "[native][lathe]") {
  // The sample's segments taken as a lathe's (z, x, y), a thread pass among them.
  Trajectory t = dwelling();
  t.frame = Frame::Zxy;
  t.info[0].spindle0 = 1200;
  t.info[0].spindle1 = 1250.5;
  t.info[1].spindle0 = 1250.5;
  t.info[1].spindle1 = 1300;
  t.info[2].spindle0 = t.info[2].spindle1 = -600;
  t.info[2].sync = true;
  const std::string text = writeNative(t, "shaft");
  INFO(text);
  CHECK(text.rfind("STEPNC-MOTION 3\n", 0) == 0);
  CHECK(text.find("\ntolerance 0.01\naxes z x y\nstart ") != std::string::npos);
  CHECK(text.find(" spindle 1200 1250.5 sync none\n") != std::string::npos);
  CHECK(text.find(" spindle -600 -600 sync index\nend\n") != std::string::npos);
  Read r = read(text);
  REQUIRE(r.errors.empty());
  REQUIRE(r.trajectory);
  requireSame(t, *r.trajectory);
  CHECK(writeNative(*r.trajectory, "shaft") == text);
  // A thread pass needs one spindle speed; the axes are a mill's or a lathe's.
  CHECK(error(replaced(text, " spindle -600 -600 sync index", " spindle -600 -610 sync index")).find(
            "a segment synchronised with the spindle (a thread pass) needs it turning at one speed, not -600 to -610 "
            "rev/min") != std::string::npos);
  CHECK(error(replaced(text, "axes z x y", "axes x z y")).find("the axes are 'x y z' (a mill) or 'z x y' (a lathe)") !=
        std::string::npos);
  CHECK(error(replaced(text, " sync none\n", " sync maybe\n")).find("unknown synchronisation 'maybe'") !=
        std::string::npos);
  CHECK(error(replaced(text, " spindle 1200 1250.5 sync none", "")).find("the line ends where 'spindle' should follow") !=
        std::string::npos);
}

TEST_CASE("tool axes are version 4, an axis turning on a cubic version 5", "[native][five-axis]") {
  Trajectory t = sample();
  const Vec3 a0 = Vec3(0.1, 0.2, 1).normalized(), a1 = Vec3(0.15, 0.1, 1).normalized();
  const Vec3 a2 = Vec3(0.2, 0.05, 1).normalized();
  t.segments[0].axis0 = a0;
  t.segments[0].axis1 = t.segments[1].axis0 = a1;
  t.segments[1].axis1 = a2;
  const std::string v4 = writeNative(t, "tilted");
  INFO(v4);
  CHECK(v4.rfind("STEPNC-MOTION 4\n", 0) == 0);
  CHECK(v4.find(" turn ") == std::string::npos);
  // The orientation smoothed across the first junction: rates across the
  // axis at each end.
  auto across = [](const Vec3 &axis, const Vec3 &v) { return Vec3(v - axis * axis.dot(v)); };
  t.segments[0].axisRate0 = across(a0, a1 - a0);
  t.segments[0].axisRate1 = across(a1, Vec3(0.01, -0.02, 0.003));
  t.segments[1].axisRate0 = across(a1, Vec3(0.02, -0.04, 0.006));
  t.segments[1].axisRate1 = across(a2, a2 - a1);
  const std::string v5 = writeNative(t, "tilted");
  INFO(v5);
  CHECK(v5.rfind("STEPNC-MOTION 5\n", 0) == 0);
  CHECK(v5.find(" turn 0 0 0 0 0 0 limited_axis ") != std::string::npos);  // the segments that turn evenly
  Read r = read(v5);
  REQUIRE(r.errors.empty());
  REQUIRE(r.trajectory);
  requireSame(t, *r.trajectory);
  CHECK(writeNative(*r.trajectory, "tilted") == v5);
  // The cubic passes through both ends with those rates.
  const Segment &seg = r.trajectory->segments[0];
  CHECK((seg.axisAt(0) - a0).norm() == 0);
  CHECK((seg.axisAt(seg.length) - a1).norm() == 0);
  CHECK((seg.axisRateAt(0) - seg.axisRate0 / seg.length).norm() < 1e-12);
  // A rate along the axis is no turn of it: refused where it is.
  const std::string along = "turn " + [&] {
    std::ostringstream o;
    o.precision(17);
    o << a0.x() << ' ' << a0.y() << ' ' << a0.z();
    return o.str();
  }();
  const size_t turnAt = v5.find(" turn ") + 1;
  const size_t rateEnd = v5.find(' ', v5.find(' ', v5.find(' ', turnAt + 5) + 1) + 1);
  std::string bad = v5;
  bad.replace(turnAt, rateEnd - turnAt, along);
  CHECK(error(bad).find("the tool axis's rates at the ends are across the axis there, not along it by") !=
        std::string::npos);
}

TEST_CASE("native dwells are checked", "[native][dwell]") {
  const std::string text = writeNative(dwelling(), "p");
  REQUIRE(read(text).errors.empty());
  const std::string dwellLine = "dwell to 10.2 0.2 0.3333333333333333 length 0 ";
  const std::string waits = "phases 7 0 0 0 0 0 0 0.5 0 0 0 0 0 0 0";
  // The first error of reading `changed`, on the dwell's line.
  auto firstError = [](const std::string &changed) {
    Read r = read(changed);
    CHECK_FALSE(r.trajectory);
    REQUIRE_FALSE(r.errors.empty());
    CHECK(r.errors[0].rfind("11:", 0) == 0);
    return r.errors[0];
  };
  // No time, negative time, a jerk.
  CHECK_THAT(firstError(replaced(text, waits, "phases 7 0 0 0 0 0 0 0 0 0 0 0 0 0 0")),
             Catch::EndsWith("a dwell waits for the duration of its phases, which must be more than 0 s"));
  CHECK_THAT(firstError(replaced(text, waits, "phases 7 0 0 0 0 0 0 -0.5 0 0 0 0 0 0 0")),
             Catch::EndsWith("a phase's duration must not be negative (found -0.5)"));
  CHECK(read(replaced(text, waits, "phases 2 0.25 0 0.25 0")).errors.empty());  // any phases of jerk 0
  CHECK_THAT(firstError(replaced(text, waits, "phases 7 0 0 0 0 0 0 0.5 1 0 0 0 0 0 0")),
             Catch::Contains("the profile covers 0.020833333 mm, not the segment's length 0 mm"));
  // A length, somewhere else, another stop reason, at speed.
  CHECK_THAT(firstError(replaced(text, dwellLine, "dwell to 10.2 0.2 0.3333333333333333 length 0.5 ")),
             Catch::EndsWith("a dwell has no length (the tool waits where it is): length 0, not 0.5"));
  CHECK_THAT(firstError(replaced(text, dwellLine, "dwell to 10.2 0.25 0.3333333333333333 length 0 ")),
             Catch::EndsWith("a dwell waits where the tool is: its end point is 0.050000000 mm from where the "
                             "previous segment ends"));
  CHECK_THAT(firstError(replaced(text, "next 1 stop dwell", "next 1 stop program")),
             Catch::EndsWith("a dwell segment stops for its dwell: 'stop dwell', not 'stop program'"));
  Trajectory atSpeed = dwelling();
  atSpeed.profiles[0] = planProfile(0, 2, atSpeed.segments[0].length, atSpeed.info[0].limits);
  CHECK_THAT(firstError(writeNative(atSpeed, "p")),
             Catch::EndsWith("v0 0 mm/s does not continue the previous segment, which ends at 2.000000000 mm/s"));
  // Version 1 has no dwells.
  Read v1 = read(replaced(text, "STEPNC-MOTION 2", "STEPNC-MOTION 1"));
  CHECK_FALSE(v1.trajectory);
  REQUIRE(v1.errors.size() == 2);
  CHECK(v1.errors[0] == "11:1: a dwell segment needs format version 2; this file is version 1");
  CHECK_THAT(v1.errors[1], Catch::StartsWith("12:") && Catch::EndsWith("the stop reason 'dwell' needs format "
                                                                        "version 2; this file is version 1"));
}

TEST_CASE("slices of one profile read back with their start acceleration", "[native]") {
  const Trajectory t = sliced();
  REQUIRE(t.profiles[1].a0 > 1);
  REQUIRE(t.profiles[2].a0 < -1);
  CHECK(t.profiles[0].a1() == t.profiles[1].a0);
  const std::string text = writeNative(t, "run");
  INFO(text);
  CHECK(text.find(" v0 0 a0 0 phases 7 ") != std::string::npos);  // the first starts at rest
  CHECK(text.find(" a0 -") != std::string::npos);  // the last starts braking
  Read r = read(text);
  REQUIRE(r.errors.empty());
  REQUIRE(r.trajectory);
  requireSame(t, *r.trajectory);
  CHECK(r.trajectory->profiles[1].a0 == t.profiles[1].a0);
  CHECK(r.trajectory->profiles[2].a0 == t.profiles[2].a0);
  CHECK(writeNative(*r.trajectory, "run") == text);
}

TEST_CASE("native numbers are plain decimals, never -0 or exponents", "[native]") {
  const std::string text = writeNative(sample(), "p");
  CHECK(text.find("\nstart 0.1 0 0.3333333333333333\n") != std::string::npos);  // -0 written as 0
  CHECK(text.find(" -0.0000000000000000000125") != std::string::npos);
  CHECK(text.find("machine \"M \\\"fast\\\" \\\\ 1\\x09\"\n") != std::string::npos);
  const std::regex numberOrWord("-?[0-9]+(\\.[0-9]+)?|[a-z_0-9]+");
  std::istringstream lines(text);
  std::string line;
  int segments = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("line ", 0) != 0 && line.rfind("arc ", 0) != 0 && line.rfind("blend ", 0) != 0)
      continue;
    ++segments;
    std::istringstream words(line);
    std::string w;
    while (words >> w) {
      INFO(w);
      CHECK(std::regex_match(w, numberOrWord));
      CHECK(w != "-0");
    }
  }
  CHECK(segments == 4);
}

TEST_CASE("the native text of a small trajectory", "[native]") {
  Trajectory t;
  t.machine = "M";
  t.tolerance = 0.01;
  t.segments.push_back(Segment::line(Vec3::Zero(), Vec3(3, 4, 0)));
  Profile p;
  p.phases = {Phase{1, 2}, Phase{0, 0}, Phase{1, -2}, Phase{0.5, 0}, Phase{1, -2}, Phase{0, 0}, Phase{1, 2}};
  t.profiles.push_back(p);
  SegmentInfo info;
  info.limits = {2, 4, 2};
  info.limitedBy = SpeedLimit::Acceleration;
  info.feed = 2.5;
  info.stop = StopReason::Start;
  t.info.push_back(info);
  CHECK(writeNative(t, "part.stpnc") == kSmall);
  Read r = read(kSmall);
  CHECK(r.errors.empty());
  REQUIRE(r.trajectory);
  requireSame(t, *r.trajectory);
}

TEST_CASE("native format mistakes are located", "[native]") {
  REQUIRE(read(kSmall).errors.empty());
  // Another version: refused at the version number.
  CHECK(error(replaced(kSmall, "STEPNC-MOTION 1", "STEPNC-MOTION 6")) ==
        "1:15: unsupported native format version 6; this stepnc reads versions 1 to 5");
  const std::string notMotion =
      ": not a stepnc native motion file: the first line must be 'STEPNC-MOTION N', N the format version (1 to 5)";
  CHECK(error("G01 X1\n") == "1:1" + notMotion);
  CHECK(error("\n" + kSmall) == "2:1" + notMotion);
  CHECK(error("") == "1:1" + notMotion);
  // Truncated: fewer segments than announced, with or without 'end'.
  const std::string two = replaced(kSmall, "segments 1", "segments 2");
  CHECK(error(replaced(two, "end\n", "")) == "11:1: the file ends after 1 of the 2 segments announced");
  CHECK(error(two) == "11:1: 'end' after 1 of the 2 segments announced");
  CHECK(error(replaced(kSmall, "end\n", "")) == "11:1: the file ends without 'end'");
  const std::string segmentLine = kSmall.substr(kSmall.find("line to"), kSmall.find("end\n") - kSmall.find("line to"));
  CHECK(error(replaced(kSmall, "end\n", segmentLine + "end\n")) ==
        "11:1: expected 'end' after the 1 segments announced, found 'line'");
  CHECK(error(kSmall + "line\n") == "12:1: unexpected 'line' after 'end'");
  // Bad numbers: letters, an exponent, a count that is not whole.
  CHECK(error(replaced(kSmall, "length 5 ", "length 5x ")) ==
        "10:22: expected the length (a decimal number such as -12.5, without exponent), found '5x'");
  CHECK(error(replaced(kSmall, "tolerance 0.01", "tolerance 1e-2")) ==
        "7:11: expected the tolerance (a decimal number such as -12.5, without exponent), found '1e-2'");
  CHECK(error(replaced(kSmall, "segments 1", "segments 1.0")) ==
        "9:10: expected the number of segments (a whole number), found '1.0'");
  CHECK(error(replaced(kSmall, "cycle_time 0.001", "cycle_time 0")) ==
        "6:12: the cycle time must be positive (found 0)");
  // Unknown keywords: in the header, as a segment kind, as a word value.
  CHECK(error(replaced(kSmall, "cycle_time", "cycletime")) == "6:1: expected 'cycle_time', found 'cycletime'");
  CHECK(error(replaced(kSmall, "line to", "circle to")) ==
        "10:1: unknown segment kind 'circle' (known: line, arc, blend, dwell)");
  CHECK(error(replaced(kSmall, "stop start", "stop halt")) ==
        "10:63: unknown stop reason 'halt' (known: none, start, reversal, tiny, program, dwell)");
  CHECK(error(replaced(kSmall, " 1 2\n", " 1 2 3\n")) == "10:157: unexpected '3' after the last phase");
  CHECK(error(replaced(kSmall, " 1 2\n", " 1\n")) ==
        "10:154: the line ends where a phase's jerk should follow");
  // A length the geometry does not have.
  CHECK(error(replaced(kSmall, "length 5 ", "length 5.1 ")) ==
        "10:22: length 5.1 does not match the line's geometry (5.000000000 mm)");
  // Profiles that would make a player jump.
  CHECK(error(replaced(kSmall, "phases 7 1 2 0 0 1 -2 0.5 0", "phases 7 1 2 0 0 1 -2 0.6 0")) ==
        "10:116: the profile covers 5.200000000 mm, not the segment's length 5 mm");
  CHECK(error(replaced(kSmall, "v0 0", "v0 0.5")) == "10:109: v0 0.5 mm/s: the first segment starts at rest");
  CHECK(error(replaced(kSmall, "a0 0 ", "a0 0.5 ")) ==
        "10:114: a0 0.5 mm/s^2: the first segment starts at rest, with zero acceleration");
  CHECK(error(replaced(kSmall, "a0 0 ", "a0 ")) ==
        "10:114: expected the start acceleration a0 (a decimal number such as -12.5, without exponent), found "
        "'phases'");
  // Ending at zero speed is not enough: the last segment ends with zero
  // acceleration too (here it brakes at -2 mm/s^2 to the end, with a longer
  // cruise to make up the length).
  CHECK(error(replaced(kSmall, " 0.5 0 1 -2 0 0 1 2\n", " 0.5416666666666666 0 1 -2 0 0 0.5 0\n")) ==
        "10:116: the last segment ends with acceleration -2.000000000 mm/s^2; a trajectory ends at rest");
  // Strings.
  CHECK(error(replaced(kSmall, "\nmachine \"M\"", "\nmachine \"M")) == "5:9: the string has no closing quote");
  CHECK(error(replaced(kSmall, "\nmachine \"M\"", "\nmachine \"M\\q\"")) ==
        "5:11: unknown escape in a string (known: \\\\, \\\", \\xHH)");
}

TEST_CASE("native arcs are checked against their ends", "[native]") {
  Trajectory t;
  t.machine = "M";
  t.segments.push_back(Segment::arc(Vec3(10, 0, 0), Vec3(0, 10, 0), Vec3::Zero(), true, kPi / 2));
  // Moving the centre onto the bisector leaves 1e-15 of rounding: exact values make the text easy to edit.
  t.segments[0].center = Vec3::Zero();
  t.segments[0].startAngle = 0;
  t.segments[0].radius = 10;
  t.start = Vec3(10, 0, 0);
  t.profiles.push_back(planProfile(0, 0, t.segments[0].length, {5, 50, 500}));
  t.info.push_back({});
  const std::string text = writeNative(t, "p");
  INFO(text);
  REQUIRE(read(text).errors.empty());
  CHECK(text.find("arc to 0 10 0 center 0 0 radius 10 start_angle 0 sweep 1.5707963267948966 dir ccw length "
                  "15.707963267948966 ") != std::string::npos);
  const std::string e = error(replaced(text, "center 0 0", "center 1 0"));
  INFO(e);
  CHECK(e == "10:22: the centre (1.000000, 0.000000) is not equally far from the arc's start and end (9.000000000 "
             "and 10.049875621 mm)");
  CHECK(error(replaced(text, "radius 10", "radius 10.5")) ==
        "10:33: radius 10.5 does not match the distance from the centre to the arc's start (10.000000000 mm)");
  CHECK(error(replaced(text, "start_angle 0", "start_angle 0.1")) ==
        "10:48: start_angle 0.1 does not point at the arc's start (at 0.000000000 rad)");
  CHECK(error(replaced(text, "dir ccw", "dir cw")).rfind("10:56: turning 1.5707963267948966 rad cw from start_angle "
                                                         "ends 20.000000000 mm from the end point", 0) == 0);
  // The angle may be written a turn away.
  CHECK(read(replaced(text, "start_angle 0", "start_angle 6.283185307179586")).errors.empty());
}

TEST_CASE("native segments join in speed", "[native]") {
  Trajectory t = sample();
  t.profiles[1] = planProfile(6, 5, t.segments[1].length, t.info[1].limits);
  Read r = read(writeNative(t, "p"));
  CHECK_FALSE(r.trajectory);
  REQUIRE(r.errors.size() == 1);
  CHECK(r.errors[0].rfind("11:", 0) == 0);
  CHECK(r.errors[0].find("v0 6 mm/s does not continue the previous segment, which ends at 7.5") != std::string::npos);
  // A segment that stops first starts at rest.
  Trajectory stops = sample();
  stops.info[1].stop = StopReason::Program;
  const std::string stopError = error(writeNative(stops, "p"));
  CHECK(stopError.rfind("11:", 0) == 0);
  CHECK(stopError.find("a segment that stops first (stop program) must start at rest, not at v0 7.5") !=
        std::string::npos);
  // The last segment ends at rest.
  Trajectory moving = sample();
  moving.profiles[3] = planProfile(1.0 / 7, 1, moving.segments[3].length, moving.info[3].limits);
  const std::string e = error(writeNative(moving, "p"));
  INFO(e);
  CHECK(e.rfind("13:", 0) == 0);
  CHECK(e.find("the last segment ends at 1.000000000 mm/s; a trajectory ends at rest") != std::string::npos);
  // Every bad line is reported, not only the first.
  std::string text = writeNative(sample(), "p");
  text = replaced(text, "line to", "lime to");
  text = replaced(text, "blend to", "blend too");
  Read two = read(text);
  REQUIRE(two.errors.size() == 2);
  CHECK(two.errors[0] == "10:1: unknown segment kind 'lime' (known: line, arc, blend, dwell)");
  CHECK(two.errors[1] == "13:7: expected 'to', found 'too'");
}

TEST_CASE("native segments join in acceleration", "[native]") {
  const Trajectory good = sliced();
  REQUIRE(read(writeNative(good, "p")).errors.empty());
  // The middle slice starting from zero acceleration: a jump of a0 at line 11.
  Trajectory jump = good;
  jump.profiles[1].a0 = 0;
  const std::string e = error(writeNative(jump, "p"));
  INFO(e);
  CHECK(e.rfind("11:", 0) == 0);
  CHECK(e.find("a0 0 mm/s^2 does not continue the previous segment, which ends with acceleration " +
               formatFixed(good.profiles[0].a1(), 9) + " mm/s^2") != std::string::npos);
  // Reported at the a0 value.
  const std::string text = writeNative(jump, "p");
  const size_t line11 = text.find("\nline", text.find("\nline") + 1) + 1;
  CHECK(e.rfind("11:" + std::to_string(text.find(" a0 ", line11) + 5 - line11) + ": ", 0) == 0);
  // Cut short after a slice that ends braking: still at speed, reported
  // at the last segment's phases.
  Trajectory cut = good;
  cut.segments.pop_back();
  cut.profiles.pop_back();
  cut.info.pop_back();
  const std::string unfinished = error(writeNative(cut, "p"));
  INFO(unfinished);
  CHECK(unfinished.rfind("11:", 0) == 0);
  CHECK(unfinished.find("the last segment ends at ") != std::string::npos);
  // A segment that stops first must start at rest: the speed is reported
  // before the acceleration.
  Trajectory stops = good;
  stops.info[1].stop = StopReason::Reversal;
  const std::string stopError = error(writeNative(stops, "p"));
  CHECK(stopError.rfind("11:", 0) == 0);
  CHECK(stopError.find("a segment that stops first (stop reversal) must start at rest, not at v0 ") !=
        std::string::npos);
}
