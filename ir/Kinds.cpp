// The kind table, made from ir/Kinds.def. Attribute names follow ISO 14649
// where it has a name for the quantity, shortened where the standard's is
// long; units are those of the value type (mm, deg, mm/min, rev/min, s).
#include "ir/Kinds.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <iostream>

namespace stepnc::ir {

namespace {

using T = ValueType;

constexpr std::array<std::string_view, 21> kCategoryNames = {
    "root",     "resource", "executable", "feature",        "island", "profile", "path",
    "curve",    "point",    "segment",    "knot",           "operation", "technology", "strategy",
    "toolpath", "move",     "motion",     "motion_segment", "state",  "branch",  "expression",
};
static_assert(kCategoryNames.size() == static_cast<size_t>(Category::Expression) + 1);

std::vector<KindSpec> makeTable() {
#define ATTRS(...) std::vector<AttrSpec>{__VA_ARGS__}
#define REQ(name, type) AttrSpec{#name, T::type, true}
#define OPT(name, type) AttrSpec{#name, T::type, false}
#define REQ_W(name, words) AttrSpec{#name, T::Word, true, words}
#define OPT_W(name, words) AttrSpec{#name, T::Word, false, words}
#define KIND(Id, name, Cat, Sig, labelled, traits, children, attrs) \
  KindSpec{Kind::Id, name, Category::Cat, Sigil::Sig, labelled, traits, children, attrs, {}, 0},
  std::vector<KindSpec> t = {
#include "ir/Kinds.def"
  };
#undef ATTRS
#undef REQ
#undef OPT
#undef REQ_W
#undef OPT_W
  // Resolve the children lists once; a name that is neither a kind nor a
  // category is a mistake in Kinds.def.
  for (KindSpec &k : t) {
    std::string_view list = k.children;
    while (!list.empty()) {
      const size_t space = list.find(' ');
      const std::string_view word = list.substr(0, space);
      list = space == std::string_view::npos ? std::string_view() : list.substr(space + 1);
      bool known = false;
      for (const KindSpec &other : t)
        if (other.name == word) {
          k.childKinds.set(static_cast<size_t>(other.id));
          known = true;
        }
      for (size_t c = 0; c < kCategoryNames.size(); ++c)
        if (kCategoryNames[c] == word) {
          k.childCategories |= 1u << c;
          known = true;
        }
      if (!known) {
        std::cerr << "stepnc: internal error: ir/Kinds.def: '" << k.name << "' takes unknown children '" << word
                  << "'\n";
        std::abort();
      }
    }
  }
  return t;
}

} // namespace

const std::vector<KindSpec> &allKinds() {
  static const std::vector<KindSpec> table = makeTable();
  return table;
}

const KindSpec &specOf(Kind kind) { return allKinds()[static_cast<size_t>(kind)]; }

std::optional<Kind> kindNamed(std::string_view name) {
  for (const KindSpec &k : allKinds())
    if (k.name == name)
      return k.id;
  return std::nullopt;
}

std::string_view categoryName(Category c) { return kCategoryNames[static_cast<size_t>(c)]; }

bool childAllowed(const KindSpec &parent, const KindSpec &child) {
  return parent.childKinds.test(static_cast<size_t>(child.id)) ||
         (parent.childCategories >> static_cast<size_t>(child.category) & 1u) != 0;
}

bool inList(std::string_view list, std::string_view word) {
  while (!list.empty()) {
    const size_t space = list.find(' ');
    if (list.substr(0, space) == word)
      return true;
    list = space == std::string_view::npos ? std::string_view() : list.substr(space + 1);
  }
  return false;
}

std::string joinWords(std::string_view list) {
  std::string out;
  for (size_t space; (space = list.find(' ')) != std::string_view::npos; list.remove_prefix(space + 1)) {
    out += list.substr(0, space);
    out += list.find(' ', space + 1) == std::string_view::npos ? " or " : ", ";
  }
  return out += list;
}

bool isNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

char sigilChar(Sigil s) {
  switch (s) {
  case Sigil::Resource: return '%';
  case Sigil::Executable: return '@';
  case Sigil::None: return '\0';
  }
  return '\0';
}

bool isSymbol(std::string_view s) {
  return s.size() >= 2 && (s[0] == '%' || s[0] == '@') && std::all_of(s.begin() + 1, s.end(), isNameChar);
}

bool wordAllowed(const AttrSpec &a, std::string_view word) {
  if (a.words.empty())
    return !word.empty() && std::all_of(word.begin(), word.end(), isNameChar);
  return inList(a.words, word);
}

std::string allowedChildren(const KindSpec &parent) {
  return parent.children.empty() ? "no children" : joinWords(parent.children);
}

const AttrSpec *findAttr(const KindSpec &kind, std::string_view name) {
  for (const AttrSpec &a : kind.attrs)
    if (a.name == name)
      return &a;
  return nullptr;
}

size_t attrIndex(const KindSpec &kind, std::string_view name) {
  for (size_t i = 0; i < kind.attrs.size(); ++i)
    if (kind.attrs[i].name == name)
      return i;
  return SIZE_MAX;
}

} // namespace stepnc::ir
