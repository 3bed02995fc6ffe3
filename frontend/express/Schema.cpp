#include "frontend/express/Schema.h"

#include <algorithm>
#include <functional>
#include <set>

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
  // Depth first without recursion, each supertype once: a plain recursion is
  // exponential in a lattice of diamonds and endless on a cycle (which
  // resolve() rejects, but the model may be queried after errors). An
  // entity is seen in this call when its mark is this call's number, so a
  // call costs what it visits, however many entities the model has.
  thread_local std::vector<EntityId> stack;
  thread_local std::vector<uint32_t> mark;
  thread_local uint32_t call = 0;
  if (mark.size() < entities_.size())
    mark.resize(entities_.size(), 0);
  if (++call == 0) {  // wrapped around: forget every old mark
    std::fill(mark.begin(), mark.end(), 0);
    call = 1;
  }
  stack.assign(1, sub);
  mark[sub] = call;
  while (!stack.empty()) {
    const EntityId e = stack.back();
    stack.pop_back();
    for (EntityId s : entities_[e].supertypes) {
      if (s == super)
        return true;
      if (mark[s] == call)
        continue;
      mark[s] = call;
      stack.push_back(s);
    }
  }
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

constexpr uint32_t kCyclic = UINT32_MAX;

/// Heights of the nodes of a directed graph (1 for a node without successors,
/// else one more than its highest successor; kCyclic for a node on or
/// leading to a cycle), by an iterative depth-first search, so that neither
/// long chains nor cycles can overflow the stack. `onCycle` gets each cycle
/// found (the nodes from the one reached again to the last, in edge order).
template <typename Successors, typename OnCycle>
std::vector<uint32_t> graphHeights(size_t n, Successors successors, OnCycle onCycle) {
  std::vector<uint32_t> height(n, 0);
  std::vector<uint8_t> state(n, 0);  // 0 new, 1 on the stack, 2 done
  std::vector<bool> cyclic(n, false);
  struct Frame {
    uint32_t node;
    size_t next;
  };
  std::vector<Frame> stack;
  for (uint32_t root = 0; root < n; ++root) {
    if (state[root] != 0)
      continue;
    state[root] = 1;
    stack.push_back({root, 0});
    while (!stack.empty()) {
      Frame &f = stack.back();
      const auto &succ = successors(f.node);
      if (f.next < succ.size()) {
        const uint32_t to = succ[f.next++];
        if (to >= n)
          continue;
        if (state[to] == 0) {
          state[to] = 1;
          stack.push_back({to, 0});  // invalidates f
        } else if (state[to] == 1) {
          std::vector<uint32_t> cycle;
          size_t k = stack.size();
          while (k > 0 && stack[k - 1].node != to)
            --k;
          for (size_t j = k - 1; j < stack.size(); ++j) {
            cycle.push_back(stack[j].node);
            cyclic[stack[j].node] = true;
          }
          onCycle(cycle);
        }
        continue;
      }
      uint32_t h = 1;
      for (uint32_t to : succ) {
        if (to >= n)
          continue;
        if (height[to] == kCyclic)
          cyclic[f.node] = true;
        else
          h = std::max(h, height[to] + 1);
      }
      height[f.node] = cyclic[f.node] ? kCyclic : h;
      state[f.node] = 2;
      stack.pop_back();
    }
  }
  return height;
}

