// The schemas compiled into stepnc: the ISO 14649 ARM (parts 10, 11, 12, 111,
// 121) from frontend/express/schemas/iso14649_arm.exp, and stepnc's extension
// of it with the pattern strategies (stepnc_pattern_strategies.exp), which
// interfaces the whole ARM.
#pragma once

#include "frontend/express/Schema.h"

#include <string>
#include <string_view>
#include <vector>

namespace stepnc::express {

/// The built-in model, resolved; loaded on first use (about a millisecond).
const Model &builtinModel();

/// The built-in schema that answers to a FILE_SCHEMA name as real files write
/// it (MACHINING_SCHEMA, MILLING_SCHEMA, COMBINED_SCHEMA, ...), or null.
const Schema *builtinSchemaFor(std::string_view fileSchemaName);

/// The built-in schema to check a file whose FILE_SCHEMA lists `names`
/// against: the extension when it is listed, else the ARM when any name
/// answers to it, else null.
const Schema *builtinSchemaFor(const std::vector<std::string> &names);

/// The FILE_SCHEMA names builtinSchemaFor() accepts, upper case.
const std::vector<std::string_view> &builtinSchemaNames();

} // namespace stepnc::express
