#include "ir/Node.h"

#include "ir/Kinds.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <iostream>

namespace stepnc::ir {

const char *valueTypeName(ValueType t) {
  switch (t) {
  case ValueType::Length: return "length";
  case ValueType::Angle: return "angle";
  case ValueType::Feed: return "feed";
  case ValueType::Spindle: return "spindle speed";
  case ValueType::Time: return "time";
  case ValueType::Ratio: return "ratio";
  case ValueType::Count: return "count";
  case ValueType::Flag: return "flag";
  case ValueType::Word: return "word";
  case ValueType::Text: return "text";
  case ValueType::Ref: return "reference";
  case ValueType::Point: return "point";
  case ValueType::Direction: return "direction";
  case ValueType::Real: return "number";
  case ValueType::Reals: return "number list";
  case ValueType::FeedPerRev: return "feed per revolution";
  case ValueType::Power: return "power";
  case ValueType::MassFlow: return "mass flow";
  }
  return "value";
}

Value Value::makeNumber(ValueType t, double v) {
  Value out;
  out.type = t;
  out.number = v;
  return out;
}
Value Value::integer(int64_t n) {
  Value out;
  out.type = ValueType::Count;
  out.count = n;
  return out;
}
Value Value::boolean(bool b) {
  Value out;
  out.type = ValueType::Flag;
  out.flag = b;
  return out;
}
Value Value::word(std::string w) {
  Value out;
  out.type = ValueType::Word;
  out.text = std::move(w);
  return out;
}
Value Value::string(std::string s) {
  Value out;
  out.type = ValueType::Text;
  out.text = std::move(s);
  return out;
}
Value Value::ref(std::string symbol) {
  Value out;
  out.type = ValueType::Ref;
  out.text = std::move(symbol);
  return out;
}
Value Value::reals(std::vector<double> v) {
  Value out;
  out.type = ValueType::Reals;
  out.numbers = std::move(v);
  return out;
}

Value Value::point(const Vec3 &p) {
  Value out;
  out.type = ValueType::Point;
  out.vec = p;
  return out;
}
Value Value::direction(const Vec3 &d) {
  Value out;
  out.type = ValueType::Direction;
  out.vec = d;
  return out;
}

bool Value::operator==(const Value &o) const {
  return type == o.type && number == o.number && count == o.count && flag == o.flag && text == o.text &&
         vec == o.vec;
}

Node &Node::set(std::string name, Value v) {
  for (Attr &a : attrs)
    if (a.name == name) {
      a.value = std::move(v);
      return *this;
    }
  // Keep the kind table's order, so that a node built in any order prints,
  // parses back and compares equal.
  const KindSpec &s = spec();
  const size_t mine = attrIndex(s, name);
  if (mine == SIZE_MAX) {
    std::cerr << "stepnc: internal error: attribute '" << name << "' is not declared for '" << s.name
              << "' (ir/Kinds.def)\n";
    std::abort();
  }
  auto at = std::find_if(attrs.begin(), attrs.end(), [&](const Attr &a) { return attrIndex(s, a.name) > mine; });
  attrs.insert(at, Attr{std::move(name), std::move(v)});
  return *this;
}

const Value *Node::get(std::string_view name) const {
  for (const Attr &a : attrs)
    if (a.name == name)
      return &a.value;
  return nullptr;
}

std::optional<double> Node::number(std::string_view name) const {
  const Value *v = get(name);
  if (!v)
    return std::nullopt;
  switch (v->type) {
  case ValueType::Length:
  case ValueType::Angle:
  case ValueType::Feed:
  case ValueType::Spindle:
  case ValueType::Time:
  case ValueType::Ratio:
  case ValueType::Real:
  case ValueType::FeedPerRev:
  case ValueType::Power:
  case ValueType::MassFlow: return v->number;
  case ValueType::Count: return static_cast<double>(v->count);
  default: return std::nullopt;
  }
}

std::optional<int64_t> Node::count(std::string_view name) const {
  const Value *v = get(name);
  return v && v->type == ValueType::Count ? std::optional<int64_t>(v->count) : std::nullopt;
}

std::optional<bool> Node::flag(std::string_view name) const {
  const Value *v = get(name);
  return v && v->type == ValueType::Flag ? std::optional<bool>(v->flag) : std::nullopt;
}

std::optional<std::string> Node::text(std::string_view name) const {
  const Value *v = get(name);
  if (!v || (v->type != ValueType::Word && v->type != ValueType::Text && v->type != ValueType::Ref))
    return std::nullopt;
  return v->text;
}

std::optional<Vec3> Node::vec(std::string_view name) const {
  const Value *v = get(name);
  if (!v || (v->type != ValueType::Point && v->type != ValueType::Direction))
    return std::nullopt;
  return v->vec;
}

std::vector<const Node *> Node::childrenOf(Kind k) const {
  std::vector<const Node *> out;
  for (const Node &c : children)
    if (c.kind == k)
      out.push_back(&c);
  return out;
}

const Node *Node::child(Kind k) const {
  for (const Node &c : children)
    if (c.kind == k)
      return &c;
  return nullptr;
}

const Node *Node::childIn(Category cat) const {
  for (const Node &c : children)
    if (c.category() == cat)
      return &c;
  return nullptr;
}

bool equal(const Node &a, const Node &b) {
  if (a.kind != b.kind || a.symbol != b.symbol || a.label != b.label || a.attrs.size() != b.attrs.size() ||
      a.children.size() != b.children.size())
    return false;
  for (size_t i = 0; i < a.attrs.size(); ++i)
    if (a.attrs[i].name != b.attrs[i].name || !(a.attrs[i].value == b.attrs[i].value))
      return false;
  for (size_t i = 0; i < a.children.size(); ++i)
    if (!equal(a.children[i], b.children[i]))
      return false;
  return true;
}

void replaceCommentPart(Node &node, std::initializer_list<std::string_view> prefixes, std::string_view text) {
  std::string kept;
  std::string_view rest = node.comment;
  while (!rest.empty()) {
    const size_t end = rest.find("; ");
    const std::string_view part = rest.substr(0, end);
    bool ours = false;
    for (std::string_view p : prefixes)
      ours = ours || part.starts_with(p);
    if (!ours)
      kept += std::string(part) + "; ";
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 2);
  }
  node.comment = kept + std::string(text);
}

} // namespace stepnc::ir
