#include "driver/SchemaSelection.h"

#include "frontend/express/Builtin.h"
#include "frontend/express/SchemaReader.h"
#include "frontend/binding/Binder.h"
#include "frontend/part28/Reader.h"
#include "frontend/part28/Writer.h"

namespace stepnc::driver {

bool SchemaSelection::load(DiagnosticEngine &diags, std::string &ioError) {
  if (opts_.files.empty())
    return true;
  const unsigned before = diags.errorCount();
  for (const std::string &path : opts_.files) {
    auto file = SourceFile::open(path, ioError);
    if (!file)
      return false;
    express::readExpress(std::move(file), loaded_, diags);
  }
  if (diags.errorCount() == before)
    loaded_.resolve(diags);
  return diags.errorCount() == before;
}

const express::Schema *SchemaSelection::select(const p21::Part21File &file, DiagnosticEngine &diags,
                                               const express::Model *&model) const {
  if (opts_.none)
    return nullptr;
  const std::vector<std::string> names = file.schemaNames();
  const p21::HeaderEntity *header = file.headerEntity("FILE_SCHEMA");
  const SourceLoc at = file.loc(header ? header->begin : 0);
  std::string listed;
  for (const std::string &n : names)
    listed += (listed.empty() ? "" : ", ") + n;
  if (!opts_.files.empty()) {
    model = &loaded_;
    for (const std::string &n : names)
      if (const express::Schema *s = loaded_.findSchema(n))
        return s;
    const express::Schema *first = &loaded_.schemas().front();
    diags.warning(at, "FILE_SCHEMA names " + (listed.empty() ? std::string("no schema") : listed) +
                          "; checking against schema '" + first->name + "' given with --schema");
    return first;
  }
  if (const express::BuiltinSchema b = express::findBuiltinSchema(names)) {
    model = b.model;
    return b.schema;
  }
  diags.warning(at, names.empty() ? "FILE_SCHEMA names no schema; checked for Part 21 syntax only"
                                  : "schema " + listed +
                                        " is not built in; checked for Part 21 syntax only (give its "
                                        "EXPRESS file with --schema FILE.exp)");
  return nullptr;
}

const express::Schema *SchemaSelection::selectToCompile(const p21::Part21File &file, DiagnosticEngine &diags,
                                                        const express::Model *&model) const {
  if (opts_.none || !opts_.files.empty())
    return select(file, diags, model);
  const std::vector<std::string> names = file.schemaNames();
  if (const express::BuiltinSchema b = express::findBuiltinSchema(names)) {
    model = b.model;
    return b.schema;
  }
  // Not a STEP-NC file as far as stepnc knows: say what the file declares
  // and what would be compiled, at the declaration.
  const p21::HeaderEntity *header = file.headerEntity("FILE_SCHEMA");
  std::string listed, known;
  for (const std::string &n : names)
    listed += (listed.empty() ? "" : ", ") + n;
  for (std::string_view n : express::builtinSchemaNames())
    known += (known.empty() ? "" : ", ") + std::string(n);
  std::string declared = names.empty() ? "FILE_SCHEMA names no schema"
                                       : "FILE_SCHEMA names " + listed +
                                             (names.size() == 1 ? ", which is not" : ", none of which is") +
                                             " a schema stepnc compiles";
  diags.error(file.loc(header ? header->begin : 0),
              declared + ": stepnc compiles ISO 14649 / AP238 STEP-NC files, whose FILE_SCHEMA names " + known +
                  "; 'stepnc check --schema FILE.exp' checks a file against another EXPRESS schema");
  return nullptr;
}

const express::Schema *SchemaSelection::find(const std::vector<std::string> &names,
                                             const express::Model *&model) const {
  if (opts_.none)
    return nullptr;
  if (!opts_.files.empty()) {
    model = &loaded_;
    for (const std::string &n : names)
      if (const express::Schema *s = loaded_.findSchema(n))
        return s;
    return loaded_.schemas().empty() ? nullptr : &loaded_.schemas().front();
  }
  const express::BuiltinSchema b =
      express::findBuiltinSchema(names.empty() ? std::vector<std::string>{"ISO14649_ARM"} : names);
  model = b.model;
  return b.schema;
}

bool SchemaSelection::readAsPart21(std::unique_ptr<SourceFile> &source, DiagnosticEngine &diags) const {
  if (!p28::isXml(source->text()))
    return true;
  auto choose = [this](const std::vector<std::string> &names, const express::Model *&model) {
    return find(names, model);
  };
  auto translation = p28::translatePart28(source, choose, diags);
  if (!translation)
    return false;
  source = std::move(translation);
  return true;
}

bool SchemaSelection::writeAsPart28(const p21::Part21File &file, OutputFile &out, DiagnosticEngine &diags,
                                    std::string &usageError) const {
  const express::Model *model = nullptr;
  const express::Schema *schema = find(file.schemaNames(), model);
  if (!schema) {
    std::string listed;
    for (const std::string &n : file.schemaNames())
      listed += (listed.empty() ? "" : ", ") + n;
    usageError = "writing Part 28 needs the file's schema, and " +
                 (listed.empty() ? std::string("FILE_SCHEMA names none") : "schema " + listed + " is not built in") +
                 ": give its EXPRESS file with --schema FILE.exp";
    return false;
  }
  DiagnosticCollector ignored;
  DiagnosticEngine bindDiags(ignored);
  binding::BindOptions lenient;
  lenient.lenient = true;
  auto bound = binding::bind(file, *model, *schema, bindDiags, lenient);
  return p28::writePart28(*bound, [&out](std::string_view chunk) { out.write(chunk); }, diags);
}

} // namespace stepnc::driver
