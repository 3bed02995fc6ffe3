// Choosing the EXPRESS schema a STEP file is checked against: the files
// given with --schema, else the built-in schema its FILE_SCHEMA names. Part 28
// XML is read through that schema too, so its translation to Part 21 text
// starts here.
#pragma once

#include "frontend/express/Schema.h"
#include "frontend/part21/Part21File.h"
#include "support/OutputFile.h"

#include <string>
#include <vector>

namespace stepnc::driver {

/// Which schemas to check against (the commands' --schema and --no-schema).
struct SchemaOptions {
  std::vector<std::string> files;  ///< EXPRESS files resolved together; empty: the built-in schemas
  bool none = false;               ///< check Part 21 syntax and references only
};

class SchemaSelection {
public:
  explicit SchemaSelection(const SchemaOptions &opts) : opts_(opts) {}

  /// Reads and resolves the --schema files, if any. Returns false when one
  /// has errors (reported to `diags`) or cannot be read (`ioError` says why).
  bool load(DiagnosticEngine &diags, std::string &ioError);

  /// The schema to check `file` against, or null with a warning saying why
  /// (unknown schema, --no-schema is silent). `model` receives its model.
  const express::Schema *select(const p21::Part21File &file, DiagnosticEngine &diags,
                                const express::Model *&model) const;

  /// The schema to compile `file` against: select's, except that a file
  /// whose FILE_SCHEMA names no built-in schema (and no --schema was given)
  /// is an error located at its FILE_SCHEMA entry that names what the file
  /// declares and what stepnc compiles. Null with that error, or silently
  /// with --no-schema (the caller's mistake: nothing to lower through).
  const express::Schema *selectToCompile(const p21::Part21File &file, DiagnosticEngine &diags,
                                         const express::Model *&model) const;

  /// The schema for a document naming `names`, without diagnostics: with
  /// --schema the one named (else the first given), else the built-in one the
  /// names answer to (the ARM when no name is given); null with --no-schema or
  /// when none fits.
  const express::Schema *find(const std::vector<std::string> &names, const express::Model *&model) const;

  /// Makes `source` Part 21 text: Part 28 XML is translated through its
  /// schema and `source` becomes the translation (which reports at the XML's
  /// lines and columns); Part 21 is left as it is. Returns false after
  /// reporting when XML cannot be translated.
  bool readAsPart21(std::unique_ptr<SourceFile> &source, DiagnosticEngine &diags) const;

  /// Writes `file` as Part 28 through its schema. The schema check itself is
  /// `stepnc check`'s business: binding here only names each instance's
  /// entity, and only what the mapping cannot express is an error. Returns
  /// false after reporting to `diags`, or with `usageError` set when the
  /// file's schema is not known (no diagnostic counted).
  bool writeAsPart28(const p21::Part21File &file, OutputFile &out, DiagnosticEngine &diags,
                     std::string &usageError) const;

private:
  const SchemaOptions &opts_;
  express::Model loaded_;
};

} // namespace stepnc::driver
