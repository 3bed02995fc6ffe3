#include "passes/PassRegistry.h"

namespace stepnc::passes {

// Factories, one per pass, defined in the pass's own file.
#define PASS(NAME, CLASS, DESCRIPTION, OPTIONS) std::unique_ptr<Pass> create##CLASS(const PassOptions &options);
#include "passes/Passes.def"
#undef PASS

const std::vector<PassInfo> &registeredPasses() {
  static const std::vector<PassInfo> passes = {
#define PASS(NAME, CLASS, DESCRIPTION, OPTIONS) {NAME, DESCRIPTION, OPTIONS},
#include "passes/Passes.def"
#undef PASS
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

bool optionKnown(const PassInfo &info, std::string_view key) {
  std::string_view list = info.options;
  while (!list.empty()) {
    const size_t end = list.find(';');
    std::string_view item = list.substr(0, end);
    while (!item.empty() && item.front() == ' ')
      item.remove_prefix(1);
    if (item.substr(0, item.find('=')) == key)
      return true;
    if (end == std::string_view::npos)
      break;
    list.remove_prefix(end + 1);
  }
  return false;
}

bool isNameChar(char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_'; }

} // namespace

std::optional<std::vector<PipelineEntry>> parsePipeline(std::string_view text, std::string &error) {
  std::vector<PipelineEntry> out;
  size_t i = 0;
  auto fail = [&](std::string message) -> std::optional<std::vector<PipelineEntry>> {
    error = "in pass pipeline '" + std::string(text) + "' at character " + std::to_string(i + 1) + ": " + message;
    return std::nullopt;
  };
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
        if (!optionKnown(*info, key))
          return fail("pass '" + entry.name + "' has no option '" + key + "'");
        const size_t v = ++i;
        while (i < text.size() && text[i] != ',' && text[i] != '>')
          ++i;
        entry.options[key] = std::string(text.substr(v, i - v));
        if (i >= text.size())
          return fail("expected '>' to close the options of '" + entry.name + "'");
        if (text[i++] == '>')
          break;
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
#define PASS(NAME, CLASS, DESCRIPTION, OPTIONS)                                                                       \
  if (entry.name == NAME)                                                                                            \
    return create##CLASS(entry.options);
#include "passes/Passes.def"
#undef PASS
  return nullptr;
}

} // namespace stepnc::passes
