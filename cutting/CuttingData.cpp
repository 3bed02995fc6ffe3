#include "cutting/CuttingData.h"

#include "runtime/TomlReader.h"

#include <cctype>
#include <stdexcept>

namespace stepnc::cutting {

namespace {

using runtime::TomlReader;

std::string normalised(const std::string &text) {
  std::string out;
  for (unsigned char c : text)
    if (!std::isspace(c) && c != '-' && c != '.' && c != '_')
      out += char(std::toupper(c));
  return out;
}

void readToolMaterials(TomlReader &r, const toml::table &root, CuttingData &data) {
  const toml::table *t = r.table(root, "tool_materials", "tool_materials", false);
  if (!t)
    return;
  for (const auto &[key, node] : *t) {
    const std::string name(key.str());
    const std::string where = "[tool_materials." + name + "]";
    if (!node.is_table()) {
      r.error(node.source(), where + " must be a table");
      continue;
    }
    const toml::table &m = *node.as_table();
    r.onlyKnown(m, {"modulus", "allowed_bending_stress", "name", "source"}, where);
    ToolMaterial &tm = data.toolMaterials[name];
    tm.key = name;
    if (auto v = r.number(m, "modulus", where, "N/mm^2", 1000, 2e6, !data.toolMaterials.count(name)))
      tm.modulus = *v;
    if (auto v = r.number(m, "allowed_bending_stress", where, "N/mm^2", 1, 1e5, false))
      tm.allowedStress = *v;
  }
}

void readMaterials(TomlReader &r, const toml::table &root, CuttingData &data) {
  const toml::table *t = r.table(root, "materials", "materials", false);
  if (!t)
    return;
  for (const auto &[key, node] : *t) {
    const std::string name(key.str());
    const std::string where = "[materials." + name + "]";
    if (!node.is_table()) {
      r.error(node.source(), where + " must be a table");
      continue;
    }
    const toml::table &m = *node.as_table();
    r.onlyKnown(m,
                {"name", "aliases", "group", "ktc", "krc", "kte", "kre", "chip_thickness", "cutting_speed", "source"},
                where);
    const bool known = data.materials.count(name) > 0;
    Material &mat = data.materials[name];
    mat.key = name;
    if (auto v = r.text(m, "name", where, !known))
      mat.name = *v;
    if (auto v = r.text(m, "group", where, false))
      mat.group = *v;
    if (auto v = r.text(m, "source", where, false))
      mat.source = *v;
    if (const toml::node *a = m.get("aliases")) {
      const toml::array *list = a->as_array();
      if (!list) {
        r.error(a->source(), where + ".aliases must be a list of strings");
      } else {
        mat.aliases.clear();
        for (const toml::node &item : *list) {
          if (auto s = item.value<std::string>())
            mat.aliases.push_back(*s);
          else
            r.error(item.source(), where + ".aliases must be a list of strings");
        }
      }
    }
    if (auto v = r.number(m, "ktc", where, "N/mm^2", 1, 1e5, !known))
      mat.ktc = *v;
    if (auto v = r.number(m, "krc", where, "N/mm^2", 0, 1e5, !known))
      mat.krc = *v;
    if (auto v = r.number(m, "kte", where, "N/mm", 0, 1e4, !known))
      mat.kte = *v;
    if (auto v = r.number(m, "kre", where, "N/mm", 0, 1e4, !known))
      mat.kre = *v;
    if (auto v = r.number(m, "chip_thickness", where, "mm", 0.001, 2, !known))
      mat.chipThickness = *v;
    if (auto v = r.number(m, "cutting_speed", where, "m/min", 1, 1e5, false))
      mat.cuttingSpeed = *v;
  }
}

void readTools(TomlReader &r, const toml::table &root, CuttingData &data) {
  const toml::table *t = r.table(root, "tools", "tools", false);
  if (!t)
    return;
  for (const auto &[key, node] : *t) {
    std::string name(key.str());
    if (!name.empty() && name[0] == '%')
      name.erase(0, 1);
    const std::string where = "[tools.\"" + name + "\"]";
    if (!node.is_table()) {
      r.error(node.source(), where + " must be a table");
      continue;
    }
    const toml::table &m = *node.as_table();
    r.onlyKnown(m, {"material", "overhang", "flute_length", "max_force"}, where);
    ToolData &tool = data.tools[name];
    if (auto v = r.text(m, "material", where, false)) {
      if (!data.toolMaterials.count(*v)) {
        std::string known;
        for (const auto &[k, tm] : data.toolMaterials)
          known += (known.empty() ? "" : ", ") + k;
        r.error(m.get("material")->source(),
                where + ".material '" + *v + "' is not a tool material (known: " + known + ")");
      }
      tool.material = v;
    }
    tool.overhang = r.number(m, "overhang", where, "mm", 0.1, 2000, false);
    tool.fluteLength = r.number(m, "flute_length", where, "mm", 0.01, 2000, false);
    tool.maxForce = r.number(m, "max_force", where, "N", 0.1, 1e6, false);
  }
}

} // namespace

const Material *CuttingData::match(const std::string &identifier, const std::string &standard,
                                   std::string &matched) const {
  const std::string a = normalised(identifier), b = normalised(standard);
  // Longer aliases first, so "AISI 1045" beats a generic "STEEL".
  // Generic entries ("generic_steel": STEEL) only when no specific one matches.
  for (const bool generic : {false, true}) {
    const Material *best = nullptr;
    size_t bestLength = 0;
    for (const auto &[key, m] : materials) {
      if (key.starts_with("generic_") != generic)
        continue;
      std::vector<std::string> names = m.aliases;
      names.push_back(key);
      for (const std::string &alias : names) {
        const std::string n = normalised(alias);
        if (n.empty() || n.size() <= bestLength)
          continue;
        // Short aliases ("AL") must be the whole word, not part of another.
        const bool found =
            n.size() <= 3 ? (a == n || b == n) : (a.find(n) != std::string::npos || b.find(n) != std::string::npos);
        if (found) {
          best = &m;
          bestLength = n.size();
          matched = alias;
        }
      }
    }
    if (best)
      return best;
  }
  return nullptr;
}

std::optional<CuttingData> readCuttingData(const SourceFile &file, CuttingData base, DiagnosticEngine &diags) {
  TomlReader r(file, diags, "the cutting-data file");
  std::optional<toml::table> root = r.parse();
  if (!root)
    return std::nullopt;
  r.onlyKnown(*root, {"format", "default_material", "tool_materials", "materials", "tools"}, "the cutting-data file");
  r.number(*root, "format", "the cutting-data file", "format version", 1, 1, true);
  readToolMaterials(r, *root, base);
  readMaterials(r, *root, base);
  readTools(r, *root, base);
  if (auto v = r.text(*root, "default_material", "the cutting-data file", false)) {
    if (!base.materials.count(*v))
      r.error(root->get("default_material")->source(),
              "default_material '" + *v + "' is not one of the file's [materials.*]");
    base.defaultMaterial = *v;
  }
  if (!r.ok())
    return std::nullopt;
  base.sources.emplace_back(file.name());
  return base;
}

// Generated from cutting/materials.toml at build time (cutting/CMakeLists.txt).
extern const char *const kShippedCuttingData;

const CuttingData &shippedCuttingData() {
  static const CuttingData data = [] {
    auto file = SourceFile::fromString("cutting/materials.toml", kShippedCuttingData);
    DiagnosticCollector collector;
    DiagnosticEngine diags(collector);
    std::optional<CuttingData> d = readCuttingData(*file, {}, diags);
    // The file is checked by the tests; a broken build-in is a build error.
    if (!d || d->defaultMaterial.empty())
      throw std::logic_error("the shipped cutting data does not read");
    d->sources = {"shipped"};
    return *d;
  }();
  return data;
}

std::optional<CuttingData> loadCuttingData(const std::string &path, std::unique_ptr<SourceFile> &file,
                                           DiagnosticEngine &diags) {
  if (path.empty())
    return shippedCuttingData();
  std::string error;
  file = SourceFile::open(path, error);
  if (!file) {
    diags.error({}, "cannot read the cutting data '" + path + "': " + error);
    return std::nullopt;
  }
  return readCuttingData(*file, shippedCuttingData(), diags);
}

} // namespace stepnc::cutting
