// Writes a schema model back as EXPRESS text: the declarations' facts only
// (entities with their supertypes, attributes, redeclarations, DERIVE and
// INVERSE attributes and UNIQUE rules; defined, SELECT and ENUMERATION
// types), without WHERE rules, functions, procedures, rules or constants,
// and with every DERIVE expression written `?` (stepnc evaluates none: a
// derived attribute matters to a Part 21 file only as the `*` it writes).
// stepnc-schemac --express uses it to make the project's own text of a
// published long-form schema (docs/ap238.md).
#pragma once

#include "frontend/express/Schema.h"

#include <string>

namespace stepnc::express {

/// The declarations of `schema` (of `model`, resolved or not) as one
/// self-contained EXPRESS schema, each declaration in the order it was read.
/// `banner` is written first as a comment (may be empty).
std::string writeExpressFacts(const Model &model, const Schema &schema, std::string_view banner);

} // namespace stepnc::express
