// Recursive-descent decoding of Part 21 parameters.
//
// Values are built on the arena's scratch stack; when a list closes, its
// children are moved to the arena as one contiguous block, so every list's
// children are a span. Nesting is bounded (ReadOptions::maxNesting) so hostile
// input cannot overflow the stack. Strings are decoded to UTF-8 following
// ISO 10303-21 §6.4.3: '' and \\, \S\ with the \P?\ code page, \X\hh, \X2\ and
// \X4\ runs; line breaks inside strings are layout and are dropped.
#include "support/Format.h"
#include "support/Utf8.h"
#include "frontend/part21/Decoder.h"

#include "frontend/part21/Lexing.h"

#include <array>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <iconv.h>

namespace stepnc::p21 {

using namespace lex;

const char *valueKindName(ValueKind k) {
  switch (k) {
  case ValueKind::Unset: return "$";
  case ValueKind::Derived: return "*";
  case ValueKind::Integer: return "integer";
  case ValueKind::Real: return "real";
  case ValueKind::String: return "string";
  case ValueKind::Binary: return "binary";
  case ValueKind::Enumeration: return "enumeration";
  case ValueKind::Reference: return "reference";
  case ValueKind::List: return "list";
  case ValueKind::Typed: return "typed parameter";
  }
  return "value";
}

namespace {

unsigned hexValue(char c) {
  if (c >= '0' && c <= '9')
    return static_cast<unsigned>(c - '0');
  if (c >= 'A' && c <= 'F')
    return static_cast<unsigned>(c - 'A' + 10);
  return static_cast<unsigned>(c - 'a' + 10);
}

// Converts one byte of ISO 8859-`part` (1..9) to UTF-8; false if unmapped.
bool appendIso8859(std::string &out, unsigned part, unsigned char byte) {
  if (part == 1 || byte < 0xA0) {
    utf8::append(out, byte);
    return true;
  }
  // The upper halves of ISO 8859-2..9, converted by iconv once, on first use
  // (a thread-safe static initialisation).
  using Pages = std::array<std::array<std::string, 96>, 10>;
  static const Pages table = [] {
    Pages pages;
    for (unsigned page = 2; page <= 9; ++page) {
      const std::string from = "ISO-8859-" + std::to_string(page);
      iconv_t cd = ::iconv_open("UTF-8", from.c_str());
      if (cd == reinterpret_cast<iconv_t>(-1))
        continue;
      for (unsigned b = 0xA0; b <= 0xFF; ++b) {
        char in[1] = {static_cast<char>(b)};
        char buf[8];
        char *inp = in, *outp = buf;
        size_t inLeft = 1, outLeft = sizeof buf;
        if (::iconv(cd, &inp, &inLeft, &outp, &outLeft) != static_cast<size_t>(-1))
          pages[page][b - 0xA0].assign(buf, static_cast<size_t>(outp - buf));
      }
      ::iconv_close(cd);
    }
    return pages;
  }();
  const std::string &utf8 = table[part][byte - 0xA0];
  if (utf8.empty())
    return false;
  out += utf8;
  return true;
}

// A byte for a message: 'c' when printable ASCII, else its hex code.
std::string describeByte(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7F)
    return std::string("'") + c + "'";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02X", u);
  return buf;
}

} // namespace

Decoder::Decoder(const Part21File &file, ValueArena &arena, DiagnosticEngine *diags,
                 const char *base, InstanceId id, const char *context)
    : file_(file), arena_(arena), diags_(diags), base_(base), id_(id), context_(context),
      scratch_(arena.scratch()) {}

uint32_t Decoder::offsetOf(const char *q) const {
  uint64_t o = static_cast<uint64_t>(q - base_);
  return o > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(o);
}

bool Decoder::fail(const char *at, std::string message) {
  if (diags_) {
    auto d = diags_->error(file_.loc(static_cast<uint64_t>(at - file_.source().begin())),
                           std::move(message));
    if (id_ != 0)
      d.entity(id_, entityName_ == kNoName ? std::string() : std::string(file_.names().name(entityName_)));
  }
  return false;
}

