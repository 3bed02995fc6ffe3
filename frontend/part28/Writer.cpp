#include "frontend/part28/Writer.h"

#include "frontend/part28/Mapping.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <unordered_map>

namespace stepnc::p28 {

using express::TypeId;
using p21::Value;
using p21::ValueKind;

namespace {

/// A FILE_NAME or FILE_DESCRIPTION parameter the header elements can carry:
/// a string, or a list of strings.
bool isString(const Value &v) { return v.kind == ValueKind::String; }
bool isStringList(const Value &v, const p21::ValueArena &arena) {
  if (v.kind != ValueKind::List)
    return false;
  for (const Value &c : arena.children(v))
    if (!isString(c))
      return false;
  return true;
}

class Writer {
public:
  Writer(const binding::BoundFile &bound, const p21::ByteSink &sink, DiagnosticEngine &diags)
      : bound_(bound), file_(bound.file()), model_(bound.model()), sink_(sink), diags_(diags) {}

  bool run();

private:
  void flush(bool force);
  void header();
  void processingInstruction(std::string_view target, std::string_view text);
  void section(const p21::DataSection &section, size_t number, const std::string &express);
  void instance(size_t index);
  void record(const express::Entity &entity, std::span<const uint32_t> slots, const std::vector<std::string> &names,
              std::span<const Value> values, int indent);
  const std::vector<std::string> &elementNames(express::EntityId entity);
  void attribute(const express::Slot &slot, const std::string &element, const Value &v, int indent);
  void content(TypeId declared, const Value &v);
  void member(TypeId elementType, const Value &v);
  void reference(const Value &v);
  void typedValue(const Value &v);
  void text(std::string_view s);
  void scalar(const TypeView &view, const Value &v);
  std::string elementOf(p21::InstanceId id);
  void fail(const std::string &message);

