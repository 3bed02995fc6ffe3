#include "frontend/binding/Binder.h"

#include "ir/Plausible.h"
#include "support/Format.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <set>

namespace stepnc::binding {

using express::DeclTypeId;
using express::EntityId;
using express::kNone;
using express::TypeExpr;
using express::TypeId;
using p21::Value;
using p21::ValueKind;

EntityId BoundFile::entity(size_t index) const {
  const p21::NameId name = file_.entries()[index].name();
  if (name == p21::kComplexInstance) {
    auto it = complex_.find(static_cast<uint32_t>(index));
    return it == complex_.end() ? kNone : it->second.mostSpecific;
  }
  return name < byName_.size() ? byName_[name] : kNone;
}

std::vector<EntityId> BoundFile::entitySet(size_t index) const {
  if (file_.entries()[index].name() == p21::kComplexInstance) {
    auto it = complex_.find(static_cast<uint32_t>(index));
    return it == complex_.end() ? std::vector<EntityId>{} : it->second.members;
  }
  const EntityId e = entity(index);
  return e == kNone ? std::vector<EntityId>{} : std::vector<EntityId>{e};
}

bool BoundFile::isA(size_t index, EntityId of) const {
  if (file_.entries()[index].name() != p21::kComplexInstance) {
    const EntityId e = entity(index);
    return e != kNone && model_.isSubtypeOf(e, of);
  }
  auto it = complex_.find(static_cast<uint32_t>(index));
  if (it == complex_.end())
    return false;
  for (EntityId m : it->second.members)
    if (model_.isSubtypeOf(m, of))
      return true;
  return false;
}

namespace {

// "a tool", "an elementary_surface".
std::string article(std::string_view word) {
  const char c = word.empty() ? 'x' : word[0];
  const bool vowel = c == 'a' || c == 'e' || c == 'i' || c == 'o' || c == 'u' || c == 'A' || c == 'E' ||
                     c == 'I' || c == 'O' || c == 'U';
  return std::string(vowel ? "an " : "a ") + std::string(word);
}

size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j)
    prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}


/// What a SELECT type admits, with nested SELECTs flattened.
struct SelectClosure {
  std::set<EntityId> entities;
  std::set<DeclTypeId> types;  ///< non-entity members (defined types, nested selects)
};

} // namespace

class Binder {
public:
  Binder(const p21::Part21File &file, const express::Model &model, const express::Schema &schema,
         DiagnosticEngine &diags, const BindOptions &options, BoundFile &out)
      : file_(file), model_(model), schema_(schema), diags_(diags), aliases_(*options.aliases),
        options_(options), out_(out) {}

  void run();

private:
  // Where a value sits, for messages.
  struct Context {
    size_t entry;
    const express::Slot *slot;
    size_t position;   ///< 1-based attribute position
    std::string path;  ///< element path inside aggregates, e.g. "[2]"
  };

  EntityId lookup(std::string_view upperName, uint64_t offset);
  void reportUnknown(size_t index, std::string_view name, uint64_t at);
  void checkInstance(size_t index, const p21::ValueArena &values);
  /// Checks one record: a whole instance's (`members` empty) or the record of
  /// `entity` in a complex instance of `members`.
  void checkRecord(size_t index, const p21::Record &rec, EntityId entity,
                   const std::vector<EntityId> *members = nullptr);
  const express::Slot &effectiveSlot(EntityId entity, uint32_t ownIndex, const std::vector<EntityId> &members,
                                     EntityId &derivedBy) const;
  void checkComplex(size_t index, const std::vector<EntityId> &set, uint64_t at);
  bool checkValue(const Value &v, TypeId type, const Context &ctx, bool optionalAllowed);
  bool checkNamed(const Value &v, const TypeExpr &t, const Context &ctx);
  bool checkDeclared(const Value &v, const TypeExpr &t, const Context &ctx);
  bool checkSelect(const Value &v, DeclTypeId decl, const Context &ctx);
  const SelectClosure &closure(DeclTypeId decl);
  std::vector<std::string> enumValues(DeclTypeId decl);

  InFlightDiagnostic error(const Context &ctx, const Value &v, const std::string &message);
  std::string describe(const Value &v) const;
  std::string expected(TypeId type) const;
  std::string entityName(size_t index) const;
  const p21::InstanceEntry &entry(size_t i) const { return file_.entries()[i]; }

