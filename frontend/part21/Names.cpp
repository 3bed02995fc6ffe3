#include "frontend/part21/Names.h"

namespace stepnc::p21 {

namespace {
inline char upper(char c) { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 32) : c; }
} // namespace

NameTable::NameTable() : slots_(256, kNoName) {}

uint64_t NameTable::hash(std::string_view s) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (char c : s) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

NameId NameTable::find(std::string_view name) const {
  const size_t mask = slots_.size() - 1;
  for (size_t i = hash(name) & mask;; i = (i + 1) & mask) {
    NameId id = slots_[i];
    if (id == kNoName)
      return kNoName;
    if (names_[id] == name)
      return id;
  }
}

NameId NameTable::intern(std::string_view name) {
  bool hasLower = false;
  for (char c : name)
    hasLower |= (c >= 'a' && c <= 'z');
  std::string upperCopy;
  if (hasLower) {
    upperCopy.reserve(name.size());
    for (char c : name)
      upperCopy.push_back(upper(c));
    name = upperCopy;
  }
  const size_t mask = slots_.size() - 1;
  size_t i = hash(name) & mask;
  for (;; i = (i + 1) & mask) {
    NameId id = slots_[i];
    if (id == kNoName)
      break;
    if (names_[id] == name)
      return id;
  }
  auto id = static_cast<NameId>(names_.size());
  names_.emplace_back(name);
  slots_[i] = id;
  if (names_.size() * 2 > slots_.size())
    grow();
  return id;
}

void NameTable::grow() {
  std::vector<NameId> bigger(slots_.size() * 2, kNoName);
  const size_t mask = bigger.size() - 1;
  for (NameId id = 0; id < names_.size(); ++id) {
    size_t i = hash(names_[id]) & mask;
    while (bigger[i] != kNoName)
      i = (i + 1) & mask;
    bigger[i] = id;
  }
  slots_.swap(bigger);
}

} // namespace stepnc::p21
