// The Part 28 XSD generator: XsdScope decides what the schema XSD declares
// and which elements each reference or SELECT allows; SchemaXsdWriter writes
// the declarations in a fixed order (the uos, entities, defined types, then
// the groups and types that attributes share), names sorted, so the same
// model always gives the same bytes.
#include "frontend/part28/Xsd.h"

#include <algorithm>
#include <functional>
#include <initializer_list>
#include <map>
#include <set>
#include <utility>

namespace stepnc::part28 {

using express::AggregateKind;
using express::DeclTypeId;
using express::EntityId;
using express::kNone;
using express::SimpleKind;
using express::TypeExpr;
using express::TypeId;

std::string schemaNamespace(std::string_view schemaName) { return "urn:iso10303-28:xs/" + express::lower(schemaName); }

std::string elementName(std::string_view expressName) {
  std::string out = express::lower(expressName);
  if (!out.empty() && out[0] >= 'a' && out[0] <= 'z')
    out[0] = static_cast<char>(out[0] - 32);
  return out;
}

std::vector<std::string> attributeElementNames(const express::Model &model, EntityId entity) {
  const std::vector<express::Slot> &slots = model.entity(entity).slots;
  std::map<std::string, int> explicitCount;
  for (const express::Slot &s : slots)
    if (!s.derived)
      ++explicitCount[s.name];
  std::vector<std::string> names;
  for (const express::Slot &s : slots) {
    const bool repeated = !s.derived && explicitCount[s.name] > 1;
    names.push_back(repeated ? elementName(model.entity(s.owner).name) + "." + elementName(s.name)
                             : elementName(s.name));
  }
  return names;
}

namespace {

/// Guards the walks along TYPE a = b chains, which resolution does not check
/// for cycles.
constexpr int kMaxTypeChain = 64;

std::string groupName(std::string_view expressName) { return elementName(expressName) + "-group"; }

const char *simpleTypeName(SimpleKind k) {
  switch (k) {
  case SimpleKind::Binary:
    return "exp:binary";
  case SimpleKind::Boolean:
    return "xs:boolean";
  case SimpleKind::Integer:
    return "xs:long";
  case SimpleKind::Logical:
    return "exp:logical";
  case SimpleKind::Number:
  case SimpleKind::Real:
    return "xs:double";
  case SimpleKind::String:
    return "xs:string";
  }
  return "xs:string";
}

/// The common element holding an aggregate member of a simple type.
const char *simpleMemberElement(SimpleKind k) {
  switch (k) {
  case SimpleKind::Binary:
    return "exp:binary";
  case SimpleKind::Boolean:
    return "exp:boolean";
  case SimpleKind::Integer:
    return "exp:long";
  case SimpleKind::Logical:
    return "exp:logical";
  case SimpleKind::Number:
  case SimpleKind::Real:
    return "exp:double";
  case SimpleKind::String:
    return "exp:string";
  }
  return "exp:string";
}

const char *aggregateMemberElement(AggregateKind k) {
  switch (k) {
  case AggregateKind::Array:
    return "exp:array";
  case AggregateKind::Bag:
    return "exp:bag";
  case AggregateKind::List:
    return "exp:list";
  case AggregateKind::Set:
    return "exp:set";
  }
  return "exp:list";
}

std::string escapeAttribute(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
    case '&':
      out += "&amp;";
      break;
    case '<':
      out += "&lt;";
      break;
    case '"':
      out += "&quot;";
      break;
    default:
      out += c;
    }
  }
  return out;
}

/// Indented XML text, one element tag per line.
class XmlText {
public:
  using Attributes = std::initializer_list<std::pair<std::string_view, std::string_view>>;