  const p21::Part21File &file_;
  const express::Model &model_;
  const express::Schema &schema_;
  DiagnosticEngine &diags_;
  const AliasTable &aliases_;
  const BindOptions &options_;
  BoundFile &out_;
  const p21::ValueArena *arena_ = nullptr;  ///< the instance being checked
  /// Set in a binder that tries an untyped SELECT value against one member
  /// type: it does not try again for values inside that value, so trying
  /// stays linear in the value's size (nested SELECTs of aggregates of
  /// SELECTs would otherwise multiply the alternatives at every level).
  bool probing_ = false;
  /// Defined types followed in a row for one value (TYPE a = b; TYPE b = c).
  /// resolve() rejects cycles and bounds the chains; this keeps any model
  /// from making checkNamed recurse without end.
  unsigned namedChain_ = 0;
  /// Checks `v` (a value inside the current one: an aggregate element, a
  /// typed value's content) with a fresh chain count.
  bool checkInner(const Value &v, TypeId type, const Context &ctx, bool optionalAllowed) {
    const unsigned saved = namedChain_;
    namedChain_ = 0;
    const bool ok = checkValue(v, type, ctx, optionalAllowed);
    namedChain_ = saved;
    return ok;
  }
  p21::ValueArena scratch_;                  ///< for decoding complex instances in pass 1
  std::map<DeclTypeId, SelectClosure> closures_;
  struct AliasUse {
    uint64_t first;
    size_t count;
    std::string target;
  };
  std::map<std::string, AliasUse> aliasUses_;
  size_t intForReal_ = 0;
  uint64_t firstIntForReal_ = 0;
  // `$` in a mandatory attribute that real writers use for "empty" or "no name".
  /// What a `$` in a mandatory attribute of this type is read as: common
  /// drift (an empty aggregate, '', the general tolerance) tallied in one
  /// warning; false for a BOOLEAN (a warning per instance); else absent.
  enum class Drift { None, EmptyAggregate, MissingString, MissingTolerance, Boolean };
  Drift driftOf(TypeId type) const;
  struct Tally {
    size_t count = 0;
    uint64_t first = 0;
  };
  Tally unsetAggregate_, unsetString_, unsetTolerance_;
  void reportTally(const Tally &t, const std::string &what);
  std::map<std::string, std::string> suggestions_;  ///< unknown name -> closest entity
  /// An instance of an entity no schema of the model has, with no close
  /// name (a writer's own entity, not a typo): where it is referred to.
  /// With the lenient reading it is left out when only optional attributes
  /// refer to it (a warning); else it is an error.
  struct Unknown {
    std::string name;
    uint64_t at = 0;
    std::vector<std::string> optionalUses;  ///< "'its_machining_strategy' of #31"
    bool needed = false;
  };
  std::map<size_t, Unknown> unknown_;
  /// A reference from `ctx` to instance `target`, whose entity is unknown.
  void referToUnknown(size_t target, const Context &ctx);
  /// The closest entity name of the schema to unknown `name` ("" if none is
  /// close), and the other schema of the model that declares it ("" if none).
  std::pair<std::string, std::string> nearest(std::string_view name);
};

Binder::Drift Binder::driftOf(TypeId type) const {
  // Follow defined types down to what they are.
  for (uint32_t guard = 0; guard <= express::kMaxTypeDepth && type != kNone; ++guard) {
    const TypeExpr &t = model_.type(type);
    if (t.kind == TypeExpr::Aggregate)
      return t.lower == 0 ? Drift::EmptyAggregate : Drift::None;
    if (t.kind == TypeExpr::Simple)
      return t.simple == express::SimpleKind::String    ? Drift::MissingString
             : t.simple == express::SimpleKind::Boolean ? Drift::Boolean
                                                        : Drift::None;
    if (t.kind != TypeExpr::Named || t.declared == kNone)
      return Drift::None;
    const express::TypeDecl &decl = model_.typeDecl(t.declared);
    if (decl.name == "tolerance_select")  // ISO 14649-10: the tolerance of a toleranced length
      return Drift::MissingTolerance;
    type = decl.underlying;
  }
  return Drift::None;
}

void Binder::reportTally(const Tally &t, const std::string &what) {
  if (t.count == 0)
    return;
  diags_.warning(file_.loc(t.first), what + " (" + std::to_string(t.count) + (t.count == 1 ? " place" : " places") +
                                         "; --strict makes each an error)");
}

EntityId Binder::lookup(std::string_view upperName, uint64_t offset) {
  const std::string name = express::lower(upperName);
  EntityId id = model_.findEntity(schema_, name);
  if (id != kNone)
    return id;
  std::string_view target = aliases_.entity(upperName);
  if (!target.empty()) {
    id = model_.findEntity(schema_, target);
    if (id != kNone) {
      auto [it, fresh] = aliasUses_.try_emplace(std::string(upperName), AliasUse{offset, 0, std::string(target)});
      ++it->second.count;
      return id;
    }
  }
  return kNone;
}

