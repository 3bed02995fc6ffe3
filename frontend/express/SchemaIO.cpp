#include "frontend/express/SchemaIO.h"

#include <charconv>
#include <sstream>

namespace stepnc::express {

namespace {

// ---- writing -------------------------------------------------------------

std::string escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '\\')
      out += "\\\\";
    else if (c == '\n')
      out += "\\n";
    else if (c == '\r')
      continue;
    else
      out.push_back(c);
  }
  return out;
}

std::string bounds(const TypeExpr &t) {
  return "[" + std::to_string(t.lower) + ":" + (t.upper < 0 ? std::string("?") : std::to_string(t.upper)) + "]";
}

void writeType(std::string &out, const Model &m, TypeId id) {
  if (id == kNone) {
    out += " -";
    return;
  }
  const TypeExpr &t = m.type(id);
  switch (t.kind) {
  case TypeExpr::Simple:
    out += ' ';
    out += simpleKindName(t.simple);
    return;
  case TypeExpr::Named:
    out += " @" + t.name;
    return;
  case TypeExpr::Select: out += " SELECT"; return;
  case TypeExpr::Enumeration: out += " ENUMERATION"; return;
  case TypeExpr::Generic:
    out += " GENERIC";
    writeType(out, m, t.element);
    return;
  case TypeExpr::Aggregate:
    out += ' ';
    out += aggregateKindName(t.aggregate);
    out += bounds(t);
    if (t.optionalElements)
      out += "o";
    if (t.unique)
      out += "u";
    writeType(out, m, t.element);
    return;
  }
}

void writeSupertype(std::string &out, const SupertypeExpr &e) {
  switch (e.op) {
  case SupertypeExpr::Leaf: out += ' ' + e.entity; return;
  case SupertypeExpr::OneOf: out += " (oneof"; break;
  case SupertypeExpr::And: out += " (and"; break;
  case SupertypeExpr::AndOr: out += " (andor"; break;
  }
  for (const SupertypeExpr &o : e.operands)
    writeSupertype(out, o);
  out += " )";
}

std::string joined(const std::vector<std::string> &v, char sep) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) {
    if (i)
      s.push_back(sep);
    s += v[i];
  }
  return s;
}

// ---- reading -------------------------------------------------------------

class Lines {
public:
  explicit Lines(std::string_view text) : text_(text) {}
  bool next(std::string_view &line) {
    if (pos_ >= text_.size())
      return false;
    size_t nl = text_.find('\n', pos_);
    if (nl == std::string_view::npos)
      nl = text_.size();
    line = text_.substr(pos_, nl - pos_);
    pos_ = nl + 1;
    ++number_;
    return true;
  }
  size_t number() const { return number_; }

private:
  std::string_view text_;
  size_t pos_ = 0;
  size_t number_ = 0;
};

class Tokens {
public:
  explicit Tokens(std::string_view line) : line_(line) {}
  bool next(std::string_view &tok) {
    while (pos_ < line_.size() && line_[pos_] == ' ')
      ++pos_;
    if (pos_ >= line_.size())
      return false;
    size_t end = line_.find(' ', pos_);
    if (end == std::string_view::npos)
      end = line_.size();
    tok = line_.substr(pos_, end - pos_);
    pos_ = end;
    return true;
  }
  std::string_view rest() {
    while (pos_ < line_.size() && line_[pos_] == ' ')
      ++pos_;
    return line_.substr(pos_);
  }

private:
  std::string_view line_;
  size_t pos_ = 0;
};

