// The native target: the planned motion (the `motion` nodes plan-motion
// wrote) in the native motion format of runtime/NativeFormat.h, for open
// controllers that play time-parameterised segments themselves.
#include "backends/Backend.h"
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
    auto trajectory = ir::readMotion(module, diags);
    if (!trajectory)
      return std::nullopt;
    return runtime::writeNative(*trajectory, options.source);
  }
};

} // namespace

std::unique_ptr<Backend> createNativeBackend() { return std::make_unique<NativeBackend>(); }

} // namespace stepnc::backends
