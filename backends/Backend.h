// A controller target: a descriptor of what the controller can do and an
// emitter that writes a program for it from the toolpath IR. Targets are
// listed once, in Targets.def; `stepnc compile --target=NAME` looks them up
// here and nothing else in stepnc names a target.
#pragma once

#include "backends/Target.h"
#include "runtime/Machine.h"
#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::backends {

class ToolTable;

struct EmitOptions {
  std::string source;           ///< the input file, as named on the command line (header)
  std::string programName;      ///< program name, from the output file (or the input) name
  std::string optionsText;      ///< the options that shaped the program (header)
  std::optional<double> tolerance;  ///< --tolerance, mm
  const ToolTable *toolTable = nullptr;
  /// The deposition head's codes of --machine, when it has one.
  const runtime::DepositionCodes *deposition = nullptr;
  /// --machine, when one is given: a table-table machine turns its rotary
  /// axes to each face of a program that re-clamps (rotaryIndexing).
  const runtime::Machine *machine = nullptr;
  /// --work-offset: where the workpiece's origin is on that machine, in
  /// machine coordinates with every axis at 0 (needed to turn it).
  std::optional<ir::Vec3> workOffset;
};

class Backend {
public:
  virtual ~Backend() = default;
  /// The target's capabilities; the driver applies --target-opt to them
  /// before emit().
  TargetDescriptor &descriptor() { return descriptor_; }
  const TargetDescriptor &descriptor() const { return descriptor_; }
  /// The program for `module` (toolpath IR: every executable has `moves`).
  /// Returns nullopt after reporting errors.
  virtual std::optional<std::string> emit(const ir::Module &module, const EmitOptions &options,
                                          DiagnosticEngine &diags) = 0;

protected:
  explicit Backend(TargetDescriptor d) : descriptor_(std::move(d)) {}

private:
  TargetDescriptor descriptor_;
};

struct TargetInfo {
  std::string_view name;
  std::string_view description;
  std::unique_ptr<Backend> (*create)();
};

/// Every target, in the order of Targets.def.
const std::vector<TargetInfo> &registeredTargets();
/// The target called `name`, or null.
std::unique_ptr<Backend> createBackend(std::string_view name);

// One factory per target (declared from Targets.def).
#define STEPNC_TARGET(NAME, DESCRIPTION, FACTORY) std::unique_ptr<Backend> FACTORY();
#include "backends/Targets.def"
#undef STEPNC_TARGET

} // namespace stepnc::backends