  const binding::BoundFile &bound_;
  const p21::Part21File &file_;
  const express::Model &model_;
  const p21::ByteSink &sink_;
  DiagnosticEngine &diags_;
  std::string buf_;
  p21::ValueArena arena_;
  size_t current_ = 0; ///< entry being written, for diagnostics
  bool ok_ = true;
  /// attributeElementNames of each entity written, made once.
  std::unordered_map<express::EntityId, std::vector<std::string>> elementNames_;
  std::vector<uint32_t> allSlots_; ///< 0, 1, 2, ...: every slot of an entity
  /// Names written differently from the file (aliases): name -> (first entry, count).
  std::map<std::string, std::pair<size_t, size_t>, std::less<>> renamed_;
};

void Writer::flush(bool force) {
  if (force || buf_.size() >= (1 << 16)) {
    sink_(buf_);
    buf_.clear();
  }
}

void Writer::fail(const std::string &message) {
  ok_ = false;
  const p21::InstanceEntry &e = file_.entries()[current_];
  diags_.error(file_.loc(e.begin()), "cannot write as Part 28: " + message)
      .entity(e.id, std::string(file_.entityName(e)));
}

void Writer::text(std::string_view s) {
  if (!appendEscaped(buf_, s))
    fail("the string '" + std::string(s) + "' holds a control character XML 1.0 cannot carry");
}

void Writer::processingInstruction(std::string_view target, std::string_view text) {
  if (text.find("?>") != std::string_view::npos) {
    ok_ = false;
    diags_.error(file_.loc(0), "cannot write as Part 28: the Part 21 text '" + std::string(text) +
                                   "' holds '?>', which would end its processing instruction");
    return;
  }
  buf_ += "  <?";
  buf_ += target;
  buf_ += ' ';
  buf_ += text;
  buf_ += "?>\n";
}

void Writer::header() {
  const p21::ValueArena &meta = file_.metadata();
  const p21::NameTable &names = file_.names();
  const p21::HeaderEntity *description = file_.headerEntity("FILE_DESCRIPTION");
  const p21::HeaderEntity *name = file_.headerEntity("FILE_NAME");
  auto params = [&](const p21::HeaderEntity *h) { return meta.params(h->record); };
  const bool descriptionFits = description && params(description).size() == 2 &&
                               isStringList(params(description)[0], meta) && isString(params(description)[1]);
  bool nameFits = name && params(name).size() == 7;
  if (nameFits)
    for (size_t i = 0; i < 7; ++i)
      nameFits &= (i == 2 || i == 3) ? isStringList(params(name)[i], meta) : isString(params(name)[i]);

  buf_ += "  <exp:iso_10303_28_header>\n";
  auto field = [&](std::string_view tag, const Value &v) {
    buf_ += "    <exp:";
    buf_ += tag;
    buf_ += '>';
    text(v.str());
    buf_ += "</exp:";
    buf_ += tag;
    buf_ += ">\n";
  };
  if (nameFits) {
    static const char *const tags[7] = {
        "name", "time_stamp", "author", "organization", "preprocessor_version", "originating_system", "authorization"};
    for (size_t i = 0; i < 7; ++i) {
      const Value &v = params(name)[i];
      if (v.kind == ValueKind::List) {
        for (const Value &c : meta.children(v))
          field(tags[i], c);
      } else {
        field(tags[i], v);
      }
    }
  }
  if (descriptionFits)
    for (const Value &c : meta.children(params(description)[0]))
      field("documentation", c);
  buf_ += "  </exp:iso_10303_28_header>\n";

  // What the header elements cannot say, as Part 21 text.
  if (descriptionFits && params(description)[1].str() != "2;1")
    processingInstruction("stepnc-p21", "implementation_level=\"" + std::string(params(description)[1].str()) + "\"");
  for (const p21::HeaderEntity &h : file_.header()) {
    const std::string_view entity = names.name(h.record.name);
    if (entity == "FILE_SCHEMA" || (entity == "FILE_NAME" && &h == name && nameFits) ||
        (entity == "FILE_DESCRIPTION" && &h == description && descriptionFits))
      continue;
    std::string record;
    p21::appendRecord(record, h.record, meta, names);
    processingInstruction("stepnc-p21-header", record + ";");
  }
  for (const p21::Anchor &a : file_.anchors()) {
    std::string line = "<" + a.name + ">=";
    p21::appendValue(line, a.value, meta, names);
    processingInstruction("stepnc-p21-anchor", line + ";");
  }
  for (const p21::ExternalReference &r : file_.references()) {
    std::string line = "#";
    line += std::to_string(r.id);
    line += "=<";
    line += r.uri;
    line += ">;";
    processingInstruction("stepnc-p21-reference", line);
  }
}

std::string Writer::elementOf(p21::InstanceId id) {
  const int64_t index = file_.indexOf(id);
  if (index < 0) {
    fail("reference to #" + std::to_string(id) + ", which is not defined");
    return "Undefined";
  }
  const p21::InstanceEntry &e = file_.entries()[static_cast<size_t>(index)];
  if (e.name() != p21::kComplexInstance) {
    const express::EntityId entity = bound_.entity(static_cast<size_t>(index));
    if (entity == express::kNone) {
      fail("reference to #" + std::to_string(id) + " " + std::string(file_.entityName(e)) +
           ", which is not an entity of schema '" + bound_.schema().name + "'");
      return "Undefined";
    }
    return xmlName(model_.entity(entity).name);
  }
  std::string joined = file_.describe(e); // the records' names in Part 21 order, "A+B"
  std::replace(joined.begin(), joined.end(), '+', '-');
  return xmlName(joined);
}

void Writer::reference(const Value &v) {
  buf_ += '<';
  buf_ += elementOf(v.ref);
  buf_ += " ref=\"i";
  buf_ += std::to_string(v.ref);
  buf_ += "\" xsi:nil=\"true\"/>";
}

// A SELECT value: a reference, or a typed value `TYPE(x)` written as the
// element of its type.
void Writer::typedValue(const Value &v) {
  if (v.kind == ValueKind::Reference) {
    reference(v);
    return;
  }
  if (v.kind != ValueKind::Typed || v.count != 1) {
    fail(std::string("a SELECT value must be a reference or a typed value, not ") + p21::valueKindName(v.kind));
    return;
  }
  const std::string typeName = express::lower(file_.names().name(v.node.name));
  const express::DeclTypeId decl = model_.findType(bound_.schema(), typeName);
  if (decl == express::kNone) {
    fail("'" + typeName + "' is not a type of schema '" + bound_.schema().name + "'");
    return;
  }
  const std::string element = xmlName(typeName);
  buf_ += '<';
  buf_ += element;
  buf_ += '>';
  content(model_.typeDecl(decl).underlying, arena_.children(v)[0]);
  buf_ += "</";
  buf_ += element;
  buf_ += '>';
}

void Writer::scalar(const TypeView &view, const Value &v) {
  switch (v.kind) {
  case ValueKind::Integer:
    // An integer where a REAL is declared is read as a real (the binder
    // warns); xs:double text cannot keep it an integer, so it is written as one.
    if (view.kind == TypeView::Simple && view.simple == express::SimpleKind::Real)
      p21::appendReal(buf_, static_cast<double>(v.integer));
    else
      buf_ += std::to_string(v.integer);
    return;
  case ValueKind::Real:
    p21::appendReal(buf_, v.real);
    return;
  case ValueKind::String:
    text(v.str());
    return;
  case ValueKind::Binary:
    buf_ += v.str();
    return;
  case ValueKind::Enumeration: {
    const std::string e = express::lower(v.str());
    if (view.kind == TypeView::Simple &&
        (view.simple == express::SimpleKind::Boolean || view.simple == express::SimpleKind::Logical))
      buf_ += e == "t" ? "true" : e == "f" ? "false" : e == "u" ? "unknown" : e;
    else
      buf_ += e;
    return;
  }
  default:
    fail(std::string("a ") + p21::valueKindName(v.kind) + " where a simple value is expected");
  }
}

void Writer::content(TypeId declared, const Value &v) {
  const TypeView view = viewType(model_, declared);
  switch (view.kind) {
  case TypeView::Entity:
    if (v.kind != ValueKind::Reference)
      fail(std::string("a ") + p21::valueKindName(v.kind) + " where a reference is expected");
    else
      reference(v);
    return;
  case TypeView::Select:
    typedValue(v);
    return;
  case TypeView::Aggregate: {
    if (v.kind != ValueKind::List) {
      fail(std::string("a ") + p21::valueKindName(v.kind) + " where an aggregate is expected");
      return;
    }
    const TypeId element = model_.type(view.aggregate).element;
    for (const Value &c : arena_.children(v))
      member(element, c);
    return;
  }
  case TypeView::Simple:
  case TypeView::Enumeration:
    scalar(view, v);
    return;
  case TypeView::Unknown:
    fail("an attribute of a type the mapping does not know");
    return;
  }
}

void Writer::member(TypeId elementType, const Value &v) {
  const TypeView view = viewType(model_, elementType);
  if (v.kind == ValueKind::Unset) {
    fail("'$' inside an aggregate cannot be written in Part 28");
    return;
  }
  switch (view.kind) {
  case TypeView::Entity:
    content(elementType, v);
    return;
  case TypeView::Select:
    typedValue(v);
    return;
  case TypeView::Aggregate:
  case TypeView::Simple:
  case TypeView::Enumeration:
    break;
  case TypeView::Unknown:
    fail("an aggregate member of a type the mapping does not know");
    return;
  }
  const std::string element = memberElement(model_, view);
  buf_ += '<';
  buf_ += element;
  buf_ += '>';
  content(elementType, v);
  buf_ += "</";
  buf_ += element;
  buf_ += '>';
}

void Writer::attribute(const express::Slot &slot, const std::string &element, const Value &v, int indent) {
  if (v.kind == ValueKind::Unset || v.kind == ValueKind::Derived)
    return;
  buf_.append(static_cast<size_t>(indent), ' ');
  buf_ += '<';
  buf_ += element;
  const TypeView view = viewType(model_, slot.type);
  if (view.kind == TypeView::Aggregate) {
    buf_ += " exp:cType=\"";
    buf_ += express::lower(express::aggregateKindName(model_.type(view.aggregate).aggregate));
    buf_ += '"';
  }
  buf_ += '>';
  content(slot.type, v);
  buf_ += "</";
  buf_ += element;
  buf_ += ">\n";
}

const std::vector<std::string> &Writer::elementNames(express::EntityId entity) {
  auto [it, added] = elementNames_.try_emplace(entity);
  if (added)
    it->second = attributeElementNames(model_, entity);
  return it->second;
}

void Writer::record(const express::Entity &entity, std::span<const uint32_t> slots,
                    const std::vector<std::string> &names, std::span<const Value> values, int indent) {
  if (values.size() != slots.size()) {
    fail(std::to_string(values.size()) + " values where " + entity.name + " has " + std::to_string(slots.size()) +
         " attributes");
    return;
  }
  for (size_t i = 0; i < slots.size(); ++i)
    attribute(entity.slots[slots[i]], names[slots[i]], values[i], indent);
}

void Writer::instance(size_t index) {
  current_ = index;
  const p21::InstanceEntry &e = file_.entries()[index];
  if (!file_.decodeInstance(index, arena_, &diags_)) {
    ok_ = false;
    return;
  }
  if (e.name() != p21::kComplexInstance && bound_.entity(index) == express::kNone) {
    fail("'" + std::string(file_.entityName(e)) + "' is not an entity of schema '" + bound_.schema().name + "'");
    return;
  }
  const std::string element = elementOf(e.id);
  if (!ok_)
    return;
  if (e.name() != p21::kComplexInstance && express::lower(file_.entityName(e)) != express::lower(element)) {
    auto [it, added] = renamed_.try_emplace(std::string(file_.entityName(e)), index, 0);
    ++it->second.second;
  }
  buf_ += "    <";
  buf_ += element;
  buf_ += " id=\"i";
  buf_ += std::to_string(e.id);
  buf_ += "\">\n";
  const size_t contentStart = buf_.size();
  const auto records = arena_.records();
  if (e.name() != p21::kComplexInstance) {
    const express::EntityId id = bound_.entity(index);
    const express::Entity &entity = model_.entity(id);
    while (allSlots_.size() < entity.slots.size())
      allSlots_.push_back(static_cast<uint32_t>(allSlots_.size()));
    record(entity, std::span(allSlots_).first(entity.slots.size()), elementNames(id), arena_.params(records[0]), 6);
  } else {
    for (const p21::Record &r : records) {
      const express::EntityId id = model_.findEntity(bound_.schema(), express::lower(file_.names().name(r.name)));
      if (id == express::kNone) {
        fail("'" + std::string(file_.names().name(r.name)) + "' is not an entity of schema '" + bound_.schema().name +
             "'");
        return;
      }
      std::vector<std::string> names;
      for (const express::Slot &slot : model_.entity(id).slots)
        names.push_back(xmlName(slot.name));
      record(model_.entity(id), model_.entity(id).ownSlots, names, arena_.params(r), 6);
    }
  }
  if (buf_.size() == contentStart) { // no attribute written: an empty element
    buf_.replace(contentStart - 2, 2, "/>\n");
    return;
  }
  buf_ += "    </";
  buf_ += element;
  buf_ += ">\n";
}

void Writer::section(const p21::DataSection &section, size_t number, const std::string &express) {
  buf_ += "  <uos xmlns=\"" + schemaNamespace(bound_.schema().name) + "\" id=\"uos_" + std::to_string(number) +
          "\" express=\"";
  text(express);
  buf_ += "\" configuration=\"default\">\n";
  if (!section.params.empty()) {
    std::string params = "(";
    for (size_t i = 0; i < section.params.size(); ++i) {
      if (i)
        params += ',';
      p21::appendValue(params, section.params[i], file_.metadata(), file_.names());
    }
    buf_ += "  ";
    processingInstruction("stepnc-p21-data", params + ")");
  }
  const auto &entries = file_.entries();
  std::vector<uint32_t> order(section.endEntry - section.firstEntry);
  std::iota(order.begin(), order.end(), section.firstEntry);
  std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return entries[x].id < entries[y].id; });
  for (uint32_t index : order) {
    instance(index);
    flush(false);
  }
  buf_ += "  </uos>\n";
}

