// The schemas compiled into stepnc: the ISO 14649 ARM (parts 10, 11, 12, 111,
// 121) from frontend/express/schemas/iso14649_arm.exp.
#pragma once

#include "frontend/express/Schema.h"

#include <string_view>

namespace stepnc::express {

/// The built-in model, resolved; loaded on first use (about a millisecond).
const Model &builtinModel();

/// The built-in schema that answers to a FILE_SCHEMA name as real files write
/// it (MACHINING_SCHEMA, MILLING_SCHEMA, COMBINED_SCHEMA, ...), or null.
const Schema *builtinSchemaFor(std::string_view fileSchemaName);

/// The FILE_SCHEMA names builtinSchemaFor() accepts, upper case.
const std::vector<std::string_view> &builtinSchemaNames();

} // namespace stepnc::express
