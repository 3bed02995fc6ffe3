// Reading EXPRESS text in unit tests.
#pragma once

#include "frontend/express/SchemaReader.h"

#include <memory>
#include <string_view>

namespace stepnc::test {

/// A model read from EXPRESS text and resolved, with its diagnostics.
struct LoadedExpress {
  express::Model model;
  DiagnosticCollector diags;
  bool ok = false;  ///< read and resolved without errors
};

inline std::unique_ptr<LoadedExpress> loadExpress(std::string_view text) {
  auto l = std::make_unique<LoadedExpress>();
  DiagnosticEngine engine(l->diags);
  l->ok = express::readExpress(SourceFile::fromString("t.exp", text), l->model, engine);
  if (l->ok)
    l->ok = l->model.resolve(engine);
  return l;
}

} // namespace stepnc::test