std::pair<std::string, std::string> Binder::nearest(std::string_view name) {
  // One suggestion per distinct unknown name.
  auto [it, fresh] = suggestions_.try_emplace(std::string(name));
  const std::string lowered = express::lower(name);
  if (fresh) {
    size_t bestDist = 4;
    for (const auto &[candidate, ref] : schema_.scope) {
      if (!ref.first)
        continue;
      size_t d = editDistance(lowered, candidate);
      if (d < bestDist || (d == bestDist && candidate < it->second)) {
        bestDist = d;
        it->second = candidate;
      }
    }
  }
  for (const express::Schema &other : model_.schemas())
    if (&other != &schema_)
      if (auto found = other.scope.find(lowered); found != other.scope.end() && found->second.first)
        return {it->second, other.name};
  return {it->second, ""};
}

void Binder::reportUnknown(size_t index, std::string_view name, uint64_t at) {
  const auto [best, declaredIn] = nearest(name);
  auto d = diags_.error(file_.loc(at), "unknown entity '" + std::string(name) + "' in schema '" + schema_.name + "'");
  d.entity(entry(index).id, std::string(name));
  // A name another schema of the model declares: the file forgot to list it.
  if (!declaredIn.empty()) {
    d.note("'" + express::lower(name) + "' is declared in schema '" + declaredIn + "': list '" +
           express::upper(declaredIn) + "' in the file's FILE_SCHEMA");
    return;
  }
  if (!best.empty())
    d.note("did you mean '" + best + "'?");
}

void Binder::referToUnknown(size_t target, const Context &ctx) {
  auto it = unknown_.find(target);
  if (it == unknown_.end())
    return;
  if (ctx.slot && ctx.slot->optional && ctx.path.empty())
    it->second.optionalUses.push_back("'" + ctx.slot->name + "' of #" + std::to_string(entry(ctx.entry).id));
  else
    it->second.needed = true;
}

std::string Binder::entityName(size_t index) const { return file_.describe(entry(index)); }

InFlightDiagnostic Binder::error(const Context &ctx, const Value &v, const std::string &message) {
  const p21::InstanceEntry &e = entry(ctx.entry);
  std::string where;
  if (ctx.slot)
    where = "attribute " + std::to_string(ctx.position) + " '" + ctx.slot->name + "'" + ctx.path + ": ";
  auto d = diags_.error(file_.loc(e.begin() + v.offset), where + message);
  d.entity(e.id, entityName(ctx.entry));
  return d;
}

std::string Binder::describe(const Value &v) const {
  switch (v.kind) {
  case ValueKind::Unset: return "'$'";
  case ValueKind::Derived: return "'*'";
  case ValueKind::Integer: return "the integer " + std::to_string(v.integer);
  case ValueKind::Real: return "the real " + formatShortest(v.real);
  case ValueKind::String: return "a string";
  case ValueKind::Binary: return "a binary";
  case ValueKind::Enumeration: return "." + std::string(v.str()) + ".";
  case ValueKind::Reference: {
    int64_t i = file_.indexOf(v.ref);
    if (i < 0)
      return hashId(v.ref);
    return hashId(v.ref) + " " + entityName(static_cast<size_t>(i));
  }
  case ValueKind::List: return "a list of " + std::to_string(v.count);
  case ValueKind::Typed: return "a typed " + std::string(file_.names().name(v.node.name)) + " value";
  }
  return "a value";
}

std::string Binder::expected(TypeId id) const {
  const TypeExpr &t = model_.type(id);
  switch (t.kind) {
  case TypeExpr::Simple: return simpleKindName(t.simple);
  case TypeExpr::Aggregate: return article(model_.typeText(id));
  case TypeExpr::Named:
    if (t.entity != kNone)
      return "a reference to " + t.name;
    return article(t.name);
  default: return model_.typeText(id);
  }
}

const SelectClosure &Binder::closure(DeclTypeId decl) {
  auto it = closures_.find(decl);
  if (it != closures_.end())
    return it->second;
  SelectClosure c;
  std::vector<DeclTypeId> stack{decl};
  std::set<DeclTypeId> seen;
  while (!stack.empty()) {
    DeclTypeId d = stack.back();
    stack.pop_back();
    if (!seen.insert(d).second)
      continue;
    const express::TypeDecl &td = model_.typeDecl(d);
    std::vector<std::string> items = td.selectItems;
    if (!td.basedOn.empty()) {
      DeclTypeId base = model_.findType(schema_, td.basedOn);
      if (base != kNone)
        stack.push_back(base);
    }
    for (const std::string &item : items) {
      EntityId e = model_.findEntity(schema_, item);
      if (e != kNone) {
        c.entities.insert(e);
        continue;
      }
      DeclTypeId t = model_.findType(schema_, item);
      if (t == kNone)
        continue;
      c.types.insert(t);
      if (model_.type(model_.typeDecl(t).underlying).kind == TypeExpr::Select)
        stack.push_back(t);
    }
  }
  return closures_.emplace(decl, std::move(c)).first->second;
}

