// Decoded Part 21 parameter values: a compact tree in a flat arena.
//
// A decoded instance is one or more entity records (one for a simple instance,
// several for a complex instance `(A(..)B(..))`), each with its parameters. Each
// parameter is a 24-byte Value; the children of a list or typed parameter sit
// contiguously in the arena, so a record's parameters are a span. Strings are
// stored decoded to UTF-8: they point into the source when no escape needed
// decoding, otherwise into the arena's string storage. Every value keeps the
// byte offset of its first character relative to its instance, so diagnostics
// can point at the exact parameter.
#pragma once

#include "frontend/part21/Names.h"

#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::p21 {

using InstanceId = uint64_t;

enum class ValueKind : uint8_t {
  Unset,        ///< `$`: no value
  Derived,      ///< `*`: value derived by the schema
  Integer,
  Real,
  String,       ///< decoded to UTF-8
  Binary,       ///< `"..."`: the hex digits as written (first digit = unused bits)
  Enumeration,  ///< `.NAME.`: the name without dots
  Reference,    ///< `#123`
  List,         ///< `( ... )`
  Typed,        ///< `TYPE_NAME(value)`: a typed (SELECT) parameter
};

const char *valueKindName(ValueKind k);

/// Where a list's or typed parameter's children are.
struct NodeRef {
  uint32_t first;  ///< index of the first child in the arena
  NameId name;     ///< Typed: the type name
};

struct Value {
  ValueKind kind = ValueKind::Unset;
  /// List/Typed: number of children; String/Binary/Enumeration: length in bytes.
  uint32_t count = 0;
  /// Offset of the value's first byte from the start of its instance.
  uint32_t offset = 0;
  union {
    int64_t integer;
    double real;
    InstanceId ref;
    const char *text;
    NodeRef node;
  };

  Value() : integer(0) {}

  std::string_view str() const { return {text, count}; }
  bool isUnset() const { return kind == ValueKind::Unset; }
};

/// One simple entity record: `NAME(params)`.
struct Record {
  NameId name = kNoName;
  uint32_t first = 0;   ///< index of the first parameter in the arena
  uint32_t count = 0;   ///< number of parameters
  uint32_t offset = 0;  ///< offset of the name from the start of the instance
};

/// Storage for decoded values; reuse one arena across instances with clear().
class ValueArena {
public:
  void clear() {
    values_.clear();
    records_.clear();
    strings_.clear();
    scratch_.clear();
  }

  std::span<const Value> params(const Record &r) const { return {values_.data() + r.first, r.count}; }
  std::span<const Value> children(const Value &v) const {
    return {values_.data() + v.node.first, v.count};
  }
  std::span<const Record> records() const { return records_; }
  const std::vector<Value> &values() const { return values_; }

  // Building (used by the decoder).
  std::vector<Value> &mutableValues() { return values_; }
  std::vector<Record> &mutableRecords() { return records_; }
  /// Working space for the decoder (kept here so its capacity is reused).
  std::vector<Value> &scratch() { return scratch_; }
  /// Stable storage for a decoded string; returns a pointer valid until clear().
  const char *storeString(std::string_view s) {
    strings_.emplace_back(s);
    return strings_.back().c_str();
  }

private:
  std::vector<Value> values_;
  std::vector<Record> records_;
  std::deque<std::string> strings_;
  std::vector<Value> scratch_;
};

} // namespace stepnc::p21
