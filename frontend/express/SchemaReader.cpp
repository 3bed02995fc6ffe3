// Builds the schema model from the ANTLR parse tree of an EXPRESS file.
//
// This is the only file that sees ANTLR: the generated parser lives in the
// stepnc_express_grammar library and everything else works on the model.
// Names are lower-cased. Expressions (WHERE rules, DERIVE) are kept as their
// source text; the model does not evaluate them.
#include "frontend/express/SchemaReader.h"

#include "ExpressLexer.h"
#include "ExpressParser.h"

#include <antlr4-runtime.h>

#include "support/Utf8.h"

#include <cstdio>
#include <optional>

namespace stepnc::express {

namespace g = stepnc::express::grammar;
using P = g::ExpressParser;

namespace {

// SourceLoc of an ANTLR position (1-based line, column in code points).
SourceLoc locAt(const SourceFile &file, size_t line, size_t column) {
  if (line == 0)
    return {&file, 0};
  // Find the line start through the line table, then walk code points.
  const LineCol probe{static_cast<uint32_t>(line), 1};
  std::string_view text = file.lineText(probe.line);
  uint64_t offset = static_cast<uint64_t>(text.data() - file.begin());
  size_t cp = 0, i = 0;
  while (i < text.size() && cp < column) {
    const auto c = static_cast<unsigned char>(text[i]);
    i += c < 0x80 ? 1 : c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC0 ? 2 : 1;
    ++cp;
  }
  return {&file, offset + std::min(i, text.size())};
}

class ErrorListener final : public antlr4::BaseErrorListener {
public:
  ErrorListener(const SourceFile &file, DiagnosticEngine &diags) : file_(file), diags_(diags) {}
  void syntaxError(antlr4::Recognizer *, antlr4::Token *, size_t line, size_t column,
                   const std::string &msg, std::exception_ptr) override {
    ++count;
    diags_.error(locAt(file_, line, column), "EXPRESS syntax: " + msg);
  }
  unsigned count = 0;

private:
  const SourceFile &file_;
  DiagnosticEngine &diags_;
};

// ---- expressions -----------------------------------------------------------

Expr makeList(Expr::Kind kind, std::string text, std::vector<Expr> args) {
  Expr e;
  e.kind = kind;
  e.text = std::move(text);
  e.args = std::move(args);
  return e;
}

// Operands are moved in one by one: a braced list would copy them (the
// elements of an initializer_list are const), and copying the left operand
// at every step made a chain of n operators cost O(n^2).
template <typename... Operands>
Expr makeExpr(Expr::Kind kind, std::string text, Operands &&...operands) {
  Expr e;
  e.kind = kind;
  e.text = std::move(text);
  e.args.reserve(sizeof...(operands));
  (e.args.push_back(std::forward<Operands>(operands)), ...);
  return e;
}

std::string upperText(antlr4::ParserRuleContext *ctx) {
  std::string t = ctx->getText();
  for (char &c : t)
    if (c >= 'a' && c <= 'z')
      c = static_cast<char>(c - 32);
  return t;
}

Expr buildExpression(P::ExpressionContext *ctx);
Expr buildSimple(P::Simple_expressionContext *ctx);

Expr buildPrimary(P::PrimaryContext *ctx) {
  Expr e;
  if (auto *lit = ctx->literal()) {
    if (lit->INTEGER_LITERAL())
      return makeExpr(Expr::Integer, lit->getText());
    if (lit->REAL_LITERAL())
      return makeExpr(Expr::Real, lit->getText());
    if (lit->BINARY_LITERAL())
      return makeExpr(Expr::BinaryLiteral, lit->getText());
    if (lit->logical_literal())
      return makeExpr(Expr::Logical, upperText(lit));
    return makeExpr(Expr::String, lit->getText());
  }
  auto *q = ctx->qualifiable_factor();
  if (auto *b = q->built_in_constant()) {
    e = makeExpr(Expr::Builtin, upperText(b));
  } else if (auto *f = q->built_in_function()) {
    e = makeExpr(Expr::Call, upperText(f));
    if (auto *params = q->actual_parameter_list())
      for (auto *p : params->parameter())
        e.args.push_back(buildExpression(p->expression()));
  } else if (auto *params = q->actual_parameter_list()) {
    e = makeExpr(Expr::Call, lower(q->simple_id()->getText()));
    for (auto *p : params->parameter())
      e.args.push_back(buildExpression(p->expression()));
  } else {
    e = makeExpr(Expr::Name, lower(q->simple_id()->getText()));
  }
  for (auto *qual : ctx->qualifier()) {
    if (auto *a = qual->attribute_qualifier()) {
      e = makeExpr(Expr::Attribute, lower(a->attribute_ref()->getText()), std::move(e));
    } else if (auto *g = qual->group_qualifier()) {
      e = makeExpr(Expr::Group, lower(g->entity_ref()->getText()), std::move(e));
    } else {
      auto *ix = qual->index_qualifier();
      std::vector<Expr> args;
      args.push_back(std::move(e));
      for (auto *n : ix->numeric_expression())
        args.push_back(buildSimple(n->simple_expression()));
      e = makeList(Expr::Index, "", std::move(args));
    }
  }
  return e;
}

Expr buildSimpleFactor(P::Simple_factorContext *ctx) {
  if (auto *agg = ctx->aggregate_initializer()) {
    Expr e = makeExpr(Expr::Aggregate, "");
    for (auto *el : agg->element()) {
      Expr item = buildExpression(el->expression());
      if (el->numeric_expression())
        item = makeExpr(Expr::Binary, ":", std::move(item), buildSimple(el->numeric_expression()->simple_expression()));
      e.args.push_back(std::move(item));
    }
    return e;
  }
  if (auto *iv = ctx->interval()) {
    std::vector<Expr> args;
    for (auto *se : iv->simple_expression())
      args.push_back(buildSimple(se));
    return makeList(Expr::Interval, iv->interval_op(0)->getText() + " " + iv->interval_op(1)->getText(),
                    std::move(args));
  }
  if (auto *qe = ctx->query_expression())
    return makeExpr(Expr::Query, lower(qe->variable_id()->getText()),
                    buildSimple(qe->simple_expression()), buildExpression(qe->logical_expression()->expression()));
  Expr inner = ctx->expression() ? buildExpression(ctx->expression()) : buildPrimary(ctx->primary());
  if (auto *u = ctx->unary_op())
    return makeExpr(Expr::Unary, upperText(u), std::move(inner));
  return inner;
}

Expr buildFactor(P::FactorContext *ctx) {
  auto parts = ctx->simple_factor();
  Expr e = buildSimpleFactor(parts[0]);
  if (parts.size() == 2)
    e = makeExpr(Expr::Binary, "**", std::move(e), buildSimpleFactor(parts[1]));
  return e;
}

Expr buildTerm(P::TermContext *ctx) {
  auto factors = ctx->factor();
  auto ops = ctx->multiplication_like_op();
  Expr e = buildFactor(factors[0]);
  for (size_t i = 1; i < factors.size(); ++i)
    e = makeExpr(Expr::Binary, upperText(ops[i - 1]), std::move(e), buildFactor(factors[i]));
  return e;
}

Expr buildSimple(P::Simple_expressionContext *ctx) {
  auto terms = ctx->term();
  auto ops = ctx->add_like_op();
  Expr e = buildTerm(terms[0]);
  for (size_t i = 1; i < terms.size(); ++i)
    e = makeExpr(Expr::Binary, upperText(ops[i - 1]), std::move(e), buildTerm(terms[i]));
  return e;
}

Expr buildExpression(P::ExpressionContext *ctx) {
  auto sides = ctx->simple_expression();
  Expr e = buildSimple(sides[0]);
  if (sides.size() == 2)
    e = makeExpr(Expr::Binary, upperText(ctx->rel_op_extended()), std::move(e), buildSimple(sides[1]));
  return e;
}

class Builder {
public:
  Builder(Model &model, const SourceFile &file, antlr4::CharStream &input)
      : model_(model), file_(file), input_(input) {}

