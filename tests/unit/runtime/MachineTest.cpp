// Machine descriptions: the shipped machines read clean, and each kind of
// mistake is reported at its line and column.
#include "runtime/Machine.h"

#include "../TestSupport.h"
#include "ShippedMachine.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

using namespace stepnc;

namespace {

using Read = test::ReadMachine;

Read read(const std::string &text) { return test::readMachineText(text); }

std::string slurp(const std::string &path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string kGood = "format = 1\nname = \"M\"\nkinematics = \"xyz\"\n"
                          "[controller]\ncycle_time = 0.001\nlookahead = 100\npath_tolerance = 0.01\n"
                          "[spindle]\nmin_speed = 100\nmax_speed = 10000\npower = 7.5\n"
                          "[axes.x]\ntravel = [0.0, 500.0]\nmax_velocity = 20000\nmax_acceleration = 2000\nmax_jerk = 20000\n"
                          "[axes.y]\ntravel = [0, 400]\nmax_velocity = 20000\nmax_acceleration = 2000\nmax_jerk = 20000\n"
                          "[axes.z]\ntravel = [-300, 0]\nmax_velocity = 15000\nmax_acceleration = 1500\nmax_jerk = 15000\n";

} // namespace

TEST_CASE("the shipped machines read clean", "[machine]") {
  for (const char *name : {"hsc-3axis.toml", "conventional-3axis.toml"}) {
    Read r = read(slurp(std::string(STEPNC_SOURCE_DIR) + "/machines/" + name));
    INFO(name);
    CHECK(r.errors.empty());
    REQUIRE(r.machine);
    REQUIRE(r.machine->axes.size() == 3);
    CHECK(r.machine->axis("z")->travelMax == 0);
  }
}

TEST_CASE("a machine description's values", "[machine]") {
  Read r = read(kGood);
  REQUIRE(r.errors.empty());
  REQUIRE(r.machine);
  CHECK(r.machine->name == "M");
  CHECK(r.machine->cycleTime == 0.001);
  CHECK(r.machine->lookahead == 100);
  CHECK(r.machine->spindleMax == 10000);
  CHECK_FALSE(r.machine->spindleTorque);
  CHECK_FALSE(r.machine->maxFeed);
  CHECK(r.machine->axis("y")->travelMax == 400);  // integers read as numbers
  CHECK(r.machine->axis("x")->jerk == 20000);
  CHECK(r.machine->axis("a") == nullptr);
}

TEST_CASE("machine description mistakes are located", "[machine]") {
  auto replaced = [](std::string from, std::string to) {
    std::string t = kGood;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  // A typo in a key: reported at the key.
  Read typo = read(replaced("max_jerk = 15000", "max_jerks = 15000"));
  CHECK_FALSE(typo.machine);
  REQUIRE(typo.errors.size() == 2);
  CHECK(typo.errors[0] == "26:1: unknown key 'max_jerks' in [axes.z] (known: travel, max_velocity, "
                          "max_acceleration, max_jerk, type)");
  CHECK(typo.errors[1].find("axes.z needs 'max_jerk' (mm/s^3)") != std::string::npos);
  // A value out of range: at the value.
  Read negative = read(replaced("max_acceleration = 2000", "max_acceleration = -5"));
  REQUIRE(negative.errors.size() == 1);
  CHECK(negative.errors[0] == "15:20: axes.x.max_acceleration must be a number of mm/s^2 from 1 to 1000000");
  // Travel the wrong way round.
  Read travel = read(replaced("travel = [-300, 0]", "travel = [0, -300]"));
  REQUIRE(travel.errors.size() == 1);
  CHECK(travel.errors[0].find("axes.z.travel must be [min, max] in mm with min below max") != std::string::npos);
  // Spindle range, kinematics, format, and TOML syntax.
  CHECK(read(replaced("min_speed = 100", "min_speed = 20000")).errors.at(0).find("is not below max_speed") !=
        std::string::npos);
  CHECK(read(replaced("kinematics = \"xyz\"", "kinematics = \"xyzbc\"")).errors.at(0).find("is not a chain type") !=
        std::string::npos);
  CHECK(read(replaced("format = 1", "format = 2")).errors.at(0).find("format version from 1 to 1") !=
        std::string::npos);
  Read syntax = read(replaced("power = 7.5", "power = = 7.5"));
  REQUIRE(syntax.errors.size() == 1);
  CHECK(syntax.errors[0].rfind("11:", 0) == 0);
  CHECK(syntax.errors[0].find("not valid TOML") != std::string::npos);
  // A missing axis.
  Read noZ = read(kGood.substr(0, kGood.find("[axes.z]")));
  REQUIRE_FALSE(noZ.machine);
  CHECK(noZ.errors.at(0).find("needs an [axes.z] table") != std::string::npos);
}

namespace {

/// kGood with its kinematics and axes as a table-table A/C machine.
const std::string kFiveAxis =
    "format = 1\nname = \"M5\"\n"
    "[kinematics]\ntype = \"table-table\"\ntable = [\"a\", \"c\"]\n"
    "[controller]\ncycle_time = 0.001\nlookahead = 100\npath_tolerance = 0.01\n"
    "[spindle]\nmin_speed = 100\nmax_speed = 10000\npower = 7.5\n"
    "[axes.x]\ntravel = [0.0, 500.0]\nmax_velocity = 20000\nmax_acceleration = 2000\nmax_jerk = 20000\n"
    "[axes.y]\ntravel = [0, 400]\nmax_velocity = 20000\nmax_acceleration = 2000\nmax_jerk = 20000\n"
    "[axes.z]\ntravel = [-300, 0]\nmax_velocity = 15000\nmax_acceleration = 1500\nmax_jerk = 15000\n"
    "[axes.a]\ntravel = [-120, 30]\nmax_velocity = 9000\nmax_acceleration = 1000\nmax_jerk = 10000\n"
    "pivot = [0, 200, -250]\n"
    "[axes.c]\ntravel = [-360, 360]\nmax_velocity = 14400\nmax_acceleration = 2000\nmax_jerk = 20000\n"
    "pivot = [250, 200, 0]\n";

using test::edited;

} // namespace

TEST_CASE("every shipped machine reads clean, with its chain", "[machine]") {
  for (const std::string &name : runtime::shippedMachineNames()) {
    INFO(name);
    Read r = read(slurp(std::string(STEPNC_SOURCE_DIR) + "/machines/" + name + ".toml"));
    CHECK(r.errors.empty());
    REQUIRE(r.machine);
  }
  Read five = read(slurp(std::string(STEPNC_SOURCE_DIR) + "/machines/table-table-5axis.toml"));
  REQUIRE(five.machine);
  CHECK(five.machine->kinematics.chain == runtime::Chain::TableTable);
  REQUIRE(five.machine->axes.size() == 5);
  CHECK(five.machine->axes[3].name == "a");
  CHECK(five.machine->axes[3].rotary);
  CHECK(five.machine->axes[3].direction == Eigen::Vector3d::UnitX());
  CHECK(five.machine->axes[4].pivotMm == Eigen::Vector3d(250, 225, -250));
  CHECK(five.machine->whyNotThreeAxis().empty());
  Read lathe = read(slurp(std::string(STEPNC_SOURCE_DIR) + "/machines/lathe-2axis.toml"));
  REQUIRE(lathe.machine);
  CHECK(lathe.machine->kinematics.chain == runtime::Chain::Lathe);
  CHECK(lathe.machine->kinematics.diameterProgramming);
  REQUIRE(lathe.machine->axes.size() == 2);
  CHECK(lathe.machine->axes[1].name == "z");
  CHECK(lathe.machine->whyNotThreeAxis().find("is a lathe") != std::string::npos);
}

TEST_CASE("a 5-axis chain's axes and order", "[machine]") {
  Read r = read(kFiveAxis);
  REQUIRE(r.errors.empty());
  REQUIRE(r.machine);
  REQUIRE(r.machine->axes.size() == 5);
  CHECK(r.machine->axes[2].name == "z");
  CHECK_FALSE(r.machine->axes[2].rotary);
  CHECK(r.machine->axes[4].name == "c");
  CHECK(r.machine->axes[4].velocity == 14400);  // deg/min
  CHECK(r.machine->kinematics.toolAxis == Eigen::Vector3d::UnitZ());
  // The old form keeps meaning xyz, and so does a table of type xyz.
  Read xyz = read(edited(kGood, "kinematics = \"xyz\"", "[kinematics]\ntype = \"xyz\""));
  CHECK(xyz.errors.size() == 0);
  // A tilt whose travel leaves out 0 cannot run 3-axis programs.
  Read tilted = read(edited(kFiveAxis, "travel = [-120, 30]", "travel = [10, 100]"));
  REQUIRE(tilted.machine);
  CHECK(tilted.machine->whyNotThreeAxis().find("cannot hold its rotary axis a at 0 deg") != std::string::npos);
}

TEST_CASE("kinematics mistakes are located at their key", "[machine]") {
  // An axis the chain names that is not a rotary axis.
  Read unknownAxis = read(edited(kFiveAxis, "table = [\"a\", \"c\"]", "table = [\"a\", \"d\"]"));
  CHECK_FALSE(unknownAxis.machine);
  REQUIRE(unknownAxis.errors.size() >= 1);
  CHECK(unknownAxis.errors[0] == "5:9: kinematics.table names the axis 'd', which is not a rotary axis of a "
                                 "table-table chain (a, b or c: about x, y or z)");
  // A rotary axis without limits.
  Read noLimits = read(edited(kFiveAxis,
                              "[axes.c]\ntravel = [-360, 360]\nmax_velocity = 14400\nmax_acceleration = 2000\n"
                              "max_jerk = 20000\n",
                              "[axes.c]\n"));
  CHECK_FALSE(noLimits.machine);
  REQUIRE(noLimits.errors.size() == 4);
  CHECK(noLimits.errors[0].find("[axes.c] has no travel: every axis needs its limits, travel = [min, max] in deg") !=
        std::string::npos);
  CHECK(noLimits.errors[1].find("axes.c needs 'max_velocity' (deg/min)") != std::string::npos);
  // A rotary axis's travel the wrong way round.
  Read backwards = read(edited(kFiveAxis, "travel = [-120, 30]", "travel = [30, -120]"));
  REQUIRE(backwards.errors.size() == 1);
  CHECK(backwards.errors[0] == "30:10: axes.a.travel must be [min, max] in deg with min below max: it is [30, -120]");
  // An unknown chain type, in either form.
  Read type = read(edited(kFiveAxis, "type = \"table-table\"", "type = \"table-tabel\""));
  REQUIRE(type.errors.size() == 1);
  CHECK(type.errors[0] == "4:8: kinematics.type 'table-tabel' is not a chain type (known: xyz, table-table, "
                          "head-table, head-head, lathe, generic)");
  CHECK(read(edited(kGood, "kinematics = \"xyz\"", "kinematics = \"head-table\"")).errors.at(0).find(
            "kinematics 'head-table' needs its axes described: write a [kinematics] table") != std::string::npos);
  // The wrong number of axes for the chain, an axis named twice, an axis
  // the chain does not have, a table the chain needs missing, a pivot on a
  // linear axis.
  CHECK(read(edited(kFiveAxis, "table = [\"a\", \"c\"]", "table = [\"c\"]")).errors.at(0).find(
            "kinematics.table must name 2 rotary axes for a table-table chain (it names 1)") != std::string::npos);
  CHECK(read(edited(kFiveAxis, "table = [\"a\", \"c\"]", "table = [\"c\", \"c\"]")).errors.at(0).find(
            "names the axis 'c' twice") != std::string::npos);
  CHECK(read(edited(kFiveAxis, "table = [\"a\", \"c\"]", "table = [\"b\", \"c\"]")).errors.at(0).find(
            "unknown key 'a' in [axes]: a table-table chain has the axes x, y, z, b, c") != std::string::npos);
  Read missing = read(kFiveAxis.substr(0, kFiveAxis.find("[axes.c]")));
  REQUIRE_FALSE(missing.machine);
  CHECK(missing.errors.at(0).find("needs an [axes.c] table (table-table kinematics)") != std::string::npos);
  CHECK(read(edited(kFiveAxis, "max_jerk = 15000\n", "max_jerk = 15000\npivot = [0, 0, 0]\n")).errors.at(0).find(
            "unknown key 'pivot' in [axes.z]") != std::string::npos);
  CHECK(read(edited(kFiveAxis, "table = [\"a\", \"c\"]", "table = [\"a\", \"c\"]\ntool_axis = [0, 0, 0]"))
            .errors.at(0)
            .find("kinematics.tool_axis must not be [0, 0, 0]") != std::string::npos);
  // Lathe keys on a 5-axis chain.
  CHECK(read(edited(kFiveAxis, "table = [\"a\", \"c\"]", "table = [\"a\", \"c\"]\ndiameter_programming = true"))
            .errors.at(0)
            .find("unknown key 'diameter_programming' in [kinematics] of type table-table") != std::string::npos);
  // A generic chain needs its solver and joints.
  Read generic = read(edited(kGood, "kinematics = \"xyz\"", "[kinematics]\ntype = \"generic\""));
  REQUIRE(generic.errors.size() >= 2);
  CHECK(generic.errors[0].find("kinematics needs 'solver'") != std::string::npos);
  CHECK(generic.errors[1].find("a generic chain needs 'joints'") != std::string::npos);
  // More joints than a joint vector holds (runtime::Joints, on the stack).
  Read many = read(edited(kGood, "kinematics = \"xyz\"",
                          "[kinematics]\ntype = \"generic\"\nsolver = \"s\"\n"
                          "joints = [\"j1\", \"j2\", \"j3\", \"j4\", \"j5\", \"j6\", \"j7\", \"j8\", \"j9\"]"));
  REQUIRE(!many.errors.empty());
  CHECK(many.errors[0].find("kinematics.joints names 9 axes; stepnc moves at most 8") != std::string::npos);
}
