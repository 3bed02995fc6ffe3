#include "frontend/part21/Writer.h"

#include "support/Format.h"
#include "support/Utf8.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <numeric>

namespace stepnc::p21 {

namespace {

void appendHex(std::string &out, uint32_t v, int digits) {
  static const char *hex = "0123456789ABCDEF";
  for (int k = digits - 1; k >= 0; --k)
    out.push_back(hex[(v >> (4 * k)) & 15]);
}

} // namespace

void appendString(std::string &out, std::string_view s) {
  out.push_back('\'');
  size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7F) {
      if (c == '\'')
        out += "''";
      else if (c == '\\')
        out += "\\\\";
      else
        out.push_back(static_cast<char>(c));
      ++i;
      continue;
    }
    size_t j = i;
    uint32_t cp = utf8::next(s, j);
    if (cp <= 0xFF) {
      out += "\\X\\";
      appendHex(out, cp, 2);
      i = j;
      continue;
    }
    // A run of characters beyond Latin-1: one \X2\ (or \X4\) group.
    std::vector<uint32_t> run;
    bool wide = false;
    size_t k = i;
    while (k < s.size() && static_cast<unsigned char>(s[k]) >= 0x80) {
      size_t next = k;
      uint32_t v = utf8::next(s, next);
      if (v <= 0xFF)
        break;
      wide |= v > 0xFFFF;
      run.push_back(v);
      k = next;
    }
    out += wide ? "\\X4\\" : "\\X2\\";
    for (uint32_t v : run)
      appendHex(out, v, wide ? 8 : 4);
    out += "\\X0\\";
    i = k;
  }
  out.push_back('\'');
}

void appendReal(std::string &out, double value) {
  // Shortest exact digits; unlike formatShortest, -0 stays -0 so that the
  // graph reads back bit for bit. Part 21 wants a decimal point and 'E'.
  char digits[64];
  auto r = std::to_chars(digits, digits + sizeof digits, value);
  const std::string_view s(digits, static_cast<size_t>(r.ptr - digits));
  const size_t e = s.find('e');
  const std::string_view mantissa = s.substr(0, e);
  out += mantissa;
  if (mantissa.find('.') == std::string_view::npos)
    out += '.';
  if (e != std::string_view::npos) {
    out += 'E';
    out += s.substr(e + 1);
  }
}

void appendValue(std::string &out, const Value &v, const ValueArena &arena, const NameTable &names) {
  switch (v.kind) {
  case ValueKind::Unset: out.push_back('$'); break;
  case ValueKind::Derived: out.push_back('*'); break;
  case ValueKind::Integer: out += std::to_string(v.integer); break;
  case ValueKind::Real: appendReal(out, v.real); break;
  case ValueKind::String: appendString(out, v.str()); break;
  case ValueKind::Binary:
    out.push_back('"');
    for (char c : v.str())
      out.push_back((c >= 'a' && c <= 'f') ? static_cast<char>(c - 32) : c);
    out.push_back('"');
    break;
  case ValueKind::Enumeration:
    out.push_back('.');
    out += v.str();
    out.push_back('.');
    break;
  case ValueKind::Reference:
    out.push_back('#');
    out += std::to_string(v.ref);
    break;
  case ValueKind::Typed:
    out += names.name(v.node.name);
    [[fallthrough]];
  case ValueKind::List: {
    out.push_back('(');
    bool first = true;
    for (const Value &c : arena.children(v)) {
      if (!first)
        out.push_back(',');
      first = false;
      appendValue(out, c, arena, names);
    }
    out.push_back(')');
    break;
  }
  }
}

void appendRecord(std::string &out, const Record &r, const ValueArena &arena, const NameTable &names) {
  out += names.name(r.name);
  out.push_back('(');
  bool first = true;
  for (const Value &c : arena.params(r)) {
    if (!first)
      out.push_back(',');
    first = false;
    appendValue(out, c, arena, names);
  }
  out.push_back(')');
}

bool writePart21(const Part21File &file, OutputFile &out, DiagnosticEngine &diags, const WriteOptions &options) {
  return writePart21(file, [&out](std::string_view chunk) { out.write(chunk); }, diags, options);
}

std::string writePart21ToString(const Part21File &file, DiagnosticEngine &diags, bool *ok) {
  std::string text;
  bool done = writePart21(file, [&text](std::string_view chunk) { text += chunk; }, diags);
  if (ok)
    *ok = done;
  return text;
}

