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
                                       std::unique_ptr<p21::Part21File> *keep) {
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
  const express::Schema *schema = schemas.select(*file, diags, model);
  if (!schema) {
    usageError = "cannot compile " + std::string(source->name()) +
                 " without a schema: give its EXPRESS file with --schema FILE.exp";
    return nullptr;
  }
  auto bound = binding::bind(*file, *model, *schema, diags, bindOptions(diags));
  if (diags.hasErrors())
    return nullptr;
  auto module = lowering::lowerToFeatureIR(*bound, diags);
  if (!module || diags.hasErrors())
    return nullptr;
  if (keep)
    *keep = std::move(file);
  return module;
}

} // namespace stepnc::driver
