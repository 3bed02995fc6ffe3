// Reading EXPRESS (ISO 10303-11) source into the schema model.
#pragma once

#include "frontend/express/Schema.h"

namespace stepnc::express {

/// Parses `file` and adds its schemas to `model` (which keeps the file alive).
/// Syntax errors are reported at file:line:col. Call Model::resolve() once
/// every file is read. Returns false if the file had syntax errors.
bool readExpress(std::unique_ptr<SourceFile> file, Model &model, DiagnosticEngine &diags);

} // namespace stepnc::express