  void schema(P::Schema_declContext *ctx);

private:
  SourceLoc loc(antlr4::ParserRuleContext *ctx) const {
    antlr4::Token *t = ctx->getStart();
    return locAt(file_, t->getLine(), t->getCharPositionInLine());
  }
  std::string text(antlr4::ParserRuleContext *ctx) const {
    if (!ctx || !ctx->getStart() || !ctx->getStop())
      return {};
    return input_.getText(antlr4::misc::Interval(ctx->getStart()->getStartIndex(),
                                                 ctx->getStop()->getStopIndex()));
  }
  static std::string id(P::Simple_idContext *ctx) { return lower(ctx->getText()); }

  int64_t bound(P::Numeric_expressionContext *ctx) const;
  TypeId parameterType(P::Parameter_typeContext *ctx);
  TypeId concreteType(P::Concrete_typesContext *ctx);
  TypeId simpleType(P::Simple_typesContext *ctx);
  TypeId named(const std::string &name);
  TypeId aggregate(AggregateKind kind, P::Bound_specContext *bounds, bool optional, bool unique,
                   TypeId element);
  SupertypeExpr supertypeExpression(P::Supertype_expressionContext *ctx);
  SupertypeExpr supertypeTerm(P::Supertype_termContext *ctx);
  void typeDecl(Schema &schema, P::Type_declContext *ctx);
  void entityDecl(Schema &schema, P::Entity_declContext *ctx);
  void attributeName(P::Attribute_declContext *ctx, std::string &name, std::string &entity,
                     std::string &attribute);

