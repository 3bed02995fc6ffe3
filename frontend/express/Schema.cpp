#include "frontend/express/Schema.h"

#include <algorithm>
#include <functional>

namespace stepnc::express {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char &c : out)
    if (c >= 'A' && c <= 'Z')
      c = static_cast<char>(c + 32);
  return out;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char &c : out)
    if (c >= 'a' && c <= 'z')
      c = static_cast<char>(c - 'a' + 'A');
  return out;
}

const char *simpleKindName(SimpleKind k) {
  switch (k) {
  case SimpleKind::Binary: return "BINARY";
  case SimpleKind::Boolean: return "BOOLEAN";
  case SimpleKind::Integer: return "INTEGER";
  case SimpleKind::Logical: return "LOGICAL";
  case SimpleKind::Number: return "NUMBER";
  case SimpleKind::Real: return "REAL";
  case SimpleKind::String: return "STRING";
  }
  return "?";
}

const char *aggregateKindName(AggregateKind k) {
  switch (k) {
  case AggregateKind::Array: return "ARRAY";
  case AggregateKind::Bag: return "BAG";
  case AggregateKind::List: return "LIST";
  case AggregateKind::Set: return "SET";
  }
  return "?";
}

TypeId Model::addTypeExpr(TypeExpr t) {
  typeExprs_.push_back(std::move(t));
  return static_cast<TypeId>(typeExprs_.size() - 1);
}

EntityId Model::addEntity(Entity e) {
  entities_.push_back(std::move(e));
  return static_cast<EntityId>(entities_.size() - 1);
}

DeclTypeId Model::addTypeDecl(TypeDecl t) {
  typeDecls_.push_back(std::move(t));
  return static_cast<DeclTypeId>(typeDecls_.size() - 1);
}

Schema &Model::addSchema(std::string name, SourceLoc loc) {
  Schema s;
  s.name = lower(name);
  s.loc = loc;
  schemas_.push_back(std::move(s));
  return schemas_.back();
}

const Schema *Model::findSchema(std::string_view name) const {
  const std::string key = lower(name);
  for (const Schema &s : schemas_)
    if (s.name == key)
      return &s;
  return nullptr;
}

EntityId Model::findEntity(const Schema &schema, std::string_view name) const {
  auto it = schema.scope.find(std::string(name));
  if (it == schema.scope.end() || !it->second.first)
    return kNone;
  return it->second.second;
}

DeclTypeId Model::findType(const Schema &schema, std::string_view name) const {
  auto it = schema.scope.find(std::string(name));
  if (it == schema.scope.end() || it->second.first)
    return kNone;
  return it->second.second;
}

bool Model::isSubtypeOf(EntityId sub, EntityId super) const {
  if (sub == super)
    return true;
  for (EntityId s : entities_[sub].supertypes)
    if (isSubtypeOf(s, super))
      return true;
  return false;
}

const Expr *Model::whereExpression(const WhereRule &rule) const {
  if (!rule.expr)
    rule.expr = parseExpression(rule.text);
  return rule.expr.get();
}

std::string Model::typeText(TypeId id) const {
  if (id == kNone)
    return "?";
  const TypeExpr &t = typeExprs_[id];
  switch (t.kind) {
  case TypeExpr::Simple: return simpleKindName(t.simple);
  case TypeExpr::Named: return t.name;
  case TypeExpr::Select: return "SELECT";
  case TypeExpr::Enumeration: return "ENUMERATION";
  case TypeExpr::Generic: return "GENERIC";
  case TypeExpr::Aggregate: {
    std::string s = aggregateKindName(t.aggregate);
    s += " [" + std::to_string(t.lower) + ":" + (t.upper < 0 ? std::string("?") : std::to_string(t.upper)) + "] OF ";
    if (t.optionalElements)
      s += "OPTIONAL ";
    if (t.unique)
      s += "UNIQUE ";
    return s + typeText(t.element);
  }
  }
  return "?";
}

namespace {

// Scope building state per schema: 0 not built, 1 building, 2 built.
struct Resolver {
  Model &model;
  std::vector<Schema> &schemas;
  std::vector<Entity> &entities;
  std::vector<TypeDecl> &types;
  std::vector<TypeExpr> &exprs;
  DiagnosticEngine &diags;
  std::vector<uint8_t> state;
  std::vector<bool> incomplete;  // a schema with a missing interfaced schema
  std::vector<unsigned> unresolvedQuiet;
  bool ok = true;

