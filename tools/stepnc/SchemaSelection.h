// Choosing the EXPRESS schema a Part 21 file is checked against: the files
// given with --schema, else the built-in schema its FILE_SCHEMA names.
#pragma once

#include "frontend/express/Schema.h"
#include "frontend/part21/Part21File.h"

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

private:
  const SchemaOptions &opts_;
  express::Model loaded_;
};

} // namespace stepnc::tool