  Model &model_;
  const SourceFile &file_;
  antlr4::CharStream &input_;
  size_t schemaIndex_ = 0;
  std::vector<std::pair<std::string, P::Subtype_constraint_declContext *>> constraints_;
};

int64_t Builder::bound(P::Numeric_expressionContext *ctx) const {
  if (!ctx)
    return -1;
  const std::string t = ctx->getText();
  if (t == "?")
    return -1;
  try {
    size_t used = 0;
    long long v = std::stoll(t, &used);
    return used == t.size() ? v : -1;
  } catch (...) {
    return -1;  // a constant expression: treated as unbounded
  }
}

TypeId Builder::named(const std::string &name) {
  TypeExpr t;
  t.kind = TypeExpr::Named;
  t.name = name;
  return model_.addTypeExpr(std::move(t));
}

TypeId Builder::aggregate(AggregateKind kind, P::Bound_specContext *bounds, bool optional,
                          bool unique, TypeId element) {
  TypeExpr t;
  t.kind = TypeExpr::Aggregate;
  t.aggregate = kind;
  t.optionalElements = optional;
  t.unique = unique;
  t.element = element;
  if (bounds) {
    t.lower = bound(bounds->bound_1);
    if (t.lower < 0)
      t.lower = 0;
    t.upper = bound(bounds->bound_2);
  }
  return model_.addTypeExpr(std::move(t));
}

TypeId Builder::simpleType(P::Simple_typesContext *ctx) {
  TypeExpr t;
  t.kind = TypeExpr::Simple;
  if (ctx->binary_type())
    t.simple = SimpleKind::Binary;
  else if (ctx->boolean_type())
    t.simple = SimpleKind::Boolean;
  else if (ctx->integer_type())
    t.simple = SimpleKind::Integer;
  else if (ctx->logical_type())
    t.simple = SimpleKind::Logical;
  else if (ctx->number_type())
    t.simple = SimpleKind::Number;
  else if (ctx->real_type())
    t.simple = SimpleKind::Real;
  else
    t.simple = SimpleKind::String;
  return model_.addTypeExpr(std::move(t));
}

TypeId Builder::concreteType(P::Concrete_typesContext *ctx) {
  if (ctx->simple_types())
    return simpleType(ctx->simple_types());
  if (ctx->named_types())
    return named(id(ctx->named_types()->simple_id()));
  auto *agg = ctx->aggregation_types();
  if (auto *a = agg->array_type())
    return aggregate(AggregateKind::Array, a->bound_spec(), a->K_OPTIONAL() != nullptr,
                     a->K_UNIQUE() != nullptr, concreteType(a->instantiable_type()->concrete_types()));
  if (auto *l = agg->list_type())
    return aggregate(AggregateKind::List, l->bound_spec(), false, l->K_UNIQUE() != nullptr,
                     concreteType(l->instantiable_type()->concrete_types()));
  if (auto *b = agg->bag_type())
    return aggregate(AggregateKind::Bag, b->bound_spec(), false, false,
                     concreteType(b->instantiable_type()->concrete_types()));
  auto *s = agg->set_type();
  return aggregate(AggregateKind::Set, s->bound_spec(), false, false,
                   concreteType(s->instantiable_type()->concrete_types()));
}

TypeId Builder::parameterType(P::Parameter_typeContext *ctx) {
  if (ctx->simple_types())
    return simpleType(ctx->simple_types());
  if (ctx->named_types())
    return named(id(ctx->named_types()->simple_id()));
  auto *gen = ctx->generalized_types();
  if (auto *ga = gen->general_aggregation_types()) {
    if (auto *a = ga->general_array_type())
      return aggregate(AggregateKind::Array, a->bound_spec(), a->K_OPTIONAL() != nullptr,
                       a->K_UNIQUE() != nullptr, parameterType(a->parameter_type()));
    if (auto *l = ga->general_list_type())
      return aggregate(AggregateKind::List, l->bound_spec(), false, l->K_UNIQUE() != nullptr,
                       parameterType(l->parameter_type()));
    if (auto *b = ga->general_bag_type())
      return aggregate(AggregateKind::Bag, b->bound_spec(), false, false, parameterType(b->parameter_type()));
    auto *s = ga->general_set_type();
    return aggregate(AggregateKind::Set, s->bound_spec(), false, false, parameterType(s->parameter_type()));
  }
  TypeExpr t;
  t.kind = TypeExpr::Generic;
  if (auto *a = gen->aggregate_type())
    t.element = parameterType(a->parameter_type());
  return model_.addTypeExpr(std::move(t));
}

SupertypeExpr Builder::supertypeTerm(P::Supertype_termContext *ctx) {
  if (ctx->entity_ref()) {
    SupertypeExpr leaf;
    leaf.entity = id(ctx->entity_ref()->simple_id());
    return leaf;
  }
  if (auto *one = ctx->one_of()) {
    SupertypeExpr e;
    e.op = SupertypeExpr::OneOf;
    for (auto *sub : one->supertype_expression())
      e.operands.push_back(supertypeExpression(sub));
    return e;
  }
  return supertypeExpression(ctx->supertype_expression());
}

SupertypeExpr Builder::supertypeExpression(P::Supertype_expressionContext *ctx) {
  std::vector<SupertypeExpr> factors;
  for (auto *f : ctx->supertype_factor()) {
    std::vector<SupertypeExpr> terms;
    for (auto *t : f->supertype_term())
      terms.push_back(supertypeTerm(t));
    if (terms.size() == 1) {
      factors.push_back(std::move(terms[0]));
    } else {
      SupertypeExpr andExpr;
      andExpr.op = SupertypeExpr::And;
      andExpr.operands = std::move(terms);
      factors.push_back(std::move(andExpr));
    }
  }
  if (factors.size() == 1)
    return std::move(factors[0]);
  SupertypeExpr andor;
  andor.op = SupertypeExpr::AndOr;
  andor.operands = std::move(factors);
  return andor;
}

void Builder::typeDecl(Schema &schema, P::Type_declContext *ctx) {
  TypeDecl decl;
  decl.name = id(ctx->type_id()->simple_id());
  decl.schema = schema.name;
  decl.loc = loc(ctx->type_id());
  auto *u = ctx->underlying_type();
  if (auto *c = u->constructed_types()) {
    TypeExpr t;
    if (auto *sel = c->select_type()) {
      t.kind = TypeExpr::Select;
      decl.extensible = sel->K_EXTENSIBLE() != nullptr;
      decl.genericEntity = sel->K_GENERIC_ENTITY() != nullptr;
      P::Select_listContext *list = sel->select_list();
      if (auto *ext = sel->select_extension()) {
        decl.basedOn = id(ext->type_ref()->simple_id());
        list = ext->select_list();
      }
      if (list)
        for (auto *n : list->named_types())
          decl.selectItems.push_back(id(n->simple_id()));
    } else {
      auto *en = c->enumeration_type();
      t.kind = TypeExpr::Enumeration;
      decl.extensible = en->K_EXTENSIBLE() != nullptr;
      P::Enumeration_itemsContext *items = en->enumeration_items();
      if (auto *ext = en->enumeration_extension()) {
        decl.basedOn = id(ext->type_ref()->simple_id());
        items = ext->enumeration_items();
      }
      if (items)
        for (auto *e : items->enumeration_id())
          decl.enumValues.push_back(id(e->simple_id()));
    }
    decl.underlying = model_.addTypeExpr(std::move(t));
  } else {
    decl.underlying = concreteType(u->concrete_types());
  }
  if (auto *w = ctx->where_clause())
    for (auto *r : w->domain_rule())
      decl.where.push_back({r->rule_label_id() ? id(r->rule_label_id()->simple_id()) : "",
                            text(r->expression()), std::make_shared<const Expr>(buildExpression(r->expression()))});
  schema.types.push_back(model_.addTypeDecl(std::move(decl)));
}

void Builder::attributeName(P::Attribute_declContext *ctx, std::string &name, std::string &entity,
                            std::string &attribute) {
  if (ctx->attribute_id()) {
    name = id(ctx->attribute_id()->simple_id());
    return;
  }
  auto *re = ctx->redeclared_attribute();
  auto *q = re->qualified_attribute();
  entity = id(q->group_qualifier()->entity_ref()->simple_id());
  attribute = id(q->attribute_qualifier()->attribute_ref()->simple_id());
  name = re->attribute_id() ? id(re->attribute_id()->simple_id()) : attribute;
}

void Builder::entityDecl(Schema &schema, P::Entity_declContext *ctx) {
  Entity e;
  auto *head = ctx->entity_head();
  e.name = id(head->entity_id()->simple_id());
  e.schema = schema.name;
  e.loc = loc(head->entity_id());
  if (auto *ss = head->subsuper()) {
    if (auto *sc = ss->supertype_constraint()) {
      if (auto *abs = sc->abstract_supertype_declaration()) {
        e.abstract = true;
        if (abs->subtype_constraint())
          e.supertypeConstraints.push_back(
              supertypeExpression(abs->subtype_constraint()->supertype_expression()));
      } else if (sc->abstract_entity_declaration()) {
        e.abstract = true;
      } else if (auto *rule = sc->supertype_rule()) {
        e.supertypeConstraints.push_back(supertypeExpression(rule->subtype_constraint()->supertype_expression()));
      }
    }
    if (auto *sd = ss->subtype_declaration())
      for (auto *r : sd->entity_ref())
        e.supertypeNames.push_back(id(r->simple_id()));
  }
  auto *body = ctx->entity_body();
  for (auto *ea : body->explicit_attr()) {
    TypeId type = parameterType(ea->parameter_type());
    for (auto *ad : ea->attribute_decl()) {
      Attribute a;
      attributeName(ad, a.name, a.redeclaresEntity, a.redeclaresAttribute);
      a.type = type;
      a.optional = ea->K_OPTIONAL() != nullptr;
      a.loc = loc(ad);
      e.attributes.push_back(std::move(a));
    }
  }
  if (auto *dc = body->derive_clause())
    for (auto *da : dc->derived_attr()) {
      DerivedAttribute d;
      attributeName(da->attribute_decl(), d.name, d.redeclaresEntity, d.redeclaresAttribute);
      d.type = parameterType(da->parameter_type());
      d.expression = text(da->expression());
      e.derived.push_back(std::move(d));
    }
  if (auto *ic = body->inverse_clause())
    for (auto *ia : ic->inverse_attr()) {
      InverseAttribute inv;
      std::string ignoredEntity, ignoredAttr;
      attributeName(ia->attribute_decl(), inv.name, ignoredEntity, ignoredAttr);
      if (auto *agg = ia->inverse_aggregate()) {
        inv.aggregate = true;
        inv.bag = agg->K_BAG() != nullptr;
        if (agg->bound_spec()) {
          inv.lower = std::max<int64_t>(0, bound(agg->bound_spec()->bound_1));
          inv.upper = bound(agg->bound_spec()->bound_2);
        }
      }
      inv.entity = id(ia->referencing_entity->simple_id());
      inv.attribute = id(ia->attribute_ref()->simple_id());
      e.inverse.push_back(std::move(inv));
    }
  if (auto *uc = body->unique_clause())
    for (auto *ur : uc->unique_rule()) {
      std::vector<std::string> attrs;
      for (auto *ra : ur->referenced_attribute())
        attrs.push_back(lower(ra->getText()));
      e.unique.push_back(std::move(attrs));
    }
  if (auto *w = body->where_clause())
    for (auto *r : w->domain_rule())
      e.where.push_back({r->rule_label_id() ? id(r->rule_label_id()->simple_id()) : "",
                         text(r->expression()), std::make_shared<const Expr>(buildExpression(r->expression()))});
  schema.entities.push_back(model_.addEntity(std::move(e)));
}

void Builder::schema(P::Schema_declContext *ctx) {
  Schema &s = model_.addSchema(ctx->schema_id()->getText(), loc(ctx->schema_id()));
  schemaIndex_ = model_.schemas().size() - 1;
  auto *body = ctx->schema_body();
  for (auto *iface : body->interface_specification()) {
    Interface in;
    in.loc = loc(iface);
    if (auto *use = iface->use_clause()) {
      in.use = true;
      in.schema = id(use->schema_ref()->simple_id());
      for (auto *item : use->named_type_or_rename())
        in.items.emplace_back(id(item->named_types()->simple_id()),
                              item->rename_id() ? id(item->rename_id()->simple_id()) : "");
    } else {
      auto *ref = iface->reference_clause();
      in.use = false;
      in.schema = id(ref->schema_ref()->simple_id());
      for (auto *item : ref->resource_or_rename())
        in.items.emplace_back(id(item->resource_ref()->simple_id()),
                              item->rename_id() ? id(item->rename_id()->simple_id()) : "");
    }
    s.interfaces.push_back(std::move(in));
  }
  if (auto *cd = body->constant_decl())
    for (auto *c : cd->constant_body())
      s.constants.push_back(id(c->constant_id()->simple_id()));
  for (auto *decl : body->declaration()) {
    Schema &cur = model_.mutableSchema(schemaIndex_);
    if (auto *t = decl->type_decl())
      typeDecl(cur, t);
    else if (auto *e = decl->entity_decl())
      entityDecl(cur, e);
    else if (auto *f = decl->function_decl())
      cur.functions.push_back(id(f->function_head()->function_id()->simple_id()));
    else if (auto *p = decl->procedure_decl())
      cur.procedures.push_back(id(p->procedure_head()->procedure_id()->simple_id()));
    else if (auto *sc = decl->subtype_constraint_decl())
      constraints_.emplace_back(cur.name, sc);
  }
  Schema &cur = model_.mutableSchema(schemaIndex_);
  for (auto *r : body->rule_decl())
    cur.rules.push_back(id(r->rule_head()->rule_id()->simple_id()));
  // SUBTYPE_CONSTRAINTs apply to an entity of this schema.
  for (auto &[schemaName, sc] : constraints_) {
    const std::string target = id(sc->subtype_constraint_head()->entity_ref()->simple_id());
    for (EntityId eid : cur.entities) {
      Entity &ent = model_.mutableEntity(eid);
      if (ent.name != target)
        continue;
      auto *b = sc->subtype_constraint_body();
      if (b->abstract_supertype())
        ent.abstract = true;
      if (b->supertype_expression())
        ent.supertypeConstraints.push_back(supertypeExpression(b->supertype_expression()));
    }
  }
  constraints_.clear();
}

} // namespace

namespace {

// Thrown by DepthGuard to abandon a parse; not a RecognitionException, so the
// generated rules do not catch it.
struct ParseTooDeep {
  antlr4::Token *at;
};

// Counts the parser's rule invocations in progress: ANTLR's parser recurses
// once per rule, so input nested deeply enough (types, statements or
// declarations inside each other) would overflow the stack.
class DepthGuard final : public antlr4::tree::ParseTreeListener {
public:
  explicit DepthGuard(antlr4::Parser &parser) : parser_(parser) {}
  void enterEveryRule(antlr4::ParserRuleContext *) override {
    if (++depth > kMaxParseDepth)
      throw ParseTooDeep{parser_.getCurrentToken()};
  }
  void exitEveryRule(antlr4::ParserRuleContext *) override { --depth; }
  void visitTerminal(antlr4::tree::TerminalNode *) override {}
  void visitErrorNode(antlr4::tree::ErrorNode *) override {}
  unsigned depth = 0;

private:
  antlr4::Parser &parser_;
};

// Thrown by BoundedErrorStrategy to stop a parse that keeps recovering.
struct TooManySyntaxErrors {
  antlr4::Token *at;
};

// ANTLR's error recovery, stopped after kMaxSyntaxRecoveries recoveries.
// Each computes the follow sets of every rule in progress, so on deeply
// nested garbage one recovery costs thousands of set operations, and the
// parser kept recovering long after the diagnostics had stopped (a 77 KB
// mutant took 25 s). Everything after the first error only adds messages.
class BoundedErrorStrategy final : public antlr4::DefaultErrorStrategy {
public:
  antlr4::Token *recoverInline(antlr4::Parser *recognizer) override {
    count(recognizer);
    return DefaultErrorStrategy::recoverInline(recognizer);
  }

protected:
  antlr4::misc::IntervalSet getErrorRecoverySet(antlr4::Parser *recognizer) override {
    count(recognizer);
    return DefaultErrorStrategy::getErrorRecoverySet(recognizer);
  }

private:
  void count(antlr4::Parser *recognizer) {
    if (++recoveries_ > kMaxSyntaxRecoveries)
      throw TooManySyntaxErrors{recognizer->getCurrentToken()};
  }
  unsigned recoveries_ = 0;
};

// The offset of the first byte of `text` that does not start well-formed
// UTF-8, or npos. ANTLR converts its input to UTF-32 with a conversion that
// throws on ill-formed input, so bad bytes must not reach it.
size_t firstInvalidUtf8(std::string_view text) {
  for (size_t i = 0; i < text.size();) {
    if (static_cast<unsigned char>(text[i]) < 0x80) {
      ++i;
      continue;
    }
    const size_t n = utf8::sequenceLength(text, i);
    if (n == 0)
      return i;
    i += n;
  }
  return std::string_view::npos;
}

// Appends text[from, to) with every code point but line breaks turned into
// one space: the lines and the code-point columns ANTLR reports stay those
// of the file.
void appendBlank(std::string &out, std::string_view text, size_t from, size_t to) {
  for (size_t i = from; i < to; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n' || c == '\r')
      out += static_cast<char>(c);
    else if ((c & 0xC0) != 0x80)  // not a continuation byte
      out += ' ';
  }
}

// The text with its remarks blanked out (ISO 10303-11 7.1.6: `--` to the end
// of the line; `(*` to the matching `*)`, nesting), or nullopt after
// reporting an embedded remark that does not end. Remarks are removed here,
// not by the grammar's lexer, because ANTLR's lexer needs time and memory
// that grow with the square of their nesting (20,000 nested remarks: more
// than a minute and 1.3 GB) and rescans to the end of the file for every
// `(*` that does not close. Strings are kept as they are: `--` and `(*` in
// them are text. `text` is well-formed UTF-8.
std::optional<std::string> blankRemarks(std::string_view text, const SourceFile &src, DiagnosticEngine &diags) {
  std::string out;
  out.reserve(text.size());
  const size_t n = text.size();
  size_t i = 0;
  while (i < n) {
    const char c = text[i];
    if (c == '\'') {
      size_t j = i + 1;
      while (j < n && !(text[j] == '\'' && (j + 1 >= n || text[j + 1] != '\'')))
        j += text[j] == '\'' ? 2 : 1;
      // An unterminated string: the lexer reports the quote and goes on
      // after it, and so does this scan.
      const size_t end = j < n ? j + 1 : i + 1;
      out.append(text.substr(i, end - i));
      i = end;
    } else if (c == '-' && i + 1 < n && text[i + 1] == '-') {
      size_t j = i;
      while (j < n && text[j] != '\n' && text[j] != '\r')
        ++j;
      appendBlank(out, text, i, j);
      i = j;
    } else if (c == '(' && i + 1 < n && text[i + 1] == '*') {
      size_t depth = 1, j = i + 2;
      while (j < n && depth > 0) {
        if (text[j] == '(' && j + 1 < n && text[j + 1] == '*') {
          ++depth;
          j += 2;
        } else if (text[j] == '*' && j + 1 < n && text[j + 1] == ')') {
          --depth;
          j += 2;
        } else {
          ++j;
        }
      }
      if (depth > 0) {
        diags.error(SourceLoc{&src, i}, "EXPRESS remark '(*' does not end: no matching '*)'" +
                                            std::string(depth > 1 ? " (" + std::to_string(depth) +
                                                                        " remarks open at the end of the file)"
                                                                  : ""));
        return std::nullopt;
      }
      appendBlank(out, text, i, j);
      i = j;
    } else {
      out += c;
      ++i;
    }
  }
  return out;
}

// Reports the first bracket that opens more than kMaxBracketNesting levels;
// false if there is one. Expressions nest only through brackets, and parsing
// them recurses about ten C++ frames per level.
bool checkBracketDepth(antlr4::CommonTokenStream &tokens, const SourceFile &src, DiagnosticEngine &diags) {
  unsigned depth = 0;
  for (antlr4::Token *t : tokens.getTokens()) {
    if (t->getChannel() != antlr4::Token::DEFAULT_CHANNEL)
      continue;
    switch (t->getType()) {
    case g::ExpressLexer::LPAREN:
    case g::ExpressLexer::LBRACKET:
    case g::ExpressLexer::LBRACE:
      if (++depth > kMaxBracketNesting) {
        diags.error(locAt(src, t->getLine(), t->getCharPositionInLine()),
                    "EXPRESS brackets nest deeper than " + std::to_string(kMaxBracketNesting) + " levels");
        return false;
      }
      break;
    case g::ExpressLexer::RPAREN:
    case g::ExpressLexer::RBRACKET:
    case g::ExpressLexer::RBRACE:
      if (depth > 0)
        --depth;
      break;
    default: break;
    }
  }
  return true;
}

} // namespace

std::shared_ptr<const Expr> parseExpression(std::string_view text) {
  if (firstInvalidUtf8(text) != std::string_view::npos)
    return nullptr;
  antlr4::ANTLRInputStream input{std::string(text)};
  g::ExpressLexer lexer(&input);
  lexer.removeErrorListeners();
  antlr4::CommonTokenStream tokens(&lexer);
  g::ExpressParser parser(&tokens);
  parser.removeErrorListeners();
  parser.setErrorHandler(std::make_shared<antlr4::BailErrorStrategy>());
  DepthGuard guard(parser);
  parser.addParseListener(&guard);
  try {
    auto *tree = parser.expression();
    if (tokens.LA(1) != antlr4::Token::EOF)
      return nullptr;
    return std::make_shared<const Expr>(buildExpression(tree));
  } catch (const antlr4::ParseCancellationException &) {
    return nullptr;
  } catch (const antlr4::RecognitionException &) {
    return nullptr;
  } catch (const ParseTooDeep &) {
    return nullptr;
  }
}

bool readExpress(std::unique_ptr<SourceFile> file, Model &model, DiagnosticEngine &diags) {
  const SourceFile &src = *file;
  // Keep the file whatever happens: diagnostics point into it.
  model.keepSource(std::move(file));
  if (const size_t bad = firstInvalidUtf8(src.text()); bad != std::string_view::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(src.text()[bad])));
    diags.error(SourceLoc{&src, bad}, std::string("EXPRESS text is not valid UTF-8: byte ") + hex +
                                          " does not start a well-formed sequence");
    return false;
  }
  std::optional<std::string> blanked = blankRemarks(src.text(), src, diags);
  if (!blanked)
    return false;
  antlr4::ANTLRInputStream input(*blanked);
  blanked.reset();
  g::ExpressLexer lexer(&input);
  ErrorListener listener(src, diags);
  lexer.removeErrorListeners();
  lexer.addErrorListener(&listener);
  antlr4::CommonTokenStream tokens(&lexer);
  tokens.fill();
  if (!checkBracketDepth(tokens, src, diags))
    return false;
  g::ExpressParser parser(&tokens);
  parser.removeErrorListeners();
  parser.addErrorListener(&listener);
  DepthGuard guard(parser);
  parser.addParseListener(&guard);
  g::ExpressParser::SyntaxContext *tree = nullptr;
  try {
    // Two-stage parsing: SLL first (fast, enough for every known schema),
    // full LL only if SLL fails.
    parser.getInterpreter<antlr4::atn::ParserATNSimulator>()->setPredictionMode(antlr4::atn::PredictionMode::SLL);
    parser.setErrorHandler(std::make_shared<antlr4::BailErrorStrategy>());
    try {
      tree = parser.syntax();
    } catch (const antlr4::ParseCancellationException &) {
      tokens.seek(0);
      parser.reset();
      guard.depth = 0;
      parser.setErrorHandler(std::make_shared<BoundedErrorStrategy>());
      parser.getInterpreter<antlr4::atn::ParserATNSimulator>()->setPredictionMode(antlr4::atn::PredictionMode::LL);
      tree = parser.syntax();
    }
  } catch (const ParseTooDeep &deep) {
    diags.error(locAt(src, deep.at ? deep.at->getLine() : 0, deep.at ? deep.at->getCharPositionInLine() : 0),
                "EXPRESS declarations nest too deeply (more than " + std::to_string(kMaxParseDepth) +
                    " grammar rules inside each other)");
    return false;
  } catch (const TooManySyntaxErrors &stop) {
    diags.error(locAt(src, stop.at ? stop.at->getLine() : 0, stop.at ? stop.at->getCharPositionInLine() : 0),
                "EXPRESS syntax: too many errors; stopped reading here");
    return false;
  }
  const bool ok = listener.count == 0;
  if (ok) {
    Builder builder(model, src, input);
    for (auto *schema : tree->schema_decl())
      builder.schema(schema);
  }
  return ok;
}

} // namespace stepnc::express
