// `stepnc schema FILE.exp...`: reads EXPRESS schemas, resolves them together
// and prints a summary, or an entity's attribute list in Part 21 order; with
// --xsd, writes the Part 28 XSD of one schema and the common XSD instead.
#include "frontend/express/Builtin.h"
#include "frontend/express/SchemaReader.h"
#include "frontend/part28/Xsd.h"
#include "support/OutputFile.h"
#include "tools/stepnc/CommandLine.h"
#include "tools/stepnc/Commands.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <set>

namespace stepnc::tool {

namespace {

struct SchemaOptions {
  std::vector<std::string> files;
  std::vector<std::string> entities;
  bool builtin = false;
  bool xsd = false;
  std::string outputDir;   ///< -o, with --xsd
  std::string schemaName;  ///< --schema-name, with --xsd
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

std::string schemaNames(const std::vector<const express::Schema *> &schemas) {
  std::string out;
  for (const express::Schema *s : schemas)
    out += (out.empty() ? "" : ", ") + s->name;
  return out;
}

/// The loaded schemas no other loaded schema interfaces (USE or REFERENCE FROM).
std::vector<const express::Schema *> topSchemas(const express::Model &model) {
  std::set<std::string> interfaced;
  for (const express::Schema &s : model.schemas())
    for (const express::Interface &i : s.interfaces)
      if (express::lower(i.schema) != s.name)
        interfaced.insert(express::lower(i.schema));
  std::vector<const express::Schema *> tops;
  for (const express::Schema &s : model.schemas())
    if (!interfaced.count(s.name))
      tops.push_back(&s);
  return tops;
}

/// The schema to write the XSD of: --schema-name; else for --builtin the ARM
/// (the schema ISO 14649 files name); else the one top schema.
const express::Schema *xsdSchema(const express::Model &model, const SchemaOptions &opts) {
  std::vector<const express::Schema *> all;
  for (const express::Schema &s : model.schemas())
    all.push_back(&s);
  if (!opts.schemaName.empty()) {
    const express::Schema *s = model.findSchema(opts.schemaName);
    if (!s)
      printToolError("no schema '" + opts.schemaName + "' among the loaded schemas (" + schemaNames(all) + ")");
    return s;
  }
  if (opts.builtin)
    return express::builtinSchemaFor("ISO14649_ARM");
  std::vector<const express::Schema *> tops = topSchemas(model);
  if (tops.size() == 1)
    return tops.front();
  printToolError("the loaded schemas (" + schemaNames(all) + ") have " + std::to_string(tops.size()) +
                 " schemas that no other uses; choose one with --schema-name");
  return nullptr;
}

/// Writes DIR/<schema>.xsd and DIR/iso_10303_28_common.xsd; neither when
/// either cannot be created.
int writeXsd(const express::Model &model, const SchemaOptions &opts) {
  const express::Schema *schema = xsdSchema(model, opts);
  if (!schema)
    return kExitUsage;
  std::string text, error;
  if (!p28::schemaXsd(model, *schema, text, error)) {
    printToolError(error);
    return kExitDiagnostics;
  }
  const std::filesystem::path dir(opts.outputDir);
  OutputFile schemaFile, commonFile;
  if (!schemaFile.open((dir / (schema->name + ".xsd")).string(), error) ||
      !commonFile.open((dir / p28::kCommonXsdFileName).string(), error)) {
    printToolError(error + "; no XSD written");
    return kExitUsage;
  }
  schemaFile.write(text);
  commonFile.write(p28::commonXsd());
  if (!schemaFile.commit(error) || !commonFile.commit(error)) {
    printToolError(error);
    return kExitUsage;
  }
  return kExitOk;
}

int checkUsage(const SchemaOptions &opts) {
  if (opts.builtin != opts.files.empty()) {
    printToolError("give EXPRESS files or --builtin, not both");
    return kExitUsage;
  }
  if (!opts.xsd && (!opts.outputDir.empty() || !opts.schemaName.empty())) {
    printToolError("-o and --schema-name go with --xsd");
    return kExitUsage;
  }
  if (opts.xsd && opts.outputDir.empty()) {
    printToolError("--xsd needs -o DIR, the folder to write the XSD files into");
    return kExitUsage;
  }
  if (opts.xsd && !opts.entities.empty()) {
    printToolError("--entity does not go with --xsd");
    return kExitUsage;
  }
  return kExitOk;
}

/// What the command does with a resolved model: the XSD, or the summary and
/// the --entity lists. `status` is the loading's exit status.
int report(const express::Model &model, const SchemaOptions &opts, int status) {
  if (opts.xsd)
    return writeXsd(model, opts);
  printSummary(model);
  if (int s = printEntities(model, opts.entities))
    return s;
  std::cout.flush();
  return status;
}

int runSchema(const SchemaOptions &opts) {
  if (int status = checkUsage(opts))
    return status;
  if (opts.builtin)
    return report(express::builtinModel(), opts, kExitOk);
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
  if (opts.xsd && diags.hasErrors()) {
    printToolError("the EXPRESS schemas have errors; no XSD written");
    return kExitDiagnostics;
  }
  return report(model, opts, diags.hasErrors() ? kExitDiagnostics : kExitOk);
}

} // namespace

void registerSchema(CLI::App &app, std::function<void(int)> setResult) {
  auto opts = std::make_shared<SchemaOptions>();
  CLI::App *cmd = app.add_subcommand(
      "schema", "Read EXPRESS (ISO 10303-11) schemas, resolve them together (USE/REFERENCE FROM\n"
                "across the files given) and print a summary; --entity prints an entity's\n"
                "attributes in Part 21 order. --builtin shows the built-in ISO 14649 ARM.\n"
                "--xsd -o DIR writes the Part 28 XML Schema of a schema instead.");
  cmd->add_option("files", opts->files, "EXPRESS files (.exp)");
  cmd->add_flag("--builtin", opts->builtin, "Use the built-in ISO 14649 ARM schema instead of files");
  cmd->add_option("--entity", opts->entities, "Print this entity's Part 21 attribute list (repeatable)");
  cmd->add_flag("--xsd", opts->xsd,
                "Write the Part 28 XSD of a schema (<schema>.xsd) and iso_10303_28_common.xsd into -o DIR");
  cmd->add_option("-o,--output", opts->outputDir, "With --xsd: the folder to write into");
  cmd->add_option("--schema-name", opts->schemaName,
                  "With --xsd: the schema (default: iso14649_arm for --builtin, else the one no other uses)");
  addDiagnosticOptions(*cmd, opts->diag);
  cmd->callback([opts, setResult] { setResult(runSchema(*opts)); });
}

} // namespace stepnc::tool
