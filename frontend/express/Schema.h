// The EXPRESS (ISO 10303-11) schema model.
//
// A Model holds one or more schemas read from .exp files (or the built-in
// ones). Names are stored lower case, as EXPRESS is case-insensitive. After
// Model::resolve(), every named type reference points at its declaration, every
// entity knows its supertypes and subtypes, and every entity has its full
// attribute list in Part 21 order (`slots`): inherited attributes first
// (supertypes in declaration order, depth first, each supertype once), then its
// own, with redeclarations narrowing an inherited slot in place and DERIVE
// redeclarations turning it into a derived slot (written `*` in Part 21).
#pragma once

#include "frontend/express/Expr.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace stepnc::express {

using TypeId = uint32_t;    ///< index of a TypeExpr in Model::typeExprs()
using EntityId = uint32_t;  ///< index of an Entity in Model::entities()
using DeclTypeId = uint32_t;  ///< index of a TypeDecl in Model::typeDecls()
inline constexpr uint32_t kNone = UINT32_MAX;

// Limits Model::resolve() enforces, each a located error, so that no schema
// can make resolution or what follows it (binding, XSD, Part 28) recurse
// without bound or take quadratic memory. Real schemas stay far below them
// (the AP238/AP242 long forms: inheritance about 12 deep, type chains 4).
/// Supertype chains: an entity at most this many levels below its root.
inline constexpr uint32_t kMaxInheritanceDepth = 256;
/// Defined types, SELECT members and BASED_ON bases referring to each other:
/// at most this many declarations in a chain (a cycle is an error anyway).
inline constexpr uint32_t kMaxTypeDepth = 64;
/// Attributes of one entity, inherited ones included.
inline constexpr uint32_t kMaxEntitySlots = 10000;
/// Attribute slots of all entities together (each entity stores its
/// inherited ones too, so this bounds what deep hierarchies cost).
inline constexpr uint64_t kMaxModelSlots = 2000000;
/// Names visible in all schemas together (USE FROM copies a schema's names).
inline constexpr uint64_t kMaxScopeNames = 4000000;

enum class SimpleKind : uint8_t { Binary, Boolean, Integer, Logical, Number, Real, String };
enum class AggregateKind : uint8_t { Array, Bag, List, Set };

const char *simpleKindName(SimpleKind k);
const char *aggregateKindName(AggregateKind k);

/// A type as written in an attribute, a TYPE declaration or an aggregate.
struct TypeExpr {
  enum Kind : uint8_t {
    Simple,       ///< INTEGER, REAL, STRING ...
    Aggregate,    ///< ARRAY/BAG/LIST/SET [lower:upper] OF element
    Named,        ///< a reference to a TYPE or an ENTITY (resolved by Model::resolve)
    Select,       ///< only as the underlying type of a TYPE declaration
    Enumeration,  ///< only as the underlying type of a TYPE declaration
    Generic,      ///< GENERIC, GENERIC_ENTITY, AGGREGATE OF (function parameters)
  };
  Kind kind = Simple;
  SimpleKind simple = SimpleKind::Integer;
  AggregateKind aggregate = AggregateKind::List;
  bool optionalElements = false;  ///< ARRAY OF OPTIONAL
  bool unique = false;            ///< LIST/ARRAY OF UNIQUE
  int64_t lower = 0;              ///< aggregate bounds; upper -1 means '?'
  int64_t upper = -1;
  TypeId element = kNone;         ///< aggregate element type
  std::string name;               ///< Named: the referenced name
  // Resolution of Named: exactly one is set.
  EntityId entity = kNone;
  DeclTypeId declared = kNone;
};

/// A domain rule of a WHERE clause.
struct WhereRule {
  std::string label;  ///< may be empty
  std::string text;   ///< the expression as written
  /// The parsed expression: set when read from EXPRESS; for built-in schemas
  /// parsed on first use (Model::whereExpression), keeping start-up fast.
  mutable std::shared_ptr<const Expr> expr;
};

/// A TYPE declaration.
struct TypeDecl {
  std::string name;
  std::string schema;
  TypeId underlying = kNone;
  // SELECT
  std::vector<std::string> selectItems;
  bool extensible = false;
  bool genericEntity = false;
  std::string basedOn;  ///< SELECT/ENUMERATION BASED_ON
  // ENUMERATION
  std::vector<std::string> enumValues;
  std::vector<WhereRule> where;
  SourceLoc loc;
};

/// An explicit attribute as declared (possibly a redeclaration).
struct Attribute {
  std::string name;
  TypeId type = kNone;
  bool optional = false;
  /// SELF\entity.attribute redeclaration: the entity and attribute redeclared.
  std::string redeclaresEntity;
  std::string redeclaresAttribute;
  SourceLoc loc;
  bool isRedeclaration() const { return !redeclaresAttribute.empty(); }
};

struct DerivedAttribute {
  std::string name;
  TypeId type = kNone;
  std::string redeclaresEntity;
  std::string redeclaresAttribute;
  std::string expression;  ///< source text
};

struct InverseAttribute {
  std::string name;
  bool aggregate = false;  ///< SET or BAG
  bool bag = false;
  int64_t lower = 0, upper = -1;
  std::string entity;     ///< the referencing entity
  std::string attribute;  ///< its attribute that points back
};

