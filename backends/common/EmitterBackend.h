// The backend every target is: the program model built from the toolpath IR,
// then written by the target's emitter (a class constructed from the
// descriptor, options and diagnostics, with `run(const Program &)`).
#pragma once

#include "backends/Backend.h"
#include "backends/common/Program.h"

namespace stepnc::backends {

template <class Emitter> class EmitterBackend final : public Backend {
public:
  explicit EmitterBackend(TargetDescriptor d) : Backend(std::move(d)) {}

  std::optional<std::string> emit(const ir::Module &module, const EmitOptions &options,
                                  DiagnosticEngine &diags) override {
    std::optional<Program> program = buildProgram(module, options.toolTable, diags);
    if (!program)
      return std::nullopt;
    return Emitter(descriptor(), options, diags).run(*program);
  }
};

} // namespace stepnc::backends
