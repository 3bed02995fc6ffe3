// Reading and checking machine descriptions (docs/machine-model.md): the
// root keys, the kinematic chain, the controller, the spindle and one table
// per axis the chain needs. Errors are reported at the key that is wrong and
// reading goes on, so one run shows every problem in the file.
#include "runtime/Machine.h"

#include "runtime/Kinematics.h"
#include "runtime/TomlReader.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace stepnc::runtime {

std::string_view chainName(Chain chain) {
  switch (chain) {
  case Chain::Xyz:
    return "xyz";
  case Chain::TableTable:
    return "table-table";
  case Chain::HeadTable:
    return "head-table";
  case Chain::HeadHead:
    return "head-head";
  case Chain::Lathe:
    return "lathe";
  case Chain::Generic:
    return "generic";
  }
  return "?";
}

std::optional<Chain> chainNamed(std::string_view name) {
  for (Chain c : kChains)
    if (chainName(c) == name)
      return c;
  return std::nullopt;
}

const Axis *Machine::axis(std::string_view axisName) const {
  const int k = axisIndex(axisName);
  return k < 0 ? nullptr : &axes[static_cast<size_t>(k)];
}

int Machine::axisIndex(std::string_view axisName) const {
  for (size_t k = 0; k < axes.size(); ++k)
    if (axes[k].name == axisName)
      return static_cast<int>(k);
  return -1;
}

std::string Machine::whyNotThreeAxis() const {
  const std::string quoted = "\"" + name + "\"";
  switch (kinematics.chain) {
  case Chain::Xyz:
    return "";
  case Chain::TableTable:
  case Chain::HeadTable:
  case Chain::HeadHead: {
    const Eigen::Vector3d &k = kinematics.toolAxis;
    if ((k - Eigen::Vector3d::UnitZ()).norm() > 1e-9)
      return "the machine " + quoted + " holds its tool along (" + formatTrimmed(k.x(), 6) + ", " +
             formatTrimmed(k.y(), 6) + ", " + formatTrimmed(k.z(), 6) +
             ") with every axis at 0: a 3-axis program needs it along +z";
    for (const Axis &a : axes)
      if (a.rotary && !(a.travelMin <= 0 && a.travelMax >= 0))
        return "the machine " + quoted + " cannot hold its rotary axis " + a.name + " at 0 deg (travel [" +
               formatTrimmed(a.travelMin, 6) + ", " + formatTrimmed(a.travelMax, 6) +
               "] deg): a 3-axis program runs with the rotary axes at 0";
    return "";
  }
  case Chain::Lathe:
    return "the machine " + quoted +
           " is a lathe (x radial, z along the spindle): a 3-axis milling program cannot run on it (lathe programs "
           "are planned and played in its ZX plane, docs/turning.md)";
  case Chain::Generic:
    return "the machine " + quoted + " has a generic chain moved by the solver '" + kinematics.solver +
           "': the planner and the player move x, y and z through the xyz and 5-axis chains only";
  }
  return "unknown kinematics";
}

