#include "frontend/express/ExpressWriter.h"

#include <algorithm>

namespace stepnc::express {

namespace {

std::string list(const std::vector<std::string> &items) {
  std::string s;
  for (const std::string &i : items)
    s += (s.empty() ? "" : ", ") + i;
  return s;
}

std::string supertypeText(const SupertypeExpr &e);

/// An AND or ANDOR operand in parentheses, so that nesting reads as it binds.
std::string parenthesised(const SupertypeExpr &e) {
  std::string s = supertypeText(e);
  if (e.op == SupertypeExpr::And || e.op == SupertypeExpr::AndOr)
    s.insert(0, 1, '(').push_back(')');
  return s;
}

std::string supertypeText(const SupertypeExpr &e) {
  const char *op = e.op == SupertypeExpr::OneOf ? "ONEOF" : e.op == SupertypeExpr::And ? "AND" : "ANDOR";
  switch (e.op) {
  case SupertypeExpr::Leaf: return e.entity;
  case SupertypeExpr::OneOf: {
    std::vector<std::string> parts;
    for (const SupertypeExpr &o : e.operands)
      parts.push_back(supertypeText(o));
    return std::string(op) + " (" + list(parts) + ")";
  }
  default: {
    std::string s;
    for (const SupertypeExpr &o : e.operands) {
      if (!s.empty())
        s.append(" ").append(op).append(" ");
      s += parenthesised(o);
    }
    return s;
  }
  }
}

void typeDecl(std::string &out, const Model &m, const TypeDecl &t) {
  out += "TYPE " + t.name + " = ";
  const TypeExpr &u = m.type(t.underlying);
  if (u.kind == TypeExpr::Select || u.kind == TypeExpr::Enumeration) {
    if (t.extensible)
      out += "EXTENSIBLE ";
    if (t.genericEntity)
      out += "GENERIC_ENTITY ";
    out += u.kind == TypeExpr::Select ? "SELECT" : "ENUMERATION";
    const std::vector<std::string> &items = u.kind == TypeExpr::Select ? t.selectItems : t.enumValues;
    if (!t.basedOn.empty())
      out += " BASED_ON " + t.basedOn + (items.empty() ? "" : " WITH");
    else if (u.kind == TypeExpr::Enumeration)
      out += " OF";
    if (!items.empty()) {
      out += "\n   (";
      for (size_t i = 0; i < items.size(); ++i)
        out += (i ? ",\n    " : "") + items[i];
      out += ")";
    }
  } else {
    out += m.typeText(t.underlying);
  }
  out += ";\nEND_TYPE;\n\n";
}

std::string redeclared(const std::string &entity, const std::string &attribute, const std::string &name) {
  return "SELF\\" + entity + "." + attribute + (name == attribute ? "" : " RENAMED " + name);
}

void entityDecl(std::string &out, const Model &m, const Entity &e) {
  out += "ENTITY " + e.name;
  // Several constraints all apply: AND says so in one expression.
  std::string super;
  for (const SupertypeExpr &c : e.supertypeConstraints) {
    if (!super.empty())
      super += " AND ";
    super += e.supertypeConstraints.size() > 1 ? parenthesised(c) : supertypeText(c);
  }
  if (e.abstract)
    out += super.empty() ? "\n  ABSTRACT SUPERTYPE" : "\n  ABSTRACT SUPERTYPE OF (" + super + ")";
  else if (!super.empty())
    out += "\n  SUPERTYPE OF (" + super + ")";
  if (!e.supertypeNames.empty())
    out += "\n  SUBTYPE OF (" + list(e.supertypeNames) + ")";
  out += ";\n";
  auto line = [&out](const std::string &name, const std::string &rest) {
    out += "  " + name;
    out.append(name.size() < 30 ? 30 - name.size() : 1, ' ');
    out += ": " + rest + ";\n";
  };
  for (const Attribute &a : e.attributes)
    line(a.isRedeclaration() ? redeclared(a.redeclaresEntity, a.redeclaresAttribute, a.name) : a.name,
         std::string(a.optional ? "OPTIONAL " : "") + m.typeText(a.type));
  if (!e.derived.empty()) {
    out += "DERIVE\n";
    for (const DerivedAttribute &d : e.derived)
      line(d.redeclaresAttribute.empty() ? d.name : redeclared(d.redeclaresEntity, d.redeclaresAttribute, d.name),
           m.typeText(d.type) + " := ?");
  }
  if (!e.inverse.empty()) {
    out += "INVERSE\n";
    for (const InverseAttribute &i : e.inverse) {
      std::string type = i.entity;
      if (i.aggregate)
        type = std::string(i.bag ? "BAG" : "SET") + " [" + std::to_string(i.lower) + ":" +
               (i.upper < 0 ? std::string("?") : std::to_string(i.upper)) + "] OF " + i.entity;
      line(i.name, type + " FOR " + i.attribute);
    }
  }
  if (!e.unique.empty()) {
    out += "UNIQUE\n";
    for (size_t k = 0; k < e.unique.size(); ++k)
      line("ur" + std::to_string(k + 1), list(e.unique[k]));
  }
  out += "END_ENTITY;\n\n";
}

} // namespace

std::string writeExpressFacts(const Model &model, const Schema &schema, std::string_view banner) {
  std::string out;
  if (!banner.empty())
    out += "(*\n" + std::string(banner) + (banner.back() == '\n' ? "" : "\n") + "*)\n\n";
  out += "SCHEMA " + schema.name + ";\n\n";
  for (DeclTypeId id : schema.types)
    typeDecl(out, model, model.typeDecl(id));
  for (EntityId id : schema.entities)
    entityDecl(out, model, model.entity(id));
  out += "END_SCHEMA;\n";
  return out;
}

} // namespace stepnc::express
