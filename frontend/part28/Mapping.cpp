#include "frontend/part28/Mapping.h"

#include <map>

namespace stepnc::p28 {

std::string schemaNamespace(std::string_view schemaName) { return "urn:iso10303-28:xs/" + express::lower(schemaName); }

std::string xmlName(std::string_view expressName) {
  std::string s = express::lower(expressName);
  if (!s.empty() && s[0] >= 'a' && s[0] <= 'z')
    s[0] = static_cast<char>(s[0] - 'a' + 'A');
  return s;
}

std::vector<std::string> attributeElementNames(const express::Model &model, express::EntityId entity) {
  const std::vector<express::Slot> &slots = model.entity(entity).slots;
  std::map<std::string, int> explicitCount;
  for (const express::Slot &s : slots)
    if (!s.derived)
      ++explicitCount[s.name];
  std::vector<std::string> names;
  for (const express::Slot &s : slots) {
    const bool repeated = !s.derived && explicitCount[s.name] > 1;
    names.push_back(repeated ? xmlName(model.entity(s.owner).name) + "." + xmlName(s.name) : xmlName(s.name));
  }
  return names;
}

TypeView viewType(const express::Model &model, express::TypeId type) {
  TypeView view;
  // A chain of defined types is finite and short (resolve() rejects cycles
  // and chains beyond kMaxTypeDepth), but bound the walk anyway so a bad
  // model cannot hang the mapping.
  for (uint32_t depth = 0; depth <= express::kMaxTypeDepth && type != express::kNone; ++depth) {
    const express::TypeExpr &t = model.type(type);
    switch (t.kind) {
    case express::TypeExpr::Simple:
      view.kind = TypeView::Simple;
      view.simple = t.simple;
      return view;
    case express::TypeExpr::Aggregate:
      view.kind = TypeView::Aggregate;
      view.aggregate = type;
      return view;
    case express::TypeExpr::Named: {
      if (t.entity != express::kNone) {
        view.kind = TypeView::Entity;
        view.entity = t.entity;
        return view;
      }
      if (t.declared == express::kNone)
        return view;
      if (view.decl == express::kNone)
        view.decl = t.declared;
      const express::TypeDecl &d = model.typeDecl(t.declared);
      const express::TypeExpr &u = model.type(d.underlying);
      if (u.kind == express::TypeExpr::Select || u.kind == express::TypeExpr::Enumeration) {
        view.kind = u.kind == express::TypeExpr::Select ? TypeView::Select : TypeView::Enumeration;
        view.innerDecl = t.declared;
        return view;
      }
      type = d.underlying;
      break;
    }
    case express::TypeExpr::Select:
    case express::TypeExpr::Enumeration:
      // Reached from a TYPE declaration's underlying type (the type of a
      // SELECT value `SPEED_NAME(.RAPID.)`): the declaration is not known here.
      view.kind = t.kind == express::TypeExpr::Select ? TypeView::Select : TypeView::Enumeration;
      return view;
    case express::TypeExpr::Generic:
      return view;
    }
  }
  return view;
}

bool appendEscaped(std::string &out, std::string_view text) {
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
    case '&':
      out += "&amp;";
      break;
    case '<':
      out += "&lt;";
      break;
    case '>':
      out += "&gt;";
      break;
    case '"':
      out += "&quot;";
      break;
    case '\t':
      out += "&#9;";
      break;
    case '\n':
      out += "&#10;";
      break;
    case '\r':
      out += "&#13;";
      break;
    default:
      if (c < 0x20 || c == 0x7F)
        return false;
      out.push_back(ch);
    }
  }
  return true;
}

std::string_view simpleMemberName(express::SimpleKind kind) {
  switch (kind) {
  case express::SimpleKind::Real:
  case express::SimpleKind::Number:
    return "double";
  case express::SimpleKind::Integer:
    return "long";
  case express::SimpleKind::String:
    return "string";
  case express::SimpleKind::Boolean:
    return "boolean";
  case express::SimpleKind::Logical:
    return "logical";
  case express::SimpleKind::Binary:
    return "binary";
  }
  return "string";
}

std::string commonElement(express::SimpleKind kind) { return "exp:" + std::string(simpleMemberName(kind)); }

std::string commonElement(express::AggregateKind kind) {
  return "exp:" + express::lower(express::aggregateKindName(kind));
}

std::string memberElement(const express::Model &model, const TypeView &view) {
  if (view.kind != TypeView::Simple && view.kind != TypeView::Enumeration && view.kind != TypeView::Aggregate)
    return {};
  if (view.decl != express::kNone)
    return xmlName(model.typeDecl(view.decl).name);
  if (view.kind == TypeView::Aggregate)
    return commonElement(model.type(view.aggregate).aggregate);
  return commonElement(view.simple);
}

} // namespace stepnc::p28
