#include "frontend/express/Builtin.h"

#include "frontend/express/SchemaIO.h"

#include <cstdlib>
#include <iostream>

namespace stepnc::embedded {
extern const char iso14649_arm_schema[];
extern const unsigned long iso14649_arm_schema_size;
extern const char ap238_aim_e1_schema[];
extern const unsigned long ap238_aim_e1_schema_size;
extern const char ap238_aim_e3_schema[];
extern const unsigned long ap238_aim_e3_schema_size;
} // namespace stepnc::embedded

namespace stepnc::express {

namespace {

Model load(std::string_view text) {
  Model m;
  std::string error;
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  if (!deserializeModel(text, m, error) || !m.resolve(diags)) {
    // The build compiled and checked this text; failing here is a bug.
    std::cerr << "stepnc: internal error: built-in schema: "
              << (error.empty() && !collector.diags.empty() ? collector.diags[0].message : error) << '\n';
    std::abort();
  }
  return m;
}

const Model &aimEdition1() {
  static const Model model = load({embedded::ap238_aim_e1_schema, embedded::ap238_aim_e1_schema_size});
  return model;
}

const Model &aimEdition3() {
  static const Model model = load({embedded::ap238_aim_e3_schema, embedded::ap238_aim_e3_schema_size});
  return model;
}

// stepnc's extension schemas, each interfacing the whole ARM; the additive
// one also the pattern strategies, so that it sees every entity.
constexpr std::string_view kPatternExtension = "STEPNC_PATTERN_STRATEGIES";
constexpr std::string_view kAdditiveExtension = "STEPNC_ADDITIVE";
constexpr std::string_view kAimEdition1 = "INTEGRATED_CNC_SCHEMA";
constexpr std::string_view kAimEdition3 = "MODEL_BASED_INTEGRATED_MANUFACTURING_SCHEMA";

/// A FILE_SCHEMA name without the object identifier some writers append
/// ('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'), upper case.
std::string schemaKey(std::string_view name) {
  if (size_t brace = name.find('{'); brace != std::string_view::npos)
    name = name.substr(0, brace);
  while (!name.empty() && (name.back() == ' ' || name.back() == '\t'))
    name.remove_suffix(1);
  while (!name.empty() && (name.front() == ' ' || name.front() == '\t'))
    name.remove_prefix(1);
  return upper(name);
}

} // namespace

const Model &builtinModel() {
  static const Model model = load({embedded::iso14649_arm_schema, embedded::iso14649_arm_schema_size});
  return model;
}

const std::vector<std::string_view> &builtinSchemaNames() {
  // ISO 14649 names its schemas per part; files name one or several of them,
  // or the merged schema's name; stepnc's extension goes beside them. AP238
  // AIM files name the AIM.
  static const std::vector<std::string_view> names = {
      "MACHINING_SCHEMA",    "MILLING_SCHEMA",  "TURNING_SCHEMA", "MILLING_TOOL_SCHEMA",
      "TURNING_TOOL_SCHEMA", "COMBINED_SCHEMA", "ISO14649_ARM",   kPatternExtension,
      kAdditiveExtension,    kAimEdition1,      kAimEdition3};
  return names;
}

BuiltinSchema findBuiltinSchema(std::string_view name) {
  const std::string wanted = schemaKey(name);
  if (wanted == kAimEdition1)
    return {&aimEdition1(), aimEdition1().findSchema(kAimEdition1)};
  if (wanted == kAimEdition3)
    return {&aimEdition3(), aimEdition3().findSchema(kAimEdition3)};
  if (wanted == kPatternExtension || wanted == kAdditiveExtension)
    return {&builtinModel(), builtinModel().findSchema(wanted)};
  for (std::string_view n : builtinSchemaNames())
    if (n == wanted)
      return {&builtinModel(), builtinModel().findSchema("iso14649_arm")};
  return {};
}

BuiltinSchema findBuiltinSchema(const std::vector<std::string> &names) {
  // An extension interfaces the whole ARM: when a file lists one, it is the
  // schema that sees every entity the file may use; the additive one sees
  // the pattern strategies too.
  auto rank = [](std::string_view key) { return key == kAdditiveExtension ? 2 : key == kPatternExtension ? 1 : 0; };
  BuiltinSchema chosen;
  int chosenRank = -1;
  for (const std::string &n : names) {
    const int r = rank(schemaKey(n));
    if (r <= chosenRank)
      continue;
    if (BuiltinSchema s = findBuiltinSchema(n)) {
      chosen = s;
      chosenRank = r;
    }
  }
  return chosen;
}

const Schema *builtinSchemaFor(std::string_view name) {
  BuiltinSchema s = findBuiltinSchema(name);
  return s.model == &builtinModel() ? s.schema : nullptr;
}

const Schema *builtinSchemaFor(const std::vector<std::string> &names) {
  BuiltinSchema s = findBuiltinSchema(names);
  return s.model == &builtinModel() ? s.schema : nullptr;
}

bool isAimSchema(const Schema &schema) {
  const std::string key = upper(schema.name);
  return key == kAimEdition1 || key == kAimEdition3;
}

} // namespace stepnc::express
