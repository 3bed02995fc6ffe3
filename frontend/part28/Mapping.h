// What the Part 28 reader, writer and XSD generator share: element names,
// namespaces, and how an EXPRESS type is seen from XML (docs/part28.md).
#pragma once

#include "frontend/express/Schema.h"

#include <string>
#include <string_view>
#include <vector>

namespace stepnc::p28 {

/// Namespace of the elements common to every schema (root, header, uos,
/// simple members, nested aggregates).
inline constexpr std::string_view kCommonNamespace = "urn:oid:1.0.10303.28.2.1.1";
inline constexpr std::string_view kXsiNamespace = "http://www.w3.org/2001/XMLSchema-instance";

/// Namespace of a schema's elements: "urn:iso10303-28:xs/iso14649_arm".
std::string schemaNamespace(std::string_view schemaName);

/// XML name of an EXPRESS entity, type or attribute: first letter upper case,
/// the rest lower case ("machining_workingstep" -> "Machining_workingstep").
std::string xmlName(std::string_view expressName);

/// The element name of each of an entity's slots, in Part 21 order:
/// xmlName(slot name), except where two explicit slots have the same name
/// (attributes of the same name inherited from two supertypes): each of those
/// is "<Declaring entity>.<Attribute>" ("Representation_item.Name"), since a
/// repeated element in the entity's sequence would be ambiguous.
std::vector<std::string> attributeElementNames(const express::Model &model, express::EntityId entity);

/// Appends `text` escaped for element content or a double-quoted XML
/// attribute (`&amp;` `&lt;` `&gt;` `&quot;`, and tab, line feed and carriage
/// return as character references so they survive attribute normalisation).
/// Returns false, having appended the rest, on a control character XML 1.0
/// cannot carry.
bool appendEscaped(std::string &out, std::string_view text);

/// A type as the XML mapping sees it: defined types followed to what they
/// finally are, remembering the outermost declared name (which names the
/// element of an aggregate member or a SELECT value).
struct TypeView {
  enum Kind : uint8_t { Simple, Enumeration, Select, Aggregate, Entity, Unknown };
  Kind kind = Unknown;
  express::SimpleKind simple = express::SimpleKind::String;
  express::DeclTypeId decl = express::kNone;      ///< outermost defined type, if any
  express::DeclTypeId innerDecl = express::kNone; ///< Enumeration/Select: the declaring type
  express::TypeId aggregate = express::kNone;     ///< Aggregate: the aggregate type expression
  express::EntityId entity = express::kNone;      ///< Entity
};

TypeView viewType(const express::Model &model, express::TypeId type);

/// The common element of a simple member: "double", "long", "string",
/// "boolean", "logical" or "binary".
std::string_view simpleMemberName(express::SimpleKind kind);

/// The common element, with its prefix, of a member of a simple type
/// ("exp:double") or of a nested aggregate without a defined type ("exp:list").
std::string commonElement(express::SimpleKind kind);
std::string commonElement(express::AggregateKind kind);

/// The element of an aggregate member seen as `view` (Simple, Enumeration or
/// Aggregate): its defined type's, else the common one with its prefix
/// ("exp:double", "exp:list"); empty for references and SELECT values,
/// which are written as the element of what they hold.
std::string memberElement(const express::Model &model, const TypeView &view);

} // namespace stepnc::p28
