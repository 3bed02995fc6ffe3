// stepnc-schemac: the build-time schema compiler. Reads EXPRESS files,
// resolves them and writes the model in stepnc's compact text form, which the
// build then embeds into the binary (frontend/express/Builtin.cpp). A schema
// that does not resolve cleanly fails the build.
//
//   stepnc-schemac OUT FILE.exp...
#include "frontend/express/SchemaIO.h"
#include "frontend/express/SchemaReader.h"
#include "support/OutputFile.h"

#include <iostream>

int main(int argc, char **argv) {
  using namespace stepnc;
  if (argc < 3) {
    std::cerr << "usage: stepnc-schemac OUT FILE.exp...\n";
    return 2;
  }
  TextDiagnosticPrinter printer(std::cerr);
  DiagnosticEngine diags(printer);
  express::Model model;
  for (int i = 2; i < argc; ++i) {
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
  OutputFile out;
  std::string error;
  if (!out.open(argv[1], error)) {
    std::cerr << "stepnc-schemac: error: " << error << '\n';
    return 2;
  }
  out.write(express::serializeModel(model));
  if (!out.commit(error)) {
    std::cerr << "stepnc-schemac: error: " << error << '\n';
    return 2;
  }
  return 0;
}
