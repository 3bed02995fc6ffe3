// A multi-process workplan on several machines (docs/additive.md,
// "Multi-process workplans"): each workingstep's process (turning,
// deposition, milling and drilling) is done by a machine that does it, chosen
// per setup (the first machine given that does every process of the setup's
// steps) or, when no machine does them all, per workingstep; the program is
// split into phases, runs of consecutive executables on one machine, each
// written as a program of its own.
#pragma once

#include "ir/Node.h"
#include "runtime/Machine.h"
#include "support/Diagnostics.h"

#include <string>
#include <vector>

namespace stepnc::driver {

/// A machine given on the command line: as named, and as read.
struct NamedMachine {
  std::string name;
  runtime::Machine machine;
};

/// The process of an executable: "turning" (a turning step, or a hole drilled
/// on the turning axis), "deposition", "milling" (milling and hole making), or
/// "" (rapid movements, stops, messages: they go with the step before).
std::string processOf(const ir::Node &executable);

struct Phase {
  size_t machine = 0;  ///< index into the machines given
  std::vector<const ir::Node *> executables;  ///< in program order
};

/// The phases of `module`'s program on `machines` (in the order given);
/// nullopt after an error at a step no machine does.
std::optional<std::vector<Phase>> splitIntoPhases(const ir::Module &module, const std::vector<NamedMachine> &machines,
                                                  DiagnosticEngine &diags);

/// `module` with only the executables of `phase` (workplans left empty dropped).
ir::Module phaseModule(const ir::Module &module, const Phase &phase);

} // namespace stepnc::driver