std::vector<std::string> Binder::enumValues(DeclTypeId decl) {
  std::vector<std::string> values;
  std::set<DeclTypeId> seen;
  while (decl != kNone && seen.insert(decl).second) {
    const express::TypeDecl &td = model_.typeDecl(decl);
    values.insert(values.end(), td.enumValues.begin(), td.enumValues.end());
    decl = td.basedOn.empty() ? kNone : model_.findType(schema_, td.basedOn);
  }
  return values;
}

bool Binder::checkSelect(const Value &v, DeclTypeId decl, const Context &ctx) {
  const SelectClosure &c = closure(decl);
  const express::TypeDecl &td = model_.typeDecl(decl);
  if (v.kind == ValueKind::Reference) {
    int64_t i = file_.indexOf(v.ref);
    if (i < 0)
      return true;  // dangling: reported by the Part 21 check
    if (out_.entity(static_cast<size_t>(i)) == kNone) {
      referToUnknown(static_cast<size_t>(i), ctx);
      return true;  // the target's own entity is unknown: reported there
    }
    for (EntityId e : c.entities)
      if (out_.isA(static_cast<size_t>(i), e))
        return true;
    std::string members;
    for (EntityId e : c.entities)
      members += (members.empty() ? "" : ", ") + model_.entity(e).name;
    error(ctx, v, "expected a reference to an entity of SELECT type '" + td.name + "' (" +
                      (members.empty() ? std::string("none") : members) + "), found " + describe(v));
    return false;
  }
  if (v.kind == ValueKind::Typed) {
    const std::string name = express::lower(file_.names().name(v.node.name));
    DeclTypeId t = model_.findType(schema_, name);
    if (t == kNone || !c.types.count(t)) {
      std::string members;
      for (DeclTypeId m : c.types)
        members += (members.empty() ? "" : ", ") + model_.typeDecl(m).name;
      error(ctx, v, "type '" + name + "' is not a member of SELECT type '" + td.name + "'" +
                        (members.empty() ? std::string() : " (types: " + members + ")"));
      return false;
    }
    const Value &inner = arena_->children(v)[0];
    return checkInner(inner, model_.typeDecl(t).underlying, ctx, false);
  }
  // An untyped simple value: the standard wants it typed; accept it if some
  // member type takes it, and say so.
  if (probing_)
    return false;  // the outer try says what was expected
  for (DeclTypeId m : c.types) {
    const TypeExpr &u = model_.type(model_.typeDecl(m).underlying);
    if (u.kind == TypeExpr::Select)
      continue;
    DiagnosticCollector scratch;
    DiagnosticEngine quiet(scratch);
    Binder probe(file_, model_, schema_, quiet, options_, out_);
    probe.arena_ = arena_;
    probe.probing_ = true;
    if (probe.checkValue(v, model_.typeDecl(m).underlying, ctx, false) && !quiet.hasErrors()) {
      diags_.warning(file_.loc(entry(ctx.entry).begin() + v.offset),
                     "attribute " + std::to_string(ctx.position) + " '" + (ctx.slot ? ctx.slot->name : "") +
                         "': a value of SELECT type '" + td.name + "' should be typed, e.g. " +
                         express::lower(model_.typeDecl(m).name) + "(...); read as " + model_.typeDecl(m).name)
          .entity(entry(ctx.entry).id, entityName(ctx.entry));
      return true;
    }
  }
  error(ctx, v, "expected a value of SELECT type '" + td.name + "', found " + describe(v));
  return false;
}

bool Binder::checkNamed(const Value &v, const TypeExpr &t, const Context &ctx) {
  if (t.entity != kNone) {
    if (v.kind != ValueKind::Reference) {
      error(ctx, v, "expected a reference to " + t.name + ", found " + describe(v));
      return false;
    }
    int64_t i = file_.indexOf(v.ref);
    if (i < 0)
      return true;  // dangling: reported by the Part 21 check
    if (out_.entity(static_cast<size_t>(i)) == kNone) {
      referToUnknown(static_cast<size_t>(i), ctx);
      return true;  // the target's own entity is unknown: reported there
    }
    if (!out_.isA(static_cast<size_t>(i), t.entity)) {
      error(ctx, v, "expected a reference to " + t.name + ", found " + describe(v) + ", which is not " + article(t.name));
      return false;
    }
    return true;
  }
  if (t.declared == kNone)
    return true;  // unresolved name: reported when the schema was resolved
  if (namedChain_ >= express::kMaxTypeDepth) {
    error(ctx, v, "type '" + t.name + "' is defined through more than " + std::to_string(express::kMaxTypeDepth) +
                      " defined types; not checked");
    return false;
  }
  ++namedChain_;
  const bool ok = checkDeclared(v, t, ctx);
  --namedChain_;
  return ok;
}

