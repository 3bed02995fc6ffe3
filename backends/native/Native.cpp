// The native target: the planned motion (the `motion` nodes plan-motion
// wrote) in the native motion format of runtime/NativeFormat.h, for open
// controllers that play time-parameterised segments themselves.
#include "backends/Backend.h"
#include "ir/Program.h"
#include "ir/motion/MotionIR.h"
#include "runtime/NativeFormat.h"

namespace stepnc::backends {

namespace {

class NativeBackend final : public Backend {
public:
  NativeBackend() : Backend(makeDescriptor()) {}

  static TargetDescriptor makeDescriptor() {
    TargetDescriptor d;
    d.name = "native";
    d.description = "stepnc native motion segments (docs/native-format.md); needs --machine";
    d.extension = ".motion";
    return d;
  }

  std::optional<std::string> emit(const ir::Module &module, const EmitOptions &options,
                                  DiagnosticEngine &diags) override {
    // A re-clamp is an operator's work between two motions; the native
    // format carries motion only.
    for (const ir::Node *e : ir::programOrder(module))
      if (e->kind == ir::Kind::ProgramStop && e->flag("reclamp").value_or(false)) {
        diags.error(e->origin.loc, "the program re-clamps the workpiece here, to reach features on another face "
                                   "(docs/setups.md); the native motion format has no stop for the operator: "
                                   "write a G-code target")
            .entity(e->origin.entityId);
        return std::nullopt;
      }
    auto trajectory = ir::readMotion(module, diags);
    if (!trajectory)
      return std::nullopt;
    return runtime::writeNative(*trajectory, options.source);
  }
};

} // namespace

std::unique_ptr<Backend> createNativeBackend() { return std::make_unique<NativeBackend>(); }

} // namespace stepnc::backends
