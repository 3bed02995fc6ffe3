#include "runtime/Machine.h"

#include "runtime/TomlReader.h"
#include "support/Format.h"

namespace stepnc::runtime {

const Axis *Machine::axis(std::string_view axisName) const {
  for (const Axis &a : axes)
    if (a.name == axisName)
      return &a;
  return nullptr;
}

std::optional<Machine> readMachine(const SourceFile &file, DiagnosticEngine &diags) {
  TomlReader r(file, diags, "the machine file");
  std::optional<toml::table> parsed = r.parse();
  if (!parsed)
    return std::nullopt;
  const toml::table &root = *parsed;
  r.onlyKnown(root, {"format", "name", "kinematics", "controller", "spindle", "axes"}, "the machine file");
  Machine m;
  if (auto format = r.number(root, "format", "the machine file", "format version", 1, 1, true); !format)
    return std::nullopt;
  m.name = r.text(root, "name", "the machine file", true).value_or("");
  m.kinematics = r.text(root, "kinematics", "the machine file", true).value_or("xyz");
  if (m.kinematics != "xyz")
    r.error(root.get("kinematics")->source(),
            "kinematics '" + m.kinematics + "' is not supported: only \"xyz\" (three linear axes in series) is");

  if (const toml::table *c = r.table(root, "controller", "controller")) {
    r.onlyKnown(*c, {"cycle_time", "lookahead", "path_tolerance", "max_feed"}, "[controller]");
    m.cycleTime = r.number(*c, "cycle_time", "controller", "s", 1e-5, 0.1, true).value_or(m.cycleTime);
    m.lookahead = static_cast<int>(r.number(*c, "lookahead", "controller", "segments", 1, 1e6, true).value_or(100));
    m.pathTolerance = r.number(*c, "path_tolerance", "controller", "mm", 1e-5, 10, true).value_or(m.pathTolerance);
    m.maxFeed = r.number(*c, "max_feed", "controller", "mm/min", 1, 1e7, false);
  }
  if (const toml::table *s = r.table(root, "spindle", "spindle")) {
    r.onlyKnown(*s, {"min_speed", "max_speed", "power", "torque"}, "[spindle]");
    m.spindleMin = r.number(*s, "min_speed", "spindle", "rev/min", 0, 2e5, true).value_or(0);
    m.spindleMax = r.number(*s, "max_speed", "spindle", "rev/min", 1, 2e5, true).value_or(0);
    m.spindlePower = r.number(*s, "power", "spindle", "kW", 0.01, 1e4, true).value_or(0);
    m.spindleTorque = r.number(*s, "torque", "spindle", "N m", 0.01, 1e6, false);
    if (r.ok() && m.spindleMin >= m.spindleMax)
      r.error(s->get("min_speed")->source(), "spindle.min_speed " + formatTrimmed(m.spindleMin, 6) +
                                                 " rev/min is not below max_speed " + formatTrimmed(m.spindleMax, 6));
  }
  if (const toml::table *axes = r.table(root, "axes", "axes")) {
    r.onlyKnown(*axes, {"x", "y", "z"}, "[axes]");
    for (const char *name : {"x", "y", "z"}) {
      const std::string what = std::string("axes.") + name;
      const toml::node *n = axes->get(name);
      if (!n || !n->is_table()) {
        r.error(n ? n->source() : axes->source(), "the machine file needs an [" + what + "] table (xyz kinematics)");
        continue;
      }
      const toml::table &t = *n->as_table();
      r.onlyKnown(t, {"travel", "max_velocity", "max_acceleration", "max_jerk"}, "[" + what + "]");
      Axis a;
      a.name = name;
      const toml::array *travel = t.get_as<toml::array>("travel");
      if (!travel || travel->size() != 2 || !(*travel)[0].value<double>() || !(*travel)[1].value<double>() ||
          !(*(*travel)[0].value<double>() < *(*travel)[1].value<double>())) {
        r.error(t.get("travel") ? t.get("travel")->source() : t.source(),
                what + ".travel must be [min, max] in mm with min below max");
      } else {
        a.travelMin = *(*travel)[0].value<double>();
        a.travelMax = *(*travel)[1].value<double>();
      }
      a.velocity = r.number(t, "max_velocity", what, "mm/min", 1, 1e7, true).value_or(0);
      a.acceleration = r.number(t, "max_acceleration", what, "mm/s^2", 1, 1e6, true).value_or(0);
      a.jerk = r.number(t, "max_jerk", what, "mm/s^3", 1, 1e9, true).value_or(0);
      m.axes.push_back(a);
    }
  }
  if (!r.ok())
    return std::nullopt;
  return m;
}

} // namespace stepnc::runtime

namespace stepnc::runtime {

// Generated from machines/*.toml at build time (runtime/CMakeLists.txt).
extern const std::vector<std::pair<std::string, std::string>> kShippedMachines;

std::vector<std::string> shippedMachineNames() {
  std::vector<std::string> names;
  for (const auto &[name, text] : kShippedMachines)
    names.push_back(name);
  return names;
}

std::optional<Machine> loadMachine(const std::string &spec, std::unique_ptr<SourceFile> &file,
                                   DiagnosticEngine &diags) {
  for (const auto &[name, text] : kShippedMachines)
    if (name == spec) {
      file = SourceFile::fromString("machines/" + name + ".toml", text);
      return readMachine(*file, diags);
    }
  std::string error;
  file = SourceFile::open(spec, error);
  if (!file) {
    std::string names;
    for (const auto &[name, text] : kShippedMachines)
      names += (names.empty() ? "" : ", ") + name;
    diags.error({}, "cannot read the machine '" + spec + "': " + error + " (shipped machines: " + names + ")");
    return std::nullopt;
  }
  return readMachine(*file, diags);
}

} // namespace stepnc::runtime