  void open(std::string_view tag, Attributes attributes = {}) {
    start(tag, attributes);
    out_ += ">\n";
    ++depth_;
  }
  void leaf(std::string_view tag, Attributes attributes = {}) {
    start(tag, attributes);
    out_ += "/>\n";
  }
  void close(std::string_view tag) {
    --depth_;
    indent();
    out_ += "</";
    out_ += tag;
    out_ += ">\n";
  }
  void line(std::string_view text) {
    indent();
    out_ += text;
    out_ += '\n';
  }
  std::string take() { return std::move(out_); }

private:
  void indent() { out_.append(static_cast<size_t>(depth_) * 2, ' '); }
  void start(std::string_view tag, Attributes attributes) {
    indent();
    out_ += '<';
    out_ += tag;
    for (const auto &[name, value] : attributes) {
      out_ += ' ';
      out_ += name;
      out_ += "=\"";
      out_ += escapeAttribute(value);
      out_ += '"';
    }
  }

  std::string out_;
  int depth_ = 0;
};

/// Writes one schema's XSD over an XsdScope.
class SchemaXsdWriter {
public:
  SchemaXsdWriter(const XsdScope &scope, const express::Schema &schema)
      : scope_(scope), model_(scope.model()), schema_(schema) {}

  std::string write() {
    writeProlog();
    writeUos();
    for (EntityId e : scope_.entities())
      writeEntity(e);
    for (DeclTypeId t : scope_.types())
      writeDefinedType(t);
    for (const auto &[name, write] : shared_)
      write();
    x_.close("xs:schema");
    return x_.take();
  }

private:
  void writeProlog() {
    const std::string ns = schemaNamespace(schema_.name);
    x_.line("<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    x_.line("<!-- ISO 10303-28 ed. 2 XSD of EXPRESS schema " + schema_.name + " (" +
            std::to_string(scope_.entities().size()) + " entities, " + std::to_string(scope_.types().size()) +
            " defined types), default configuration; generated by stepnc (docs/part28.md). -->");
    x_.open("xs:schema", {{"xmlns:xs", "http://www.w3.org/2001/XMLSchema"},
                          {"xmlns:exp", kCommonNamespace},
                          {"xmlns", ns},
                          {"targetNamespace", ns},
                          {"elementFormDefault", "qualified"}});
    x_.leaf("xs:import", {{"namespace", kCommonNamespace}, {"schemaLocation", kCommonXsdFileName}});
  }

  /// The schema's uos: any number of entity elements, in any order.
  void writeUos() {
    x_.open("xs:element", {{"name", "uos"}, {"substitutionGroup", "exp:uos"}});
    x_.open("xs:complexType");
    x_.open("xs:complexContent");
    x_.open("xs:extension", {{"base", "exp:uos"}});
    x_.open("xs:choice", {{"minOccurs", "0"}, {"maxOccurs", "unbounded"}});
    for (EntityId e : scope_.entities())
      x_.leaf("xs:element", {{"ref", elementName(model_.entity(e).name)}});
    x_.close("xs:choice");
    x_.close("xs:extension");
    x_.close("xs:complexContent");
    x_.close("xs:complexType");
    x_.close("xs:element");
  }

  /// An entity's element and its type: one optional element per explicit
  /// attribute in Part 21 order (derived ones are never written).
  void writeEntity(EntityId id) {
    const express::Entity &e = model_.entity(id);
    const std::string name = elementName(e.name);
    x_.leaf("xs:element", {{"name", name}, {"type", name}, {"nillable", "true"}});
    x_.open("xs:complexType", {{"name", name}});
    bool any = std::any_of(e.slots.begin(), e.slots.end(), [](const express::Slot &s) { return !s.derived; });
    if (any) {
      const std::vector<std::string> names = attributeElementNames(model_, id);
      x_.open("xs:sequence");
      for (size_t i = 0; i < e.slots.size(); ++i)
        if (!e.slots[i].derived)
          writeAttributeElement(names[i], e.slots[i].type);
      x_.close("xs:sequence");
    }
    x_.leaf("xs:attributeGroup", {{"ref", "exp:instanceAttributes"}});
    x_.close("xs:complexType");
  }

  void writeAttributeElement(const std::string &name, TypeId typeId) {
    const std::string type = namedType(typeId);
    if (!type.empty()) {
      x_.leaf("xs:element", {{"name", name}, {"type", type}, {"minOccurs", "0"}});
      return;
    }
    x_.open("xs:element", {{"name", name}, {"minOccurs", "0"}});
    x_.open("xs:complexType");
    writeAggregateContent(model_.type(typeId));
    x_.close("xs:complexType");
    x_.close("xs:element");
  }

  /// The XSD type of a value of `id` when it has a name; empty for an
  /// aggregate of simple values, defined-type values or aggregates, whose
  /// content is written in place. GENERIC (function parameters only, never an
  /// attribute) allows anything.
  std::string namedType(TypeId id) {
    const TypeExpr &t = model_.type(id);
    if (t.kind == TypeExpr::Simple)
      return simpleTypeName(t.simple);
    if (t.kind == TypeExpr::Named && t.declared != kNone)
      return elementName(model_.typeDecl(t.declared).name);
    if (t.kind == TypeExpr::Named && t.entity != kNone)
      return useReferenceType(t.entity);
    if (t.kind != TypeExpr::Aggregate)
      return "xs:anyType";
    const TypeExpr &member = model_.type(t.element);
    if (member.kind == TypeExpr::Named && member.entity != kNone)
      return useAggregateType(model_.entity(member.entity).name, useGroup(member.entity));
    if (member.kind == TypeExpr::Named && member.declared != kNone && scope_.isSelect(member.declared))
      return useAggregateType(model_.typeDecl(member.declared).name, groupName(model_.typeDecl(member.declared).name));
    return "";
  }

  /// Content of a complex type holding an aggregate.
  void writeAggregateContent(const TypeExpr &t) {
    x_.open("xs:sequence");
    writeMember(t.element);
    x_.close("xs:sequence");
    x_.leaf("xs:attribute", {{"ref", "exp:cType"}});
  }

  /// One aggregate member particle, repeated any number of times.
  void writeMember(TypeId id) {
    const TypeExpr &t = model_.type(id);
    if (t.kind == TypeExpr::Simple)
      return repeated("xs:element", simpleMemberElement(t.simple));
    if (t.kind == TypeExpr::Aggregate)
      return repeated("xs:element", aggregateMemberElement(t.aggregate));
    if (t.kind == TypeExpr::Named && t.entity != kNone)
      return repeated("xs:group", useGroup(t.entity));
    if (t.kind == TypeExpr::Named && t.declared != kNone) {
      const std::string &name = model_.typeDecl(t.declared).name;
      if (scope_.isSelect(t.declared))
        return repeated("xs:group", groupName(name));
      return repeated("xs:element", elementName(name));
    }
    x_.leaf("xs:any", {{"processContents", "lax"}, {"minOccurs", "0"}, {"maxOccurs", "unbounded"}});
  }

  void repeated(std::string_view tag, std::string_view ref) {
    x_.leaf(tag, {{"ref", ref}, {"minOccurs", "0"}, {"maxOccurs", "unbounded"}});
  }

  /// A defined type: a SELECT becomes a group (the choice of its elements)
  /// and a complex type holding it; any other type a global element (for
  /// typed SELECT values and aggregate members) and a simple or complex type.
  void writeDefinedType(DeclTypeId id) {
    const express::TypeDecl &decl = model_.typeDecl(id);
    const std::string name = elementName(decl.name);
    if (scope_.isSelect(id)) {
      x_.open("xs:group", {{"name", groupName(decl.name)}});
      x_.open("xs:choice");
      for (const std::string &element : scope_.selectChoice(id))
        x_.leaf("xs:element", {{"ref", element}});
      x_.close("xs:choice");
      x_.close("xs:group");
      x_.open("xs:complexType", {{"name", name}});
      x_.leaf("xs:group", {{"ref", groupName(decl.name)}});
      x_.close("xs:complexType");
      return;
    }
    x_.leaf("xs:element", {{"name", name}, {"type", name}});
    const TypeExpr &u = model_.type(decl.underlying);
    if (u.kind == TypeExpr::Enumeration) {
      writeEnumeration(id);
      return;
    }
    if (u.kind == TypeExpr::Simple || (u.kind == TypeExpr::Named && u.declared != kNone && isSimple(u.declared))) {
      x_.open("xs:simpleType", {{"name", name}});
      x_.leaf("xs:restriction", {{"base", namedType(decl.underlying)}});
      x_.close("xs:simpleType");
      return;
    }
    x_.open("xs:complexType", {{"name", name}});
    if (u.kind == TypeExpr::Aggregate) {
      writeAggregateContent(u);
    } else { // TYPE a = b (an aggregate type) or TYPE a = some_entity
      x_.open("xs:complexContent");
      x_.leaf("xs:extension", {{"base", namedType(decl.underlying)}});
      x_.close("xs:complexContent");
    }
    x_.close("xs:complexType");
  }

  void writeEnumeration(DeclTypeId id) {
    x_.open("xs:simpleType", {{"name", elementName(model_.typeDecl(id).name)}});
    x_.open("xs:restriction", {{"base", "xs:string"}});
    for (const std::string &value : scope_.enumerationValues(id))
      x_.leaf("xs:enumeration", {{"value", value}});
    x_.close("xs:restriction");
    x_.close("xs:simpleType");
  }

  /// True if values of the type are text: a simple type or an enumeration,
  /// directly or through TYPE a = b.
  bool isSimple(DeclTypeId id) const {
    for (int depth = 0; depth < kMaxTypeChain; ++depth) {
      const TypeExpr &u = model_.type(model_.typeDecl(id).underlying);
      if (u.kind == TypeExpr::Simple || u.kind == TypeExpr::Enumeration)
        return true;
      if (u.kind != TypeExpr::Named || u.declared == kNone)
        return false;
      id = u.declared;
    }
    return false;
  }

  /// Declares `name` once, to be written by `write` after the entities and
  /// defined types; returns the name.
  std::string share(std::string name, std::function<void()> write) {
    shared_.try_emplace(name, std::move(write));
    return name;
  }

  /// The group of the elements a reference to `entity` may be.
  std::string useGroup(EntityId entity) {
    return share(groupName(model_.entity(entity).name), [this, entity] {
      x_.open("xs:group", {{"name", groupName(model_.entity(entity).name)}});
      x_.open("xs:choice");
      for (const std::string &element : scope_.entityChoice(entity))
        x_.leaf("xs:element", {{"ref", element}});
      x_.close("xs:choice");
      x_.close("xs:group");
    });
  }

  // Attributes refer to entities and hold aggregates of entities and SELECTs
  // through named types rather than types in place: a validator compiles the
  // content model of a large choice once, not once per attribute.

  /// The type of an attribute referring to `entity`: "<Entity>-ref".
  std::string useReferenceType(EntityId entity) {
    std::string group = useGroup(entity);
    return share(elementName(model_.entity(entity).name) + "-ref", [this, entity, group] {
      x_.open("xs:complexType", {{"name", elementName(model_.entity(entity).name) + "-ref"}});
      x_.leaf("xs:group", {{"ref", group}});
      x_.close("xs:complexType");
    });
  }

  /// The type of an aggregate whose members are the choice `group` (of an
  /// entity or a SELECT named `member`): "<Member>-aggregate".
  std::string useAggregateType(const std::string &member, std::string group) {
    std::string name = elementName(member) + "-aggregate";
    return share(name, [this, name, group] {
      x_.open("xs:complexType", {{"name", name}});
      x_.open("xs:sequence");
      repeated("xs:group", group);
      x_.close("xs:sequence");
      x_.leaf("xs:attribute", {{"ref", "exp:cType"}});
      x_.close("xs:complexType");
    });
  }

  const XsdScope &scope_;
  const express::Model &model_;
  const express::Schema &schema_;
  XmlText x_;
  std::map<std::string, std::function<void()>> shared_; ///< by name: written sorted
};

/// Names two declarations of the scope would both get, as "Name (entity a in
/// schema s, type a in schema t)"; empty when every element name is unique.
std::string nameClashes(const XsdScope &scope) {
  const express::Model &m = scope.model();
  std::map<std::string, std::vector<std::string>> owners;
  for (EntityId e : scope.entities())
    owners[elementName(m.entity(e).name)].push_back("entity " + m.entity(e).name + " in schema " + m.entity(e).schema);
  for (DeclTypeId t : scope.types())
    owners[elementName(m.typeDecl(t).name)].push_back("type " + m.typeDecl(t).name + " in schema " +
                                                      m.typeDecl(t).schema);
  std::string out;
  for (const auto &[name, what] : owners) {
    if (what.size() < 2)
      continue;
    out += (out.empty() ? "" : "; ") + name + " (";
    for (size_t i = 0; i < what.size(); ++i)
      out += (i ? ", " : "") + what[i];
    out += ")";
  }
  return out;
}

} // namespace

