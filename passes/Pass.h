// The pass interface. A pass transforms (or analyses) a module, reports
// through the diagnostics engine, and says whether it succeeded and whether
// it changed anything. Passes are listed in Passes.def and built by name.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace stepnc::passes {

/// A pass's options from `name<key=value,...>`, checked and converted by
/// the registry against their declaration in Passes.def (PassRegistry.h):
/// lengths (mm) and angles (deg) are numbers, flags are booleans, files and
/// machines are text. An option the pipeline does not give holds its
/// declared default, or is absent when it has none.
class PassOptions {
public:
  using Value = std::variant<double, bool, std::string>;

  void set(std::string name, Value value) { values_[std::move(name)] = std::move(value); }
  bool has(std::string_view name) const { return values_.find(name) != values_.end(); }
  bool empty() const { return values_.empty(); }
  /// A length (mm) or an angle (deg); nullopt when absent.
  std::optional<double> number(std::string_view name) const {
    const double *v = get<double>(name);
    return v ? std::optional<double>(*v) : std::nullopt;
  }
  /// A flag; false when absent.
  bool flag(std::string_view name) const {
    const bool *v = get<bool>(name);
    return v && *v;
  }
  /// A file path or a machine; empty when absent.
  std::string text(std::string_view name) const {
    const std::string *v = get<std::string>(name);
    return v ? *v : std::string();
  }

private:
  template <typename T> const T *get(std::string_view name) const {
    auto it = values_.find(name);
    return it == values_.end() ? nullptr : std::get_if<T>(&it->second);
  }

  std::map<std::string, Value, std::less<>> values_;
};

struct PassResult {
  bool ok = true;
  bool changed = false;
};

/// Per-pass counters, printed by `--stats` (LLVM's STATISTIC).
using PassStats = std::map<std::string, long long, std::less<>>;

class Pass {
public:
  virtual ~Pass() = default;
  virtual std::string_view name() const = 0;
  virtual PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) = 0;
  /// Figures of the last run that counters cannot hold (a table per
  /// workingstep, say), printed by `--stats` after the counters; one
  /// line per entry.
  virtual std::vector<std::string> report() const { return {}; }
};

} // namespace stepnc::passes
