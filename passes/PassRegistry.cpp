#include "passes/PassRegistry.h"

#include "runtime/Machine.h"

#include <charconv>
#include <cmath>

namespace stepnc::passes {

// Factories, one per pass, defined in the pass's own file.
#define PASS(NAME, CLASS, DESCRIPTION, ...) std::unique_ptr<Pass> create##CLASS(const PassOptions &options);
#include "passes/Passes.def"
#undef PASS

const std::vector<PassInfo> &registeredPasses() {
  static const std::vector<PassInfo> passes = {
#define OPTION(NAME, TYPE, DEFAULT, HELP) OptionInfo{NAME, OptionType::TYPE, DEFAULT, HELP}
#define PASS(NAME, CLASS, DESCRIPTION, ...) PassInfo{NAME, DESCRIPTION, {__VA_ARGS__}},
#include "passes/Passes.def"
#undef PASS
#undef OPTION
  };
  return passes;
}

namespace {

const PassInfo *findPass(std::string_view name) {
  for (const PassInfo &p : registeredPasses())
    if (p.name == name)
      return &p;
  return nullptr;
}

const OptionInfo *findOption(const PassInfo &info, std::string_view name) {
  for (const OptionInfo &o : info.options)
    if (o.name == name)
      return &o;
  return nullptr;
}

/// How an option type is written in the help, and what a value of it is.
struct TypeText {
  std::string_view placeholder;
  std::string expects;
};

TypeText typeText(OptionType type) {
  switch (type) {
  case OptionType::Length:
    return {"<mm>", "a positive length in mm, such as 0.05 or 0.05mm"};
  case OptionType::Angle:
    return {"<deg>", "an angle in degrees above 0 and at most 180, such as 60 or 60deg"};
  case OptionType::Bool:
    return {"true|false", "true or false"};
  case OptionType::File:
    return {"<file>", "a file path"};
  case OptionType::Point:
    return {"<x:y:z>", "three numbers in mm separated by ':', such as 200:195:-250"};
  case OptionType::Machine: {
    std::string names;
    for (const std::string &n : runtime::shippedMachineNames())
      names += (names.empty() ? "" : ", ") + n;
    return {"<machine>", "a machine description (a TOML file) or a shipped machine (" + names + ")"};
  }
  }
  return {};
}

/// `text` as a finite number followed by nothing or by `unit`.
std::optional<double> numberWithUnit(std::string_view text, std::string_view unit) {
  if (text.size() > unit.size() && text.ends_with(unit))
    text.remove_suffix(unit.size());
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

/// `text` as a value of `type`; nullopt when it is not one.
std::optional<PassOptions::Value> convert(OptionType type, std::string_view text) {
  switch (type) {
  case OptionType::Length:
    if (auto v = numberWithUnit(text, "mm"); v && *v > 0)
      return *v;
    return std::nullopt;
  case OptionType::Angle:
    if (auto v = numberWithUnit(text, "deg"); v && *v > 0 && *v <= 180)
      return *v;
    return std::nullopt;
  case OptionType::Bool:
    if (text == "true" || text == "false")
      return text == "true";
    return std::nullopt;
  case OptionType::File:
  case OptionType::Machine:
    if (text.empty())
      return std::nullopt;
    return std::string(text);
  case OptionType::Point:
    if (!parsePoint(text))
      return std::nullopt;
    return std::string(text);
  }
  return std::nullopt;
}

} // namespace

std::optional<std::array<double, 3>> parsePoint(std::string_view text) {
  std::array<double, 3> out{};
  for (size_t k = 0; k < 3; ++k) {
    const size_t end = k < 2 ? text.find(':') : text.size();
    if (end == std::string_view::npos)
      return std::nullopt;
    const std::optional<double> v = numberWithUnit(text.substr(0, end), "mm");
    if (!v)
      return std::nullopt;
    out[k] = *v;
    text.remove_prefix(std::min(text.size(), end + 1));
  }
  return out;
}

namespace {

bool isNameChar(char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_'; }

} // namespace

std::string describePass(const PassInfo &info) {
  std::string text = std::string(info.name) + "\n    " + std::string(info.description) + '\n';
  if (!info.options.empty())
    text += "    options:\n";
  for (const OptionInfo &o : info.options) {
    text += "      " + std::string(o.name) + "=" + std::string(typeText(o.type).placeholder) + "  " +
            std::string(o.help);
    switch (o.fallback.kind) {
    case OptionDefault::Kind::Value:
      text += " (default " + std::string(o.fallback.text) + ")";
      break;
    case OptionDefault::Kind::Absent:
      text += " (without it: " + std::string(o.fallback.text) + ")";
      break;
    case OptionDefault::Kind::Required:
      text += " (required)";
      break;
    }
    text += '\n';
  }
  return text;
}

std::string describeOptionTypes() {
  std::string text = "option values:\n";
  for (OptionType type : {OptionType::Length, OptionType::Angle, OptionType::Bool, OptionType::File,
                          OptionType::Machine, OptionType::Point}) {
    const TypeText t = typeText(type);
    text += "    " + std::string(t.placeholder) + ": " + t.expects + '\n';
  }
  return text;
}

std::optional<std::vector<PipelineEntry>> parsePipeline(std::string_view text, std::string &error) {
  std::vector<PipelineEntry> out;
  size_t i = 0;
  // `at` is the index of the character the message is about.
  auto failAt = [&](size_t at, std::string message) -> std::optional<std::vector<PipelineEntry>> {
    error = "in pass pipeline '" + std::string(text) + "' at character " + std::to_string(at + 1) + ": " + message;
    return std::nullopt;
  };
  auto fail = [&](std::string message) { return failAt(i, std::move(message)); };
  while (i < text.size()) {
    PipelineEntry entry;
    const size_t start = i;
    while (i < text.size() && isNameChar(text[i]))
      ++i;
    entry.name = std::string(text.substr(start, i - start));
    if (entry.name.empty())
      return fail("expected a pass name");
    const PassInfo *info = findPass(entry.name);
    if (!info)
      return fail("unknown pass '" + entry.name + "' (stepnc opt --list-passes lists them)");
    if (i < text.size() && text[i] == '<') {
      ++i;
      for (;;) {
        const size_t k = i;
        while (i < text.size() && isNameChar(text[i]))
          ++i;
        std::string key(text.substr(k, i - k));
        if (key.empty() || i >= text.size() || text[i] != '=')
          return fail("expected key=value in the options of '" + entry.name + "'");
        const OptionInfo *option = findOption(*info, key);
        if (!option)
          return fail("pass '" + entry.name + "' has no option '" + key + "'");
        const size_t v = ++i;
        while (i < text.size() && text[i] != ',' && text[i] != '>')
          ++i;
        const std::string_view value = text.substr(v, i - v);
        auto converted = convert(option->type, value);
        if (!converted)
          return failAt(v, "pass '" + entry.name + "' option '" + key + "' expects " + typeText(option->type).expects +
                               ", got '" + std::string(value) + "'");
        entry.options.set(key, std::move(*converted));
        if (i >= text.size())
          return fail("expected '>' to close the options of '" + entry.name + "'");
        if (text[i++] == '>')
          break;
      }
    }
    for (const OptionInfo &o : info->options) {
      if (entry.options.has(o.name))
        continue;
      if (o.fallback.kind == OptionDefault::Kind::Required)
        return fail("pass '" + entry.name + "' needs option '" + std::string(o.name) + "', " +
                    typeText(o.type).expects);
      if (o.fallback.kind == OptionDefault::Kind::Value) {
        auto value = convert(o.type, o.fallback.text);
        if (!value)  // a mistake in Passes.def, which the unit tests look for
          return fail("pass '" + entry.name + "' option '" + std::string(o.name) + "' declares the default '" +
                      std::string(o.fallback.text) + "', which is not " + typeText(o.type).expects);
        entry.options.set(std::string(o.name), std::move(*value));
      }
    }
    out.push_back(std::move(entry));
    if (i < text.size()) {
      if (text[i] != ',')
        return fail("expected ',' between passes");
      ++i;
      if (i == text.size())
        return fail("expected a pass name after ','");
    }
  }
  return out;
}

std::unique_ptr<Pass> createPass(const PipelineEntry &entry) {
#define PASS(NAME, CLASS, DESCRIPTION, ...)                                                                          \
  if (entry.name == NAME)                                                                                            \
    return create##CLASS(entry.options);
#include "passes/Passes.def"
#undef PASS
  return nullptr;
}

} // namespace stepnc::passes