bool Decoder::skipLayoutSlow() {
  if (skipLayout(p_, end_) == Layout::UnterminatedComment)
    return fail(p_, "unterminated comment: '/*' has no matching '*/'");
  return true;
}

bool Decoder::parseParam(unsigned depth) {
  if (!layout())
    return false;
  if (p_ >= end_)
    return fail(p_, "expected a parameter before end of input");
  Value v;
  v.offset = offsetOf(p_);
  const char c = *p_;
  switch (c) {
  case '$':
    v.kind = ValueKind::Unset;
    ++p_;
    break;
  case '*':
    v.kind = ValueKind::Derived;
    ++p_;
    break;
  case '#': {
    const char *q = p_ + 1;
    if (q >= end_ || !isDigit(*q))
      return fail(p_, "expected an instance id (digits) after '#'");
    uint64_t id = 0;
    while (q < end_ && isDigit(*q)) {
      if (id > (UINT64_MAX - 9) / 10)
        return fail(p_, "instance id is too large");
      id = id * 10 + static_cast<uint64_t>(*q++ - '0');
    }
    v.kind = ValueKind::Reference;
    v.ref = id;
    p_ = q;
    break;
  }
  case '\'':
    if (!parseString(v))
      return false;
    break;
  case '"':
    if (!parseBinary(v))
      return false;
    break;
  case '.':
    if (!parseEnum(v))
      return false;
    break;
  case '(':
    if (depth >= file_.options().maxNesting)
      return fail(p_, "parameters nested deeper than " +
                          std::to_string(file_.options().maxNesting) + " levels");
    if (!parseListInto(depth + 1, v))
      return false;
    break;
  case '@':
    return fail(p_, "value instance references '@...' are not supported");
  default:
    if (isDigit(c) || c == '-' || c == '+') {
      if (!parseNumber(v))
        return false;
    } else if (isKeywordStart(c)) {
      // Typed parameter: TYPE_NAME(value).
      const char *n = p_;
      if (*p_ == '!' && (++p_ >= end_ || !isKeywordStart(*p_) || *p_ == '!'))
        return fail(n, "expected a user-defined type name after '!'");
      while (p_ < end_ && isKeywordChar(*p_))
        ++p_;
      const std::string_view typeName(n, static_cast<size_t>(p_ - n));
      NameId name = file_.intern(typeName);
      if (!layout())
        return false;
      if (p_ >= end_ || *p_ != '(')
        return fail(p_, "expected '(' after type name '" + std::string(typeName) + "'");
      if (depth >= file_.options().maxNesting)
        return fail(p_, "parameters nested deeper than " +
                            std::to_string(file_.options().maxNesting) + " levels");
      const char *open = p_;
      if (!parseListInto(depth + 1, v))
        return false;
      if (v.count != 1)
        return fail(open, "typed parameter '" + std::string(file_.names().name(name)) +
                              "' must have exactly one value, found " + std::to_string(v.count));
      v.kind = ValueKind::Typed;
      v.node.name = name;
    } else if (static_cast<unsigned char>(c) >= 0x80) {
      return fail(p_, "non-ASCII byte outside a string");
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned char>(c));
      return fail(p_, std::string("control character ") + buf + " in parameters");
    } else {
      return fail(p_, "unexpected " + describeByte(c) + " where a parameter was expected");
    }
  }
  scratch_.push_back(v);
  return true;
}

// Parses `( p, p, ... )` at p_; children go to the arena, `list` describes them.
bool Decoder::parseListInto(unsigned depth, Value &list) {
  const char *open = p_;
  ++p_;  // '('
  const size_t mark = scratch_.size();
  if (!layout())
    return false;
  if (p_ < end_ && *p_ == ')') {
    ++p_;
  } else {
    for (;;) {
      if (!parseParam(depth))
        return false;
      if (!layout())
        return false;
      if (p_ < end_ && *p_ == ',') {
        ++p_;
        continue;
      }
      if (p_ < end_ && *p_ == ')') {
        ++p_;
        break;
      }
      if (p_ >= end_ || *p_ == ';')
        return fail(open, "unbalanced '(': no matching ')'");
      return fail(p_, "expected ',' or ')' in parameter list, found " + describeByte(*p_));
    }
  }
  auto &values = arena_.mutableValues();
  const size_t n = scratch_.size() - mark;
  if (values.size() + n > UINT32_MAX)
    return fail(open, "too many values in one instance");
  list.kind = ValueKind::List;
  list.node.first = static_cast<uint32_t>(values.size());
  list.node.name = kNoName;
  list.count = static_cast<uint32_t>(n);
  values.insert(values.end(), scratch_.begin() + static_cast<std::ptrdiff_t>(mark), scratch_.end());
  scratch_.resize(mark);
  return true;
}

