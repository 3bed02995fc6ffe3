// A compact text form of the schema model, so that built-in schemas are
// compiled into the binary at build time and loaded in about a millisecond
// instead of being parsed from EXPRESS at every start.
//
// The form keeps everything the reader produced (names unresolved); loading
// it and calling Model::resolve() gives the same model as reading the .exp.
#pragma once

#include "frontend/express/Schema.h"

#include <string>
#include <string_view>

namespace stepnc::express {

/// Writes every schema of `model` (resolved or not).
std::string serializeModel(const Model &model);

/// Adds the schemas in `text` to `model`; on malformed input returns false and
/// sets `error` ("line N: ...").
bool deserializeModel(std::string_view text, Model &model, std::string &error);

} // namespace stepnc::express