  int schemaIndex(std::string_view name) {
    for (size_t i = 0; i < schemas.size(); ++i)
      if (schemas[i].name == name)
        return static_cast<int>(i);
    return -1;
  }

  void buildScope(size_t si) {
    if (state[si] != 0)
      return;
    state[si] = 1;
    Schema &s = schemas[si];
    for (EntityId e : s.entities)
      s.scope[entities[e].name] = {true, e};
    for (DeclTypeId t : s.types)
      s.scope[types[t].name] = {false, t};
    for (const Interface &iface : s.interfaces) {
      int target = schemaIndex(iface.schema);
      if (target < 0) {
        diags.error(iface.loc, "schema '" + s.name + "' " + (iface.use ? "uses" : "references") +
                                   " schema '" + iface.schema + "', which is not loaded")
            .note("give the EXPRESS file that declares it as well; names it provides stay unresolved");
        incomplete[si] = true;
        ok = false;
        continue;
      }
      buildScope(static_cast<size_t>(target));
      if (incomplete[static_cast<size_t>(target)])
        incomplete[si] = true;
      const Schema &from = schemas[static_cast<size_t>(target)];
      if (iface.items.empty()) {
        for (const auto &[name, ref] : from.scope)
          s.scope.emplace(name, ref);
        continue;
      }
      for (const auto &[name, rename] : iface.items) {
        auto it = from.scope.find(name);
        if (it == from.scope.end()) {
          if (!incomplete[static_cast<size_t>(target)]) {
            diags.error(iface.loc, "'" + name + "' is not declared in schema '" + from.name + "'");
            ok = false;
          }
          continue;
        }
        s.scope.emplace(rename.empty() ? name : rename, it->second);
      }
    }
    state[si] = 2;
  }

  // Resolves a type expression in schema `si`; `what` describes its place.
  void resolveType(size_t si, TypeId id, SourceLoc loc, const std::string &what) {
    if (id == kNone)
      return;
    TypeExpr &t = exprs[id];
    if (t.kind == TypeExpr::Aggregate) {
      resolveType(si, t.element, loc, what);
      return;
    }
    if (t.kind != TypeExpr::Named)
      return;
    auto it = schemas[si].scope.find(t.name);
    if (it == schemas[si].scope.end()) {
      if (incomplete[si]) {
        ++unresolvedQuiet[si];
      } else {
        diags.error(loc, "unknown type '" + t.name + "' in " + what);
        ok = false;
      }
      return;
    }
    if (it->second.first)
      t.entity = it->second.second;
    else
      t.declared = it->second.second;
  }
};

} // namespace

bool Model::resolve(DiagnosticEngine &diags) {
  Resolver r{*this, schemas_, entities_, typeDecls_, typeExprs_, diags, {}, {}, {}, true};
  r.state.assign(schemas_.size(), 0);
  r.incomplete.assign(schemas_.size(), false);
  r.unresolvedQuiet.assign(schemas_.size(), 0);
  for (size_t si = 0; si < schemas_.size(); ++si)
    r.buildScope(si);

  for (size_t si = 0; si < schemas_.size(); ++si) {
    Schema &s = schemas_[si];
    for (DeclTypeId t : s.types) {
      TypeDecl &decl = typeDecls_[t];
      r.resolveType(si, decl.underlying, decl.loc, "type '" + decl.name + "'");
      for (const std::string &item : decl.selectItems)
        if (!s.scope.count(item)) {
          if (r.incomplete[si]) {
            ++r.unresolvedQuiet[si];
          } else {
            diags.error(decl.loc, "unknown type '" + item + "' in SELECT type '" + decl.name + "'");
            r.ok = false;
          }
        }
    }
    for (EntityId e : s.entities) {
      Entity &ent = entities_[e];
      for (Attribute &a : ent.attributes)
        r.resolveType(si, a.type, a.loc, "attribute '" + a.name + "' of entity '" + ent.name + "'");
      for (DerivedAttribute &d : ent.derived)
        r.resolveType(si, d.type, ent.loc, "derived attribute '" + d.name + "' of entity '" + ent.name + "'");
      ent.supertypes.clear();
      for (const std::string &sup : ent.supertypeNames) {
        EntityId id = findEntity(s, sup);
        if (id == kNone) {
          if (r.incomplete[si]) {
            ++r.unresolvedQuiet[si];
          } else {
            diags.error(ent.loc, "entity '" + ent.name + "' is a subtype of unknown entity '" + sup + "'");
            r.ok = false;
          }
          continue;
        }
        ent.supertypes.push_back(id);
      }
    }
    if (r.unresolvedQuiet[si] > 0)
      diags.report(Severity::Note, s.loc,
                   std::to_string(r.unresolvedQuiet[si]) + " name(s) in schema '" + s.name +
                       "' stay unresolved because interfaced schemas are missing");
  }
  for (EntityId e = 0; e < entities_.size(); ++e) {
    entities_[e].subtypes.clear();
  }
  for (EntityId e = 0; e < entities_.size(); ++e)
    for (EntityId sup : entities_[e].supertypes)
      entities_[sup].subtypes.push_back(e);

  std::vector<uint8_t> state(entities_.size(), 0);
  for (EntityId e = 0; e < entities_.size(); ++e)
    if (!computeSlots(e, state, diags))
      r.ok = false;
  return r.ok;
}

