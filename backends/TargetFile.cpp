#include "backends/TargetFile.h"

#include "runtime/TomlReader.h"
#include "support/Format.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

namespace stepnc::backends {

namespace {

namespace fs = std::filesystem;

/// A TOML value as written, for messages.
std::string tomlText(const toml::node &n) {
  std::ostringstream out;
  n.visit([&](const auto &v) { out << v; });
  return out.str();
}

/// How deep descriptors may extend one another.
constexpr int kMaxExtends = 16;

/// Reads descriptor files, each extending the next, down to a built-in target.
class Loader {
public:
  Loader(std::vector<std::unique_ptr<SourceFile>> &files, DiagnosticEngine &diags, std::string &usageError)
      : files_(files), diags_(diags), usageError_(usageError) {}

  /// The backend of the descriptor at `path` (`shown` as the file that
  /// names it writes it). `from` is that descriptor, with where it names it
  /// (null for --target itself).
  std::unique_ptr<Backend> file(const std::string &path, runtime::TomlReader *from, const toml::source_region *where,
                                const std::string &shown) {
    std::error_code ec;
    const std::string key = fs::weakly_canonical(fs::path(path), ec).string();
    if (!seen_.insert(key.empty() ? path : key).second) {
      from->error(*where, "'" + shown + "' extends itself, through the files it extends");
      return nullptr;
    }
    if (seen_.size() > kMaxExtends) {
      from->error(*where, "descriptors extend one another more than " + std::to_string(kMaxExtends) + " deep");
      return nullptr;
    }
    std::string error;
    std::unique_ptr<SourceFile> source = SourceFile::open(path, error);
    if (!source) {
      if (from)
        from->error(*where, "the descriptor '" + shown + "' it extends: " + error);
      else
        usageError_ = "target descriptor: " + error;
      return nullptr;
    }
    files_.push_back(std::move(source));
    const SourceFile &text = *files_.back();
    runtime::TomlReader r(text, diags_, "the target descriptor");
    std::optional<toml::table> root = r.parse();
    if (!root)
      return nullptr;
    r.onlyKnown(*root, {"format", "name", "description", "extends", "extension", "numbers", "blocks", "arcs", "cycles",
                        "splines"},
                "the target descriptor");
    const toml::node *format = root->get("format");
    if (!format) {
      r.error(root->source(), "the target descriptor needs 'format = 1' (its format's version)");
      return nullptr;
    }
    if (format->value<int64_t>() != 1) {
      r.error(format->source(), "format " + tomlText(*format) + " is not a descriptor format this stepnc reads (1)");
      return nullptr;
    }
    const std::optional<std::string> name = r.text(*root, "name", "the target descriptor", true);
    const std::optional<std::string> description = r.text(*root, "description", "the target descriptor", true);
    const std::optional<std::string> extends = r.text(*root, "extends", "the target descriptor", true);
    if (!name || !description || !extends)
      return nullptr;
    std::unique_ptr<Backend> backend = base(*extends, path, r, root->get("extends")->source());
    if (!backend)
      return nullptr;
    TargetDescriptor &d = backend->descriptor();
    if (!plainName(*name))
      r.error(root->get("name")->source(), "a target's name is letters, digits, '-' and '_', not '" + *name + "'");
    // What the target extends decides what may change (its messages name it).
    apply(r, *root, d);
    d.name = *name;
    d.description = *description;
    return r.ok() ? std::move(backend) : nullptr;
  }

private:
  /// What `extends` names: a built-in target, or a descriptor file (a path
  /// relative to the descriptor's folder).
  std::unique_ptr<Backend> base(const std::string &extends, const std::string &path, runtime::TomlReader &r,
                                const toml::source_region &where) {
    if (isTargetFile(extends)) {
      const fs::path parent = fs::path(path).parent_path();
      const std::string next = fs::path(extends).is_absolute() ? extends : (parent / extends).string();
      return file(next, &r, &where, extends);
    }
    if (extends == "native") {
      r.error(where, "'native' writes motion, not a controller's program: a descriptor extends a G-code target");
      return nullptr;
    }
    std::unique_ptr<Backend> b = createBackend(extends);
    if (!b) {
      std::string names;
      for (const TargetInfo &t : registeredTargets())
        if (t.name != "native")
          names += (names.empty() ? "" : ", ") + std::string(t.name);
      r.error(where, "extends '" + extends + "', which is neither a built-in target (" + names +
                         ") nor a descriptor file (.toml)");
    }
    return b;
  }

  static bool plainName(const std::string &s) {
    if (s.empty() || s.size() > 64)
      return false;
    for (char c : s)
      if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_'))
        return false;
    return true;
  }

  /// A whole number in [lo, hi] at `key`; nullopt when absent or wrong.
  static std::optional<int> count(runtime::TomlReader &r, const toml::table &t, std::string_view key,
                                  const std::string &where, const char *unit, int lo, int hi) {
    const std::optional<double> v = r.number(t, key, where, unit, lo, hi, false);
    if (!v)
      return std::nullopt;
    if (*v != std::floor(*v)) {
      r.error(t.get(key)->source(), where + "." + std::string(key) + " is a whole number, not " + formatShortest(*v));
      return std::nullopt;
    }
    return static_cast<int>(*v);
  }

