// Reads IR text line by line. A line is one node; its indentation picks the
// open node it belongs under. Fields come in a fixed order (symbol, label,
// attributes, location, comment), one space apart. A value is parsed by the
// type its attribute has in the kind table, then printed back and compared
// with the text, so only the printer's spelling is accepted.
#include "ir/Parser.h"

#include "ir/Kinds.h"
#include "ir/Printer.h"

#include <charconv>
#include <cstring>
#include <optional>
#include <string_view>
#include <vector>

namespace stepnc::ir {

namespace {

std::string quoted(std::string_view s) {
  std::string out = "'";
  out += s;
  return out + "'";
}

/// A number in fixed notation filling all of `s`.
bool parseDouble(std::string_view s, double &out) {
  auto r = std::from_chars(s.data(), s.data() + s.size(), out, std::chars_format::fixed);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

template <class Int>
bool parseInteger(std::string_view s, Int &out) {
  auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

/// `<number><unit>`: the number must be followed by exactly the unit of `t`.
bool parseNumber(std::string_view tok, ValueType t, Value &out) {
  size_t unitAt = tok.find_first_not_of("+-0123456789.");
  if (unitAt == std::string_view::npos)
    unitAt = tok.size();
  if (tok.substr(unitAt) != unitSuffix(t) || !parseDouble(tok.substr(0, unitAt), out.number))
    return false;
  out.type = t;
  return true;
}

/// `(x,y,z)<unit>`.
bool parseVector(std::string_view tok, ValueType t, Value &out) {
  const size_t close = tok.find(')');
  if (tok.empty() || tok[0] != '(' || close == std::string_view::npos || tok.substr(close + 1) != unitSuffix(t))
    return false;
  std::string_view rest = tok.substr(1, close - 1);
  for (int i = 0; i < 3; ++i) {
    const size_t comma = i < 2 ? rest.find(',') : rest.size();
    if (comma == std::string_view::npos || !parseDouble(rest.substr(0, comma), out.vec[i]))
      return false;
    rest.remove_prefix(i < 2 ? comma + 1 : comma);
  }
  out.type = t;
  return true;
}

/// `<file>:<line>:<col>`, then ` #<id>` or nothing (`id` stays 0). The file,
/// line and column are those of the input the IR was made from; they are
/// checked, not kept: the node's origin is its place in the IR text.
bool parseLocation(std::string_view body, uint64_t &id) {
  const size_t hash = body.rfind(" #");
  if (hash != std::string_view::npos) {
    if (!parseInteger(body.substr(hash + 2), id) || id == 0)
      return false;
    body = body.substr(0, hash);
  }
  const size_t colAt = body.rfind(':');
  if (colAt == std::string_view::npos || colAt == 0)
    return false;
  const size_t lineAt = body.rfind(':', colAt - 1);
  uint32_t line = 0;
  uint32_t col = 0;
  return lineAt != std::string_view::npos && lineAt > 0 &&
         parseInteger(body.substr(lineAt + 1, colAt - lineAt - 1), line) && parseInteger(body.substr(colAt + 1), col);
}

/// A value of attribute `a` written as `tok` (not a quoted string); false if `tok` is not of its type.
bool parseToken(std::string_view tok, const AttrSpec &a, Value &out) {
  switch (a.type) {
  case ValueType::Length:
  case ValueType::Angle:
  case ValueType::Feed:
  case ValueType::Spindle:
  case ValueType::Time:
  case ValueType::Ratio:
  case ValueType::FeedPerRev:
  case ValueType::Power:
  case ValueType::MassFlow: return parseNumber(tok, a.type, out);
  case ValueType::Count:
    out = Value::integer(0);
    return parseInteger(tok, out.count);
  case ValueType::Flag:
    out = Value::boolean(tok == "true");
    return tok == "true" || tok == "false";
  case ValueType::Word:
    out = Value::word(std::string(tok));
    return wordAllowed(a, tok);
  case ValueType::Ref:
    out = Value::ref(std::string(tok));
    return isSymbol(tok);
  case ValueType::Text: return false;
  case ValueType::Point:
  case ValueType::Direction: return parseVector(tok, a.type, out);
  case ValueType::Real:
    out = Value::real(0);
    return parseDouble(tok, out.number);
  case ValueType::Reals: {
    out = Value::reals({});
    if (tok.size() < 2 || tok.front() != '(' || tok.back() != ')')
      return false;
    std::string_view rest = tok.substr(1, tok.size() - 2);
    while (!rest.empty()) {
      const size_t comma = rest.find(',');
      double x = 0;
      if (!parseDouble(rest.substr(0, comma), x))
        return false;
      out.numbers.push_back(x);
      if (comma == std::string_view::npos)
        break;
      rest.remove_prefix(comma + 1);
      if (rest.empty())
        return false;
    }
    return true;
  }
  }
  return false;
}

/// Reads one SourceFile of IR text into a Module.
class Parser {
public:
  Parser(const SourceFile &src, DiagnosticEngine &diags) : src_(src), diags_(diags) {}

  std::unique_ptr<Module> run();

private:
  /// A node that can still receive children: the chain from the root to the last node read.
  struct Open {
    Node *node;
    const KindSpec *spec;
  };
  /// The field a node line may hold next; each may be absent, none may come back.
  enum class Field { Symbol, Label, Attr, Comment };

  void readLine(const char *begin, const char *end);
  bool checkIndent(size_t indent);
  /// The node on the current line, `spec` set to its kind's; empty when the kind
  /// is missing or unknown. A bad field is reported and ends the line, but the
  /// node is kept, so that its children are still checked against it.
  std::optional<Node> readNode(const KindSpec *&spec);
  void readFields(Node &n, const KindSpec &spec);
  bool readField(Node &n, const KindSpec &spec, Field &next);
  bool readSymbol(Node &n, const KindSpec &spec);
  bool readLabel(Node &n, const KindSpec &spec);
  bool readAttr(Node &n, const KindSpec &spec);
  bool readValue(const AttrSpec &a, const KindSpec &spec, Value &out);
  bool readString(std::string &out);
  bool readLocation(Node &n);
  /// Adds `n` under the open node one level up (or as the root); false when it
  /// cannot be placed, and then its subtree is skipped.
  bool place(Node n, const KindSpec &spec, size_t depth, const char *at);
  bool placeRoot(Node n, const KindSpec &spec, const char *at);

  std::string_view readToken();
  std::string_view readName();
  bool startsWith(const char *p, std::string_view s) const {
    return static_cast<size_t>(end_ - p) >= s.size() && std::memcmp(p, s.data(), s.size()) == 0;
  }
  /// What is at `p`, for messages: `'token'` or "the end of the line".
  std::string found(const char *p) const;
  SourceLoc loc(const char *p) const { return {&src_, static_cast<uint64_t>(p - src_.begin())}; }
  InFlightDiagnostic error(const char *p, std::string message) {
    failed_ = true;
    return diags_.error(loc(p), std::move(message));
  }

  const SourceFile &src_;
  DiagnosticEngine &diags_;
  std::unique_ptr<Module> module_ = std::make_unique<Module>();
  bool haveRoot_ = false;
  bool failed_ = false;
  std::vector<Open> open_;
  /// Set after a line that could not be placed: deeper lines (its subtree) are skipped.
  std::optional<size_t> skipBelow_;
  // The rest of the current line.
  const char *p_ = nullptr;
  const char *end_ = nullptr;
  /// The value just read, printed back (kept to reuse its buffer).
  std::string printed_;
};

std::unique_ptr<Module> Parser::run() {
  module_->sourceName = std::string(src_.name());
  const char *p = src_.begin();
  while (p < src_.end() && !diags_.limitReached()) {
    const auto *nl = static_cast<const char *>(std::memchr(p, '\n', static_cast<size_t>(src_.end() - p)));
    const char *lineEnd = nl ? nl : src_.end();
    readLine(p, lineEnd);
    p = lineEnd + 1;
  }
  if (!haveRoot_ && !failed_)
    error(src_.end(), "expected a 'project' node, found no node");
  return failed_ ? nullptr : std::move(module_);
}

void Parser::readLine(const char *begin, const char *end) {
  p_ = begin;
  end_ = end;
  while (p_ < end_ && *p_ == ' ')
    ++p_;
  if (p_ == end_ || *p_ == ';')
    return;
  const auto indent = static_cast<size_t>(p_ - begin);
  if (skipBelow_ && indent > *skipBelow_)
    return;
  skipBelow_.reset();
  const char *at = p_;
  const KindSpec *spec = nullptr;
  std::optional<Node> n;
  if (checkIndent(indent))
    n = readNode(spec);
  if (!n || !place(std::move(*n), *spec, indent / 2, at))
    skipBelow_ = indent;
}

bool Parser::checkIndent(size_t indent) {
  const size_t most = 2 * open_.size();
  if (indent % 2 == 0 && (haveRoot_ || indent == 0) && indent <= most)
    return true;
  const std::string spaces = std::to_string(indent) + " spaces";
  if (indent % 2 != 0)
    error(p_, "indentation of " + spaces + " is not a multiple of two");
  else if (!haveRoot_)
    error(p_, "expected the root node without indentation, found " + spaces);
  else
    error(p_, "indentation of " + spaces + " is more than one level below the node above, expected at most " +
                  std::to_string(most));
  return false;
}

std::optional<Node> Parser::readNode(const KindSpec *&spec) {
  const char *at = p_;
  std::string_view kind = readName();
  if (kind.empty()) {
    error(at, "expected a node kind, found " + found(at));
    return std::nullopt;
  }
  const std::optional<Kind> known = kindNamed(kind);
  if (!known) {
    error(at, "unknown node kind " + quoted(kind));
    return std::nullopt;
  }
  spec = &specOf(*known);
  Node n{*known};
  n.origin.loc = loc(at);
  readFields(n, *spec);
  return n;
}

void Parser::readFields(Node &n, const KindSpec &spec) {
  Field next = Field::Symbol;
  while (p_ < end_) {
    if (startsWith(p_, "  ; ")) {
      n.comment.assign(p_ + 4, end_);
      return;
    }
    if (*p_ != ' ') {
      error(p_, "expected a space after the previous field, found " + found(p_));
      return;
    }
    ++p_;
    if (p_ == end_ || *p_ == ' ') {
      error(p_, std::string("expected a field after one space, found ") +
                    (p_ == end_ ? "the end of the line" : "another space"));
      return;
    }
    if (!readField(n, spec, next))
      return;
  }
}

bool Parser::readField(Node &n, const KindSpec &spec, Field &next) {
  const char c = *p_;
  if ((c == '%' || c == '@') && next == Field::Symbol) {
    next = Field::Label;
    return readSymbol(n, spec);
  }
  if (c == '"' && next <= Field::Label) {
    next = Field::Attr;
    return readLabel(n, spec);
  }
  if (startsWith(p_, "loc(") && next <= Field::Attr) {
    next = Field::Comment;
    return readLocation(n);
  }
  if (isNameChar(c) && next <= Field::Attr) {
    next = Field::Attr;
    return readAttr(n, spec);
  }
  error(p_, std::string(next == Field::Comment ? "expected a comment after 'loc(...)'"
                                               : "expected an attribute 'name=value'") +
                ", found " + found(p_));
  return false;
}

bool Parser::readSymbol(Node &n, const KindSpec &spec) {
  const char *at = p_;
  std::string_view symbol = readToken();
  if (!isSymbol(symbol))
    error(at, "expected a symbol ('%' or '@' and then letters, digits or '_'), found " + quoted(symbol));
  else if (spec.sigil == Sigil::None)
    error(at, quoted(spec.name) + " takes no symbol, found " + quoted(symbol));
  else if (symbol[0] != sigilChar(spec.sigil))
    error(at, quoted(spec.name) + " takes a '" + sigilChar(spec.sigil) + "' symbol, found " + quoted(symbol));
  else {
    n.symbol = symbol;
    return true;
  }
  return false;
}

bool Parser::readLabel(Node &n, const KindSpec &spec) {
  const char *at = p_;
  if (!readString(n.label))
    return false;
  if (!spec.label) {
    error(at, quoted(spec.name) + " takes no label, found " + std::string(at, p_));
    return false;
  }
  return true;
}

bool Parser::readAttr(Node &n, const KindSpec &spec) {
  const char *at = p_;
  std::string_view name = readName();
  if (p_ == end_ || *p_ != '=') {
    error(at, "expected an attribute 'name=value', found " + found(at));
    return false;
  }
  const AttrSpec *a = findAttr(spec, name);
  if (!a) {
    error(at, "unknown attribute " + quoted(name) + " for " + quoted(spec.name));
    return false;
  }
  if (n.has(name)) {
    error(at, "attribute " + quoted(name) + " is given twice");
    return false;
  }
  ++p_;  // '='
  Value v;
  if (!readValue(*a, spec, v))
    return false;
  n.attrs.push_back({std::string(name), std::move(v)});
  return true;
}

bool Parser::readValue(const AttrSpec &a, const KindSpec &spec, Value &out) {
  const char *at = p_;
  auto subject = [&] { return "attribute " + quoted(a.name) + " of " + quoted(spec.name); };
  if (p_ < end_ && *p_ == '"') {
    if (!readString(out.text))
      return false;
    if (a.type == ValueType::Text) {
      out.type = ValueType::Text;
      return true;
    }
    error(at, subject() + " is " + describeValue(a) + ", found " + std::string(at, p_));
    return false;
  }
  std::string_view tok = readToken();
  if (!parseToken(tok, a, out)) {
    error(at, subject() + " is " + describeValue(a) + ", found " + (tok.empty() ? "nothing" : quoted(tok)));
    return false;
  }
  printed_.clear();
  printValue(out, printed_);
  if (printed_ != tok) {
    error(at, subject() + " must be written " + quoted(printed_) + ", found " + quoted(tok));
    return false;
  }
  return true;
}

bool Parser::readString(std::string &out) {
  const char *open = p_++;
  while (p_ < end_ && *p_ != '"') {
    if (*p_ != '\\') {
      out += *p_++;
      continue;
    }
    if (p_ + 1 == end_)
      break;
    const char escaped = p_[1];
    if (escaped != '"' && escaped != '\\' && escaped != 'n') {
      error(p_, "unknown escape " + quoted(std::string_view(p_, 2)) + " in a string, expected \\\", \\\\ or \\n");
      return false;
    }
    out += escaped == 'n' ? '\n' : escaped;
    p_ += 2;
  }
  if (p_ == end_) {
    error(open, "unterminated string: no closing '\"' on this line");
    return false;
  }
  ++p_;
  return true;
}

bool Parser::readLocation(Node &n) {
  // The field ends at the first ')' that ends the line or is followed by a space.
  const char *at = p_;
  const char *close = p_ + 4;
  while (close < end_ && !(*close == ')' && (close + 1 == end_ || close[1] == ' ')))
    ++close;
  uint64_t id = 0;
  if (close == end_ || !parseLocation(std::string_view(at + 4, static_cast<size_t>(close - at - 4)), id)) {
    error(at, "expected 'loc(file:line:col)' or 'loc(file:line:col #id)', found " + found(at));
    return false;
  }
  n.origin.entityId = id;
  p_ = close + 1;
  return true;
}

bool Parser::place(Node n, const KindSpec &spec, size_t depth, const char *at) {
  if (depth == 0)
    return placeRoot(std::move(n), spec, at);
  open_.resize(depth);
  const Open parent = open_.back();
  if (!childAllowed(*parent.spec, spec))
    error(at, quoted(spec.name) + " is not allowed under " + quoted(parent.spec->name) + ", which takes " +
                  allowedChildren(*parent.spec));
  Node &child = parent.node->add(std::move(n));
  open_.push_back({&child, &spec});
  return true;
}

bool Parser::placeRoot(Node n, const KindSpec &spec, const char *at) {
  if (haveRoot_) {
    error(at, "expected one root node, found a second one: " + quoted(spec.name));
    return false;
  }
  if (spec.id != Kind::Project) {
    error(at, "expected the root node 'project', found " + quoted(spec.name));
    return false;
  }
  module_->root = std::move(n);
  haveRoot_ = true;
  open_.assign(1, {&module_->root, &spec});
  return true;
}

std::string_view Parser::readToken() {
  const char *start = p_;
  while (p_ < end_ && *p_ != ' ')
    ++p_;
  return {start, static_cast<size_t>(p_ - start)};
}

std::string_view Parser::readName() {
  const char *start = p_;
  while (p_ < end_ && isNameChar(*p_))
    ++p_;
  return {start, static_cast<size_t>(p_ - start)};
}

std::string Parser::found(const char *p) const {
  if (p == end_)
    return "the end of the line";
  const char *e = p;
  while (e < end_ && *e != ' ')
    ++e;
  return quoted(std::string_view(p, static_cast<size_t>(e - p)));
}

} // namespace

std::unique_ptr<Module> parseModule(const SourceFile &src, DiagnosticEngine &diags) {
  return Parser(src, diags).run();
}

} // namespace stepnc::ir
