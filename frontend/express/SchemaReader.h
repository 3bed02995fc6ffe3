// Reading EXPRESS (ISO 10303-11) source into the schema model.
#pragma once

#include "frontend/express/Schema.h"

namespace stepnc::express {

/// Brackets ( [ { may nest this deep in EXPRESS text; deeper is an error at
/// the bracket that goes too far. Expressions nest only through brackets.
inline constexpr unsigned kMaxBracketNesting = 256;
/// Grammar rules may be this deep inside each other while parsing (about ten
/// per bracket level, four per `LIST OF`, two per nested statement); deeper
/// is an error, so no input can overflow the parser's stack.
inline constexpr unsigned kMaxParseDepth = 4096;
/// The parser recovers from at most this many syntax errors, then stops with
/// an error where it is (each recovery costs as much as the nesting is deep).
inline constexpr unsigned kMaxSyntaxRecoveries = 100;

/// Parses `file` and adds its schemas to `model` (which keeps the file alive).
/// Syntax errors, bytes that are not UTF-8 and nesting beyond the limits
/// above are reported at file:line:col. Call Model::resolve() once
/// every file is read. Returns false if the file had syntax errors.
bool readExpress(std::unique_ptr<SourceFile> file, Model &model, DiagnosticEngine &diags);

} // namespace stepnc::express
