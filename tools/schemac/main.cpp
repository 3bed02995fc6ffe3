// stepnc-schemac: the build-time schema compiler. Reads EXPRESS files,
// resolves them and writes the model in stepnc's compact text form, which the
// build then embeds into the binary (frontend/express/Builtin.cpp). A schema
// that does not resolve cleanly fails the build.
//
//   stepnc-schemac OUT FILE.exp...
//   stepnc-schemac --express BANNER OUT FILE.exp
//
// The second form writes the declarations of a long-form schema back as
// EXPRESS, facts only (frontend/express/ExpressWriter.h), after the comment
// in the file BANNER: how the project's own text of a published schema is
// made (docs/ap238.md). It runs by hand, never in the build.
#include "frontend/express/ExpressWriter.h"
#include "frontend/express/SchemaIO.h"
#include "frontend/express/SchemaReader.h"
#include "support/OutputFile.h"

#include <iostream>
#include <string_view>

namespace {

int usage() {
  std::cerr << "usage: stepnc-schemac OUT FILE.exp...\n"
               "       stepnc-schemac --express BANNER OUT FILE.exp\n";
  return 2;
}

} // namespace

int main(int argc, char **argv) {
  using namespace stepnc;
  const bool express = argc > 1 && std::string_view(argv[1]) == "--express";
  const int first = express ? 4 : 2;
  if (argc < first + 1 || (express && argc != first + 1))
    return usage();
  TextDiagnosticPrinter printer(std::cerr);
  DiagnosticEngine diags(printer);
  express::Model model;
  for (int i = first; i < argc; ++i) {
    std::string error;
    auto file = SourceFile::open(argv[i], error);
    if (!file) {
      std::cerr << "stepnc-schemac: error: " << error << '\n';
      return 2;
    }
    express::readExpress(std::move(file), model, diags);
  }
  if (diags.hasErrors() || !model.resolve(diags) || diags.hasErrors())
    return 1;
  std::string text;
  if (express) {
    std::string error;
    auto banner = SourceFile::open(argv[2], error);
    if (!banner || model.schemas().size() != 1) {
      std::cerr << "stepnc-schemac: error: "
                << (banner ? std::string("--express takes one long-form schema") : error) << '\n';
      return 2;
    }
    text = express::writeExpressFacts(model, model.schemas().front(), banner->text());
  } else {
    text = express::serializeModel(model);
  }
  OutputFile out;
  std::string error;
  if (!out.open(argv[first - 1], error)) {
    std::cerr << "stepnc-schemac: error: " << error << '\n';
    return 2;
  }
  out.write(text);
  if (!out.commit(error)) {
    std::cerr << "stepnc-schemac: error: " << error << '\n';
    return 2;
  }
  return 0;
}
