// Machine descriptions: the shipped machines read clean, and each kind of
// mistake is reported at its line and column.
#include "runtime/Machine.h"

#include "../TestSupport.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

using namespace stepnc;

namespace {

struct Read {
  std::unique_ptr<SourceFile> file;
  std::optional<runtime::Machine> machine;
  std::vector<std::string> errors;  ///< "line:col: message"
};

Read read(const std::string &text) {
  Read r;
  r.file = SourceFile::fromString("m.toml", text);
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  r.machine = runtime::readMachine(*r.file, diags);
  r.errors = test::locatedMessages(collector, *r.file);
  return r;
}

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
                          "max_acceleration, max_jerk)");
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
  CHECK(read(replaced("kinematics = \"xyz\"", "kinematics = \"xyzbc\"")).errors.at(0).find("is not supported") !=
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
