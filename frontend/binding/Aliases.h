// Names that real STEP-NC files use but the schema spells differently, read
// from one documented data file (frontend/binding/aliases.txt, compiled in).
#pragma once

#include <string>
#include <string_view>
#include <unordered_map>

namespace stepnc::binding {

class AliasTable {
public:
  /// The table compiled into stepnc.
  static const AliasTable &builtin();

  /// Parses the data file format; on error returns false and sets `error`.
  bool parse(std::string_view text, std::string &error);

  /// The schema entity (lower case) that `name` (upper case, as written) stands
  /// for, or empty.
  std::string_view entity(std::string_view name) const;
  size_t size() const { return entities_.size(); }

private:
  std::unordered_map<std::string, std::string> entities_;
};

} // namespace stepnc::binding