bool Model::computeSlots(EntityId id, std::vector<uint8_t> &state, DiagnosticEngine &diags) {
  if (state[id] == 2)
    return true;
  Entity &e = entities_[id];
  if (state[id] == 1) {
    diags.error(e.loc, "entity '" + e.name + "' is its own supertype (inheritance cycle)");
    return false;
  }
  state[id] = 1;
  bool ok = true;
  std::vector<Slot> slots;
  // Owner and original attribute name identify an inherited attribute, so a
  // supertype reached twice (diamond inheritance) contributes its attributes once.
  std::vector<std::pair<EntityId, std::string>> identity;
  for (EntityId sup : e.supertypes) {
    if (!computeSlots(sup, state, diags)) {
      ok = false;
      continue;
    }
    const Entity &s = entities_[sup];
    for (size_t k = 0; k < s.slots.size(); ++k) {
      const Slot &slot = s.slots[k];
      std::pair<EntityId, std::string> key{slot.owner, slot.name};
      if (std::find(identity.begin(), identity.end(), key) != identity.end())
        continue;
      identity.push_back(key);
      slots.push_back(slot);
    }
  }
  std::vector<uint32_t> own;
  auto findSlot = [&](const std::string &entity, const std::string &attr) -> Slot * {
    // Prefer the slot first declared by `entity`; else any slot of that name.
    Slot *any = nullptr;
    for (Slot &s : slots) {
      if (s.name != attr)
        continue;
      if (s.owner != kNone && entities_[s.owner].name == entity)
        return &s;
      any = &s;
    }
    return any;
  };
  for (const Attribute &a : e.attributes) {
    if (a.isRedeclaration()) {
      Slot *s = findSlot(a.redeclaresEntity, a.redeclaresAttribute);
      if (!s) {
        diags.error(a.loc, "entity '" + e.name + "' redeclares '" + a.redeclaresEntity + "." +
                               a.redeclaresAttribute + "', which it does not inherit");
        ok = false;
        continue;
      }
      s->type = a.type;
      s->optional = a.optional;
      s->name = a.name;  // RENAMED, or the same name
      continue;
    }
    own.push_back(static_cast<uint32_t>(slots.size()));
    slots.push_back({a.name, a.type, a.optional, false, id});
  }
  for (const DerivedAttribute &d : e.derived) {
    if (d.redeclaresAttribute.empty())
      continue;
    Slot *s = findSlot(d.redeclaresEntity, d.redeclaresAttribute);
    if (!s) {
      diags.error(e.loc, "entity '" + e.name + "' derives '" + d.redeclaresEntity + "." +
                             d.redeclaresAttribute + "', which it does not inherit");
      ok = false;
      continue;
    }
    s->derived = true;
    s->name = d.name;
  }
  e.slots = std::move(slots);
  e.ownSlots = std::move(own);
  state[id] = 2;
  return ok;
}

} // namespace stepnc::express
