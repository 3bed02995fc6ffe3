#include "frontend/express/Expr.h"

namespace stepnc::express {

Expr::~Expr() {
  // Move every grandchild out before its parent goes, so each Expr destroyed
  // here has no children left and the destructor never recurses.
  std::vector<Expr> pending;
  for (Expr &a : args)
    if (!a.args.empty())
      pending.push_back(std::move(a));
  args.clear();
  while (!pending.empty()) {
    Expr e = std::move(pending.back());
    pending.pop_back();
    for (Expr &a : e.args)
      if (!a.args.empty())
        pending.push_back(std::move(a));
    e.args.clear();
  }
}

std::string printExpr(const Expr &e) {
  auto list = [&](const std::string &head) {
    std::string out = "(";
    out += head;
    for (const Expr &a : e.args) {
      out += ' ';
      out += printExpr(a);
    }
    out += ')';
    return out;
  };
  switch (e.kind) {
  case Expr::Integer:
  case Expr::Real:
  case Expr::String:
  case Expr::BinaryLiteral:
  case Expr::Logical:
  case Expr::Name:
  case Expr::Builtin: return e.text;
  case Expr::Call: return list("call " + e.text);
  case Expr::Unary:
  case Expr::Binary: return list(e.text);
  case Expr::Attribute: return list(". " + e.text);
  case Expr::Group: return list("\\ " + e.text);
  case Expr::Index: return list("[]");
  case Expr::Aggregate: return list("aggregate");
  case Expr::Interval: return list("interval " + e.text);
  case Expr::Query: return list("query " + e.text);
  }
  return "?";
}

} // namespace stepnc::express