bool Decoder::parseString(Value &v) {
  const char *open = p_;
  const char *q = p_ + 1;
  // Fast path: no escapes, no doubled quotes, no line breaks, plain ASCII.
  const char *close = static_cast<const char *>(std::memchr(q, '\'', static_cast<size_t>(end_ - q)));
  if (!close)
    return fail(open, "unterminated string");
  bool simple = close + 1 >= end_ || close[1] != '\'';
  for (const char *r = q; simple && r < close; ++r) {
    const auto c = static_cast<unsigned char>(*r);
    simple = c >= 0x20 && c < 0x7F && c != '\\';
  }
  v.kind = ValueKind::String;
  if (simple) {
    v.text = q;
    v.count = static_cast<uint32_t>(close - q);
    p_ = close + 1;
    return true;
  }
  decoded_.clear();
  unsigned page = 1;  // \P?\ code page: ISO 8859-<page>
  for (;;) {
    if (q >= end_)
      return fail(open, "unterminated string");
    const auto c = static_cast<unsigned char>(*q);
    if (c == '\'') {
      if (q + 1 < end_ && q[1] == '\'') {
        decoded_.push_back('\'');
        q += 2;
        continue;
      }
      ++q;
      break;
    }
    if (c == '\n' || c == '\r') {
      ++q;  // line breaks are layout, not content
      continue;
    }
    if (c == '\\') {
      const char *esc = q;
      auto need = [&](size_t n) { return static_cast<size_t>(end_ - q) >= n; };
      if (need(2) && q[1] == '\\') {
        decoded_.push_back('\\');
        q += 2;
      } else if (need(4) && q[1] == 'S' && q[2] == '\\') {
        const auto ch = static_cast<unsigned char>(q[3]);
        if (ch < 0x20 || ch > 0x7E)
          return fail(esc, "invalid character after \\S\\ escape");
        if (!appendIso8859(decoded_, page, static_cast<unsigned char>(ch + 128)))
          return fail(esc, "character not in ISO 8859-" + std::to_string(page));
        q += 4;
      } else if (need(4) && q[1] == 'P' && q[3] == '\\' && q[2] >= 'A' && q[2] <= 'I') {
        page = static_cast<unsigned>(q[2] - 'A' + 1);
        q += 4;
      } else if (need(5) && q[1] == 'X' && q[2] == '\\' && isHexDigit(q[3]) && isHexDigit(q[4])) {
        utf8::append(decoded_, hexValue(q[3]) * 16 + hexValue(q[4]));
        q += 5;
      } else if (need(4) && q[1] == 'X' && (q[2] == '2' || q[2] == '4') && q[3] == '\\') {
        const unsigned width = q[2] == '2' ? 4 : 8;
        q += 4;
        uint32_t pendingHigh = 0;
        for (;;) {
          if (need(4) && q[0] == '\\' && q[1] == 'X' && q[2] == '0' && q[3] == '\\') {
            q += 4;
            break;
          }
          uint32_t cp = 0;
          for (unsigned i = 0; i < width; ++i) {
            if (q >= end_ || !isHexDigit(*q))
              return fail(q < end_ ? q : esc, std::string("expected ") + std::to_string(width) +
                                                  " hex digits or \\X0\\ in \\X" + esc[2] + "\\ escape");
            cp = cp * 16 + hexValue(*q++);
          }
          if (width == 4 && cp >= 0xD800 && cp < 0xDC00) {
            pendingHigh = cp;
            continue;
          }
          if (width == 4 && cp >= 0xDC00 && cp < 0xE000) {
            if (!pendingHigh)
              return fail(esc, "unpaired UTF-16 surrogate in \\X2\\ escape");
            cp = 0x10000 + ((pendingHigh - 0xD800) << 10) + (cp - 0xDC00);
            pendingHigh = 0;
          } else if (pendingHigh) {
            return fail(esc, "unpaired UTF-16 surrogate in \\X2\\ escape");
          }
          if (cp > 0x10FFFF || (cp >= 0xD800 && cp < 0xE000))
            return fail(esc, "invalid character code in \\X4\\ escape");
          utf8::append(decoded_, cp);
        }
        if (pendingHigh)
          return fail(esc, "unpaired UTF-16 surrogate in \\X2\\ escape");
      } else if (need(3) && (q[1] == 'N' || q[1] == 'F') && q[2] == '\\') {
        q += 3;  // ed. 2 print control directives: no content
      } else {
        return fail(esc, "invalid escape sequence in string");
      }
      continue;
    }
    if (c >= 0x80) {
      size_t n = utf8::sequenceLength(std::string_view(q, static_cast<size_t>(end_ - q)), 0);
      if (n == 0)
        return fail(q, "byte in string is neither ASCII nor UTF-8; encode it with \\X\\ or \\X2\\");
      decoded_.append(q, n);
      q += n;
      continue;
    }
    if (c < 0x20 || c == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "%02X", c);
      return fail(q, std::string("control character in string; write it as \\X\\") + buf);
    }
    decoded_.push_back(static_cast<char>(c));
    ++q;
  }
  p_ = q;
  if (decoded_.size() > UINT32_MAX)
    return fail(open, "string longer than 4 GiB");
  v.text = arena_.storeString(decoded_);
  v.count = static_cast<uint32_t>(decoded_.size());
  return true;
}

