// The kind table: what each IR node kind holds. One table serves the printer
// (attribute order), the parser (what may appear), the verifier (required
// attributes, value types, allowed children) and the docs.
#pragma once

#include "ir/Node.h"

#include <string>
#include <string_view>
#include <vector>

namespace stepnc::ir {

enum class Sigil : uint8_t { None, Resource, Executable };  ///< none, '%', '@'

struct AttrSpec {
  std::string_view name;
  ValueType type;
  bool required = false;
  /// For Word attributes: the allowed words, space separated (empty: any).
  std::string_view words = {};
};

struct KindSpec {
  std::string_view kind;
  std::string_view category;  ///< "feature", "operation", "strategy", "curve", "profile", "executable", ...
  Sigil sigil = Sigil::None;
  bool label = false;         ///< carries the STEP-NC id string
  std::vector<AttrSpec> attrs;
  /// Kinds or categories allowed as children, space separated.
  std::string_view children = {};
};

/// The spec of `kind`, or null.
const KindSpec *findKind(std::string_view kind);
/// Every kind, in table order.
const std::vector<KindSpec> &allKinds();
/// True if a child of kind `child` may appear under a node of kind `parent`.
bool childAllowed(const KindSpec &parent, const KindSpec &child);
/// The spec of attribute `name` of `kind`, or null.
const AttrSpec *findAttr(const KindSpec &kind, std::string_view name);

/// True if the space-separated `list` contains `word`.
bool inList(std::string_view list, std::string_view word);
/// "a, b or c" from the space-separated "a b c", for messages.
std::string joinWords(std::string_view list);

// Rules of the text form and the table, shared by the parser and the verifier.

/// Letters, digits and '_': what kinds, attribute names, words and symbol names are made of.
bool isNameChar(char c);
/// '%' for resources, '@' for executables, '\0' for kinds without a symbol.
char sigilChar(Sigil s);
/// True for a sigil ('%' or '@') followed by one or more letters, digits or '_'.
bool isSymbol(std::string_view s);
/// True if `word` may be the value of the Word attribute `a`: one of its words,
/// or any run of letters, digits and '_' when the table lists none.
bool wordAllowed(const AttrSpec &a, std::string_view word);
/// The children `parent` takes, for messages: "rawpiece, clamp or feature", or "no children".
std::string allowedChildren(const KindSpec &parent);

} // namespace stepnc::ir
