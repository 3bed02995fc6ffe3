// A machine shipped in machines/, for the tests that plan or play motion.
#pragma once

#include "runtime/Machine.h"

#include <catch2/catch.hpp>

#include <memory>
#include <optional>
#include <string>

namespace stepnc::test {

/// A shipped machine by name (hsc-3axis, conventional-3axis); fails the
/// test when it does not load.
inline runtime::Machine shippedMachine(const std::string &name) {
  std::unique_ptr<SourceFile> file;
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  const std::optional<runtime::Machine> machine = runtime::loadMachine(name, file, diags);
  REQUIRE(machine);
  return *machine;
}

} // namespace stepnc::test