bool Decoder::parseNumber(Value &v) {
  const char *start = p_;
  const char *q = p_;
  bool negative = false;
  if (*q == '+' || *q == '-') {
    negative = *q == '-';
    ++q;
  }
  const char *digits = q;
  while (q < end_ && isDigit(*q))
    ++q;
  if (q == digits)
    return fail(start, "expected digits after sign");
  bool real = false;
  if (q < end_ && *q == '.') {
    real = true;
    ++q;
    while (q < end_ && isDigit(*q))
      ++q;
    if (q < end_ && (*q == 'E' || *q == 'e')) {
      const char *e = q++;
      if (q < end_ && (*q == '+' || *q == '-'))
        ++q;
      if (q >= end_ || !isDigit(*q))
        return fail(e, "expected digits in the exponent of a real");
      while (q < end_ && isDigit(*q))
        ++q;
    }
  } else if (q < end_ && (*q == 'E' || *q == 'e')) {
    return fail(start, "a real needs a decimal point before its exponent (e.g. '1.E5')");
  }
  if (q < end_ && (isLetter(*q) || *q == '.'))
    return fail(q, "unexpected character after number");
  if (real) {
    double d = 0;
    auto r = std::from_chars(digits, q, d);
    if (r.ec == std::errc::result_out_of_range)
      return fail(start, "real out of range");
    if (r.ec != std::errc() || r.ptr != q)
      return fail(start, "malformed real");
    v.kind = ValueKind::Real;
    v.real = negative ? -d : d;
  } else {
    uint64_t u = 0;
    auto r = std::from_chars(digits, q, u);
    if (r.ec != std::errc() || u > (negative ? uint64_t(INT64_MAX) + 1 : uint64_t(INT64_MAX)))
      return fail(start, "integer out of range");
    v.kind = ValueKind::Integer;
    v.integer = negative ? static_cast<int64_t>(0 - u) : static_cast<int64_t>(u);
  }
  p_ = q;
  return true;
}

bool Decoder::parseBinary(Value &v) {
  const char *open = p_;
  const char *q = p_ + 1;
  if (q < end_ && *q >= '0' && *q <= '3') {
    ++q;
    while (q < end_ && isHexDigit(*q))
      ++q;
  } else {
    return fail(q, "a binary value starts with the number of unused bits (0-3)");
  }
  if (q >= end_ || *q != '"')
    return fail(q, "expected hex digits or '\"' to end the binary value");
  v.kind = ValueKind::Binary;
  v.text = open + 1;
  v.count = static_cast<uint32_t>(q - open - 1);
  p_ = q + 1;
  return true;
}