XsdScope::XsdScope(const express::Model &model, const express::Schema &schema)
    : model_(model), entityIn_(model.entities().size(), false), typeIn_(model.typeDecls().size(), false) {
  std::vector<std::pair<bool, uint32_t>> work;
  for (const auto &[name, item] : schema.scope)
    add(item.first, item.second, work);
  while (!work.empty()) {
    auto [isEntity, id] = work.back();
    work.pop_back();
    if (isEntity) {
      for (const express::Slot &s : model_.entity(id).slots)
        if (!s.derived)
          addTypeRefs(s.type, work);
      continue;
    }
    const express::TypeDecl &decl = model_.typeDecl(id);
    addTypeRefs(decl.underlying, work);
    for (const std::string &item : decl.selectItems) {
      auto [itemIsEntity, itemId] = resolveIn(decl, item);
      add(itemIsEntity, itemId, work);
    }
    if (!decl.basedOn.empty()) {
      auto [baseIsEntity, baseId] = resolveIn(decl, decl.basedOn);
      add(baseIsEntity, baseId, work);
    }
  }
  for (EntityId e = 0; e < entityIn_.size(); ++e)
    if (entityIn_[e])
      entities_.push_back(e);
  for (DeclTypeId t = 0; t < typeIn_.size(); ++t)
    if (typeIn_[t])
      types_.push_back(t);
  std::stable_sort(entities_.begin(), entities_.end(),
                   [&](EntityId a, EntityId b) { return model_.entity(a).name < model_.entity(b).name; });
  std::stable_sort(types_.begin(), types_.end(),
                   [&](DeclTypeId a, DeclTypeId b) { return model_.typeDecl(a).name < model_.typeDecl(b).name; });
}

