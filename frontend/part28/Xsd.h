// The XML Schema (XSD 1.0) that the Part 28 (ISO 10303-28 ed. 2) default
// configuration gives for an EXPRESS schema, as docs/part28.md describes it:
// one XSD for the schema (an element and a complex type per entity, a named
// type per defined type, a group per entity and SELECT listing the elements a
// value may be, named types for references and aggregates of them) and the
// common XSD it imports (root, header, abstract uos, simple and aggregate
// member elements, the check that every ref names an id). The model must be
// resolved.
#pragma once

#include "frontend/express/Schema.h"
#include "frontend/part28/Mapping.h"

#include <string>
#include <string_view>
#include <vector>

namespace stepnc::p28 {

/// The file name the schema XSDs import the common XSD from.
inline constexpr std::string_view kCommonXsdFileName = "iso_10303_28_common.xsd";

/// The entities and defined types an XSD declares: every one visible in the
/// schema (declared or interfaced) and, transitively, every one their
/// attributes, defined types and SELECT items refer to.
class XsdScope {
public:
  XsdScope(const express::Model &model, const express::Schema &schema);

  const express::Model &model() const { return model_; }
  /// Sorted by element name.
  const std::vector<express::EntityId> &entities() const { return entities_; }
  const std::vector<express::DeclTypeId> &types() const { return types_; }
  bool contains(express::EntityId entity) const { return entityIn_[entity]; }

  /// The elements a reference to `entity` may be: the entity's own and each
  /// of its subtypes' in the scope, each once although multiple inheritance
  /// reaches a subtype along several paths (XSD's Unique Particle
  /// Attribution forbids a repeated element in a choice).
  std::vector<std::string> entityChoice(express::EntityId entity) const;
  /// The elements a value of a SELECT type (or a type defined as one) may be:
  /// each entity item as in entityChoice(), each defined-type item's element,
  /// nested SELECTs flattened; each element once.
  std::vector<std::string> selectChoice(express::DeclTypeId select) const;
  /// An enumeration's values in lower case: its own, then those of the types
  /// it is BASED_ON.
  std::vector<std::string> enumerationValues(express::DeclTypeId enumeration) const;
  /// True if the type is a SELECT or is defined as one (TYPE a = some_select).
  bool isSelect(express::DeclTypeId type) const;

private:
  void add(bool isEntity, uint32_t id, std::vector<std::pair<bool, uint32_t>> &work);
  void addTypeRefs(express::TypeId type, std::vector<std::pair<bool, uint32_t>> &work);
  void collectSelect(express::DeclTypeId type, std::vector<std::string> &out, std::vector<bool> &seenTypes,
                     std::vector<bool> &seenEntities) const;
  void collectSubtree(express::EntityId entity, std::vector<std::string> &out, std::vector<bool> &seen) const;
  /// A SELECT item or BASED_ON name, resolved where its type is declared.
  std::pair<bool, uint32_t> resolveIn(const express::TypeDecl &decl, const std::string &name) const;

  const express::Model &model_;
  std::vector<express::EntityId> entities_;
  std::vector<express::DeclTypeId> types_;
  std::vector<bool> entityIn_, typeIn_;
};

/// The common XSD (namespace kCommonNamespace); the same text for every schema.
std::string commonXsd();

/// The XSD of `schema` (target namespace schemaNamespace(schema.name)). Fails
/// with `error` when two declarations in the scope would have the same
/// element name (entities or types of the same name in different schemas).
bool schemaXsd(const express::Model &model, const express::Schema &schema, std::string &out, std::string &error);

} // namespace stepnc::p28