bool writePart21(const Part21File &file, const ByteSink &sink, DiagnosticEngine &diags,
                 const WriteOptions &options) {
  const unsigned errorsBefore = diags.errorCount();
  if (options.checkReferences)
    checkAnchorReferences(file, diags);
  const NameTable &names = file.names();
  const ValueArena &meta = file.metadata();
  std::string buf;
  buf.reserve(1 << 16);
  auto flush = [&](bool force) {
    if (force || buf.size() >= (1 << 16)) {
      sink(buf);
      buf.clear();
    }
  };

  buf += "ISO-10303-21;\nHEADER;\n";
  for (const HeaderEntity &h : file.header()) {
    appendRecord(buf, h.record, meta, names);
    buf += ";\n";
  }
  buf += "ENDSEC;\n";
  if (!file.anchors().empty()) {
    buf += "ANCHOR;\n";
    for (const Anchor &a : file.anchors()) {
      buf += '<';
      buf += a.name;
      buf += ">=";
      appendValue(buf, a.value, meta, names);
      buf += ";\n";
    }
    buf += "ENDSEC;\n";
  }
  if (!file.references().empty()) {
    buf += "REFERENCE;\n";
    for (const ExternalReference &r : file.references()) {
      buf += '#';
      buf += std::to_string(r.id);
      buf += "=<";
      buf += r.uri;
      buf += ">;\n";
    }
    buf += "ENDSEC;\n";
  }

  ValueArena arena;
  std::vector<uint32_t> order;
  bool ok = true;
  const auto &entries = file.entries();
  for (const DataSection &section : file.sections()) {
    buf += "DATA";
    if (!section.params.empty()) {
      buf.push_back('(');
      for (size_t i = 0; i < section.params.size(); ++i) {
        if (i)
          buf.push_back(',');
        appendValue(buf, section.params[i], meta, names);
      }
      buf.push_back(')');
    }
    buf += ";\n";
    order.resize(section.endEntry - section.firstEntry);
    std::iota(order.begin(), order.end(), section.firstEntry);
    // Writers usually emit ascending ids already; sort only when they did not.
    if (!std::is_sorted(order.begin(), order.end(),
                        [&](uint32_t x, uint32_t y) { return entries[x].id < entries[y].id; }))
      std::stable_sort(order.begin(), order.end(),
                       [&](uint32_t x, uint32_t y) { return entries[x].id < entries[y].id; });
    for (uint32_t i : order) {
      if (!file.decodeInstance(i, arena, &diags)) {
        ok = false;
        continue;
      }
      if (options.checkReferences)
        checkReferences(file, i, arena, diags);
      buf.push_back('#');
      buf += std::to_string(entries[i].id);
      buf.push_back('=');
      const auto records = arena.records();
      if (entries[i].name() == kComplexInstance) {
        buf.push_back('(');
        for (const Record &r : records)
          appendRecord(buf, r, arena, names);
        buf.push_back(')');
      } else {
        appendRecord(buf, records[0], arena, names);
      }
      buf += ";\n";
      flush(false);
    }
    buf += "ENDSEC;\n";
  }
  buf += "END-ISO-10303-21;\n";
  flush(true);
  return ok && diags.errorCount() == errorsBefore;
}

// --- graph comparison ----------------------------------------------------------

namespace {

struct Side {
  const Part21File &file;
  const ValueArena &arena;
  const NameMap *rename = nullptr;  ///< for the record names of one side
};

bool sameValue(const Value &x, const Side &a, const Value &y, const Side &b) {
  if (x.kind != y.kind)
    return false;
  switch (x.kind) {
  case ValueKind::Unset:
  case ValueKind::Derived: return true;
  case ValueKind::Integer: return x.integer == y.integer;
  case ValueKind::Real: return std::memcmp(&x.real, &y.real, sizeof(double)) == 0;
  case ValueKind::Reference: return x.ref == y.ref;
  case ValueKind::String:
  case ValueKind::Enumeration: return x.str() == y.str();
  case ValueKind::Binary: {
    if (x.count != y.count)
      return false;
    for (uint32_t i = 0; i < x.count; ++i)
      if ((x.text[i] | 0x20) != (y.text[i] | 0x20))
        return false;
    return true;
  }
  case ValueKind::Typed:
    if (a.file.names().name(x.node.name) != b.file.names().name(y.node.name))
      return false;
    [[fallthrough]];
  case ValueKind::List: {
    if (x.count != y.count)
      return false;
    auto cx = a.arena.children(x);
    auto cy = b.arena.children(y);
    for (size_t i = 0; i < cx.size(); ++i)
      if (!sameValue(cx[i], a, cy[i], b))
        return false;
    return true;
  }
  }
  return false;
}

bool sameRecord(const Record &x, const Side &a, const Record &y, const Side &b) {
  const std::string_view nameA = a.file.names().name(x.name);
  const bool sameName = a.rename && *a.rename ? (*a.rename)(nameA) == b.file.names().name(y.name)
                                              : nameA == b.file.names().name(y.name);
  if (!sameName || x.count != y.count)
    return false;
  auto px = a.arena.params(x);
  auto py = b.arena.params(y);
  for (size_t i = 0; i < px.size(); ++i)
    if (!sameValue(px[i], a, py[i], b))
      return false;
  return true;
}

std::string recordText(const Record &r, const Side &s) {
  std::string out;
  appendRecord(out, r, s.arena, s.file.names());
  return out;
}

} // namespace