/// SUPERTYPE OF (...) expressions: leaves name subtypes.
struct SupertypeExpr {
  enum Op : uint8_t { Leaf, OneOf, And, AndOr };
  Op op = Leaf;
  std::string entity;
  std::vector<SupertypeExpr> operands;
};

/// One position in an entity's Part 21 attribute list.
struct Slot {
  std::string name;
  TypeId type = kNone;
  bool optional = false;
  bool derived = false;     ///< redeclared as DERIVE in a subtype: written `*`
  EntityId owner = kNone;   ///< the entity that declared the attribute first
};

struct Entity {
  std::string name;
  std::string schema;
  bool abstract = false;
  /// SUPERTYPE OF (...) and SUBTYPE_CONSTRAINT expressions; all apply.
  std::vector<SupertypeExpr> supertypeConstraints;
  std::vector<std::string> supertypeNames;
  std::vector<Attribute> attributes;  ///< explicit attributes in declaration order
  std::vector<DerivedAttribute> derived;
  std::vector<InverseAttribute> inverse;
  std::vector<std::vector<std::string>> unique;  ///< UNIQUE rules: labelled attribute lists
  std::vector<WhereRule> where;
  SourceLoc loc;

  // Filled by Model::resolve().
  std::vector<EntityId> supertypes;
  std::vector<EntityId> subtypes;
  std::vector<Slot> slots;        ///< full Part 21 attribute list
  std::vector<uint32_t> ownSlots; ///< slots this entity declares (its record in a complex instance)
};

/// USE FROM / REFERENCE FROM.
struct Interface {
  bool use = true;  ///< USE (instantiable) or REFERENCE
  std::string schema;
  std::vector<std::pair<std::string, std::string>> items;  ///< name, rename (empty: same); none = all
  SourceLoc loc;
};

struct Schema {
  std::string name;
  std::vector<Interface> interfaces;
  std::vector<EntityId> entities;    ///< declared here
  std::vector<DeclTypeId> types;     ///< declared here
  std::vector<std::string> functions, procedures, rules, constants;
  SourceLoc loc;
  /// Every name visible in this schema (own and interfaced), after resolve().
  std::unordered_map<std::string, std::pair<bool, uint32_t>> scope;  ///< name -> (isEntity, id)
};

class Model {
public:
  Model() = default;
  Model(Model &&) = default;
  Model &operator=(Model &&) = default;

  // Building.
  TypeId addTypeExpr(TypeExpr t);
  EntityId addEntity(Entity e);
  DeclTypeId addTypeDecl(TypeDecl t);
  Schema &addSchema(std::string name, SourceLoc loc);
  Schema &mutableSchema(size_t index) { return schemas_[index]; }
  Entity &mutableEntity(EntityId id) { return entities_[id]; }
  TypeDecl &mutableTypeDecl(DeclTypeId id) { return typeDecls_[id]; }
  /// Keeps a source file alive as long as the model (for diagnostic locations).
  void keepSource(std::unique_ptr<SourceFile> f) { sources_.push_back(std::move(f)); }

  /// Resolves interfaces, names, supertypes and attribute lists; reports
  /// unknown names, missing schemas, inheritance cycles, defined types and
  /// SELECTs that refer to themselves, and anything beyond the limits above.
  /// Returns false on errors. After a successful resolve the supertype and
  /// type graphs are acyclic and within kMaxInheritanceDepth / kMaxTypeDepth.
  bool resolve(DiagnosticEngine &diags);

  // Queries.
  const std::vector<Schema> &schemas() const { return schemas_; }
  const Schema *findSchema(std::string_view name) const;  ///< case-insensitive
  const std::vector<Entity> &entities() const { return entities_; }
  const std::vector<TypeDecl> &typeDecls() const { return typeDecls_; }
  const std::vector<TypeExpr> &typeExprs() const { return typeExprs_; }
  const Entity &entity(EntityId id) const { return entities_[id]; }
  const TypeDecl &typeDecl(DeclTypeId id) const { return typeDecls_[id]; }
  const TypeExpr &type(TypeId id) const { return typeExprs_[id]; }

  /// Entity visible in `schema` under `name` (lower case), or kNone.
  EntityId findEntity(const Schema &schema, std::string_view name) const;
  DeclTypeId findType(const Schema &schema, std::string_view name) const;
  /// True if `sub` is `super` or one of its subtypes (transitively). Each
  /// supertype is visited once, so diamonds cost no more than trees.
  bool isSubtypeOf(EntityId sub, EntityId super) const;
  /// The parsed form of a WHERE rule (parsing it now if needed); null if its
  /// text does not parse.
  const Expr *whereExpression(const WhereRule &rule) const;
  /// Writes a type expression as EXPRESS text ("LIST [1:?] OF cartesian_point").
  std::string typeText(TypeId id) const;

private:
  bool computeSlots(EntityId id, std::vector<uint8_t> &state, uint64_t &total, DiagnosticEngine &diags);

  std::vector<Schema> schemas_;
  std::vector<Entity> entities_;
  std::vector<TypeDecl> typeDecls_;
  std::vector<TypeExpr> typeExprs_;
  std::vector<std::unique_ptr<SourceFile>> sources_;
};

/// Lower-cases ASCII.
std::string lower(std::string_view s);
/// Upper-cases ASCII.
std::string upper(std::string_view s);

} // namespace stepnc::express
