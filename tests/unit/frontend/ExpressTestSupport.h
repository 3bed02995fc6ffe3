// Reading EXPRESS text in unit tests.
#pragma once

#include "frontend/express/SchemaReader.h"

#include <catch2/catch.hpp>

#include <memory>
#include <string_view>

namespace stepnc::test {

/// A model read from EXPRESS text and resolved, with its diagnostics.
struct LoadedExpress {
  express::Model model;
  DiagnosticCollector diags;
  bool ok = false;  ///< read and resolved without errors
};

inline std::unique_ptr<LoadedExpress> loadExpress(std::unique_ptr<SourceFile> file) {
  auto l = std::make_unique<LoadedExpress>();
  DiagnosticEngine engine(l->diags);
  l->ok = file && express::readExpress(std::move(file), l->model, engine);
  if (l->ok)
    l->ok = l->model.resolve(engine);
  return l;
}

inline std::unique_ptr<LoadedExpress> loadExpress(std::string_view text) {
  return loadExpress(SourceFile::fromString("t.exp", text));
}

/// An EXPRESS file (a corpus schema) read and resolved; `ok` false when it
/// cannot be opened or has errors.
inline std::unique_ptr<LoadedExpress> loadExpressFile(const std::string &path) {
  std::string error;
  return loadExpress(SourceFile::open(path, error));
}

/// Checks that entity `oe` of `ours` has the Part 21 slots of `re` of `ref`:
/// name, optional, derived and type, in order (a built-in schema against the
/// published text it was written from).
inline void checkSameSlots(const express::Model &ours, const express::Entity &oe, const express::Model &ref,
                           const express::Entity &re) {
  CHECK(oe.abstract == re.abstract);
  REQUIRE(oe.slots.size() == re.slots.size());
  for (size_t i = 0; i < re.slots.size(); ++i) {
    INFO("slot " << i + 1 << " " << re.slots[i].name);
    CHECK(oe.slots[i].name == re.slots[i].name);
    CHECK(oe.slots[i].optional == re.slots[i].optional);
    CHECK(oe.slots[i].derived == re.slots[i].derived);
    CHECK(ours.typeText(oe.slots[i].type) == ref.typeText(re.slots[i].type));
  }
}

} // namespace stepnc::test
