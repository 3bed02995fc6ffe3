// Typed, by-name access to bound instances: what lowering and later passes use
// instead of Part 21 positions. An Instance decodes its values once, knows its
// entity, and follows references to other instances.
//
//   Instance ws = bound.instance(index);
//   if (ws.isA("machining_workingstep"))
//     Instance feature = ws.ref("its_feature");
//   std::optional<double> depth = op.real("axial_cutting_depth");
#pragma once

#include "frontend/binding/Binder.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::binding {

class Instance {
public:
  Instance() = default;
  /// Entry `index` of the bound file (decoded now).
  Instance(const BoundFile &bound, size_t index);

  bool valid() const { return bound_ != nullptr && decoded_; }
  explicit operator bool() const { return valid(); }

  size_t index() const { return index_; }
  p21::InstanceId id() const;
  /// The entity (most specific, for a complex instance) or express::kNone.
  express::EntityId entity() const;
  /// Its schema name, lower case ("closed_pocket"); empty when unknown.
  std::string_view entityName() const;
  /// True if the instance is the named entity or one of its subtypes.
  bool isA(std::string_view entity) const;
  /// Where the instance starts, for diagnostics.
  SourceLoc loc() const;

  /// The value of attribute `name` (nullptr if the entity has no such
  /// attribute). For a complex instance, the attribute of whichever record
  /// declares it.
  const p21::Value *attr(std::string_view name) const;
  /// Where an attribute's value starts (or the instance, if absent).
  SourceLoc attrLoc(std::string_view name) const;

  // Typed accessors: empty when the attribute is absent, `$`, or of another
  // kind. Typed values such as LENGTH_MEASURE(5.) are unwrapped; integers read
  // as reals where a real is asked for.
  std::optional<double> real(std::string_view name) const;
  std::optional<int64_t> integer(std::string_view name) const;
  std::optional<std::string> string(std::string_view name) const;
  /// An enumeration value, lower case (".CW." -> "cw").
  std::optional<std::string> enumeration(std::string_view name) const;
  std::optional<bool> boolean(std::string_view name) const;
  /// The instance a reference attribute points to (invalid if none).
  Instance ref(std::string_view name) const;
  /// The 0-based position of attribute `name` in a simple instance's
  /// parameters (what a writer patches); -1 for a complex instance or an
  /// attribute the entity does not have.
  int parameterIndex(std::string_view name) const;
  /// The instances an aggregate of references points to, in order.
  std::vector<Instance> refs(std::string_view name) const;
  /// The reals of an aggregate (e.g. coordinates).
  std::vector<double> reals(std::string_view name) const;

  /// Follows a reference value (e.g. an aggregate element).
  Instance follow(const p21::Value &v) const;
  const p21::ValueArena &values() const { return arena_; }

private:
  const p21::Value *find(std::string_view name) const;
  static const p21::Value &unwrap(const p21::ValueArena &arena, const p21::Value &v);

  const BoundFile *bound_ = nullptr;
  size_t index_ = 0;
  bool decoded_ = false;
  p21::ValueArena arena_;
};

} // namespace stepnc::binding
