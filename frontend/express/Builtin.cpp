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

const std::vector<std::string_view> &builtinSchemaNames() {
  // ISO 14649 names its schemas per part; files name one or several of them,
  // or the merged schema's name.
  static const std::vector<std::string_view> names = {
      "MACHINING_SCHEMA", "MILLING_SCHEMA",      "TURNING_SCHEMA",        "MILLING_TOOL_SCHEMA",
      "TURNING_TOOL_SCHEMA", "COMBINED_SCHEMA",  "ISO14649_ARM"};
  return names;
}

const Schema *builtinSchemaFor(std::string_view name) {
  std::string upper(name);
  for (char &c : upper)
    if (c >= 'a' && c <= 'z')
      c = static_cast<char>(c - 32);
  for (std::string_view n : builtinSchemaNames())
    if (n == upper)
      return &builtinModel().schemas().front();
  return nullptr;
}

} // namespace stepnc::express
