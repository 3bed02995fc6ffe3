#include "frontend/express/Builtin.h"

#include "frontend/express/SchemaIO.h"

#include <cstdlib>
#include <iostream>

namespace stepnc::embedded {
extern const char iso14649_arm_schema[];
extern const unsigned long iso14649_arm_schema_size;
} // namespace stepnc::embedded

namespace stepnc::express {

const Model &builtinModel() {
  static const Model model = [] {
    Model m;
    std::string error;
    DiagnosticCollector collector;
    DiagnosticEngine diags(collector);
    if (!deserializeModel({embedded::iso14649_arm_schema, embedded::iso14649_arm_schema_size}, m, error) ||
        !m.resolve(diags)) {
      // The build compiled and checked this text; failing here is a bug.
      std::cerr << "stepnc: internal error: built-in schema: "
                << (error.empty() && !collector.diags.empty() ? collector.diags[0].message : error) << '\n';
      std::abort();
    }
    return m;
  }();
  return model;
}

namespace {

constexpr std::string_view kExtensionName = "STEPNC_PATTERN_STRATEGIES";

} // namespace

const std::vector<std::string_view> &builtinSchemaNames() {
  // ISO 14649 names its schemas per part; files name one or several of them,
  // or the merged schema's name; stepnc's extension goes beside them.
  static const std::vector<std::string_view> names = {
      "MACHINING_SCHEMA",    "MILLING_SCHEMA",  "TURNING_SCHEMA", "MILLING_TOOL_SCHEMA",
      "TURNING_TOOL_SCHEMA", "COMBINED_SCHEMA", "ISO14649_ARM",   kExtensionName};
  return names;
}

const Schema *builtinSchemaFor(std::string_view name) {
  const std::string wanted = upper(name);
  if (wanted == kExtensionName)
    return builtinModel().findSchema(kExtensionName);
  for (std::string_view n : builtinSchemaNames())
    if (n == wanted)
      return builtinModel().findSchema("iso14649_arm");
  return nullptr;
}

const Schema *builtinSchemaFor(const std::vector<std::string> &names) {
  // The extension interfaces the whole ARM: when a file lists it, it is the
  // schema that sees every entity the file may use.
  const Schema *chosen = nullptr;
  for (const std::string &n : names)
    if (const Schema *s = builtinSchemaFor(n); s && (!chosen || upper(n) == kExtensionName))
      chosen = s;
  return chosen;
}

} // namespace stepnc::express