void XsdScope::add(bool isEntity, uint32_t id, std::vector<std::pair<bool, uint32_t>> &work) {
  if (id == kNone)
    return;
  std::vector<bool> &in = isEntity ? entityIn_ : typeIn_;
  if (in[id])
    return;
  in[id] = true;
  work.emplace_back(isEntity, id);
}

void XsdScope::addTypeRefs(TypeId type, std::vector<std::pair<bool, uint32_t>> &work) {
  while (type != kNone) {
    const TypeExpr &t = model_.type(type);
    if (t.kind == TypeExpr::Named) {
      if (t.entity != kNone)
        add(true, t.entity, work);
      else
        add(false, t.declared, work);
      return;
    }
    type = t.kind == TypeExpr::Aggregate ? t.element : kNone;
  }
}

std::pair<bool, uint32_t> XsdScope::resolveIn(const express::TypeDecl &decl, const std::string &name) const {
  const express::Schema *s = model_.findSchema(decl.schema);
  if (!s)
    return {false, kNone};
  auto it = s->scope.find(name);
  return it == s->scope.end() ? std::pair<bool, uint32_t>{false, kNone} : it->second;
}

bool XsdScope::isSelect(DeclTypeId type) const {
  for (int depth = 0; depth < kMaxTypeChain; ++depth) {
    const TypeExpr &u = model_.type(model_.typeDecl(type).underlying);
    if (u.kind == TypeExpr::Select)
      return true;
    if (u.kind != TypeExpr::Named || u.declared == kNone)
      return false;
    type = u.declared;
  }
  return false;
}

