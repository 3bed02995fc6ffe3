// EXPRESS expressions in parsed form (WHERE rules, DERIVE), as a small tree.
// The model does not evaluate them yet; the tree is what an evaluator will walk.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::express {

struct Expr {
  enum Kind : uint8_t {
    Integer, Real, String, BinaryLiteral, Logical,  ///< literals; `text` as written
    Name,       ///< an attribute, constant, variable or enumeration item
    Builtin,    ///< SELF, PI, CONST_E, ? (indeterminate)
    Call,       ///< function call or entity constructor: text = name, args
    Unary,      ///< text = "-", "+", "NOT"; args[0]
    Binary,     ///< text = operator ("<", "AND", "IN", "||", ...); args[0], args[1]
    Attribute,  ///< args[0].text: text = attribute name
    Group,      ///< args[0]\text: text = entity name
    Index,      ///< args[0][args[1]] or args[0][args[1]:args[2]]
    Aggregate,  ///< [a, b, ...]; an element with repetition is a Binary ":"
    Interval,   ///< {args[0] text[0] args[1] text[1] args[2]}, text = "<" / "<=" pair "a b"
    Query,      ///< QUERY(text <* args[0] | args[1])
  };
  Kind kind = Name;
  std::string text;
  std::vector<Expr> args;

  Expr() = default;
  Expr(Expr &&) noexcept = default;
  Expr &operator=(Expr &&) noexcept = default;
  // No copies: a copy would recurse as deep as the tree, and the reader
  // only ever moves operands into their operator.
  Expr(const Expr &) = delete;
  Expr &operator=(const Expr &) = delete;
  /// Frees the tree without recursion: a chain of n binary operators (a
  /// WHERE rule of thousands of ANDs) is a left-deep tree n levels deep.
  ~Expr();
};

/// A compact, unambiguous S-expression of the tree, for tests and debugging:
/// (> (. SELF radius) 0).
std::string printExpr(const Expr &e);

/// Parses EXPRESS expression text (e.g. a WHERE rule's). Returns null on a
/// syntax error.
std::shared_ptr<const Expr> parseExpression(std::string_view text);

} // namespace stepnc::express