bool Binder::checkDeclared(const Value &v, const TypeExpr &t, const Context &ctx) {
  const express::TypeDecl &td = model_.typeDecl(t.declared);
  const TypeExpr &u = model_.type(td.underlying);
  if (u.kind == TypeExpr::Select)
    return checkSelect(v, t.declared, ctx);
  if (u.kind == TypeExpr::Enumeration) {
    if (v.kind != ValueKind::Enumeration) {
      error(ctx, v, "expected an enumeration value of '" + td.name + "', found " + describe(v));
      return false;
    }
    const std::string value = express::lower(v.str());
    std::vector<std::string> values = enumValues(t.declared);
    if (std::find(values.begin(), values.end(), value) == values.end()) {
      std::string list;
      for (const std::string &s : values)
        list += (list.empty() ? "." : ", .") + s + ".";
      error(ctx, v, "." + std::string(v.str()) + ". is not a value of '" + td.name + "' (" + list + ")");
      return false;
    }
    return true;
  }
  // A defined type: its value, possibly written typed with its own name.
  if (v.kind == ValueKind::Typed) {
    const std::string name = express::lower(file_.names().name(v.node.name));
    if (name != td.name) {
      error(ctx, v, "expected " + article(td.name) + ", found " + describe(v));
      return false;
    }
    return checkInner(arena_->children(v)[0], td.underlying, ctx, false);
  }
  return checkValue(v, td.underlying, ctx, false);
}

bool Binder::checkValue(const Value &v, TypeId type, const Context &ctx, bool optionalAllowed) {
  if (type == kNone)
    return true;
  if (v.kind == ValueKind::Unset) {
    if (optionalAllowed)
      return true;
    const Drift drift = ctx.path.empty() && !options_.strict ? driftOf(type) : Drift::None;
    const bool simple = entry(ctx.entry).name() != p21::kComplexInstance;
    const int parameter = static_cast<int>(ctx.position) - 1;
    if (drift == Drift::EmptyAggregate || drift == Drift::MissingString || drift == Drift::MissingTolerance) {
      Tally &t = drift == Drift::EmptyAggregate  ? unsetAggregate_
                 : drift == Drift::MissingString ? unsetString_
                                                 : unsetTolerance_;
      if (t.count++ == 0)
        t.first = entry(ctx.entry).begin() + v.offset;
      if (simple)
        out_.fixes_.push_back({entry(ctx.entry).id, parameter,
                               drift == Drift::EmptyAggregate  ? "()"
                               : drift == Drift::MissingString ? "''"
                                                               : "",
                               drift == Drift::MissingTolerance});
      return true;
    }
    if (options_.lenient && ctx.path.empty()) {
      const p21::InstanceEntry &e = entry(ctx.entry);
      // A flag the file leaves unset is off: what every reader of it assumes.
      const bool flag = drift == Drift::Boolean;
      diags_.assumption(file_.loc(e.begin() + v.offset),
                        "attribute " + std::to_string(ctx.position) + " '" + (ctx.slot ? ctx.slot->name : "") +
                            "': '$' (no value) where a value is required (" + expected(type) + "); read as " +
                            (flag ? "false (.F.)" : "absent"))
          .entity(e.id, entityName(ctx.entry));
      if (flag && simple)
        out_.fixes_.push_back({e.id, parameter, ".F."});
      return true;
    }
    error(ctx, v, "'$' (no value) where a value is required (" + expected(type) + ")");
    return false;
  }
  if (v.kind == ValueKind::Derived) {
    error(ctx, v, "'*' but the attribute is not derived; expected " + expected(type));
    return false;
  }
  const TypeExpr &t = model_.type(type);
  switch (t.kind) {
  case TypeExpr::Simple: {
    bool ok = false;
    switch (t.simple) {
    case express::SimpleKind::Integer: ok = v.kind == ValueKind::Integer; break;
    case express::SimpleKind::Real:
    case express::SimpleKind::Number:
      ok = v.kind == ValueKind::Real;
      if (v.kind == ValueKind::Integer) {
        if (intForReal_++ == 0)
          firstIntForReal_ = entry(ctx.entry).begin() + v.offset;
        ok = true;
      }
      if (t.simple == express::SimpleKind::Number && v.kind == ValueKind::Integer)
        --intForReal_;  // NUMBER takes integers as they are
      break;
    case express::SimpleKind::String: ok = v.kind == ValueKind::String; break;
    case express::SimpleKind::Binary: ok = v.kind == ValueKind::Binary; break;
    case express::SimpleKind::Boolean:
      ok = v.kind == ValueKind::Enumeration && (v.str() == "T" || v.str() == "F");
      break;
    case express::SimpleKind::Logical:
      ok = v.kind == ValueKind::Enumeration && (v.str() == "T" || v.str() == "F" || v.str() == "U");
      break;
    }
    if (!ok) {
      const char *want = t.simple == express::SimpleKind::Boolean   ? "BOOLEAN (.T. or .F.)"
                         : t.simple == express::SimpleKind::Logical ? "LOGICAL (.T., .F. or .U.)"
                                                                    : simpleKindName(t.simple);
      error(ctx, v, std::string("expected ") + want + ", found " + describe(v));
    }
    return ok;
  }
  case TypeExpr::Aggregate: {
    if (v.kind != ValueKind::List) {
      error(ctx, v, "expected " + expected(type) + ", found " + describe(v));
      return false;
    }
    bool ok = true;
    if (static_cast<int64_t>(v.count) < t.lower || (t.upper >= 0 && static_cast<int64_t>(v.count) > t.upper)) {
      const std::string what = "expected " + expected(type) + ", found " + std::to_string(v.count) +
                               (v.count == 1 ? " element" : " elements");
      if (options_.lenient) {
        // Generators write () for a list the file has nothing for; what
        // needs its elements says so where it reads them.
        const p21::InstanceEntry &e = entry(ctx.entry);
        diags_.assumption(file_.loc(e.begin() + v.offset), "attribute " + std::to_string(ctx.position) + " '" +
                                                               (ctx.slot ? ctx.slot->name : "") + "'" + ctx.path +
                                                               ": " + what + "; read as written")
            .entity(e.id, entityName(ctx.entry));
      } else {
        error(ctx, v, what);
        ok = false;
      }
    }
    auto children = arena_->children(v);
    for (size_t i = 0; i < children.size(); ++i) {
      Context inner = ctx;
      inner.path += "[" + std::to_string(i + 1) + "]";
      ok &= checkInner(children[i], t.element, inner, t.optionalElements);
    }
    return ok;
  }
  case TypeExpr::Named: return checkNamed(v, t, ctx);
  default: return true;  // generic types do not occur in attributes
  }
}

