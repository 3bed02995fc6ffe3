// Helpers shared by the unit tests of the G-code readers
// (backends/common/ReadBack.h): a target's descriptor, and a reading's
// problems for failure messages and checks.
#pragma once

#include "backends/Backend.h"
#include "backends/common/ReadBack.h"

#include <catch2/catch.hpp>

#include <memory>
#include <string>

namespace stepnc::test {

/// The descriptor of target `name`, as compile has it without options.
inline backends::TargetDescriptor descriptorOf(const char *name) {
  std::unique_ptr<backends::Backend> b = backends::createBackend(name);
  REQUIRE(b);
  return b->descriptor();
}

/// The problems as "line: why", for failure messages.
inline std::string problems(const backends::ProgramReading &r) {
  std::string out;
  for (const auto &[line, why] : r.problems)
    out += std::to_string(line) + ": " + why + "\n";
  return out;
}

/// True when a problem on `line` says `what`.
inline bool hasProblem(const backends::ProgramReading &r, size_t line, const std::string &what) {
  for (const auto &[l, why] : r.problems)
    if (l == line && why.find(what) != std::string::npos)
      return true;
  return false;
}

} // namespace stepnc::test