std::string compareGraphs(const Part21File &a, const Part21File &b, const NameMap &renameA) {
  Side ma{a, a.metadata()}, mb{b, b.metadata()};
  if (a.header().size() != b.header().size())
    return "header entity count differs: " + std::to_string(a.header().size()) + " vs " +
           std::to_string(b.header().size());
  for (size_t i = 0; i < a.header().size(); ++i)
    if (!sameRecord(a.header()[i].record, ma, b.header()[i].record, mb))
      return "header entity differs: " + recordText(a.header()[i].record, ma) + " vs " +
             recordText(b.header()[i].record, mb);
  if (a.anchors().size() != b.anchors().size())
    return "anchor count differs";
  for (size_t i = 0; i < a.anchors().size(); ++i)
    if (a.anchors()[i].name != b.anchors()[i].name ||
        !sameValue(a.anchors()[i].value, ma, b.anchors()[i].value, mb))
      return "anchor <" + a.anchors()[i].name + "> differs";
  if (a.references().size() != b.references().size())
    return "REFERENCE entry count differs";
  for (size_t i = 0; i < a.references().size(); ++i)
    if (a.references()[i].id != b.references()[i].id || a.references()[i].uri != b.references()[i].uri)
      return "REFERENCE entry " + hashId(a.references()[i].id) + " differs";
  if (a.sections().size() != b.sections().size())
    return "DATA section count differs";
  for (size_t s = 0; s < a.sections().size(); ++s) {
    const auto &sa = a.sections()[s];
    const auto &sb = b.sections()[s];
    if (sa.params.size() != sb.params.size())
      return "DATA section parameters differ";
    for (size_t i = 0; i < sa.params.size(); ++i)
      if (!sameValue(sa.params[i], ma, sb.params[i], mb))
        return "DATA section parameters differ";
    if (sa.endEntry - sa.firstEntry != sb.endEntry - sb.firstEntry)
      return "DATA section " + std::to_string(s + 1) + " instance count differs: " +
             std::to_string(sa.endEntry - sa.firstEntry) + " vs " +
             std::to_string(sb.endEntry - sb.firstEntry);
  }
  ValueArena arenaA, arenaB;
  for (size_t i = 0; i < a.entries().size(); ++i) {
    const InstanceEntry &ea = a.entries()[i];
    int64_t j = b.indexOf(ea.id);
    const std::string id = hashId(ea.id);
    if (j < 0)
      return id + " is missing from the second graph";
    bool okA = a.decodeInstance(i, arenaA, nullptr);
    bool okB = b.decodeInstance(static_cast<size_t>(j), arenaB, nullptr);
    if (!okA || !okB)
      return id + " does not decode";
    Side sa{a, arenaA, &renameA}, sb{b, arenaB};
    auto ra = arenaA.records();
    auto rb = arenaB.records();
    if (ra.size() != rb.size())
      return id + ": record count differs";
    for (size_t k = 0; k < ra.size(); ++k)
      if (!sameRecord(ra[k], sa, rb[k], sb))
        return id + " differs: " + recordText(ra[k], sa) + " vs " + recordText(rb[k], sb);
  }
  if (a.entries().size() != b.entries().size())
    return "instance count differs: " + std::to_string(a.entries().size()) + " vs " +
           std::to_string(b.entries().size());
  return {};
}

} // namespace stepnc::p21