std::vector<std::string> XsdScope::enumerationValues(DeclTypeId enumeration) const {
  std::vector<std::string> values;
  std::set<std::string> seen;
  for (int depth = 0; enumeration != kNone && depth < kMaxTypeChain; ++depth) {
    const express::TypeDecl &decl = model_.typeDecl(enumeration);
    for (const std::string &v : decl.enumValues)
      if (seen.insert(express::lower(v)).second)
        values.push_back(express::lower(v));
    auto [isEntity, base] =
        decl.basedOn.empty() ? std::pair<bool, uint32_t>{false, kNone} : resolveIn(decl, decl.basedOn);
    enumeration = isEntity ? kNone : base;
  }
  return values;
}

std::vector<std::string> XsdScope::entityChoice(EntityId entity) const {
  std::vector<std::string> out;
  std::vector<bool> seen(entityIn_.size(), false);
  collectSubtree(entity, out, seen);
  return out;
}

std::vector<std::string> XsdScope::selectChoice(DeclTypeId select) const {
  std::vector<std::string> out;
  std::vector<bool> seenTypes(typeIn_.size(), false), seenEntities(entityIn_.size(), false);
  collectSelect(select, out, seenTypes, seenEntities);
  return out;
}

void XsdScope::collectSubtree(EntityId entity, std::vector<std::string> &out, std::vector<bool> &seen) const {
  if (seen[entity])
    return;
  seen[entity] = true;
  if (entityIn_[entity])
    out.push_back(elementName(model_.entity(entity).name));
  for (EntityId sub : model_.entity(entity).subtypes)
    collectSubtree(sub, out, seen);
}

