// Interned entity and type names (upper case).
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::p21 {

using NameId = uint32_t;
inline constexpr NameId kNoName = UINT32_MAX;

/// Maps names to dense ids with an open-addressing hash table. Names are
/// stored upper-cased, in a deque so that the views name() returns stay valid
/// while new names are added (decoding interns typed-parameter names).
class NameTable {
public:
  NameTable();
  /// Returns the id of `name` (upper-cased), adding it if new.
  NameId intern(std::string_view name);
  /// As intern(), for a name the caller knows to have no lower-case letters.
  NameId internUpper(std::string_view name);
  /// Returns the id of `name` or kNoName; `name` must already be upper case.
  NameId find(std::string_view name) const;
  std::string_view name(NameId id) const { return names_[id]; }
  size_t size() const { return names_.size(); }

private:
  void grow();
  static uint64_t hash(std::string_view upper);

  std::deque<std::string> names_;
  std::vector<NameId> slots_;  // kNoName = empty
};

} // namespace stepnc::p21
