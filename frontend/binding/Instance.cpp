#include "frontend/binding/Instance.h"

namespace stepnc::binding {

using p21::Value;
using p21::ValueKind;

Instance::Instance(const BoundFile &bound, size_t index) : bound_(&bound), index_(index) {
  decoded_ = index < bound.file().entries().size() && bound.file().decodeInstance(index, arena_, nullptr);
}

p21::InstanceId Instance::id() const { return bound_ ? bound_->file().entries()[index_].id : 0; }

express::EntityId Instance::entity() const { return bound_ ? bound_->entity(index_) : express::kNone; }

std::string_view Instance::entityName() const {
  const express::EntityId e = entity();
  return e == express::kNone ? std::string_view() : std::string_view(bound_->model().entity(e).name);
}

bool Instance::isA(std::string_view name) const {
  if (!bound_)
    return false;
  const express::EntityId target = bound_->model().findEntity(bound_->schema(), name);
  return target != express::kNone && bound_->isA(index_, target);
}

SourceLoc Instance::loc() const {
  return bound_ ? bound_->file().loc(bound_->file().entries()[index_].begin()) : SourceLoc{};
}

const Value *Instance::find(std::string_view name) const {
  if (!valid())
    return nullptr;
  const express::Model &model = bound_->model();
  const auto records = arena_.records();
  if (bound_->file().entries()[index_].name() != p21::kComplexInstance) {
    const express::EntityId e = entity();
    if (e == express::kNone)
      return nullptr;
    const auto &slots = model.entity(e).slots;
    const auto params = arena_.params(records[0]);
    for (size_t i = 0; i < slots.size() && i < params.size(); ++i)
      if (slots[i].name == name)
        return &params[i];
    return nullptr;
  }
  // Complex: each record carries the attributes its entity declares.
  const std::vector<express::EntityId> members = bound_->entitySet(index_);
  for (size_t r = 0; r < records.size() && r < members.size(); ++r) {
    const express::Entity &ent = model.entity(members[r]);
    const auto params = arena_.params(records[r]);
    for (size_t k = 0; k < ent.ownSlots.size() && k < params.size(); ++k)
      if (ent.slots[ent.ownSlots[k]].name == name)
        return &params[k];
  }
  return nullptr;
}

const Value *Instance::attr(std::string_view name) const { return find(name); }

int Instance::parameterIndex(std::string_view name) const {
  if (!valid() || bound_->file().entries()[index_].name() == p21::kComplexInstance)
    return -1;
  const Value *v = find(name);
  if (!v)
    return -1;
  const auto params = arena_.params(arena_.records()[0]);
  return static_cast<int>(v - params.data());
}

SourceLoc Instance::attrLoc(std::string_view name) const {
  const Value *v = find(name);
  return v ? bound_->file().loc(bound_->file().entries()[index_].begin() + v->offset) : loc();
}

const Value &Instance::unwrap(const p21::ValueArena &arena, const Value &v) {
  const Value *cur = &v;
  while (cur->kind == ValueKind::Typed && cur->count == 1)
    cur = &arena.children(*cur)[0];
  return *cur;
}

std::optional<double> Instance::real(std::string_view name) const {
  const Value *v = find(name);
  if (!v)
    return std::nullopt;
  const Value &u = unwrap(arena_, *v);
  if (u.kind == ValueKind::Real)
    return u.real;
  if (u.kind == ValueKind::Integer)
    return static_cast<double>(u.integer);
  return std::nullopt;
}

std::optional<int64_t> Instance::integer(std::string_view name) const {
  const Value *v = find(name);
  if (!v)
    return std::nullopt;
  const Value &u = unwrap(arena_, *v);
  return u.kind == ValueKind::Integer ? std::optional<int64_t>(u.integer) : std::nullopt;
}

std::optional<std::string> Instance::string(std::string_view name) const {
  const Value *v = find(name);
  if (!v)
    return std::nullopt;
  const Value &u = unwrap(arena_, *v);
  return u.kind == ValueKind::String ? std::optional<std::string>(std::string(u.str())) : std::nullopt;
}

std::optional<std::string> Instance::enumeration(std::string_view name) const {
  const Value *v = find(name);
  if (!v)
    return std::nullopt;
  const Value &u = unwrap(arena_, *v);
  if (u.kind != ValueKind::Enumeration)
    return std::nullopt;
  return express::lower(u.str());
}

std::optional<bool> Instance::boolean(std::string_view name) const {
  std::optional<std::string> e = enumeration(name);
  if (e == "t")
    return true;
  if (e == "f")
    return false;
  return std::nullopt;
}

Instance Instance::follow(const Value &v) const {
  const Value &u = unwrap(arena_, v);
  if (!bound_ || u.kind != ValueKind::Reference)
    return {};
  const int64_t i = bound_->file().indexOf(u.ref);
  // An instance of an entity the schema does not have reads as absent: the
  // binder reported it (left out, or an error).
  if (i < 0 || bound_->entity(static_cast<size_t>(i)) == express::kNone)
    return Instance();
  return Instance(*bound_, static_cast<size_t>(i));
}

Instance Instance::ref(std::string_view name) const {
  const Value *v = find(name);
  return v ? follow(*v) : Instance();
}

std::vector<Instance> Instance::refs(std::string_view name) const {
  std::vector<Instance> out;
  const Value *v = find(name);
  if (!v || v->kind != ValueKind::List)
    return out;
  for (const Value &c : arena_.children(*v)) {
    Instance target = follow(c);
    if (target)
      out.push_back(std::move(target));
  }
  return out;
}

std::vector<double> Instance::reals(std::string_view name) const {
  std::vector<double> out;
  const Value *v = find(name);
  if (!v || v->kind != ValueKind::List)
    return out;
  for (const Value &c : arena_.children(*v)) {
    const Value &u = unwrap(arena_, c);
    if (u.kind == ValueKind::Real)
      out.push_back(u.real);
    else if (u.kind == ValueKind::Integer)
      out.push_back(static_cast<double>(u.integer));
  }
  return out;
}

} // namespace stepnc::binding