// In a complex instance a subtype may redeclare an attribute of a supertype's
// record as DERIVE (si_unit derives named_unit.dimensions): the supertype's
// record then writes it `*`. The k-th attribute `entity` declares is the k-th
// slot it owns in every subtype's list, whatever the subtype renamed.
const express::Slot &Binder::effectiveSlot(EntityId entity, uint32_t ownIndex, const std::vector<EntityId> &members,
                                           EntityId &derivedBy) const {
  const express::Entity &e = model_.entity(entity);
  const express::Slot &own = e.slots[e.ownSlots[ownIndex]];
  derivedBy = entity;
  for (EntityId m : members) {
    if (m == entity || !model_.isSubtypeOf(m, entity))
      continue;
    uint32_t k = 0;
    for (const express::Slot &s : model_.entity(m).slots) {
      if (s.owner != entity)
        continue;
      if (k++ == ownIndex) {
        if (s.derived) {
          derivedBy = m;
          return s;
        }
        break;
      }
    }
  }
  return own;
}

void Binder::checkRecord(size_t index, const p21::Record &rec, EntityId entity, const std::vector<EntityId> *members) {
  const bool partial = members != nullptr;
  const express::Entity &e = model_.entity(entity);
  auto params = arena_->params(rec);
  std::vector<uint32_t> positions;
  if (partial) {
    positions = e.ownSlots;
  } else {
    positions.resize(e.slots.size());
    for (uint32_t i = 0; i < positions.size(); ++i)
      positions[i] = i;
  }
  const p21::InstanceEntry &en = entry(index);
  if (params.size() != positions.size()) {
    std::string names;
    for (uint32_t p : positions)
      names += (names.empty() ? "" : ", ") + e.slots[p].name;
    diags_
        .error(file_.loc(en.begin() + rec.offset),
               std::string(partial ? "record '" + e.name + "' of a complex instance" : "'" + e.name + "'") +
                   " has " + std::to_string(positions.size()) + " attribute" +
                   (positions.size() == 1 ? "" : "s") + ", found " + std::to_string(params.size()))
        .entity(en.id, entityName(index))
        .note("attributes of " + e.name + " in order: " + (names.empty() ? std::string("(none)") : names));
    return;
  }
  for (size_t i = 0; i < params.size(); ++i) {
    EntityId derivedBy = entity;
    const express::Slot &slot =
        partial ? effectiveSlot(entity, static_cast<uint32_t>(i), *members, derivedBy) : e.slots[positions[i]];
    Context ctx{index, &slot, i + 1, {}};
    const Value &v = params[i];
    if (slot.derived) {
      if (v.kind != ValueKind::Derived)
        error(ctx, v, "the attribute is derived in '" + model_.entity(derivedBy).name +
                          "' and must be written '*', found " + describe(v));
      continue;
    }
    checkValue(v, slot.type, ctx, slot.optional);
  }
}