namespace {

/// The direction a rotary axis named a, b or c turns about (ISO 841: about
/// x, y, z); nullopt for other names.
std::optional<Eigen::Vector3d> rotaryDirection(std::string_view name) {
  if (name == "a")
    return Eigen::Vector3d::UnitX();
  if (name == "b")
    return Eigen::Vector3d::UnitY();
  if (name == "c")
    return Eigen::Vector3d::UnitZ();
  return std::nullopt;
}

std::string joined(const std::vector<std::string> &names) {
  std::string out;
  for (const std::string &n : names)
    out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// Three numbers, [x, y, z]; nullopt (after an error) when the node is not.
std::optional<Eigen::Vector3d> vector3(TomlReader &r, const toml::node &n, const std::string &what,
                                       const char *unit) {
  const toml::array *a = n.as_array();
  if (a && a->size() == 3) {
    Eigen::Vector3d v;
    bool ok = true;
    for (size_t k = 0; k < 3; ++k) {
      const std::optional<double> x = (*a)[k].value<double>();
      ok &= x.has_value() && std::isfinite(*x);
      v[static_cast<Eigen::Index>(k)] = x.value_or(0);
    }
    if (ok)
      return v;
  }
  r.error(n.source(), what + " must be three numbers [x, y, z]" + (*unit ? std::string(" in ") + unit : ""));
  return std::nullopt;
}

/// A list of axis names at `key`; nullopt (after an error) when it is not
/// one. A missing key is an empty list.
std::optional<std::vector<std::string>> names(TomlReader &r, const toml::table &t, std::string_view key) {
  const toml::node *n = t.get(key);
  std::vector<std::string> out;
  if (!n)
    return out;
  const toml::array *a = n->as_array();
  if (a)
    for (const toml::node &e : *a)
      if (auto s = e.value<std::string>())
        out.push_back(*s);
  if (!a || out.size() != a->size()) {
    r.error(n->source(), "kinematics." + std::string(key) + " must be a list of axis names, such as [\"a\", \"c\"]");
    return std::nullopt;
  }
  return out;
}

/// A generic chain's parameters against those its solver declared
/// (runtime/Kinematics.h), when it is registered with them: each unknown
/// one at its key, each missing one at the table, each out of its range at
/// its value.
void checkSolverParameters(TomlReader &r, const toml::table &t, const KinematicsSpec &spec) {
  const std::optional<std::vector<SolverParameter>> wanted = kinematicsSolverParameters(spec.solver);
  if (!wanted)
    return;
  const toml::table *given = t.get("parameters") ? t.get("parameters")->as_table() : nullptr;
  std::set<std::string> known;
  std::string list;
  for (const SolverParameter &p : *wanted) {
    known.insert(p.name);
    list += (list.empty() ? "" : ", ") + p.name;
  }
  if (given)
    for (const auto &[key, value] : *given)
      if (!known.count(std::string(key.str())))
        r.error(key.source(), "unknown key '" + std::string(key.str()) + "' in [kinematics.parameters]: the solver '" +
                                  spec.solver + "' reads " + list);
  for (const SolverParameter &p : *wanted) {
    const toml::node *n = given ? given->get(p.name) : nullptr;
    if (!n) {
      r.error(given ? given->source() : t.source(), "the solver '" + spec.solver + "' needs kinematics.parameters." +
                                                        p.name + " (" + p.unit + ": " + p.meaning + ")");
      continue;
    }
    const std::optional<double> v = n->value<double>();
    if (v && std::isfinite(*v) && !(*v >= p.min && *v <= p.max))
      r.error(n->source(), "kinematics.parameters." + p.name + " must be from " + formatTrimmed(p.min, 6) + " to " +
                               formatTrimmed(p.max, 6) + " " + p.unit + " (" + p.meaning + "), not " +
                               formatTrimmed(*v, 6));
  }
}

/// The [kinematics] table. False when the chain's type is unknown (its axes
/// cannot then be checked).
bool readChain(TomlReader &r, const toml::table &t, KinematicsSpec &spec) {
  const std::optional<std::string> type = r.text(t, "type", "kinematics", true);
  if (!type)
    return false;
  const std::optional<Chain> chain = chainNamed(*type);
  if (!chain) {
    std::string known;
    for (Chain c : kChains)
      known += (known.empty() ? "" : ", ") + std::string(chainName(c));
    r.error(t.get("type")->source(), "kinematics.type '" + *type + "' is not a chain type (known: " + known + ")");
    return false;
  }
  spec.chain = *chain;
  const std::string where = "[kinematics] of type " + *type;
  switch (spec.chain) {
  case Chain::Xyz:
    r.onlyKnown(t, {"type"}, where);
    break;
  case Chain::TableTable:
  case Chain::HeadTable:
  case Chain::HeadHead: {
    r.onlyKnown(t, {"type", "head", "table", "tool_axis"}, where);
    const size_t wantHead = spec.chain == Chain::TableTable ? 0 : spec.chain == Chain::HeadTable ? 1 : 2;
    const size_t wantTable = 2 - wantHead;
    std::set<std::string> seen;
    for (const auto &[key, want] : {std::pair<std::string_view, size_t>{"head", wantHead}, {"table", wantTable}}) {
      const std::optional<std::vector<std::string>> list = names(r, t, key);
      if (!list)
        continue;
      const toml::node *n = t.get(key);
      // A wrong count is reported and the names still read, so that their
      // [axes] tables are not reported as unknown too.
      if (list->size() != want)
        r.error(n ? n->source() : t.source(), "kinematics." + std::string(key) + " must name " +
                                                  std::to_string(want) + (want == 1 ? " rotary axis" : " rotary axes") +
                                                  " for a " + *type + " chain (it names " +
                                                  std::to_string(list->size()) + ")");
      for (const std::string &axis : *list) {
        if (!rotaryDirection(axis))
          r.error(n->source(), "kinematics." + std::string(key) + " names the axis '" + axis +
                                   "', which is not a rotary axis of a " + *type +
                                   " chain (a, b or c: about x, y or z)");
        else if (!seen.insert(axis).second)
          r.error(n->source(), "kinematics." + std::string(key) + " names the axis '" + axis + "' twice");
      }
      (key == "head" ? spec.head : spec.table) = *list;
    }
    break;
  }
  case Chain::Lathe:
    r.onlyKnown(t, {"type", "diameter_programming", "tool_axis"}, where);
    spec.toolAxis = Eigen::Vector3d::UnitX();
    if (const toml::node *n = t.get("diameter_programming")) {
      if (auto b = n->value<bool>())
        spec.diameterProgramming = *b;
      else
        r.error(n->source(), "kinematics.diameter_programming must be true or false");
    }
    break;
  case Chain::Generic:
    r.onlyKnown(t, {"type", "solver", "joints", "parameters"}, where);
    spec.solver = r.text(t, "solver", "kinematics", true).value_or("");
    if (const toml::node *n = t.get("joints"); !n) {
      r.error(t.source(), "a generic chain needs 'joints', the names of its axes in the solver's order");
    } else if (auto list = names(r, t, "joints")) {
      std::set<std::string> seen;
      for (const std::string &axis : *list) {
        const bool wellFormed = !axis.empty() && axis.size() <= 16 && axis[0] >= 'a' && axis[0] <= 'z' &&
                                axis.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") == std::string::npos;
        if (!wellFormed)
          r.error(n->source(), "kinematics.joints: '" + axis +
                                   "' is not an axis name (lower-case letters, digits and _, starting with a letter)");
        else if (!seen.insert(axis).second)
          r.error(n->source(), "kinematics.joints names the axis '" + axis + "' twice");
      }
      if (list->empty())
        r.error(n->source(), "kinematics.joints names no axis");
      else if (list->size() > size_t(kMaxJoints))
        r.error(n->source(), "kinematics.joints names " + std::to_string(list->size()) + " axes; stepnc moves at most " +
                                 std::to_string(kMaxJoints));
      spec.head = *list;  // kept in `head` until the axes are read
    }
    if (const toml::table *p = r.table(t, "parameters", "kinematics.parameters", false))
      for (const auto &[key, value] : *p) {
        if (auto v = value.value<double>(); v && std::isfinite(*v))
          spec.parameters.emplace_back(std::string(key.str()), *v);
        else
          r.error(value.source(), "kinematics.parameters." + std::string(key.str()) + " must be a number");
      }
    checkSolverParameters(r, t, spec);
    break;
  }
  if (const toml::node *n = t.get("tool_axis"))
    if (auto v = vector3(r, *n, "kinematics.tool_axis", "")) {
      if (v->norm() < 1e-9)
        r.error(n->source(), "kinematics.tool_axis must not be [0, 0, 0]: it is the tool's direction");
      else
        spec.toolAxis = v->normalized();
    }
  return true;
}

/// One axis the chain needs, as [axes.NAME].
struct AxisWant {
  std::string name;
  bool rotary = false;
  bool required = true;
  bool pivot = false;       ///< may have a pivot (5-axis rotaries)
  bool typeFixed = true;    ///< the chain fixes linear or rotary (all but generic)
};

std::vector<AxisWant> axesWanted(const KinematicsSpec &spec) {
  std::vector<AxisWant> out;
  switch (spec.chain) {
  case Chain::Xyz:
    out = {{"x"}, {"y"}, {"z"}};
    break;
  case Chain::TableTable:
  case Chain::HeadTable:
  case Chain::HeadHead:
    out = {{"x"}, {"y"}, {"z"}};
    for (const auto *list : {&spec.head, &spec.table})
      for (const std::string &n : *list)
        if (rotaryDirection(n))
          out.push_back({n, true, true, true});
    break;
  case Chain::Lathe:
    out = {{"x"}, {"z"}, {"c", true, false}};
    break;
  case Chain::Generic:
    for (const std::string &n : spec.head)
      out.push_back({n, rotaryDirection(n).has_value(), true, false, false});
    break;
  }
  return out;
}

void readAxis(TomlReader &r, const toml::table &t, const AxisWant &want, Chain chain, Axis &a) {
  const std::string what = "axes." + want.name;
  a.name = want.name;
  a.rotary = want.rotary;
  if (want.pivot)
    r.onlyKnown(t, {"travel", "max_velocity", "max_acceleration", "max_jerk", "type", "pivot"}, "[" + what + "]");
  else
    r.onlyKnown(t, {"travel", "max_velocity", "max_acceleration", "max_jerk", "type"}, "[" + what + "]");
  if (const toml::node *n = t.get("type")) {
    const std::optional<std::string> type = n->value<std::string>();
    if (!type || (*type != "linear" && *type != "rotary"))
      r.error(n->source(), what + ".type must be \"linear\" or \"rotary\"");
    else if (want.typeFixed && (*type == "rotary") != want.rotary)
      r.error(n->source(), what + ".type is \"" + *type + "\", but " + want.name + " is a " +
                               (want.rotary ? "rotary" : "linear") + " axis in a " + std::string(chainName(chain)) +
                               " chain");
    else
      a.rotary = *type == "rotary";
  }
  const char *length = a.rotary ? "deg" : "mm";
  const toml::node *travelNode = t.get("travel");
  const toml::array *travel = travelNode ? travelNode->as_array() : nullptr;
  if (!travelNode) {
    r.error(t.source(), "[" + what + "] has no travel: every axis needs its limits, travel = [min, max] in " +
                            length);
  } else if (!travel || travel->size() != 2 || !(*travel)[0].value<double>() || !(*travel)[1].value<double>()) {
    r.error(travelNode->source(), what + ".travel must be [min, max] in " + length + " with min below max");
  } else {
    const double lo = *(*travel)[0].value<double>(), hi = *(*travel)[1].value<double>();
    if (!(lo < hi))
      r.error(travelNode->source(), what + ".travel must be [min, max] in " + length +
                                        " with min below max: it is [" + formatTrimmed(lo, 6) + ", " +
                                        formatTrimmed(hi, 6) + "]");
    a.travelMin = lo;
    a.travelMax = hi;
  }
  a.velocity = r.number(t, "max_velocity", what, a.rotary ? "deg/min" : "mm/min", 1, 1e7, true).value_or(0);
  a.acceleration = r.number(t, "max_acceleration", what, a.rotary ? "deg/s^2" : "mm/s^2", 1, 1e6, true).value_or(0);
  a.jerk = r.number(t, "max_jerk", what, a.rotary ? "deg/s^3" : "mm/s^3", 1, 1e9, true).value_or(0);
  if (auto dir = rotaryDirection(want.name); dir && a.rotary)
    a.direction = *dir;
  if (const toml::node *n = t.get("pivot"); n && want.pivot)
    a.pivotMm = vector3(r, *n, what + ".pivot", "mm").value_or(Eigen::Vector3d::Zero());
}

void readAxes(TomlReader &r, const toml::table &axes, Machine &m) {
  const std::vector<AxisWant> wanted = axesWanted(m.kinematics);
  std::set<std::string> known;
  std::vector<std::string> knownList;
  for (const AxisWant &w : wanted)
    if (known.insert(w.name).second)
      knownList.push_back(w.name);
  const std::string chain(chainName(m.kinematics.chain));
  for (const auto &[key, value] : axes)
    if (!known.count(std::string(key.str())))
      r.error(key.source(), "unknown key '" + std::string(key.str()) + "' in [axes]: a " + chain +
                                " chain has the axes " + joined(knownList));
  std::set<std::string> done;
  for (const AxisWant &want : wanted) {
    if (!done.insert(want.name).second)
      continue;
    const std::string what = "axes." + want.name;
    const toml::node *n = axes.get(want.name);
    if (!n) {
      if (want.required)
        r.error(axes.source(), "the machine file needs an [" + what + "] table (" + chain + " kinematics)");
      continue;
    }
    if (!n->is_table()) {
      r.error(n->source(), "'" + what + "' must be a table ([" + what + "])");
      continue;
    }
    Axis a;
    readAxis(r, *n->as_table(), want, m.kinematics.chain, a);
    m.axes.push_back(std::move(a));
  }
  if (m.kinematics.chain == Chain::Generic)
    m.kinematics.head.clear();  // the joints are the axes, in order
}

} // namespace

Machine latheFrameMachine(const Machine &lathe) {
  Machine out = lathe;
  out.kinematics = KinematicsSpec{};
  out.axes.clear();
  const Axis *x = lathe.axis("x"), *z = lathe.axis("z");
  if (!x || !z)
    return out;
  out.axes.push_back(*z);
  out.axes.push_back(*x);
  Axis y = *x;
  y.name = "y";
  y.travelMin = y.travelMax = 0;
  out.axes.push_back(y);
  return out;
}

std::optional<Machine> readMachine(const SourceFile &file, DiagnosticEngine &diags) {
  TomlReader r(file, diags, "the machine file");
  std::optional<toml::table> parsed = r.parse();
  if (!parsed)
    return std::nullopt;
  const toml::table &root = *parsed;
  r.onlyKnown(root, {"format", "name", "processes", "kinematics", "controller", "spindle", "axes", "deposition"},
              "the machine file");
  Machine m;
  if (auto format = r.number(root, "format", "the machine file", "format version", 1, 1, true); !format)
    return std::nullopt;
  m.name = r.text(root, "name", "the machine file", true).value_or("");

  // `kinematics = "xyz"` (the form of the first machine files) or a table.
  bool chainKnown = false;
  if (const toml::node *k = root.get("kinematics"); !k) {
    r.error(root.source(), "the machine file needs 'kinematics': \"xyz\", or a [kinematics] table with its type");
  } else if (auto word = k->value<std::string>()) {
    if (*word == "xyz")
      chainKnown = true;
    else if (chainNamed(*word))
      r.error(k->source(), "kinematics '" + *word +
                               "' needs its axes described: write a [kinematics] table with type = \"" + *word +
                               "\" (docs/machine-model.md)");
    else
      r.error(k->source(), "kinematics '" + *word +
                               "' is not a chain type (known: xyz, table-table, head-table, head-head, lathe, generic)");
  } else if (const toml::table *t = k->as_table()) {
    chainKnown = readChain(r, *t, m.kinematics);
  } else {
    r.error(k->source(), "kinematics must be \"xyz\" or a [kinematics] table");
  }

  if (const toml::table *c = r.table(root, "controller", "controller")) {
    r.onlyKnown(*c, {"cycle_time", "lookahead", "path_tolerance", "orientation_tolerance", "max_feed"},
                "[controller]");
    m.cycleTime = r.number(*c, "cycle_time", "controller", "s", 1e-5, 0.1, true).value_or(m.cycleTime);
    m.lookahead = static_cast<int>(r.number(*c, "lookahead", "controller", "segments", 1, 1e6, true).value_or(100));
    m.pathTolerance = r.number(*c, "path_tolerance", "controller", "mm", 1e-5, 10, true).value_or(m.pathTolerance);
    m.maxFeed = r.number(*c, "max_feed", "controller", "mm/min", 1, 1e7, false);
    m.orientationTolerance = r.number(*c, "orientation_tolerance", "controller", "deg", 0, 5, false)
                                 .value_or(m.orientationTolerance);
  }
  if (const toml::table *d = r.table(root, "deposition", "deposition", false)) {
    r.onlyKnown(*d, {"target", "energy_on", "energy_off", "power", "powder", "wire", "max_power", "max_powder",
                     "max_wire"},
                "[deposition]");
    DepositionCodes c;
    c.target = r.text(*d, "target", "deposition", true).value_or("");
    c.energyOn = r.text(*d, "energy_on", "deposition", true).value_or("");
    c.energyOff = r.text(*d, "energy_off", "deposition", true).value_or("");
    c.power = r.text(*d, "power", "deposition", true).value_or("");
    c.powder = r.text(*d, "powder", "deposition", false).value_or("");
    c.wire = r.text(*d, "wire", "deposition", false).value_or("");
    c.maxPower = r.number(*d, "max_power", "deposition", "W", 1, 1e6, true).value_or(0);
    c.maxPowder = r.number(*d, "max_powder", "deposition", "g/min", 0.01, 1e4, false);
    c.maxWire = r.number(*d, "max_wire", "deposition", "mm/min", 1, 1e6, false);
    m.deposition = std::move(c);
  }
  if (const toml::table *s = r.table(root, "spindle", "spindle")) {
    r.onlyKnown(*s, {"min_speed", "max_speed", "power", "torque", "acceleration"}, "[spindle]");
    m.spindleMin = r.number(*s, "min_speed", "spindle", "rev/min", 0, 2e5, true).value_or(0);
    m.spindleMax = r.number(*s, "max_speed", "spindle", "rev/min", 1, 2e5, true).value_or(0);
    m.spindlePower = r.number(*s, "power", "spindle", "kW", 0.01, 1e4, true).value_or(0);
    m.spindleTorque = r.number(*s, "torque", "spindle", "N m", 0.01, 1e6, false);
    m.spindleAcceleration = r.number(*s, "acceleration", "spindle", "rev/min per s", 1, 1e6, false);
    if (r.ok() && m.spindleMin >= m.spindleMax)
      r.error(s->get("min_speed")->source(), "spindle.min_speed " + formatTrimmed(m.spindleMin, 6) +
                                                 " rev/min is not below max_speed " + formatTrimmed(m.spindleMax, 6));
  }
  if (const toml::table *axes = r.table(root, "axes", "axes"); axes && chainKnown)
    readAxes(r, *axes, m);
  // The processes it does: as the file lists them, else a lathe turns and
  // any other machine mills, and deposits when it has a deposition head.
  if (const toml::node *p = root.get("processes")) {
    const toml::array *a = p->as_array();
    if (a)
      for (const toml::node &e : *a) {
        const std::optional<std::string> name = e.value<std::string>();
        if (name && (*name == "milling" || *name == "turning" || *name == "deposition"))
          m.processes.push_back(*name);
      }
    if (!a || a->empty() || m.processes.size() != a->size())
      r.error(p->source(), "processes must list some of \"milling\", \"turning\", \"deposition\"");
  } else {
    m.processes = {m.kinematics.chain == Chain::Lathe ? "turning" : "milling"};
    if (m.deposition)
      m.processes.push_back("deposition");
  }
  if (m.deposition && std::find(m.processes.begin(), m.processes.end(), "deposition") == m.processes.end())
    r.error(root.get("deposition")->source(), "a machine with a [deposition] table deposits: list \"deposition\" "
                                              "among its processes");
  // A generic chain whose solver is registered: what only the solver can
  // check (its joints, how its numbers go together), at the [kinematics]
  // table.
  if (r.ok() && m.kinematics.chain == Chain::Generic && kinematicsSolverRegistered(m.kinematics.solver)) {
    std::string error;
    if (!makeKinematics(m, error))
      r.error(root.get("kinematics")->source(), error);
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
