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

namespace CLI {
class App;
}

namespace stepnc::tool {

struct SchemaOptions {
  std::vector<std::string> files;  ///< --schema FILE.exp (repeatable)
  bool none = false;               ///< --no-schema
};

void addSchemaOptions(CLI::App &cmd, SchemaOptions &opts);

class SchemaSelection {
public:
  explicit SchemaSelection(const SchemaOptions &opts) : opts_(opts) {}

  /// Reads and resolves the --schema files, if any. Returns false (after
  /// reporting) when one cannot be read or has errors.
  bool load(DiagnosticEngine &diags, bool &ioError);

  /// The schema to check `file` against, or null with a warning saying why
  /// (unknown schema, --no-schema is silent). `model` receives its model.
  const express::Schema *select(const p21::Part21File &file, DiagnosticEngine &diags,
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
  /// false after reporting (a schema that is not known is a usage error,
  /// printed, with no diagnostic counted).
  bool writeAsPart28(const p21::Part21File &file, OutputFile &out, DiagnosticEngine &diags) const;

private:
  const SchemaOptions &opts_;
  express::Model loaded_;
};

} // namespace stepnc::tool