bool Decoder::parseEnum(Value &v) {
  const char *open = p_;
  const char *q = p_ + 1;
  if (q >= end_ || !(isLetter(*q) || *q == '_'))
    return fail(open, "expected an enumeration name after '.'");
  while (q < end_ && isKeywordChar(*q))
    ++q;
  if (q >= end_ || *q != '.')
    return fail(q, "expected '.' to end the enumeration value");
  v.kind = ValueKind::Enumeration;
  v.text = open + 1;
  v.count = static_cast<uint32_t>(q - open - 1);
  for (const char *r = v.text; r < q; ++r)
    if (*r >= 'a' && *r <= 'z') {
      // Enumeration names are upper case in Part 21; keep a normalised copy.
      std::string upper(v.text, v.count);
      for (char &ch : upper)
        if (ch >= 'a' && ch <= 'z')
          ch = static_cast<char>(ch - 32);
      v.text = arena_.storeString(upper);
      break;
    }
  p_ = q + 1;
  return true;
}

bool Decoder::parseRecordBody(Record &out, NameId known) {
  const char *n = p_;
  if (p_ >= end_ || !isKeywordStart(*p_))
    return fail(p_, "expected an entity name");
  if (*p_ == '!' && (++p_ >= end_ || !isKeywordStart(*p_) || *p_ == '!'))
    return fail(n, "expected a user-defined entity name after '!'");
  while (p_ < end_ && isKeywordChar(*p_))
    ++p_;
  // The instance table already interned a simple instance's name.
  out.name = known != kNoName ? known : file_.intern({n, static_cast<size_t>(p_ - n)});
  out.offset = offsetOf(n);
  if (!layout())
    return false;
  if (p_ >= end_ || *p_ != '(')
    return fail(p_, "expected '(' after entity name '" + std::string(file_.names().name(out.name)) + "'");
  Value list;
  if (!parseListInto(1, list))
    return false;
  out.first = list.node.first;
  out.count = list.count;
  return true;
}

const char *Decoder::parseRecord(const char *p, const char *end, Record &out) {
  p_ = p;
  end_ = end;
  scratch_.clear();
  if (!parseRecordBody(out))
    return nullptr;
  auto &records = arena_.mutableRecords();
  records.push_back(out);
  return p_;
}

const char *Decoder::parseParamList(const char *p, const char *end, std::vector<Value> &out) {
  p_ = p;
  end_ = end;
  scratch_.clear();
  Value list;
  if (!parseListInto(1, list))
    return nullptr;
  auto span = arena_.children(list);
  out.assign(span.begin(), span.end());
  return p_;
}

const char *Decoder::parseSingleParam(const char *p, const char *end, Value &out) {
  p_ = p;
  end_ = end;
  scratch_.clear();
  if (!parseParam(1))
    return nullptr;
  out = scratch_.back();
  scratch_.clear();
  return p_;
}

bool Decoder::parseInstance(const char *p, const char *end, NameId known) {
  p_ = p + 1;  // '#'
  end_ = end;
  scratch_.clear();
  while (p_ < end_ && isDigit(*p_))
    ++p_;
  if (!layout())
    return false;
  ++p_;  // '=' (checked by the scanner)
  if (!layout())
    return false;
  if (p_ < end_ && *p_ == '(') {
    // Complex instance: ( NAME(...) NAME(...) ... )
    const char *open = p_++;
    for (;;) {
      if (!layout())
        return false;
      if (p_ < end_ && *p_ == ')') {
        ++p_;
        break;
      }
      if (p_ >= end_ || *p_ == ';')
        return fail(open, "unbalanced '(' in complex instance: no matching ')'");
      Record rec;
      if (!parseRecordBody(rec))
        return false;
      arena_.mutableRecords().push_back(rec);
    }
    if (arena_.records().empty())
      return fail(open, "complex instance with no entity records");
  } else {
    Record rec;
    if (!parseRecordBody(rec, known))
      return false;
    arena_.mutableRecords().push_back(rec);
  }
  // What follows the closing ')' is the scanner's business: it ended the
  // instance there and reported a missing ';' already.
  return true;
}