/// "a -> b -> a", at most eight names.
template <typename Name>
std::string cycleText(const std::vector<uint32_t> &cycle, Name name) {
  std::string out;
  for (size_t i = 0; i < cycle.size() && i < 8; ++i)
    out += name(cycle[i]) + " -> ";
  if (cycle.size() > 8)
    out += "... (" + std::to_string(cycle.size()) + " in all) -> ";
  return out + name(cycle.front());
}

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

  std::unordered_map<std::string_view, size_t> schemaByName;
  uint64_t scopeNames = 0;
  bool scopeFull = false;

  int schemaIndex(std::string_view name) const {
    auto it = schemaByName.find(name);
    return it == schemaByName.end() ? -1 : static_cast<int>(it->second);
  }

  void addOwnNames(size_t si) {
    state[si] = 1;
    Schema &s = schemas[si];
    for (EntityId e : s.entities)
      s.scope[entities[e].name] = {true, e};
    for (DeclTypeId t : s.types)
      s.scope[types[t].name] = {false, t};
    scopeNames += s.scope.size();
  }

  // Builds the scopes of `root` and the schemas it interfaces, depth first
  // without recursion (a chain of USE FROM may be as long as the input). A
  // schema reached again while it is being built (schemas that use each
  // other) contributes the names it has so far, as before.
  void buildScope(size_t root) {
    if (state[root] != 0)
      return;
    struct Frame {
      size_t si;
      size_t next;  // the interface to merge next
    };
    std::vector<Frame> stack;
    addOwnNames(root);
    stack.push_back({root, 0});
    while (!stack.empty()) {
      const Frame f = stack.back();
      const Schema &s = schemas[f.si];
      if (f.next == s.interfaces.size()) {
        state[f.si] = 2;
        stack.pop_back();
        continue;
      }
      const int target = schemaIndex(s.interfaces[f.next].schema);
      if (target >= 0 && state[static_cast<size_t>(target)] == 0) {
        addOwnNames(static_cast<size_t>(target));
        stack.push_back({static_cast<size_t>(target), 0});
        continue;
      }
      mergeInterface(f.si, s.interfaces[f.next], target);
      ++stack.back().next;
    }
  }

  void addName(Schema &s, const Interface &iface, const std::string &name, std::pair<bool, uint32_t> ref) {
    if (scopeFull || !s.scope.emplace(name, ref).second)
      return;
    if (++scopeNames > kMaxScopeNames) {
      diags.error(iface.loc, "the schemas make more than " + std::to_string(kMaxScopeNames) +
                                 " names visible in all (through USE FROM and REFERENCE FROM); stopped here");
      scopeFull = true;
      ok = false;
    }
  }

  void mergeInterface(size_t si, const Interface &iface, int target) {
    Schema &s = schemas[si];
    if (target < 0) {
      diags.error(iface.loc, "schema '" + s.name + "' " + (iface.use ? "uses" : "references") + " schema '" +
                                 iface.schema + "', which is not loaded")
          .note("give the EXPRESS file that declares it as well; names it provides stay unresolved");
      incomplete[si] = true;
      ok = false;
      return;
    }
    if (incomplete[static_cast<size_t>(target)])
      incomplete[si] = true;
    const Schema &from = schemas[static_cast<size_t>(target)];
    if (iface.items.empty()) {
      if (&from == &s)
        return;  // USE FROM itself: nothing to add (and no iterating a map while inserting into it)
      for (const auto &[name, ref] : from.scope)
        addName(s, iface, name, ref);
      return;
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
      addName(s, iface, rename.empty() ? name : rename, it->second);
    }
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
  Resolver r{*this, schemas_, entities_, typeDecls_, typeExprs_, diags, {}, {}, {}, true, {}, 0, false};
  for (size_t si = 0; si < schemas_.size(); ++si)
    r.schemaByName.emplace(schemas_[si].name, si);
  r.state.assign(schemas_.size(), 0);
  r.incomplete.assign(schemas_.size(), false);
  r.unresolvedQuiet.assign(schemas_.size(), 0);
  for (size_t si = 0; si < schemas_.size(); ++si)
    r.buildScope(si);

  // Which declarations each type declaration is made of: the type it renames
  // (TYPE a = b), its SELECT members that are types, its BASED_ON base. A
  // cycle among them (TYPE t = t, a SELECT that is its own member) has no
  // values, and everything that follows defined types would loop on it.
  std::vector<std::vector<uint32_t>> typeRefs(typeDecls_.size());
  for (size_t si = 0; si < schemas_.size(); ++si) {
    Schema &s = schemas_[si];
    for (DeclTypeId t : s.types) {
      TypeDecl &decl = typeDecls_[t];
      r.resolveType(si, decl.underlying, decl.loc, "type '" + decl.name + "'");
      if (decl.underlying != kNone) {
        const TypeExpr &u = typeExprs_[decl.underlying];
        if (u.kind == TypeExpr::Named && u.declared != kNone)
          typeRefs[t].push_back(u.declared);
      }
      if (!decl.basedOn.empty())
        if (DeclTypeId base = findType(s, decl.basedOn); base != kNone)
          typeRefs[t].push_back(base);
      for (const std::string &item : decl.selectItems) {
        if (!s.scope.count(item)) {
          if (r.incomplete[si]) {
            ++r.unresolvedQuiet[si];
          } else {
            diags.error(decl.loc, "unknown type '" + item + "' in SELECT type '" + decl.name + "'");
            r.ok = false;
          }
          continue;
        }
        if (DeclTypeId member = findType(s, item); member != kNone)
          typeRefs[t].push_back(member);
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

  auto typeName = [&](uint32_t t) { return typeDecls_[t].name; };
  const std::vector<uint32_t> typeHeights = graphHeights(
      typeDecls_.size(), [&](uint32_t t) -> const std::vector<uint32_t> & { return typeRefs[t]; },
      [&](const std::vector<uint32_t> &cycle) {
        diags.error(typeDecls_[cycle.front()].loc, "type '" + typeName(cycle.front()) +
                                                       "' is defined in terms of itself: " +
                                                       cycleText(cycle, typeName));
        r.ok = false;
      });
  for (DeclTypeId t = 0; t < typeDecls_.size(); ++t)
    if (typeHeights[t] == kMaxTypeDepth + 1) {  // only where the chain crosses the limit
      diags.error(typeDecls_[t].loc, "type '" + typeDecls_[t].name + "' is built from a chain of more than " +
                                         std::to_string(kMaxTypeDepth) +
                                         " defined types (TYPE a = b, SELECT members, BASED_ON)");
      r.ok = false;
    }

  // Supertype chains: cycles and depth first, so that computing the
  // attribute lists (recursive, and storing each entity's inherited
  // attributes) only ever sees a finite, shallow hierarchy.
  auto entityName = [&](uint32_t e) { return entities_[e].name; };
  const std::vector<uint32_t> depth = graphHeights(
      entities_.size(), [&](uint32_t e) -> const std::vector<EntityId> & { return entities_[e].supertypes; },
      [&](const std::vector<uint32_t> &cycle) {
        diags.error(entities_[cycle.front()].loc, "entity '" + entityName(cycle.front()) +
                                                      "' is its own supertype (inheritance cycle: " +
                                                      cycleText(cycle, entityName) + ")");
        r.ok = false;
      });
  std::vector<uint8_t> state(entities_.size(), 0);
  for (EntityId e = 0; e < entities_.size(); ++e) {
    if (depth[e] == kCyclic || depth[e] > kMaxInheritanceDepth) {
      if (depth[e] == kMaxInheritanceDepth + 1) {  // only where the chain crosses the limit
        diags.error(entities_[e].loc, "entity '" + entities_[e].name + "' has a chain of more than " +
                                          std::to_string(kMaxInheritanceDepth) + " supertypes above it");
      }
      r.ok = false;
      state[e] = 3;  // left without attribute list
    }
  }
  uint64_t totalSlots = 0;
  for (EntityId e = 0; e < entities_.size(); ++e)
    if (!computeSlots(e, state, totalSlots, diags))
      r.ok = false;
  return r.ok;
}

// Recursive over supertypes: resolve() has checked the hierarchy is acyclic
// and at most kMaxInheritanceDepth deep (state 3 marks the entities it left
// out), so the recursion is bounded.
bool Model::computeSlots(EntityId id, std::vector<uint8_t> &state, uint64_t &total, DiagnosticEngine &diags) {
  if (state[id] == 2)
    return true;
  if (state[id] != 0)
    return false;  // left out (reported already), or on a cycle
  Entity &e = entities_[id];
  state[id] = 1;
  bool ok = true;
  std::vector<Slot> slots;
  // Owner and original attribute name identify an inherited attribute, so a
  // supertype reached twice (diamond inheritance) contributes its attributes
  // once. The names point into the supertypes' slots, which stay put here.
  std::set<std::pair<EntityId, std::string_view>> identity;
  for (EntityId sup : e.supertypes) {
    if (!computeSlots(sup, state, total, diags)) {
      ok = false;
      continue;
    }
    const Entity &s = entities_[sup];
    for (const Slot &slot : s.slots)
      if (identity.emplace(slot.owner, slot.name).second)
        slots.push_back(slot);
  }
  // Each entity stores its inherited attributes, so what a hierarchy costs
  // grows with its depth times its width: bound both.
  const uint64_t need = slots.size() + e.attributes.size();
  if (need > kMaxEntitySlots) {
    diags.error(e.loc, "entity '" + e.name + "' has more than " + std::to_string(kMaxEntitySlots) +
                           " attributes, counting inherited ones");
    state[id] = 3;
    return false;
  }
  if (total + need > kMaxModelSlots) {
    if (total <= kMaxModelSlots)  // once
      diags.error(e.loc, "the entities have more than " + std::to_string(kMaxModelSlots) +
                             " attributes in all, counting inherited ones; stopped at entity '" + e.name + "'");
    total = kMaxModelSlots + 1;
    state[id] = 3;
    return false;
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
  total += slots.size();
  e.slots = std::move(slots);
  e.ownSlots = std::move(own);
  state[id] = 2;
  return ok;
}

} // namespace stepnc::express
