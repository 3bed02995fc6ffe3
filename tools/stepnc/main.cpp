// The stepnc command: a thin layer of subcommands over the stepnc libraries.
#include "tools/stepnc/CommandLine.h"
#include "tools/stepnc/Commands.h"

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

int main(int argc, char **argv) {
  using namespace stepnc::tool;
  CLI::App app("stepnc: a compiler from STEP-NC (ISO 14649 / ISO 10303-238) to machine tools.\n"
               "Run 'stepnc <command> --help' for a command's options.",
               "stepnc");
  app.require_subcommand(1);
  app.set_version_flag("--version", "stepnc 0.1.0");
  app.footer("Exit status: 0 success, 1 the input has errors, 2 usage or I/O error, 3 an internal error.");
  int result = kExitOk;
  auto setResult = [&result](int r) { result = r; };
  registerCompile(app, setResult);
  registerCheck(app, setResult);
  registerConvert(app, setResult);
  registerSchema(app, setResult);
  registerOpt(app, setResult);
  registerSim(app, setResult);
  // LLVM spells the pipeline option -passes=...; accept that spelling too.
  std::vector<std::string> rewritten;
  for (int i = 0; i < argc; ++i)
    rewritten.emplace_back(std::string_view(argv[i]).starts_with("-passes=") ? "-" + std::string(argv[i]) : argv[i]);
  std::vector<char *> args;
  for (std::string &a : rewritten)
    args.push_back(a.data());
  argv = args.data();
  // A first word that is neither an option nor a command is a typo.
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App *sub : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + sub->get_name();
      known |= sub->get_name() == argv[1];
    }
    if (!known) {
      printToolError(std::string("unknown command '") + argv[1] + "' (commands: " + names + ")");
      return kExitUsage;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp &e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp &e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion &e) {
    return app.exit(e);
  } catch (const CLI::ParseError &e) {
    app.exit(e);
    return kExitUsage;
  } catch (const std::bad_alloc &) {
    // What a pass could not bound ahead (they refuse, located, what they can).
    printToolError("out of memory: the input asks for more work than this machine holds; nothing written");
    return kExitDiagnostics;
  } catch (const std::exception &e) {
    // A defect of stepnc, not of the input: said, never an abort.
    printToolError(std::string("internal error: ") + e.what() +
                   "; nothing written (please report it with the input)");
    return kExitInternal;
  }
  return result;
}
