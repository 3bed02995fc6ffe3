#include "backends/Backend.h"

namespace stepnc::backends {

const std::vector<TargetInfo> &registeredTargets() {
  static const std::vector<TargetInfo> targets = {
#define STEPNC_TARGET(NAME, DESCRIPTION, FACTORY) {NAME, DESCRIPTION, &FACTORY},
#include "backends/Targets.def"
#undef STEPNC_TARGET
  };
  return targets;
}

std::unique_ptr<Backend> createBackend(std::string_view name) {
  for (const TargetInfo &t : registeredTargets())
    if (t.name == name)
      return t.create();
  return nullptr;
}

} // namespace stepnc::backends