namespace {

// Does the complex entity set satisfy a supertype expression's ONEOF parts?
// Returns the names of two mutually exclusive members found, if any.
bool present(const express::Model &m, const express::Schema &s, const express::SupertypeExpr &e,
             const std::set<EntityId> &set) {
  switch (e.op) {
  case express::SupertypeExpr::Leaf: {
    EntityId id = m.findEntity(s, e.entity);
    if (id == kNone)
      return false;
    for (EntityId member : set)
      if (m.isSubtypeOf(member, id))
        return true;
    return false;
  }
  case express::SupertypeExpr::And:
    return std::all_of(e.operands.begin(), e.operands.end(), [&](const auto &o) { return present(m, s, o, set); });
  default:
    return std::any_of(e.operands.begin(), e.operands.end(), [&](const auto &o) { return present(m, s, o, set); });
  }
}

const express::SupertypeExpr *oneofViolation(const express::Model &m, const express::Schema &s,
                                             const express::SupertypeExpr &e, const std::set<EntityId> &set,
                                             std::string &a, std::string &b) {
  if (e.op == express::SupertypeExpr::OneOf) {
    const express::SupertypeExpr *first = nullptr;
    for (const auto &o : e.operands) {
      if (!present(m, s, o, set))
        continue;
      if (first) {
        a = first->op == express::SupertypeExpr::Leaf ? first->entity : "(group)";
        b = o.op == express::SupertypeExpr::Leaf ? o.entity : "(group)";
        return &e;
      }
      first = &o;
    }
  }
  for (const auto &o : e.operands)
    if (auto *v = oneofViolation(m, s, o, set, a, b))
      return v;
  return nullptr;
}

} // namespace

void Binder::checkComplex(size_t index, const std::vector<EntityId> &members, uint64_t at) {
  const p21::InstanceEntry &en = entry(index);
  std::set<EntityId> set(members.begin(), members.end());
  for (EntityId m : members) {
    for (EntityId sup : model_.entity(m).supertypes)
      if (!set.count(sup))
        diags_.error(file_.loc(at), "complex instance has '" + model_.entity(m).name + "' but not its supertype '" +
                                        model_.entity(sup).name + "'; every supertype must have its record")
            .entity(en.id, entityName(index));
    const express::Entity &e = model_.entity(m);
    if (e.abstract) {
      bool hasSub = std::any_of(members.begin(), members.end(),
                                [&](EntityId o) { return o != m && model_.isSubtypeOf(o, m); });
      if (!hasSub)
        diags_.error(file_.loc(at), "entity '" + e.name + "' is abstract and none of its subtypes is in this complex instance")
            .entity(en.id, entityName(index));
    }
    for (const express::SupertypeExpr &c : e.supertypeConstraints) {
      std::string a, b;
      if (oneofViolation(model_, schema_, c, set, a, b))
        diags_.error(file_.loc(at), "'" + a + "' and '" + b + "' cannot be combined: they are ONEOF subtypes of '" +
                                        e.name + "'")
            .entity(en.id, entityName(index));
    }
  }
}

void Binder::checkInstance(size_t index, const p21::ValueArena &values) {
  const p21::InstanceEntry &en = entry(index);
  arena_ = &values;
  auto records = values.records();
  if (en.name() != p21::kComplexInstance) {
    EntityId e = out_.entity(index);
    if (e == kNone)
      return;
    const express::Entity &ent = model_.entity(e);
    if (ent.abstract) {
      std::string subs;
      for (EntityId s : ent.subtypes)
        subs += (subs.empty() ? "" : ", ") + model_.entity(s).name;
      const std::string message = "entity '" + ent.name + "' is abstract and cannot be instantiated" +
                                  (subs.empty() ? std::string() : "; use one of its subtypes: " + subs);
      const SourceLoc at = file_.loc(en.begin() + records[0].offset);
      if (!options_.lenient) {
        diags_.error(at, message).entity(en.id, entityName(index));
        return;
      }
      diags_.assumption(at, message + " (read as written)").entity(en.id, entityName(index));
    }
    checkRecord(index, records[0], e);
    return;
  }
  std::vector<EntityId> members;
  for (const p21::Record &r : records) {
    EntityId e = lookup(file_.names().name(r.name), en.begin() + r.offset);
    if (e == kNone)
      return;  // reported in the first pass
    members.push_back(e);
  }
  checkComplex(index, members, en.begin());
  for (size_t k = 0; k < records.size(); ++k)
    checkRecord(index, records[k], members[k], &members);
}