void XsdScope::collectSelect(DeclTypeId type, std::vector<std::string> &out, std::vector<bool> &seenTypes,
                             std::vector<bool> &seenEntities) const {
  if (seenTypes[type])
    return;
  seenTypes[type] = true;
  const express::TypeDecl &decl = model_.typeDecl(type);
  const TypeExpr &u = model_.type(decl.underlying);
  if (u.kind == TypeExpr::Named && u.declared != kNone) { // TYPE a = some_select
    collectSelect(u.declared, out, seenTypes, seenEntities);
    return;
  }
  std::vector<std::string> items = decl.selectItems;
  if (!decl.basedOn.empty())
    items.push_back(decl.basedOn);
  for (const std::string &item : items) {
    auto [isEntity, id] = resolveIn(decl, item);
    if (id == kNone)
      continue;
    if (isEntity)
      collectSubtree(id, out, seenEntities);
    else if (isSelect(id))
      collectSelect(id, out, seenTypes, seenEntities);
    else if (!seenTypes[id]) {
      seenTypes[id] = true;
      out.push_back(elementName(model_.typeDecl(id).name));
    }
  }
}

std::string commonXsd() {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- ISO 10303-28 ed. 2 common elements as stepnc writes and reads them (docs/part28.md); generated by stepnc. -->
<xs:schema xmlns:xs="http://www.w3.org/2001/XMLSchema" xmlns:exp="urn:oid:1.0.10303.28.2.1.1" targetNamespace="urn:oid:1.0.10303.28.2.1.1" elementFormDefault="qualified">
  <xs:element name="iso_10303_28">
    <xs:complexType>
      <xs:sequence>
        <xs:element ref="exp:iso_10303_28_header" minOccurs="0"/>
        <xs:element ref="exp:uos" maxOccurs="unbounded"/>
      </xs:sequence>
      <xs:attribute name="version" type="xs:string"/>
    </xs:complexType>
    <!-- Every ref names an id of the document (xs:IDREF alone is not checked by every validator). -->
    <xs:unique name="instance-id">
      <xs:selector xpath=".//*"/>
      <xs:field xpath="@id"/>
    </xs:unique>
    <xs:keyref name="instance-ref" refer="exp:instance-id">
      <xs:selector xpath=".//*"/>
      <xs:field xpath="@ref"/>
    </xs:keyref>
  </xs:element>
  <xs:element name="iso_10303_28_header">
    <xs:complexType>
      <xs:sequence>
        <xs:element name="name" type="xs:string" minOccurs="0"/>
        <xs:element name="time_stamp" type="xs:string" minOccurs="0"/>
        <xs:element name="author" type="xs:string" minOccurs="0" maxOccurs="unbounded"/>
        <xs:element name="organization" type="xs:string" minOccurs="0" maxOccurs="unbounded"/>
        <xs:element name="preprocessor_version" type="xs:string" minOccurs="0"/>
        <xs:element name="originating_system" type="xs:string" minOccurs="0"/>
        <xs:element name="authorization" type="xs:string" minOccurs="0"/>
        <xs:element name="documentation" type="xs:string" minOccurs="0" maxOccurs="unbounded"/>
      </xs:sequence>
    </xs:complexType>
  </xs:element>
  <!-- A unit of serialisation; each schema's XSD substitutes its own uos, holding its entity elements. -->
  <xs:element name="uos" type="exp:uos" abstract="true"/>
  <xs:complexType name="uos">
    <xs:attribute name="id" type="xs:ID"/>
    <xs:attribute name="express" type="xs:string"/>
    <xs:attribute name="configuration" type="xs:string"/>
    <xs:attribute name="description" type="xs:string"/>
  </xs:complexType>
  <!-- On every entity element: its instance id, or the id of the instance it refers to. -->
  <xs:attributeGroup name="instanceAttributes">
    <xs:attribute name="id" type="xs:ID"/>
    <xs:attribute name="ref" type="xs:IDREF"/>
  </xs:attributeGroup>
  <xs:simpleType name="logical">
    <xs:restriction base="xs:string">
      <xs:enumeration value="true"/>
      <xs:enumeration value="false"/>
      <xs:enumeration value="unknown"/>
    </xs:restriction>
  </xs:simpleType>
  <!-- The Part 21 hexadecimal digits; the first counts the unused bits. -->
  <xs:simpleType name="binary">
    <xs:restriction base="xs:string">
      <xs:pattern value="[0-3][0-9A-Fa-f]*"/>
    </xs:restriction>
  </xs:simpleType>
  <xs:simpleType name="aggregateKind">
    <xs:restriction base="xs:string">
      <xs:enumeration value="list"/>
      <xs:enumeration value="set"/>
      <xs:enumeration value="bag"/>
      <xs:enumeration value="array"/>
    </xs:restriction>
  </xs:simpleType>
  <xs:attribute name="cType" type="exp:aggregateKind"/>
  <!-- Aggregate members of simple types. -->
  <xs:element name="double" type="xs:double"/>
  <xs:element name="long" type="xs:long"/>
  <xs:element name="string" type="xs:string"/>
  <xs:element name="boolean" type="xs:boolean"/>
  <xs:element name="logical" type="exp:logical"/>
  <xs:element name="binary" type="exp:binary"/>
  <!-- Aggregate members that are aggregates; their members are checked where they are declared. -->
  <xs:complexType name="aggregate">
    <xs:sequence>
      <xs:any processContents="lax" minOccurs="0" maxOccurs="unbounded"/>
    </xs:sequence>
    <xs:attribute ref="exp:cType"/>
  </xs:complexType>
  <xs:element name="list" type="exp:aggregate"/>
  <xs:element name="set" type="exp:aggregate"/>
  <xs:element name="bag" type="exp:aggregate"/>
  <xs:element name="array" type="exp:aggregate"/>
</xs:schema>
)";
}

bool schemaXsd(const express::Model &model, const express::Schema &schema, std::string &out, std::string &error) {
  XsdScope scope(model, schema);
  std::string clashes = nameClashes(scope);
  if (!clashes.empty()) {
    error = "schema '" + schema.name +
            "' has no Part 28 XSD: declarations of the same name would share an element: " + clashes;
    return false;
  }
  out = SchemaXsdWriter(scope, schema).write();
  return true;
}

} // namespace stepnc::part28