std::string unescape(std::string_view s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) {
      out.push_back(s[i + 1] == 'n' ? '\n' : s[i + 1]);
      ++i;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

bool parseInt(std::string_view s, int64_t &v) {
  if (s == "?") {
    v = -1;
    return true;
  }
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

struct Reader {
  Model &model;
  std::string error;

  bool type(Tokens &t, TypeId &out) {
    std::string_view tok;
    if (!t.next(tok))
      return fail("missing type");
    if (tok == "-") {
      out = kNone;
      return true;
    }
    TypeExpr e;
    static const std::pair<std::string_view, SimpleKind> simple[] = {
        {"BINARY", SimpleKind::Binary}, {"BOOLEAN", SimpleKind::Boolean}, {"INTEGER", SimpleKind::Integer},
        {"LOGICAL", SimpleKind::Logical}, {"NUMBER", SimpleKind::Number}, {"REAL", SimpleKind::Real},
        {"STRING", SimpleKind::String}};
    for (const auto &[name, kind] : simple)
      if (tok == name) {
        e.kind = TypeExpr::Simple;
        e.simple = kind;
        out = model.addTypeExpr(std::move(e));
        return true;
      }
    if (tok[0] == '@') {
      e.kind = TypeExpr::Named;
      e.name = std::string(tok.substr(1));
    } else if (tok == "SELECT") {
      e.kind = TypeExpr::Select;
    } else if (tok == "ENUMERATION") {
      e.kind = TypeExpr::Enumeration;
    } else if (tok == "GENERIC") {
      e.kind = TypeExpr::Generic;
      if (!type(t, e.element))
        return false;
    } else {
      static const std::pair<std::string_view, AggregateKind> aggs[] = {
          {"ARRAY", AggregateKind::Array}, {"BAG", AggregateKind::Bag},
          {"LIST", AggregateKind::List}, {"SET", AggregateKind::Set}};
      bool found = false;
      for (const auto &[name, kind] : aggs)
        if (tok.starts_with(name)) {
          e.kind = TypeExpr::Aggregate;
          e.aggregate = kind;
          std::string_view b = tok.substr(name.size());
          size_t colon = b.find(':'), close = b.find(']');
          if (b.empty() || b[0] != '[' || colon == std::string_view::npos || close == std::string_view::npos ||
              !parseInt(b.substr(1, colon - 1), e.lower) || !parseInt(b.substr(colon + 1, close - colon - 1), e.upper))
            return fail("bad aggregate bounds '" + std::string(tok) + "'");
          std::string_view flags = b.substr(close + 1);
          e.optionalElements = flags.find('o') != std::string_view::npos;
          e.unique = flags.find('u') != std::string_view::npos;
          found = true;
          break;
        }
      if (!found)
        return fail("unknown type token '" + std::string(tok) + "'");
      if (!type(t, e.element))
        return false;
    }
    out = model.addTypeExpr(std::move(e));
    return true;
  }

  bool supertype(Tokens &t, SupertypeExpr &out) {
    std::string_view tok;
    if (!t.next(tok))
      return fail("missing supertype expression");
    if (tok == "(oneof" || tok == "(and" || tok == "(andor") {
      out.op = tok == "(oneof" ? SupertypeExpr::OneOf : tok == "(and" ? SupertypeExpr::And : SupertypeExpr::AndOr;
      for (;;) {
        Tokens peek = t;
        std::string_view p;
        if (!peek.next(p))
          return fail("unterminated supertype expression");
        if (p == ")") {
          t = peek;
          return true;
        }
        SupertypeExpr sub;
        if (!supertype(t, sub))
          return false;
        out.operands.push_back(std::move(sub));
      }
    }
    out.op = SupertypeExpr::Leaf;
    out.entity = std::string(tok);
    return true;
  }

  bool fail(std::string msg) {
    if (error.empty())
      error = std::move(msg);
    return false;
  }
};

// An optional `redeclares=entity.attribute` token.
void readRedeclaration(Tokens &t, std::string &entity, std::string &attribute) {
  Tokens save = t;
  std::string_view maybe;
  if (t.next(maybe) && maybe.starts_with("redeclares=")) {
    std::string_view target = maybe.substr(11);
    size_t dot = target.find('.');
    entity = std::string(target.substr(0, dot));
    attribute = std::string(target.substr(dot + 1));
  } else {
    t = save;
  }
}

std::vector<std::string> split(std::string_view s, char sep) {
  std::vector<std::string> out;
  if (s.empty())
    return out;
  size_t start = 0;
  for (;;) {
    size_t p = s.find(sep, start);
    out.emplace_back(s.substr(start, p == std::string_view::npos ? std::string_view::npos : p - start));
    if (p == std::string_view::npos)
      return out;
    start = p + 1;
  }
}

} // namespace

std::string serializeModel(const Model &m) {
  std::string out = "stepnc-schema 1\n";
  for (const Schema &s : m.schemas()) {
    out += "schema " + s.name + "\n";
    for (const Interface &i : s.interfaces) {
      out += std::string(i.use ? "use " : "reference ") + i.schema;
      for (const auto &[name, rename] : i.items)
        out += " " + name + (rename.empty() ? "" : "=" + rename);
      out += "\n";
    }
    for (const std::string &c : s.constants)
      out += "constant " + c + "\n";
    for (DeclTypeId id : s.types) {
      const TypeDecl &t = m.typeDecl(id);
      out += "type " + t.name;
      writeType(out, m, t.underlying);
      if (t.extensible)
        out += " extensible";
      if (t.genericEntity)
        out += " generic_entity";
      if (!t.basedOn.empty())
        out += " based_on=" + t.basedOn;
      if (!t.selectItems.empty())
        out += " : " + joined(t.selectItems, ' ');
      if (!t.enumValues.empty())
        out += " : " + joined(t.enumValues, ' ');
      out += "\n";
      for (const WhereRule &w : t.where)
        out += " where " + (w.label.empty() ? "-" : w.label) + " " + escape(w.text) + "\n";
    }
    for (EntityId id : s.entities) {
      const Entity &e = m.entity(id);
      out += "entity " + e.name;
      if (e.abstract)
        out += " abstract";
      if (!e.supertypeNames.empty())
        out += " subtype_of=" + joined(e.supertypeNames, ',');
      out += "\n";
      for (const SupertypeExpr &c : e.supertypeConstraints) {
        out += " supertype";
        writeSupertype(out, c);
        out += "\n";
      }
      for (const Attribute &a : e.attributes) {
        out += " attr " + a.name + (a.optional ? " optional" : " mandatory");
        if (a.isRedeclaration())
          out += " redeclares=" + a.redeclaresEntity + "." + a.redeclaresAttribute;
        writeType(out, m, a.type);
        out += "\n";
      }
      for (const DerivedAttribute &d : e.derived) {
        out += " derive " + d.name;
        if (!d.redeclaresAttribute.empty())
          out += " redeclares=" + d.redeclaresEntity + "." + d.redeclaresAttribute;
        writeType(out, m, d.type);
        out += " := " + escape(d.expression) + "\n";
      }
      for (const InverseAttribute &i : e.inverse)
        out += " inverse " + i.name + " " + (i.aggregate ? (i.bag ? "BAG" : "SET") : "ONE") + " " +
               std::to_string(i.lower) + " " + (i.upper < 0 ? std::string("?") : std::to_string(i.upper)) +
               " " + i.entity + " " + i.attribute + "\n";
      for (const auto &u : e.unique)
        out += " unique " + joined(u, ',') + "\n";
      for (const WhereRule &w : e.where)
        out += " where " + (w.label.empty() ? "-" : w.label) + " " + escape(w.text) + "\n";
    }
    for (const std::string &f : s.functions)
      out += "function " + f + "\n";
    for (const std::string &p : s.procedures)
      out += "procedure " + p + "\n";
    for (const std::string &r : s.rules)
      out += "rule " + r + "\n";
  }
  return out;
}

bool deserializeModel(std::string_view text, Model &model, std::string &error) {
  Lines lines(text);
  Reader r{model, {}};
  std::string_view line;
  if (!lines.next(line) || line != "stepnc-schema 1") {
    error = "line 1: not a stepnc schema file (version 1)";
    return false;
  }
  long schemaIndex = -1;
  EntityId entity = kNone;
  DeclTypeId typeDecl = kNone;
  auto failAt = [&](const std::string &msg) {
    error = "line " + std::to_string(lines.number()) + ": " + msg;
    return false;
  };
  while (lines.next(line)) {
    if (line.empty())
      continue;
    Tokens t(line);
    std::string_view kw;
    t.next(kw);
    const bool member = line[0] == ' ';
    if (!member && kw != "schema" && schemaIndex < 0)
      return failAt("declaration before any schema");
    if (kw == "schema") {
      std::string_view name;
      if (!t.next(name))
        return failAt("schema without a name");
      model.addSchema(std::string(name), {});
      schemaIndex = static_cast<long>(model.schemas().size() - 1);
      entity = kNone;
      typeDecl = kNone;
      continue;
    }
    Schema &schema = model.mutableSchema(static_cast<size_t>(schemaIndex));
    if (!member) {
      entity = kNone;
      typeDecl = kNone;
    }
    if (!member && (kw == "use" || kw == "reference")) {
      Interface i;
      i.use = kw == "use";
      std::string_view name;
      if (!t.next(name))
        return failAt("interface without a schema");
      i.schema = std::string(name);
      std::string_view item;
      while (t.next(item)) {
        size_t eq = item.find('=');
        i.items.emplace_back(std::string(item.substr(0, eq)),
                             eq == std::string_view::npos ? std::string() : std::string(item.substr(eq + 1)));
      }
      schema.interfaces.push_back(std::move(i));
    } else if (!member && (kw == "constant" || kw == "function" || kw == "procedure" || kw == "rule")) {
      std::string_view name;
      t.next(name);
      auto &list = kw == "constant" ? schema.constants : kw == "function" ? schema.functions
                   : kw == "procedure" ? schema.procedures : schema.rules;
      list.emplace_back(name);
    } else if (!member && kw == "type") {
      TypeDecl d;
      std::string_view name;
      if (!t.next(name))
        return failAt("type without a name");
      d.name = std::string(name);
      d.schema = schema.name;
      if (!r.type(t, d.underlying))
        return failAt(r.error);
      std::string_view tok;
      bool items = false;
      while (t.next(tok)) {
        if (items) {
          (model.type(d.underlying).kind == TypeExpr::Select ? d.selectItems : d.enumValues).emplace_back(tok);
        } else if (tok == "extensible") {
          d.extensible = true;
        } else if (tok == "generic_entity") {
          d.genericEntity = true;
        } else if (tok.starts_with("based_on=")) {
          d.basedOn = std::string(tok.substr(9));
        } else if (tok == ":") {
          items = true;
        } else {
          return failAt("unexpected '" + std::string(tok) + "' in type");
        }
      }
      typeDecl = model.addTypeDecl(std::move(d));
      schema.types.push_back(typeDecl);
    } else if (!member && kw == "entity") {
      Entity e;
      std::string_view name, tok;
      if (!t.next(name))
        return failAt("entity without a name");
      e.name = std::string(name);
      e.schema = schema.name;
      while (t.next(tok)) {
        if (tok == "abstract")
          e.abstract = true;
        else if (tok.starts_with("subtype_of="))
          e.supertypeNames = split(tok.substr(11), ',');
        else
          return failAt("unexpected '" + std::string(tok) + "' in entity");
      }
      entity = model.addEntity(std::move(e));
      schema.entities.push_back(entity);
    } else if (member && kw == "where" && (entity != kNone || typeDecl != kNone)) {
      std::string_view label;
      t.next(label);
      WhereRule rule{label == "-" ? std::string() : std::string(label), unescape(t.rest()), nullptr};
      if (entity != kNone)
        model.mutableEntity(entity).where.push_back(std::move(rule));
      else
        model.mutableTypeDecl(typeDecl).where.push_back(std::move(rule));
    } else if (member && entity != kNone) {
      Entity &e = model.mutableEntity(entity);
      if (kw == "supertype") {
        SupertypeExpr s;
        if (!r.supertype(t, s))
          return failAt(r.error);
        e.supertypeConstraints.push_back(std::move(s));
      } else if (kw == "attr") {
        Attribute a;
        std::string_view name, opt;
        if (!t.next(name) || !t.next(opt))
          return failAt("incomplete attribute");
        a.name = std::string(name);
        a.optional = opt == "optional";
        readRedeclaration(t, a.redeclaresEntity, a.redeclaresAttribute);
        if (!r.type(t, a.type))
          return failAt(r.error);
        e.attributes.push_back(std::move(a));
      } else if (kw == "derive") {
        DerivedAttribute d;
        std::string_view name;
        if (!t.next(name))
          return failAt("incomplete derived attribute");
        d.name = std::string(name);
        readRedeclaration(t, d.redeclaresEntity, d.redeclaresAttribute);
        if (!r.type(t, d.type))
          return failAt(r.error);
        std::string_view assign;
        t.next(assign);
        d.expression = unescape(t.rest());
        e.derived.push_back(std::move(d));
      } else if (kw == "inverse") {
        InverseAttribute i;
        std::string_view name, agg, lo, hi, ent, attr;
        if (!t.next(name) || !t.next(agg) || !t.next(lo) || !t.next(hi) || !t.next(ent) || !t.next(attr))
          return failAt("incomplete inverse attribute");
        i.name = std::string(name);
        i.aggregate = agg != "ONE";
        i.bag = agg == "BAG";
        if (!parseInt(lo, i.lower) || !parseInt(hi, i.upper))
          return failAt("bad inverse bounds");
        i.entity = std::string(ent);
        i.attribute = std::string(attr);
        e.inverse.push_back(std::move(i));
      } else if (kw == "unique") {
        e.unique.push_back(split(t.rest(), ','));
      } else {
        return failAt("unknown entity member '" + std::string(kw) + "'");
      }
    } else {
      return failAt("unexpected '" + std::string(kw) + "'");
    }
  }
  return true;
}

} // namespace stepnc::express
