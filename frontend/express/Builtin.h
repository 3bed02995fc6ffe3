// The schemas compiled into stepnc, each its own model, loaded on first use:
// - the ISO 14649 ARM (parts 10, 11, 12, 111, 121) from
//   frontend/express/schemas/iso14649_arm.exp, with stepnc's extension of it
//   (the pattern strategies, stepnc_pattern_strategies.exp), which interfaces
//   the whole ARM;
// - the AP238 AIM long forms: edition 1 (integrated_cnc_schema,
//   ap238_aim_e1.exp) and edition 3 (model_based_integrated_manufacturing_schema,
//   ap238_aim_e3.exp). docs/ap238.md.
#pragma once

#include "frontend/express/Schema.h"

#include <string>
#include <string_view>
#include <vector>

namespace stepnc::express {

/// The ARM's model, resolved; loaded on first use (about a millisecond).
const Model &builtinModel();

/// A built-in schema and the model that holds it.
struct BuiltinSchema {
  const Model *model = nullptr;
  const Schema *schema = nullptr;
  explicit operator bool() const { return schema != nullptr; }
};

/// The built-in schema that answers to a FILE_SCHEMA name as real files write
/// it (MACHINING_SCHEMA, MILLING_SCHEMA, COMBINED_SCHEMA, INTEGRATED_CNC_SCHEMA,
/// ...; case-insensitive, an object identifier in braces after the name
/// ignored), or none.
BuiltinSchema findBuiltinSchema(std::string_view fileSchemaName);

/// The built-in schema to check a file whose FILE_SCHEMA lists `names`
/// against: the pattern extension when it is listed, else the first name
/// that answers to a built-in schema, else none.
BuiltinSchema findBuiltinSchema(const std::vector<std::string> &names);

/// The ARM's schema for a FILE_SCHEMA name (null for any other name).
const Schema *builtinSchemaFor(std::string_view fileSchemaName);
const Schema *builtinSchemaFor(const std::vector<std::string> &names);

/// True when `schema` is one of the AP238 AIM schemas.
bool isAimSchema(const Schema &schema);

/// The FILE_SCHEMA names findBuiltinSchema() accepts, upper case.
const std::vector<std::string_view> &builtinSchemaNames();

} // namespace stepnc::express
