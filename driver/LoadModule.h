// Reading an input into the process IR, as every command that compiles does
// (compile, opt, sim): IR text is parsed; STEP-NC, Part 21 or Part 28 XML, is
// read, checked against its schema (leniently unless --strict) and lowered to
// the feature IR.
#pragma once

#include "driver/SchemaSelection.h"
#include "frontend/binding/Binder.h"
#include "frontend/lowering/Lowering.h"
#include "frontend/part21/Part21File.h"
#include "ir/Node.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>
#include <string>

namespace stepnc::driver {

/// How every command reads STEP-NC against its schema (check, compile, opt,
/// sim, so that one file gets the same diagnostics from each): leniently,
/// where what leaves the meaning clear is a warning that says what was read;
/// strictly, each of those an error, when `diags` is strict (--strict).
binding::BindOptions bindOptions(const DiagnosticEngine &diags);

/// Reads `source` as IR text (a file that starts with the IR's comment line
/// or `project`) or as STEP-NC. Part 28 XML is translated first and `source`
/// becomes the translation (whose diagnostics point into the XML); Part 21 is
/// bound to its schema as bindOptions(diags) says and lowered. Returns null
/// after reporting the input's errors to `diags` (a FILE_SCHEMA that names
/// no schema stepnc compiles is one, located there), or with `usageError` set
/// when the caller is at fault (--no-schema). `file`, when given, receives
/// the Part 21 file read (null for IR text). `lower` says how lowering reads
/// the file's units (--feed-unit, ...).
std::unique_ptr<ir::Module> loadModule(std::unique_ptr<SourceFile> &source, const SchemaSelection &schemas,
                                       DiagnosticEngine &diags, std::string &usageError,
                                       std::unique_ptr<p21::Part21File> *file = nullptr,
                                       const lowering::LowerOptions &lower = {});

} // namespace stepnc::driver