  static std::optional<bool> flag(runtime::TomlReader &r, const toml::table &t, std::string_view key,
                                  const std::string &where) {
    const toml::node *n = t.get(key);
    if (!n)
      return std::nullopt;
    if (const auto *b = n->as_boolean())
      return b->get();
    r.error(n->source(), where + "." + std::string(key) + " is true or false");
    return std::nullopt;
  }

  /// --target-opt's rule for a setting (`option`), its refusal located at
  /// the descriptor's `key` and named by it.
  static void override(runtime::TomlReader &r, const toml::node &at, TargetDescriptor &d, const std::string &option,
                       const std::string &key) {
    std::string error = applyOverrides(d, {option});
    if (error.empty())
      return;
    const std::string prefix = "--target-opt " + option.substr(0, option.find('=')) + ": ";
    if (error.starts_with(prefix))
      error = key + ": " + error.substr(prefix.size());
    r.error(at.source(), error);
  }

  void apply(runtime::TomlReader &r, const toml::table &root, TargetDescriptor &d) {
    if (const std::optional<std::string> ext = r.text(root, "extension", "the target descriptor", false)) {
      bool plain = ext->size() >= 2 && ext->size() <= 8 && (*ext)[0] == '.';
      for (size_t i = 1; plain && i < ext->size(); ++i)
        plain = std::isalnum(static_cast<unsigned char>((*ext)[i])) != 0;
      if (!plain)
        r.error(root.get("extension")->source(), "the extension is a dot and 1 to 7 letters or digits, not '" + *ext +
                                                     "'");
      d.extension = *ext;
    }
    if (const toml::table *t = r.table(root, "numbers", "numbers", false)) {
      r.onlyKnown(*t, {"coordinates", "feed", "speed"}, "[numbers]");
      if (const auto v = count(r, *t, "coordinates", "numbers", "decimals", 0, 6))
        d.coordDecimals = *v;
      if (const auto v = count(r, *t, "feed", "numbers", "decimals", 0, 4))
        d.feedDecimals = *v;
      if (const auto v = count(r, *t, "speed", "numbers", "decimals", 0, 3))
        d.speedDecimals = *v;
    }
    if (const toml::table *t = r.table(root, "blocks", "blocks", false)) {
      r.onlyKnown(*t, {"numbering", "step", "max_line_length"}, "[blocks]");
      if (const std::optional<std::string> n = r.text(*t, "numbering", "blocks", false)) {
        if (*n != "none" && *n != "every")
          r.error(t->get("numbering")->source(), "blocks.numbering is \"none\" or \"every\", not \"" + *n + "\"");
        else
          override(r, *t->get("numbering"), d, "line-numbers=" + *n, "blocks.numbering");
      }
      if (const auto v = count(r, *t, "step", "blocks", "block numbers", 1, 1000))
        d.numberStep = *v;
      if (const auto v = count(r, *t, "max_line_length", "blocks", "characters", 0, 100000))
        d.maxLineLength = static_cast<size_t>(*v);
    }
    if (const toml::table *t = r.table(root, "arcs", "arcs", false)) {
      r.onlyKnown(*t, {"form"}, "[arcs]");
      if (const std::optional<std::string> f = r.text(*t, "form", "arcs", false)) {
        if (*f != "ijk" && *f != "radius")
          r.error(t->get("form")->source(), "arcs.form is \"ijk\" or \"radius\", not \"" + *f + "\"");
        else
          override(r, *t->get("form"), d, "arcs=" + *f, "arcs.form");
      }
    }
    if (const toml::table *t = r.table(root, "cycles", "cycles", false)) {
      r.onlyKnown(*t, {"use"}, "[cycles]");
      if (const std::optional<bool> use = flag(r, *t, "use", "cycles")) {
        if (*use && d.cycles.empty())
          r.error(t->get("use")->source(), d.name + " has no canned cycles stepnc writes: holes stay moves");
        else if (!*use)
          override(r, *t->get("use"), d, "cycles=off", "cycles.use");
      }
    }
    if (const toml::table *t = r.table(root, "splines", "splines", false)) {
      r.onlyKnown(*t, {"use"}, "[splines]");
      if (const std::optional<bool> use = flag(r, *t, "use", "splines"))
        override(r, *t->get("use"), d, *use ? "splines=on" : "splines=off", "splines.use");
    }
  }

  std::vector<std::unique_ptr<SourceFile>> &files_;
  DiagnosticEngine &diags_;
  std::string &usageError_;
  std::set<std::string> seen_;
};

} // namespace

bool isTargetFile(const std::string &spec) { return spec.size() > 5 && spec.ends_with(".toml"); }

std::unique_ptr<Backend> loadTarget(const std::string &spec, std::vector<std::unique_ptr<SourceFile>> &files,
                                    DiagnosticEngine &diags, std::string &usageError) {
  if (!isTargetFile(spec)) {
    std::unique_ptr<Backend> b = createBackend(spec);
    if (!b)
      usageError = "unknown target '" + spec + "'";
    return b;
  }
  Loader loader(files, diags, usageError);
  return loader.file(spec, nullptr, nullptr, spec);
}

} // namespace stepnc::backends
