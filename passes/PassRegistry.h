// The pass registry: every pass by name with its options as Passes.def
// declares them, pipelines such as `resolve-feeds,other-pass<key=value>`
// parsed with every option value checked and converted, and passes built
// from them.
#pragma once

#include "passes/Pass.h"

#include <memory>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::passes {

/// The type of a pass option: the text it takes and the value the pass reads
/// (PassOptions::number, flag or text).
enum class OptionType {
  Length,  ///< a positive length in mm: "0.05" or "0.05mm"; a number
  Angle,   ///< an angle in deg, above 0 and at most 180: "60" or "60deg"; a number
  Bool,    ///< "true" or "false"; a flag
  File,    ///< a file path, not empty; text
  Machine, ///< a machine description (TOML file) or a shipped machine's name, not empty; text
  Point,   ///< three numbers in mm separated by ':' ("200:195:-250"; commas separate options); text
};

/// A Point option's text as (x, y, z); nullopt when it is not three finite numbers.
std::optional<std::array<double, 3>> parsePoint(std::string_view text);

/// What an option is when a pipeline does not give it.
struct OptionDefault {
  enum class Kind { Value, Absent, Required };
  Kind kind;
  /// Value: the default as the option's text; Absent: what the pass does
  /// without it, for the help.
  std::string_view text;
};

/// In Passes.def: the option defaults to `value`, written as the option takes it.
constexpr OptionDefault byDefault(std::string_view value) { return {OptionDefault::Kind::Value, value}; }
/// In Passes.def: the option has no default; `meaning` says what the pass
/// does without it ("without it: ..." in the help).
constexpr OptionDefault absent(std::string_view meaning) { return {OptionDefault::Kind::Absent, meaning}; }
/// In Passes.def: a pipeline must give the option.
constexpr OptionDefault required() { return {OptionDefault::Kind::Required, {}}; }

/// One option of a pass, as Passes.def declares it.
struct OptionInfo {
  std::string_view name;
  OptionType type;
  OptionDefault fallback;
  std::string_view help;
};

struct PassInfo {
  std::string_view name;
  std::string_view description;
  std::vector<OptionInfo> options;
};

/// Every registered pass, in Passes.def order.
const std::vector<PassInfo> &registeredPasses();

/// A pass's --list-passes entry: its name, its description and its options
/// (name, type, help and default), one line each.
std::string describePass(const PassInfo &info);

/// What each type of option value takes, for the end of --list-passes.
std::string describeOptionTypes();

/// One element of a parsed pipeline: the pass and its options, checked,
/// converted and completed with their defaults.
struct PipelineEntry {
  std::string name;
  PassOptions options;
};

/// Parses `a,b<k=v,k2=v2>,c`. On a syntax error, an unknown pass, an option
/// the pass does not take, a value not of the option's type or a required
/// option not given, returns nullopt and sets `error`, which says where in
/// the text.
std::optional<std::vector<PipelineEntry>> parsePipeline(std::string_view text, std::string &error);

/// Builds a registered pass with its options (as parsePipeline gives them);
/// null for an unknown name.
std::unique_ptr<Pass> createPass(const PipelineEntry &entry);

} // namespace stepnc::passes
