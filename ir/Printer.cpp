// Prints IR nodes as text, appending to one string. The spelling of each value
// type is defined here and nowhere else: the parser checks what it reads by
// printing the value it parsed and comparing.
#include "ir/Printer.h"

#include "support/Format.h"

namespace stepnc::ir {

namespace {

constexpr std::string_view kHeader =
    "; stepnc feature IR (lengths mm, angles deg, feeds mm/min, spindle rev/min, times s)\n";

/// Digits after the decimal point, per number type.
int decimalsOf(ValueType t) {
  switch (t) {
  case ValueType::Feed:
  case ValueType::Spindle:
  case ValueType::Power: return 1;
  case ValueType::Time:
  case ValueType::MassFlow: return 3;
  case ValueType::Direction: return 6;
  default: return kLengthDecimals;
  }
}

} // namespace

bool printsAsOnePoint(const Vec3 &a, const Vec3 &b) {
  for (int k = 0; k < 3; ++k)
    if (formatFixed(a[k], kLengthDecimals) != formatFixed(b[k], kLengthDecimals))
      return false;
  return true;
}

namespace {

void appendVector(const Vec3 &v, ValueType t, std::string &out) {
  out += '(';
  for (int i = 0; i < 3; ++i) {
    if (i > 0)
      out += ',';
    out += formatFixed(v[i], decimalsOf(t));
  }
  out += ')';
  out += unitSuffix(t);
}

/// `"..."` with `\"`, `\\` and `\n` escaped; other bytes (UTF-8 included) as they are.
void appendQuoted(std::string_view s, std::string &out) {
  out += '"';
  for (char c : s) {
    switch (c) {
    case '"': out += "\\\""; break;
    case '\\': out += "\\\\"; break;
    case '\n': out += "\\n"; break;
    default: out += c;
    }
  }
  out += '"';
}

void appendAttr(const Attr &a, std::string &out) {
  out += ' ';
  out += a.name;
  out += '=';
  printValue(a.value, out);
}

/// Attributes in the order of the kind's spec, then those it does not list.
void appendAttrs(const Node &n, const KindSpec *spec, std::string &out) {
  if (spec)
    for (const AttrSpec &s : spec->attrs)
      for (const Attr &a : n.attrs)
        if (a.name == s.name)
          appendAttr(a, out);
  for (const Attr &a : n.attrs)
    if (!spec || !findAttr(*spec, a.name))
      appendAttr(a, out);
}

void appendLocation(const Origin &origin, std::string &out) {
  LineCol lc = origin.loc.file->lineCol(origin.loc.offset);
  out += " loc(";
  out += origin.loc.file->name();
  out += ':';
  out += std::to_string(lc.line);
  out += ':';
  out += std::to_string(lc.col);
  if (origin.entityId != 0) {
    out += ' ';
    out += hashId(origin.entityId);
  }
  out += ')';
}

/// "(a, b, c)" from a space-separated word list.
std::string wordList(std::string_view words) {
  std::string out = "(";
  for (char c : words) {
    if (c == ' ')
      out += ", ";
    else
      out += c;
  }
  return out + ")";
}

} // namespace

std::string_view unitSuffix(ValueType t) {
  switch (t) {
  case ValueType::Length:
  case ValueType::Point: return "mm";
  case ValueType::Angle: return "deg";
  case ValueType::Feed: return "mm/min";
  case ValueType::Spindle: return "rev/min";
  case ValueType::Time: return "s";
  case ValueType::FeedPerRev: return "mm/rev";
  case ValueType::Power: return "W";
  case ValueType::MassFlow: return "g/min";
  default: return {};
  }
}

void printValue(const Value &v, std::string &out) {
  switch (v.type) {
  case ValueType::Length:
  case ValueType::Angle:
  case ValueType::Feed:
  case ValueType::Spindle:
  case ValueType::Time:
  case ValueType::Ratio:
  case ValueType::FeedPerRev:
  case ValueType::Power:
  case ValueType::MassFlow:
    out += formatFixed(v.number, decimalsOf(v.type));
    out += unitSuffix(v.type);
    break;
  case ValueType::Count: out += std::to_string(v.count); break;
  case ValueType::Flag: out += v.flag ? "true" : "false"; break;
  case ValueType::Word:
  case ValueType::Ref: out += v.text; break;
  case ValueType::Text: appendQuoted(v.text, out); break;
  case ValueType::Point:
  case ValueType::Direction: appendVector(v.vec, v.type, out); break;
  case ValueType::Real: out += formatExact(v.number); break;
  case ValueType::Reals:
    out += '(';
    for (size_t i = 0; i < v.numbers.size(); ++i) {
      if (i > 0)
        out += ',';
      out += formatExact(v.numbers[i]);
    }
    out += ')';
    break;
  }
}

std::string describeValue(const AttrSpec &a) {
  switch (a.type) {
  case ValueType::Length: return "a length in mm";
  case ValueType::Angle: return "an angle in deg";
  case ValueType::Feed: return "a feed in mm/min";
  case ValueType::Spindle: return "a spindle speed in rev/min";
  case ValueType::Time: return "a time in s";
  case ValueType::Ratio: return "a ratio (a plain number)";
  case ValueType::Count: return "a count (an integer)";
  case ValueType::Flag: return "a flag (true or false)";
  case ValueType::Word: return a.words.empty() ? "a word (letters, digits and '_')" : "one of " + wordList(a.words);
  case ValueType::Text: return "a quoted string";
  case ValueType::Ref: return "a reference (%name or @name)";
  case ValueType::Point: return "a point (x,y,z)mm";
  case ValueType::Direction: return "a direction (x,y,z)";
  case ValueType::Real: return "a number";
  case ValueType::Reals: return "a list of numbers (a,b,...)";
  case ValueType::FeedPerRev: return "a feed per revolution in mm/rev";
  case ValueType::Power: return "a power in W";
  case ValueType::MassFlow: return "a mass flow in g/min";
  }
  return "a value";
}

void printNode(const Node &n, std::string &out, const PrintOptions &o, int depth) {
  out.append(static_cast<size_t>(2 * depth), ' ');
  out += n.spec().name;
  if (!n.symbol.empty()) {
    out += ' ';
    out += n.symbol;
  }
  if (!n.label.empty()) {
    out += ' ';
    appendQuoted(n.label, out);
  }
  appendAttrs(n, &n.spec(), out);
  if (o.locations && n.origin.loc.valid())
    appendLocation(n.origin, out);
  if (!n.comment.empty()) {
    out += "  ; ";
    out += n.comment;
  }
  out += '\n';
  for (const Node &c : n.children)
    printNode(c, out, o, depth + 1);
}

std::string printModule(const Module &m, const PrintOptions &o) {
  std::string out(kHeader);
  printNode(m.root, out, o);
  return out;
}

} // namespace stepnc::ir
