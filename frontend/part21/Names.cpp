#include "frontend/part21/Names.h"

#include <cstring>

namespace stepnc::p21 {

NameTable::NameTable() : slots_(256, kNoName) {}

// Eight bytes at a time with a multiply-xorshift mix: names are short (10-40
// bytes), so this is a handful of multiplies per lookup.
uint64_t NameTable::hash(std::string_view s) {
  uint64_t h = 0x9E3779B97F4A7C15ull ^ s.size();
  const char *p = s.data();
  size_t n = s.size();
  while (n >= 8) {
    uint64_t w;
    std::memcpy(&w, p, 8);
    h = (h ^ w) * 0xBF58476D1CE4E5B9ull;
    h ^= h >> 31;
    p += 8;
    n -= 8;
  }
  uint64_t tail = 0;
  std::memcpy(&tail, p, n);
  h = (h ^ tail) * 0x94D049BB133111EBull;
  return h ^ (h >> 29);
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
  for (char c : name)
    if (c >= 'a' && c <= 'z') {
      std::string upper(name);
      for (char &u : upper)
        if (u >= 'a' && u <= 'z')
          u = static_cast<char>(u - 32);
      return internUpper(upper);
    }
  return internUpper(name);
}

NameId NameTable::internUpper(std::string_view name) {
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