bool Writer::run() {
  buf_ += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  buf_ += "<exp:iso_10303_28 xmlns:exp=\"" + std::string(kCommonNamespace) + "\" xmlns:xsi=\"" +
          std::string(kXsiNamespace) + "\" version=\"2.0\">\n";
  header();
  std::string express;
  for (const std::string &s : file_.schemaNames())
    express += (express.empty() ? "" : " ") + s;
  size_t number = 1;
  for (const p21::DataSection &s : file_.sections())
    section(s, number++, express);
  buf_ += "</exp:iso_10303_28>\n";
  flush(true);
  for (const auto &[name, where] : renamed_) {
    const p21::InstanceEntry &e = file_.entries()[where.first];
    diags_.warning(file_.loc(e.begin()), "'" + name + "' is not an entity of schema '" + bound_.schema().name +
                                             "'; written as '" + model_.entity(bound_.entity(where.first)).name +
                                             "', the entity it stands for (" + std::to_string(where.second) +
                                             (where.second == 1 ? " instance)" : " instances)"));
  }
  return ok_;
}

} // namespace

bool writePart28(const binding::BoundFile &bound, const p21::ByteSink &sink, DiagnosticEngine &diags) {
  const unsigned before = diags.errorCount();
  Writer writer(bound, sink, diags);
  return writer.run() && diags.errorCount() == before;
}

std::string writePart28ToString(const binding::BoundFile &bound, DiagnosticEngine &diags, bool *ok) {
  std::string xml;
  const bool done = writePart28(
      bound, [&xml](std::string_view chunk) { xml += chunk; }, diags);
  if (ok)
    *ok = done;
  return xml;
}

} // namespace stepnc::p28