void Binder::run() {
  const auto &entries = file_.entries();
  // Pass 1: the entity of every instance, so references can be checked
  // against their target's type in pass 2. Simple instances are typed by
  // name, once per distinct name.
  constexpr EntityId kUnseen = kNone - 1;
  out_.byName_.assign(file_.names().size(), kUnseen);
  std::vector<bool> isAlias(file_.names().size(), false);
  for (size_t i = 0; i < entries.size(); ++i) {
    const p21::InstanceEntry &en = entries[i];
    const p21::NameId nameId = en.name();
    if (nameId != p21::kComplexInstance) {
      EntityId &slot = out_.byName_[nameId];
      const std::string_view name = file_.names().name(nameId);
      if (slot == kUnseen) {
        const size_t aliasesBefore = aliasUses_.size();
        slot = lookup(name, en.begin());
        isAlias[nameId] = aliasUses_.size() != aliasesBefore;
      } else if (isAlias[nameId]) {
        ++aliasUses_[std::string(name)].count;
      }
      if (isAlias[nameId])
        out_.fixes_.push_back({en.id, -1, express::upper(aliasUses_[std::string(name)].target)});
      if (slot == kNone) {
        // Decided once its references are known (after pass 2).
        if (const auto [best, declaredIn] = nearest(name); best.empty() && declaredIn.empty())
          unknown_.emplace(i, Unknown{std::string(name), en.begin(), {}, false});
        else
          reportUnknown(i, name, en.begin());
      }
      continue;
    }
    if (!file_.decodeInstance(i, scratch_, nullptr))
      continue;
    BoundFile::Complex c;
    for (const p21::Record &r : scratch_.records()) {
      EntityId e = lookup(file_.names().name(r.name), en.begin() + r.offset);
      if (e == kNone) {
        diags_.error(file_.loc(en.begin() + r.offset), "unknown entity '" +
                                                           std::string(file_.names().name(r.name)) +
                                                           "' in schema '" + schema_.name + "'")
            .entity(en.id, file_.describe(en));
        continue;
      }
      c.members.push_back(e);
    }
    if (!c.members.empty()) {
      // The most specific member stands for the instance.
      c.mostSpecific = c.members[0];
      for (EntityId e : c.members)
        if (model_.isSubtypeOf(e, c.mostSpecific))
          c.mostSpecific = e;
      out_.complex_.emplace(static_cast<uint32_t>(i), std::move(c));
    }
  }
  for (EntityId &e : out_.byName_)
    if (e == kUnseen)
      e = kNone;
  // Pass 2: decode each instance once for the Part 21 reference check and the
  // attribute checks together.
  p21::checkInstances(file_, diags_, [this](size_t i, const p21::ValueArena &values) {
    if (!diags_.limitReached())
      checkInstance(i, values);
  });

  // A writer's own entity that only optional attributes refer to: left
  // out, what refers to it read as `$` (lowering reads the attribute as
  // absent, and says what it assumes for it).
  for (const auto &[i, u] : unknown_) {
    if (u.needed || !options_.lenient) {
      reportUnknown(i, u.name, u.at);
      continue;
    }
    std::string uses;
    for (size_t k = 0; k < u.optionalUses.size(); ++k)
      uses += (k == 0 ? "" : k + 1 == u.optionalUses.size() ? " and " : ", ") + u.optionalUses[k];
    diags_.assumption(file_.loc(u.at), "'" + u.name + "' is an entity of no schema stepnc knows (the writer's own, "
                                           "it seems): #" + std::to_string(entry(i).id) + " is left out" +
                                           (uses.empty() ? std::string(", and nothing refers to it")
                                                         : "; " + uses + ", which refer" +
                                                               (u.optionalUses.size() == 1 ? "s" : "") +
                                                               " to it, read as absent ($)"))
        .entity(entry(i).id, u.name);
  }
  // An alias: one diagnostic per name, at its first use; an error with
  // --strict, where only the schema's own names are read.
  for (const auto &[alias, use] : aliasUses_) {
    const std::string count =
        " (" + std::to_string(use.count) + (use.count == 1 ? " instance" : " instances");
    const std::string head = "'" + alias + "' is not an entity of schema '" + schema_.name + "'";
    if (options_.strict)
      diags_.error(file_.loc(use.first), head + "; it is an alias of '" + use.target + "', read as such without --strict" + count + ")");
    else
      diags_.warning(file_.loc(use.first),
                     head + "; read as its alias '" + use.target + "'" + count + "; --strict makes each an error)");
  }
  reportTally(unsetAggregate_, "'$' written for a mandatory aggregate; read as empty");
  reportTally(unsetString_, "'$' written for a mandatory string (a name, label or identifier); read as ''");
  reportTally(unsetTolerance_, "'$' written for the tolerance of a toleranced length (implicit_tolerance); read as "
                              "the general tolerance: the workpiece's global_tolerance, else " +
                                  formatFixed(ir::kDefaultTolerance, 2) + " mm either way");
  if (intForReal_ > 0)
    diags_.warning(file_.loc(firstIntForReal_),
                   "integer written where a REAL is expected; read as a real (" + std::to_string(intForReal_) +
                       (intForReal_ == 1 ? " place)" : " places)"));
}

std::unique_ptr<BoundFile> bind(const p21::Part21File &file, const express::Model &model,
                                const express::Schema &schema, DiagnosticEngine &diags,
                                const BindOptions &options) {
  auto out = std::make_unique<BoundFile>(file, model, schema);
  Binder binder(file, model, schema, diags, options, *out);
  binder.run();
  return out;
}

} // namespace stepnc::binding
