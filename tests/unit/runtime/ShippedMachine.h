// A machine shipped in machines/, for the tests that plan or play motion;
// a machine file's text read as readMachine reads it, for the tests of its
// checks.
#pragma once

#include "runtime/Machine.h"
#include "tests/unit/TestSupport.h"

#include <catch2/catch.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

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

/// A machine file's text as readMachine reads it, with its diagnostics.
struct ReadMachine {
  std::unique_ptr<SourceFile> file;
  std::optional<runtime::Machine> machine;
  std::vector<std::string> errors;  ///< "line:col: message"
};

inline ReadMachine readMachineText(const std::string &text) {
  ReadMachine r;
  r.file = SourceFile::fromString("m.toml", text);
  DiagnosticCollector collector;
  DiagnosticEngine diags(collector);
  r.machine = runtime::readMachine(*r.file, diags);
  r.errors = locatedMessages(collector, *r.file);
  return r;
}

/// `text` with the first `from` replaced by `to` (which must stand in it).
inline std::string edited(std::string text, const std::string &from, const std::string &to) {
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  text.replace(at, from.size(), to);
  return text;
}

} // namespace stepnc::test
