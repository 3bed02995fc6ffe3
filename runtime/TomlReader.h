// Reading human-edited TOML files (machine descriptions, cutting data) with
// located diagnostics: unknown keys, missing or out-of-range values and TOML
// syntax errors are reported at their line and column, and reading goes on
// so that one run shows every problem.
//
// Debian's libtomlplusplus is built with exceptions: parse errors arrive as
// toml::parse_error; `parse` turns them into diagnostics.
#pragma once

#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <toml++/toml.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace stepnc::runtime {

class TomlReader {
public:
  /// `what` names the file in messages: "the machine file".
  TomlReader(const SourceFile &file, DiagnosticEngine &diags, std::string what)
      : file_(file), diags_(diags), what_(std::move(what)) {}

  bool ok() const { return ok_; }

  /// The file's root table; nullopt (after an error) when it is not TOML.
  std::optional<toml::table> parse();

  /// A located error at a TOML node (its first character), or at the file
  /// start.
  void error(const toml::source_region &where, const std::string &message);

  /// Every key of `table` must be one of `known`; `where` names the table in
  /// messages.
  void onlyKnown(const toml::table &table, std::initializer_list<std::string_view> known, const std::string &where);

  /// A number (integer or float) at `key`, within [lo, hi]; `unit` is shown in
  /// messages.
  std::optional<double> number(const toml::table &table, std::string_view key, const std::string &where,
                               const char *unit, double lo, double hi, bool required);

  std::optional<std::string> text(const toml::table &table, std::string_view key, const std::string &where,
                                  bool required);

  /// The sub-table `key` of `parent`; null (with an error when `required`)
  /// when it is missing or not a table.
  const toml::table *table(const toml::table &parent, std::string_view key, const std::string &where,
                           bool required = true);

private:
  SourceLoc locate(const toml::source_position &p) const;

  const SourceFile &file_;
  DiagnosticEngine &diags_;
  std::string what_;
  bool ok_ = true;
};

} // namespace stepnc::runtime