// --- Part21File members that need the decoder ---------------------------------

std::string_view Part21File::entityName(const InstanceEntry &e) const {
  if (e.name() == kComplexInstance)
    return "(complex)";
  return names_.name(e.name());
}

const HeaderEntity *Part21File::headerEntity(std::string_view name) const {
  for (const HeaderEntity &h : header_)
    if (names_.name(h.record.name) == name)
      return &h;
  return nullptr;
}

std::vector<std::string> Part21File::schemaNames() const {
  std::vector<std::string> out;
  const HeaderEntity *h = headerEntity("FILE_SCHEMA");
  if (!h || h->record.count < 1)
    return out;
  const Value &list = metadata_.params(h->record)[0];
  if (list.kind != ValueKind::List)
    return out;
  for (const Value &v : metadata_.children(list))
    if (v.kind == ValueKind::String)
      out.emplace_back(v.str());
  return out;
}

std::string Part21File::describe(const InstanceEntry &e) const {
  if (e.name() != kComplexInstance)
    return std::string(names_.name(e.name()));
  ValueArena arena;
  if (!decodeInstance(static_cast<size_t>(&e - entries_.data()), arena, nullptr))
    return "(complex)";
  std::string s;
  for (const Record &r : arena.records()) {
    if (!s.empty())
      s += '+';
    s += names_.name(r.name);
  }
  return s;
}

bool Part21File::decodeInstance(size_t index, ValueArena &arena, DiagnosticEngine *diags) const {
  const InstanceEntry &e = entries_[index];
  arena.clear();
  const char *begin = source_->begin() + e.begin();
  Decoder dec(*this, arena, diags, begin, e.id, "instance");
  const NameId name = e.name();
  if (diags && name != kComplexInstance)
    dec.setEntityName(name);
  return dec.parseInstance(begin, source_->end(), name);
}

namespace {

void reportUndefined(const Part21File &file, const Value &v, uint64_t base, const InstanceEntry *from,
                     DiagnosticEngine &diags) {
  auto d = diags.error(file.loc(base + v.offset), "reference to " + hashId(v.ref) + ", which is not defined");
  if (from)
    d.entity(from->id, std::string(file.entityName(*from)));
  d.note("no instance " + hashId(v.ref) + " in the DATA sections or the REFERENCE section");
}

} // namespace

void checkReferences(const Part21File &file, size_t index, const ValueArena &values, DiagnosticEngine &diags) {
  const InstanceEntry &e = file.entries()[index];
  for (const Value &v : values.values())
    if (v.kind == ValueKind::Reference && !file.isDefined(v.ref))
      reportUndefined(file, v, e.begin(), &e, diags);
}

void checkAnchorReferences(const Part21File &file, DiagnosticEngine &diags) {
  const ValueArena &meta = file.metadata();
  for (const Anchor &a : file.anchors()) {
    std::vector<const Value *> stack{&a.value};
    while (!stack.empty()) {
      const Value *v = stack.back();
      stack.pop_back();
      if (v->kind == ValueKind::Reference && !file.isDefined(v->ref))
        reportUndefined(file, *v, 0, nullptr, diags);
      else if (v->kind == ValueKind::List || v->kind == ValueKind::Typed)
        for (const Value &c : meta.children(*v))
          stack.push_back(&c);
    }
  }
}

size_t checkInstances(const Part21File &file, DiagnosticEngine &diags, const InstanceVisitor &visit) {
  // Anchors first: they precede the DATA sections in a file.
  checkAnchorReferences(file, diags);
  ValueArena arena;
  size_t clean = 0;
  for (size_t i = 0; i < file.entries().size() && !diags.limitReached(); ++i) {
    if (!file.decodeInstance(i, arena, &diags))
      continue;
    ++clean;
    checkReferences(file, i, arena, diags);
    if (visit)
      visit(i, arena);
  }
  return clean;
}

} // namespace stepnc::p21
