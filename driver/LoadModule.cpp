#include "driver/LoadModule.h"

#include "frontend/lowering/Lowering.h"
#include "ir/Parser.h"

namespace stepnc::driver {

binding::BindOptions bindOptions(const DiagnosticEngine &diags) {
  binding::BindOptions options;
  options.strict = diags.strict();
  options.lenient = !diags.strict();
  return options;
}

std::unique_ptr<ir::Module> loadModule(std::unique_ptr<SourceFile> &source, const SchemaSelection &schemas,
                                       DiagnosticEngine &diags, std::string &usageError,
                                       std::unique_ptr<p21::Part21File> *keep,
                                       const lowering::LowerOptions &lower) {
  if (!schemas.readAsPart21(source, diags))
    return nullptr;
  std::string_view text = source->text();
  while (!text.empty() && (text[0] == ' ' || text[0] == '\n' || text[0] == '\r' || text[0] == '\t'))
    text.remove_prefix(1);
  if (text.starts_with(";") || text.starts_with("project")) {
    auto module = ir::parseModule(*source, diags);
    if (!module || diags.hasErrors())
      return nullptr;
    return module;
  }
  auto file = p21::readPart21(*source, diags);
  if (diags.hasErrors())
    return nullptr;
  const express::Model *model = nullptr;
  const express::Schema *schema = schemas.selectToCompile(*file, diags, model);
  if (!schema) {
    // A schema stepnc does not compile is the file's error, reported at its
    // FILE_SCHEMA; --no-schema is the caller's.
    if (!diags.hasErrors())
      usageError = "cannot compile " + std::string(source->name()) +
                   " with --no-schema: lowering reads the file through its schema";
    return nullptr;
  }
  auto bound = binding::bind(*file, *model, *schema, diags, bindOptions(diags));
  if (diags.hasErrors())
    return nullptr;
  auto module = lowering::lowerToFeatureIR(*bound, diags, lower);
  if (!module || diags.hasErrors())
    return nullptr;
  if (keep)
    *keep = std::move(file);
  return module;
}

} // namespace stepnc::driver
