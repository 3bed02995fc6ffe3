// `stepnc schema FILE.exp...`: reads EXPRESS schemas, resolves them together
// and prints a summary, or an entity's attribute list in Part 21 order.
#include "frontend/express/Builtin.h"
#include "frontend/express/SchemaReader.h"
#include "tools/stepnc/Driver.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace stepnc::tool {

namespace {

struct SchemaOptions {
  std::vector<std::string> files;
  std::vector<std::string> entities;
  bool builtin = false;
  DiagnosticOptions diag;
};

void printEntity(const express::Model &model, express::EntityId id) {
  const express::Entity &e = model.entity(id);
  std::cout << "entity " << e.name << " (schema " << e.schema << ")";
  if (e.abstract)
    std::cout << ", abstract";
  if (!e.supertypeNames.empty()) {
    std::cout << ", subtype of ";
    for (size_t i = 0; i < e.supertypeNames.size(); ++i)
      std::cout << (i ? ", " : "") << e.supertypeNames[i];
  }
  std::cout << '\n';
  size_t width = 0;
  for (const express::Slot &s : e.slots)
    width = std::max(width, s.name.size());
  for (size_t i = 0; i < e.slots.size(); ++i) {
    const express::Slot &s = e.slots[i];
    std::string idx = std::to_string(i + 1);
    std::cout << std::string(4 - std::min<size_t>(4, idx.size()), ' ') << idx << "  " << s.name
              << std::string(width - s.name.size(), ' ') << " : " << (s.optional ? "OPTIONAL " : "")
              << model.typeText(s.type);
    if (s.derived)
      std::cout << "  (derived: written *)";
    if (s.owner != id)
      std::cout << "  [from " << model.entity(s.owner).name << "]";
    std::cout << '\n';
  }
  if (!e.subtypes.empty()) {
    std::cout << "  subtypes:";
    for (express::EntityId s : e.subtypes)
      std::cout << ' ' << model.entity(s).name;
    std::cout << '\n';
  }
}

void printSummary(const express::Model &model) {
  for (const express::Schema &s : model.schemas())
    std::cout << "schema " << s.name << ": " << s.entities.size() << " entities, " << s.types.size()
              << " types, " << s.functions.size() << " functions, " << s.procedures.size()
              << " procedures, " << s.rules.size() << " rules, " << s.interfaces.size()
              << " interface clauses\n";
}

int printEntities(const express::Model &model, const std::vector<std::string> &names) {
  for (const std::string &name : names) {
    bool found = false;
    for (const express::Schema &s : model.schemas()) {
      express::EntityId id = model.findEntity(s, express::lower(name));
      if (id != express::kNone) {
        printEntity(model, id);
        found = true;
        break;
      }
    }
    if (!found) {
      printToolError("no entity '" + name + "' in the loaded schemas");
      return kExitUsage;
    }
  }
  return kExitOk;
}

int runSchema(const SchemaOptions &opts) {
  if (opts.builtin != opts.files.empty()) {
    printToolError("give EXPRESS files or --builtin, not both");
    return kExitUsage;
  }
  if (opts.builtin) {
    const express::Model &model = express::builtinModel();
    printSummary(model);
    int status = printEntities(model, opts.entities);
    std::cout.flush();
    return status;
  }
  DiagnosticSession session(opts.diag);
  DiagnosticEngine &diags = session.engine();
  express::Model model;
  bool io = false;
  for (const std::string &path : opts.files) {
    std::string error;
    auto file = SourceFile::open(path, error);
    if (!file) {
      printToolError(error);
      io = true;
      continue;
    }
    express::readExpress(std::move(file), model, diags);
  }
  if (io)
    return kExitUsage;
  if (!diags.hasErrors())
    model.resolve(diags);
  printSummary(model);
  if (int status = printEntities(model, opts.entities))
    return status;
  std::cout.flush();
  return diags.hasErrors() ? kExitDiagnostics : kExitOk;
}

} // namespace

void registerSchema(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<SchemaOptions>();
  CLI::App *cmd = app.add_subcommand(
      "schema", "Read EXPRESS (ISO 10303-11) schemas, resolve them together (USE/REFERENCE FROM\n"
                "across the files given) and print a summary; --entity prints an entity's\n"
                "attributes in Part 21 order. --builtin shows the built-in ISO 14649 ARM.");
  cmd->add_option("files", opts->files, "EXPRESS files (.exp)");
  cmd->add_flag("--builtin", opts->builtin, "Use the built-in ISO 14649 ARM schema instead of files");
  cmd->add_option("--entity", opts->entities, "Print this entity's Part 21 attribute list (repeatable)");
  addDiagnosticOptions(*cmd, opts->diag);
  cmd->callback([opts, setResult] { setResult(runSchema(*opts)); });
}

} // namespace stepnc::tool
