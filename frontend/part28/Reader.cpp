#include "frontend/part28/Reader.h"

#include "frontend/part21/Writer.h"
#include "frontend/part28/Mapping.h"

#include <libxml/parser.h>
#include <libxml/xmlerror.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <unordered_map>

namespace stepnc::p28 {

using express::EntityId;
using express::kNone;
using express::TypeId;
using express::upper;

bool isXml(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF"))
    text.remove_prefix(3);
  while (!text.empty() && (text[0] == ' ' || text[0] == '\t' || text[0] == '\r' || text[0] == '\n'))
    text.remove_prefix(1);
  return text.starts_with("<");
}

namespace {

/// Part 21 text with the XML offsets its pieces came from.
struct Piece {
  std::string text;
  std::vector<std::pair<uint64_t, uint64_t>> marks; ///< offset in text -> XML offset

  /// Appends `p`; its marks too unless `withMarks` is false (members of an
  /// aggregate of numbers or strings are located by their aggregate's mark).
  void append(const Piece &p, bool withMarks = true) {
    if (withMarks)
      for (const auto &[at, xml] : p.marks)
        marks.emplace_back(text.size() + at, xml);
    text += p.text;
  }
  void mark(uint64_t xml) { marks.emplace_back(text.size(), xml); }
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\n' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\n' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

bool isBlank(std::string_view s) { return trim(s).empty(); }

std::vector<std::string_view> splitWhitespace(std::string_view s) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r'))
      ++i;
    size_t j = i;
    while (j < s.size() && !(s[j] == ' ' || s[j] == '\t' || s[j] == '\n' || s[j] == '\r'))
      ++j;
    if (j > i)
      out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

bool sameName(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return (x >= 'A' && x <= 'Z' ? x + 32 : x) == (y >= 'A' && y <= 'Z' ? y + 32 : y);
         });
}

bool isIntegerText(std::string_view s) {
  if (!s.empty() && (s[0] == '+' || s[0] == '-'))
    s.remove_prefix(1);
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// One open XML element.
struct Frame {
  enum Kind : uint8_t { Root, Header, HeaderField, Uos, Instance, Attribute, Value, Skipped };
  Kind kind = Skipped;
  std::string name; ///< local name
  uint64_t at = 0;  ///< XML offset of its '<'
  // Attribute and Value frames: the declared type of what they hold.
  TypeId type = kNone;
  std::string typedName; ///< Value frames inside a SELECT: `TYPE(x)`
  std::string text;
  std::vector<Piece> children;
  bool broken = false; ///< a child was rejected: no value is made (its error says why)
  uint32_t slot = 0;   ///< Attribute: slot index in its instance
  size_t instance = 0; ///< Instance and Attribute: index into the instance stack
};

/// The slots of an instance of one entity, or of one combination of records
/// (a complex instance), with their element names: the same for every
/// instance of it, so made once per document.
struct Layout {
  std::vector<std::pair<EntityId, uint32_t>> slots; ///< (record entity, slot index in that entity)
  std::vector<std::string> elements;                ///< each slot's element name
};

/// An instance being read: its entity records and the values of its slots.
struct Building {
  p21::InstanceId id = 0;
  std::vector<EntityId> records; ///< one entity, or the records of a complex instance
  const Layout *layout = nullptr;
  std::vector<std::optional<Piece>> values;
  bool isReference = false;
  uint64_t at = 0;
};

class Translator {
public:
  Translator(const SourceFile &xml, const SchemaChooser &choose, DiagnosticEngine &diags)
      : xml_(xml), choose_(choose), diags_(diags) {}

  bool run();
  std::string takeText(std::vector<std::pair<uint64_t, uint64_t>> &map);

  // SAX callbacks.
  void startElement(const xmlChar *local, const xmlChar *uri, int nbAttributes, const xmlChar **attributes);
  void endElement();
  void characters(const xmlChar *ch, int len);
  void processingInstruction(const xmlChar *target, const xmlChar *data);
  void reportXmlError(const ::xmlError *error);
  void doctype();

private:
  /// Offset of the markup the parser has just read: a tag ("<") or a
  /// processing instruction ("<?").
  uint64_t markupStart(std::string_view opener) const;
  SourceLoc loc(uint64_t offset) const { return {&xml_, offset}; }
  InFlightDiagnostic error(uint64_t at, const std::string &message);
  bool chooseSchema(const std::string &express, uint64_t at);
  bool isCommon(std::string_view local, const xmlChar *uri) const;

  void openInstance(Frame &frame, std::string_view local, int nbAttributes, const xmlChar **attributes);
  void openChildValue(Frame &frame, const Frame &parent, std::string_view local, const xmlChar *uri);
  void openAttribute(Frame &frame, Frame &parent, std::string_view local);
  bool entityRecords(std::string_view local, std::vector<EntityId> &records) const;
  const Layout &layoutOf(const std::vector<EntityId> &records);
  std::string expectation(TypeId declared) const;
  int findSlot(const Building &b, std::string_view local) const;
  void setSlot(size_t instance, int slot, Piece value, uint64_t at);

  std::optional<Piece> valueOf(const Frame &f);
  std::optional<Piece> scalar(TypeId type, std::string_view text, uint64_t at);
  std::optional<Piece> fromText(TypeId type, std::string_view text, uint64_t at);
  std::optional<p21::InstanceId> idOf(std::string_view text, uint64_t at);
  p21::InstanceId freshId();
  void closeInstance();
  void writeHeader();
  void beginData(uint64_t at);
  void openSection();
  void endData();
  void headerText();

  const SourceFile &xml_;
  const SchemaChooser &choose_;
  DiagnosticEngine &diags_;
  xmlParserCtxtPtr ctxt_ = nullptr;
  const express::Model *model_ = nullptr;
  const express::Schema *schema_ = nullptr;
  bool failed_ = false;
  bool schemaRefused_ = false;
  bool sawXmlError_ = false;

  std::vector<Frame> frames_;
  std::vector<Building> instances_;
  std::map<std::vector<EntityId>, Layout> layouts_;

  // Header.
  std::vector<std::pair<std::string, std::string>> headerFields_;
  std::string level_ = "2;1";
  std::vector<std::string> schemaNames_;
  Piece extraHeader_; ///< header entities from processing instructions
  std::vector<std::string> extraHeaderNames_;
  Piece anchors_, references_;
  uint64_t headerAt_ = 0;
  bool headerDone_ = false; ///< the header is in out_: what changes it must come earlier

  // The Part 21 text: header, then each DATA section as its instances close.
  Piece out_;
  std::string sectionParams_;
  bool inSection_ = false;
  bool sectionOpened_ = false; ///< its DATA line is written
  uint64_t sectionAt_ = 0;

  // Ids.
  std::unordered_map<std::string, p21::InstanceId> named_;
  p21::InstanceId nextFresh_ = 0;
};

InFlightDiagnostic Translator::error(uint64_t at, const std::string &message) {
  failed_ = true;
  InFlightDiagnostic d = diags_.error(loc(at), message);
  // Inside an instance, name it (the innermost, for an inline one).
  if (!instances_.empty() && instances_.back().id != 0)
    d.entity(instances_.back().id, upper(model_->entity(instances_.back().records.back()).name));
  return d;
}

uint64_t Translator::markupStart(std::string_view opener) const {
  // The parser has just read past the markup; it begins at the last opener
  // before that point (attribute values and PI text cannot hold '<').
  const long consumed = xmlByteConsumed(ctxt_);
  const std::string_view text = xml_.text();
  const uint64_t end = consumed > 0 ? std::min<uint64_t>(static_cast<uint64_t>(consumed), text.size()) : 0;
  const size_t at = text.substr(0, end).rfind(opener);
  return at == std::string_view::npos ? 0 : at;
}

bool Translator::isCommon(std::string_view local, const xmlChar *uri) const {
  if (uri && std::string_view(reinterpret_cast<const char *>(uri)) == kCommonNamespace)
    return true;
  // Documents without namespaces: a common name that is not the schema's.
  return !uri && model_ && model_->findEntity(*schema_, express::lower(local)) == kNone &&
         model_->findType(*schema_, express::lower(local)) == kNone;
}

bool Translator::chooseSchema(const std::string &express, uint64_t at) {
  if (schema_)
    return true;
  if (schemaRefused_)
    return false;
  for (std::string_view n : splitWhitespace(express))
    schemaNames_.emplace_back(n);
  schema_ = choose_(schemaNames_, model_);
  if (!schema_) {
    schemaRefused_ = true;
    std::string listed;
    for (const std::string &n : schemaNames_)
      listed += (listed.empty() ? "" : ", ") + n;
    error(at, (schemaNames_.empty() ? std::string("the document names no schema")
                                    : "schema " + listed + " is not built in") +
                  "; Part 28 is read through its schema: give its EXPRESS file with --schema FILE.exp");
    return false;
  }
  return true;
}

bool Translator::entityRecords(std::string_view local, std::vector<EntityId> &records) const {
  records.clear();
  size_t start = 0;
  while (start <= local.size()) {
    size_t dash = local.find('-', start);
    if (dash == std::string_view::npos)
      dash = local.size();
    const EntityId e = model_->findEntity(*schema_, express::lower(local.substr(start, dash - start)));
    if (e == kNone)
      return false;
    records.push_back(e);
    start = dash + 1;
  }
  return !records.empty();
}

const Layout &Translator::layoutOf(const std::vector<EntityId> &records) {
  auto [it, added] = layouts_.try_emplace(records);
  Layout &layout = it->second;
  if (!added)
    return layout;
  for (EntityId e : records) {
    const express::Entity &entity = model_->entity(e);
    if (records.size() == 1) {
      layout.elements = attributeElementNames(*model_, e);
      for (uint32_t s = 0; s < entity.slots.size(); ++s)
        layout.slots.emplace_back(e, s);
    } else {
      for (uint32_t s : entity.ownSlots) {
        layout.slots.emplace_back(e, s);
        layout.elements.push_back(xmlName(entity.slots[s].name));
      }
    }
  }
  return layout;
}

p21::InstanceId Translator::freshId() {
  if (nextFresh_ == 0) {
    // Ids that are not numbers get numbers above every numeric id in the
    // document: find the largest once, with a scan of the raw text (an
    // overestimate from text that only looks like an id does no harm).
    const std::string_view text = xml_.text();
    p21::InstanceId largest = 0;
    for (size_t p = text.find("id=\""); p != std::string_view::npos; p = text.find("id=\"", p + 4)) {
      size_t q = p + 4;
      if (q < text.size() && (text[q] == 'i' || text[q] == '#'))
        ++q;
      p21::InstanceId v = 0;
      auto r = std::from_chars(text.data() + q, text.data() + text.size(), v);
      if (r.ec == std::errc() && *r.ptr == '"')
        largest = std::max(largest, v);
    }
    nextFresh_ = largest + 1;
  }
  return nextFresh_++;
}

std::optional<p21::InstanceId> Translator::idOf(std::string_view text, uint64_t at) {
  text = trim(text);
  std::string_view digits = text;
  if (!digits.empty() && (digits[0] == 'i' || digits[0] == '#'))
    digits.remove_prefix(1);
  p21::InstanceId v = 0;
  auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (!digits.empty() && r.ec == std::errc() && r.ptr == digits.data() + digits.size() && v > 0)
    return v;
  if (text.empty()) {
    error(at, "empty instance id");
    return std::nullopt;
  }
  auto [it, added] = named_.try_emplace(std::string(text), 0);
  if (added)
    it->second = freshId();
  return it->second;
}

void Translator::doctype() {
  error(markupStart("<"), "a document type declaration (<!DOCTYPE>) is not read in Part 28 documents");
  xmlStopParser(ctxt_);
}

void Translator::reportXmlError(const ::xmlError *e) {
  if (!e || e->level == XML_ERR_NONE)
    return;
  std::string message = e->message ? e->message : "XML error";
  while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
    message.pop_back();
  const uint64_t at =
      xml_.offsetOf({static_cast<uint32_t>(std::max(e->line, 0)), static_cast<uint32_t>(std::max(e->int2, 0))});
  // The push parser calls an unfinished document "extra content at the end";
  // run() reports which element was left open instead.
  if (e->code == XML_ERR_DOCUMENT_END && !frames_.empty()) {
    failed_ = true;
    return;
  }
  if (e->level == XML_ERR_WARNING) {
    diags_.warning(loc(at), "XML: " + message);
    return;
  }
  sawXmlError_ = true;
  error(at, "XML: " + message);
}

void Translator::startElement(const xmlChar *localName, const xmlChar *uri, int nbAttributes,
                              const xmlChar **attributes) {
  const std::string_view local(reinterpret_cast<const char *>(localName));
  Frame frame;
  frame.name = std::string(local);
  frame.at = markupStart("<");
  auto attribute = [&](std::string_view name) -> std::optional<std::string> {
    for (int i = 0; i < nbAttributes; ++i) {
      const xmlChar **a = attributes + 5 * i;
      if (std::string_view(reinterpret_cast<const char *>(a[0])) == name)
        return std::string(reinterpret_cast<const char *>(a[3]), static_cast<size_t>(a[4] - a[3]));
    }
    return std::nullopt;
  };

  if (frames_.empty()) {
    if (local != "iso_10303_28" && local != "iso_10303_28_terse") {
      error(frame.at, "not a Part 28 document: the root element is <" + frame.name +
                          ">, not <iso_10303_28> or <iso_10303_28_terse>");
      xmlStopParser(ctxt_);
      return;
    }
    frame.kind = Frame::Root;
    if (auto express = attribute("express"))
      chooseSchema(*express, frame.at);
    frames_.push_back(std::move(frame));
    return;
  }

  Frame &parent = frames_.back();
  switch (parent.kind) {
  case Frame::Skipped:
  case Frame::HeaderField:
    frame.kind = Frame::Skipped;
    break;
  case Frame::Header:
    frame.kind = Frame::HeaderField;
    if (headerAt_ == 0)
      headerAt_ = parent.at;
    break;
  case Frame::Root:
    if (local == "iso_10303_28_header") {
      frame.kind = Frame::Header;
      headerAt_ = frame.at;
      break;
    }
    if (local == "uos") {
      frame.kind = Frame::Uos;
      if (!chooseSchema(attribute("express").value_or(""), frame.at)) {
        frame.kind = Frame::Skipped;
        break;
      }
      beginData(frame.at);
      break;
    }
    // The terse form: entities straight under the root.
    if (!chooseSchema("", frame.at)) {
      frame.kind = Frame::Skipped;
      break;
    }
    if (!inSection_)
      beginData(frame.at);
    [[fallthrough]];
  case Frame::Uos:
    openInstance(frame, local, nbAttributes, attributes);
    break;
  case Frame::Instance:
    openAttribute(frame, parent, local);
    break;
  case Frame::Attribute:
  case Frame::Value:
    openChildValue(frame, parent, local, uri);
    if (frame.kind == Frame::Instance)
      openInstance(frame, local, nbAttributes, attributes);
    parent.broken |= frame.kind == Frame::Skipped;
    break;
  }
  frames_.push_back(std::move(frame));
}

void Translator::openInstance(Frame &frame, std::string_view local, int nbAttributes, const xmlChar **attributes) {
  Building b;
  b.at = frame.at;
  if (!entityRecords(local, b.records)) {
    InFlightDiagnostic d =
        error(frame.at, "<" + std::string(local) + "> is not an entity of schema '" + schema_->name + "'");
    for (int i = 0; i < nbAttributes; ++i) {
      const xmlChar **a = attributes + 5 * i;
      if (!a[1] && std::string_view(reinterpret_cast<const char *>(a[0])) == "id")
        if (auto id =
                idOf(std::string(reinterpret_cast<const char *>(a[3]), static_cast<size_t>(a[4] - a[3])), frame.at))
          d.entity(*id, upper(local));
    }
    frame.kind = Frame::Skipped;
    return;
  }
  b.layout = &layoutOf(b.records);
  b.values.resize(b.layout->slots.size());
  std::optional<std::string> id, ref;
  std::vector<std::pair<std::string, std::string>> terse;
  for (int i = 0; i < nbAttributes; ++i) {
    const xmlChar **a = attributes + 5 * i;
    const std::string name(reinterpret_cast<const char *>(a[0]));
    std::string value(reinterpret_cast<const char *>(a[3]), static_cast<size_t>(a[4] - a[3]));
    const bool qualified = a[1] != nullptr; // xsi:nil, exp:...
    if (name == "id" && !qualified)
      id = std::move(value);
    else if (name == "ref" && !qualified)
      ref = std::move(value);
    else if (!qualified)
      terse.emplace_back(name, std::move(value));
  }
  if (ref) {
    auto target = idOf(*ref, frame.at);
    if (!target) {
      frame.kind = Frame::Skipped;
      return;
    }
    b.id = *target;
    b.isReference = true;
  } else if (id) {
    auto own = idOf(*id, frame.at);
    if (!own) {
      frame.kind = Frame::Skipped;
      return;
    }
    b.id = *own;
  } else {
    b.id = freshId();
  }
  frame.kind = Frame::Instance;
  frame.instance = instances_.size();
  instances_.push_back(std::move(b));
  for (const auto &[name, value] : terse) {
    const int slot = findSlot(instances_.back(), name);
    if (slot < 0) {
      error(frame.at, "<" + std::string(local) + "> has no attribute '" + express::lower(name) + "'");
      continue;
    }
    const auto &[entity, index] = instances_.back().layout->slots[static_cast<size_t>(slot)];
    if (auto v = fromText(model_->entity(entity).slots[index].type, value, frame.at))
      setSlot(frame.instance, slot, std::move(*v), frame.at);
  }
}

int Translator::findSlot(const Building &b, std::string_view local) const {
  for (size_t i = 0; i < b.layout->slots.size(); ++i)
    if (sameName(b.layout->elements[i], local))
      return static_cast<int>(i);
  return -1;
}

void Translator::setSlot(size_t instance, int slot, Piece value, uint64_t at) {
  Building &b = instances_[instance];
  auto &target = b.values[static_cast<size_t>(slot)];
  if (target) {
    const auto &[entity, index] = b.layout->slots[static_cast<size_t>(slot)];
    error(at,
          "#" + std::to_string(b.id) + ": attribute '" + model_->entity(entity).slots[index].name + "' is given twice");
    return;
  }
  target = std::move(value);
}

void Translator::openAttribute(Frame &frame, Frame &parent, std::string_view local) {
  Building &b = instances_[parent.instance];
  if (b.isReference) {
    error(frame.at, "a reference (an element with 'ref') has no attributes; <" + frame.name + "> is not read");
    frame.kind = Frame::Skipped;
    return;
  }
  const int slot = findSlot(b, local);
  if (slot < 0) {
    std::string names;
    const Layout &layout = *b.layout;
    for (size_t i = 0; i < layout.slots.size(); ++i)
      if (!model_->entity(layout.slots[i].first).slots[layout.slots[i].second].derived)
        names += (names.empty() ? "" : ", ") + layout.elements[i];
    error(frame.at, "<" + std::string(local) + "> is not an attribute of " + model_->entity(b.records.back()).name)
        .note(names.empty() ? "it has no attributes" : "its attributes are " + names);
    frame.kind = Frame::Skipped;
    return;
  }
  const auto &[entity, index] = b.layout->slots[static_cast<size_t>(slot)];
  frame.kind = Frame::Attribute;
  frame.type = model_->entity(entity).slots[index].type;
  frame.slot = static_cast<uint32_t>(slot);
  frame.instance = parent.instance;
}

void Translator::openChildValue(Frame &frame, const Frame &parent, std::string_view local, const xmlChar *uri) {
  const TypeView outer = viewType(*model_, parent.type);
  // The type of the value this element holds: the parent's own type for a
  // single value, its element type for an aggregate member.
  const TypeId declared = outer.kind == TypeView::Aggregate ? model_->type(outer.aggregate).element : parent.type;
  const TypeView view = viewType(*model_, declared);
  const std::string lowered = express::lower(local);
  auto reject = [&](const std::string &expected) {
    error(frame.at, "<" + frame.name + "> is not expected here: " + expected);
    frame.kind = Frame::Skipped;
  };

  if (isCommon(local, uri)) {
    const bool aggregateElement = lowered == "list" || lowered == "set" || lowered == "bag" || lowered == "array";
    if (outer.kind != TypeView::Aggregate)
      return reject("a single value is written as text or as one element naming its type or entity");
    if (aggregateElement != (view.kind == TypeView::Aggregate) ||
        (view.kind == TypeView::Simple && simpleMemberName(view.simple) != lowered))
      return reject("the members here are " + model_->typeText(declared));
    frame.kind = Frame::Value;
    frame.type = declared;
    return;
  }
  std::vector<EntityId> records;
  if ((view.kind == TypeView::Entity || view.kind == TypeView::Select) && entityRecords(local, records)) {
    frame.kind = Frame::Instance; // the caller reads it with openInstance
    return;
  }
  const express::DeclTypeId decl = model_->findType(*schema_, lowered);
  if (decl != kNone && view.kind == TypeView::Select) {
    frame.kind = Frame::Value;
    frame.type = model_->typeDecl(decl).underlying;
    frame.typedName = upper(lowered);
    return;
  }
  if (decl != kNone && decl == view.decl && outer.kind == TypeView::Aggregate) {
    frame.kind = Frame::Value;
    frame.type = declared;
    return;
  }
  if (outer.kind != TypeView::Aggregate && (view.kind == TypeView::Simple || view.kind == TypeView::Enumeration))
    return reject("a value of type " + model_->typeText(declared) + " is written as text");
  reject(expectation(declared));
}

std::string Translator::expectation(TypeId declared) const {
  const TypeView view = viewType(*model_, declared);
  switch (view.kind) {
  case TypeView::Entity:
    return "expected <" + xmlName(model_->entity(view.entity).name) + "> or the element of one of its subtypes";
  case TypeView::Select:
    if (view.innerDecl == kNone)
      return "expected the element of an entity or type the select allows";
    return "expected the element of an entity or type that select " + model_->typeDecl(view.innerDecl).name +
           " allows";
  case TypeView::Simple:
  case TypeView::Enumeration:
  case TypeView::Aggregate: {
    // An aggregate member: the element of its defined type, else a common one.
    const std::string element = memberElement(*model_, view);
    return element.empty() ? "expected " + model_->typeText(declared)
                           : "expected <" + element + "> (" + model_->typeText(declared) + ")";
  }
  case TypeView::Unknown:
    break;
  }
  return "expected " + model_->typeText(declared);
}

std::optional<Piece> Translator::scalar(TypeId type, std::string_view text, uint64_t at) {
  const TypeView view = viewType(*model_, type);
  Piece p;
  p.mark(at);
  const std::string_view t = trim(text);
  auto bad = [&](const std::string &what) -> std::optional<Piece> {
    error(at, "'" + std::string(t) + "' is not " + what);
    return std::nullopt;
  };
  switch (view.kind) {
  case TypeView::Enumeration: {
    if (t.empty() || !std::all_of(t.begin(), t.end(), [](char c) {
          return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
        }))
      return bad("an enumeration value");
    p.text = "." + upper(t) + ".";
    return p;
  }
  case TypeView::Simple:
    switch (view.simple) {
    case express::SimpleKind::String:
      p21::appendString(p.text, text);
      return p;
    case express::SimpleKind::Integer:
      if (!isIntegerText(t))
        return bad("an integer");
      p.text = t[0] == '+' ? std::string(t.substr(1)) : std::string(t);
      return p;
    case express::SimpleKind::Real:
    case express::SimpleKind::Number: {
      if (view.simple == express::SimpleKind::Number && isIntegerText(t)) { // an INTEGER is a NUMBER
        p.text = t[0] == '+' ? std::string(t.substr(1)) : std::string(t);
        return p;
      }
      std::string_view digits = t.starts_with('+') ? t.substr(1) : t;
      double v = 0;
      auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
      if (digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size() || !std::isfinite(v))
        return bad("a finite real number");
      p21::appendReal(p.text, v);
      return p;
    }
    case express::SimpleKind::Boolean:
    case express::SimpleKind::Logical:
      if (t == "true" || t == "1")
        p.text = ".T.";
      else if (t == "false" || t == "0")
        p.text = ".F.";
      else if (t == "unknown" && view.simple == express::SimpleKind::Logical)
        p.text = ".U.";
      else
        return bad(view.simple == express::SimpleKind::Logical ? "true, false or unknown" : "true or false");
      return p;
    case express::SimpleKind::Binary:
      if (t.empty() || t[0] < '0' || t[0] > '3' || !std::all_of(t.begin(), t.end(), [](char c) {
            return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'F') || (c >= 'a' && c <= 'f');
          }))
        return bad("a binary (hex digits after the count of unused bits)");
      p.text = "\"" + upper(t) + "\"";
      return p;
    }
    break;
  case TypeView::Entity:
  case TypeView::Select: {
    if (t.empty())
      return bad("a reference");
    auto id = idOf(t, at);
    if (!id)
      return std::nullopt;
    p.text = "#" + std::to_string(*id);
    return p;
  }
  case TypeView::Aggregate:
  case TypeView::Unknown:
    break;
  }
  error(at, "a value of type " + model_->typeText(type) + " cannot be read from text");
  return std::nullopt;
}

// A value written as text: a scalar, or (terse form) an aggregate as a
// whitespace-separated list.
std::optional<Piece> Translator::fromText(TypeId type, std::string_view text, uint64_t at) {
  const TypeView view = viewType(*model_, type);
  if (view.kind != TypeView::Aggregate)
    return scalar(type, text, at);
  const TypeId element = model_->type(view.aggregate).element;
  Piece p;
  p.mark(at);
  p.text = "(";
  bool first = true;
  for (std::string_view token : splitWhitespace(text)) {
    auto v = scalar(element, token, at);
    if (!v)
      return std::nullopt;
    if (!first)
      p.text += ',';
    first = false;
    p.append(*v, false);
  }
  p.text += ')';
  return p;
}

std::optional<Piece> Translator::valueOf(const Frame &f) {
  const TypeView view = viewType(*model_, f.type);
  std::optional<Piece> inner;
  if (view.kind == TypeView::Aggregate && (!f.children.empty() || isBlank(f.text))) {
    const TypeView member = viewType(*model_, model_->type(view.aggregate).element);
    const bool memberMarks = member.kind != TypeView::Simple && member.kind != TypeView::Enumeration;
    Piece p;
    p.mark(f.at);
    p.text = "(";
    for (size_t i = 0; i < f.children.size(); ++i) {
      if (i)
        p.text += ',';
      p.append(f.children[i], memberMarks);
    }
    p.text += ')';
    inner = std::move(p);
  } else if (f.children.size() == 1) {
    inner = f.children[0];
  } else if (f.children.size() > 1) {
    error(f.at, "<" + f.name + "> holds " + std::to_string(f.children.size()) + " values where one is expected");
    return std::nullopt;
  } else {
    inner = fromText(f.type, f.text, f.at);
  }
  if (!inner || f.typedName.empty())
    return inner;
  Piece typed;
  typed.mark(f.at);
  typed.text = f.typedName + "(";
  typed.append(*inner);
  typed.text += ')';
  return typed;
}

void Translator::closeInstance() {
  Building b = std::move(instances_.back());
  instances_.pop_back();
  Piece ref;
  ref.mark(b.at);
  ref.text = "#" + std::to_string(b.id);
  if (!b.isReference) {
    Piece p;
    p.mark(b.at);
    p.text = ref.text + "=";
    const bool complex = b.records.size() > 1;
    if (complex)
      p.text += '(';
    size_t slot = 0;
    for (EntityId e : b.records) {
      const express::Entity &entity = model_->entity(e);
      p.text += upper(entity.name);
      p.text += '(';
      const size_t count = complex ? entity.ownSlots.size() : entity.slots.size();
      for (size_t i = 0; i < count; ++i, ++slot) {
        if (i)
          p.text += ',';
        if (b.values[slot]) {
          p.append(*b.values[slot]);
        } else {
          p.mark(b.at); // a missing value is reported at its instance's element
          p.text += entity.slots[b.layout->slots[slot].second].derived ? '*' : '$';
        }
      }
      p.text += ')';
    }
    if (complex)
      p.text += ')';
    p.text += ";\n";
    openSection();
    out_.append(p);
  }
  if (frames_.empty())
    return;
  Frame &parent = frames_.back();
  if (parent.kind == Frame::Attribute || parent.kind == Frame::Value)
    parent.children.push_back(std::move(ref));
}

void Translator::endElement() {
  if (frames_.empty())
    return;
  Frame frame = std::move(frames_.back());
  frames_.pop_back();
  switch (frame.kind) {
  case Frame::Root:
    if (inSection_)
      endData();
    break;
  case Frame::Header:
    break;
  case Frame::HeaderField:
    headerFields_.emplace_back(frame.name, frame.text);
    break;
  case Frame::Uos:
    endData();
    break;
  case Frame::Instance:
    closeInstance();
    break;
  case Frame::Attribute:
    if (frame.broken)
      break;
    if (auto v = valueOf(frame))
      setSlot(frame.instance, static_cast<int>(frame.slot), std::move(*v), frame.at);
    break;
  case Frame::Value:
    if (frame.broken)
      frames_.back().broken = true;
    else if (auto v = valueOf(frame))
      frames_.back().children.push_back(std::move(*v));
    else
      frames_.back().broken = true;
    break;
  case Frame::Skipped:
    break;
  }
}

void Translator::characters(const xmlChar *ch, int len) {
  if (frames_.empty())
    return;
  Frame &f = frames_.back();
  if (f.kind == Frame::Attribute || f.kind == Frame::Value || f.kind == Frame::HeaderField)
    f.text.append(reinterpret_cast<const char *>(ch), static_cast<size_t>(len));
}

void Translator::processingInstruction(const xmlChar *targetName, const xmlChar *dataText) {
  const std::string_view target(reinterpret_cast<const char *>(targetName));
  const std::string data = dataText ? reinterpret_cast<const char *>(dataText) : "";
  if (!target.starts_with("stepnc-p21"))
    return;
  const uint64_t at = markupStart("<?");
  Piece line;
  line.mark(at);
  if (target == "stepnc-p21") {
    const std::string key = "implementation_level=\"";
    const size_t k = data.find(key);
    const size_t end = k == std::string::npos ? k : data.find('"', k + key.size());
    if (end == std::string::npos) {
      error(at, "a 'stepnc-p21' processing instruction gives implementation_level=\"...\"");
      return;
    }
    level_ = data.substr(k + key.size(), end - k - key.size());
  } else if (target == "stepnc-p21-header" || target == "stepnc-p21-anchor" || target == "stepnc-p21-reference") {
    if (headerDone_) {
      error(at, "a '" + std::string(target) + "' processing instruction must come before the first uos");
      return;
    }
    line.text = data + "\n";
    if (target == "stepnc-p21-header") {
      extraHeaderNames_.push_back(upper(data.substr(0, data.find('('))));
      extraHeader_.append(line);
    } else {
      (target == "stepnc-p21-anchor" ? anchors_ : references_).append(line);
    }
  } else if (target == "stepnc-p21-data") {
    if (!inSection_ || sectionOpened_) {
      error(at, "a 'stepnc-p21-data' processing instruction must come first in its uos");
      return;
    }
    sectionParams_ = data;
  } else {
    diags_.warning(loc(at), "unknown processing instruction '" + std::string(target) + "' ignored");
  }
}

void Translator::beginData(uint64_t at) {
  if (!headerDone_)
    writeHeader();
  inSection_ = true;
  sectionOpened_ = false;
  sectionAt_ = at;
  sectionParams_.clear();
}

void Translator::openSection() {
  if (sectionOpened_)
    return;
  sectionOpened_ = true;
  out_.mark(sectionAt_);
  out_.text += "DATA";
  out_.text += sectionParams_;
  out_.text += ";\n";
}

void Translator::endData() {
  if (!inSection_)
    return;
  openSection();
  out_.text += "ENDSEC;\n";
  inSection_ = false;
}

void Translator::writeHeader() {
  headerDone_ = true;
  Piece &out = out_;
  out.mark(0);
  out.text += "ISO-10303-21;\nHEADER;\n";
  out.mark(headerAt_);
  auto strings = [](const std::vector<std::string> &list) {
    std::string s = "(";
    for (size_t i = 0; i < list.size(); ++i) {
      if (i)
        s += ',';
      p21::appendString(s, list[i]);
    }
    return s + ")";
  };
  auto fields = [&](std::string_view name) {
    std::vector<std::string> values;
    for (const auto &[field, value] : headerFields_)
      if (field == name)
        values.push_back(value);
    return values;
  };
  auto one = [&](std::string_view name) {
    auto values = fields(name);
    std::string s;
    p21::appendString(s, values.empty() ? std::string() : values.front());
    return s;
  };
  auto overridden = [&](std::string_view name) {
    return std::find(extraHeaderNames_.begin(), extraHeaderNames_.end(), name) != extraHeaderNames_.end();
  };
  std::string level;
  p21::appendString(level, level_);
  if (!overridden("FILE_DESCRIPTION"))
    out.text += "FILE_DESCRIPTION(" + strings(fields("documentation")) + "," + level + ");\n";
  if (!overridden("FILE_NAME"))
    out.text += "FILE_NAME(" + one("name") + "," + one("time_stamp") + "," + strings(fields("author")) + "," +
                strings(fields("organization")) + "," + one("preprocessor_version") + "," + one("originating_system") +
                "," + one("authorization") + ");\n";
  if (!overridden("FILE_SCHEMA"))
    out.text += "FILE_SCHEMA(" + strings(schemaNames_) + ");\n";
  out.append(extraHeader_);
  out.text += "ENDSEC;\n";
  if (!anchors_.text.empty()) {
    out.text += "ANCHOR;\n";
    out.append(anchors_);
    out.text += "ENDSEC;\n";
  }
  if (!references_.text.empty()) {
    out.text += "REFERENCE;\n";
    out.append(references_);
    out.text += "ENDSEC;\n";
  }
}

std::string Translator::takeText(std::vector<std::pair<uint64_t, uint64_t>> &map) {
  if (!headerDone_)
    writeHeader();
  out_.text += "END-ISO-10303-21;\n";
  // Marks are appended in text order, except those of an instance written
  // inside another's text; a stable sort puts them in place.
  map = std::move(out_.marks);
  if (!std::is_sorted(map.begin(), map.end(), [](const auto &x, const auto &y) { return x.first < y.first; }))
    std::stable_sort(map.begin(), map.end(), [](const auto &x, const auto &y) { return x.first < y.first; });
  return std::move(out_.text);
}

// libxml2 calls back through these with the translator as user data.
void onStart(void *ctx, const xmlChar *local, const xmlChar *, const xmlChar *uri, int, const xmlChar **, int nb, int,
             const xmlChar **attributes) {
  static_cast<Translator *>(ctx)->startElement(local, uri, nb, attributes);
}
void onEnd(void *ctx, const xmlChar *, const xmlChar *, const xmlChar *) {
  static_cast<Translator *>(ctx)->endElement();
}
void onCharacters(void *ctx, const xmlChar *ch, int len) { static_cast<Translator *>(ctx)->characters(ch, len); }
void onPI(void *ctx, const xmlChar *target, const xmlChar *data) {
  static_cast<Translator *>(ctx)->processingInstruction(target, data);
}
void onError(void *ctx, xmlErrorPtr error) { static_cast<Translator *>(ctx)->reportXmlError(error); }
void onDoctype(void *ctx, const xmlChar *, const xmlChar *, const xmlChar *) {
  static_cast<Translator *>(ctx)->doctype();
}

bool Translator::run() {
  xmlSAXHandler sax;
  std::memset(&sax, 0, sizeof sax);
  sax.initialized = XML_SAX2_MAGIC;
  sax.startElementNs = onStart;
  sax.endElementNs = onEnd;
  sax.characters = onCharacters;
  sax.cdataBlock = onCharacters;
  sax.processingInstruction = onPI;
  sax.serror = onError;
  sax.internalSubset = onDoctype;
  const std::string name(xml_.name());
  ctxt_ = xmlCreatePushParserCtxt(&sax, this, nullptr, 0, name.c_str());
  if (!ctxt_) {
    error(0, "cannot start the XML parser");
    return false;
  }
  xmlCtxtUseOptions(ctxt_, XML_PARSE_NONET | XML_PARSE_NOCDATA);
  const std::string_view text = xml_.text();
  constexpr size_t kChunk = 1 << 18;
  size_t offset = 0;
  bool stopped = false;
  while (!stopped && offset < text.size()) {
    const size_t n = std::min(kChunk, text.size() - offset);
    stopped = xmlParseChunk(ctxt_, text.data() + offset, static_cast<int>(n), 0) != 0;
    offset += n;
    // libxml2 has copied what it still needs; keep a margin for looking back
    // at the tag being read.
    if (offset > 4 * kChunk)
      xml_.releaseBefore(offset - 2 * kChunk);
  }
  if (!stopped)
    xmlParseChunk(ctxt_, nullptr, 0, 1);
  const bool wellFormed = ctxt_->wellFormed != 0;
  xmlFreeParserCtxt(ctxt_);
  ctxt_ = nullptr;
  if (!frames_.empty() && !stopped && !sawXmlError_) {
    const Frame &open = frames_.back();
    error(text.size(), "the document ends inside <" + open.name + ">: the file is cut short")
        .note(loc(open.at), "<" + open.name + "> opens here");
  }
  if (!wellFormed && !failed_)
    error(text.size(), "the XML is not well-formed");
  if (!failed_ && !schema_ && !schemaRefused_)
    chooseSchema("", 0);
  return !failed_;
}

} // namespace

std::unique_ptr<SourceFile> translatePart28(std::unique_ptr<SourceFile> &xml, const SchemaChooser &choose,
                                            DiagnosticEngine &diags) {
  Translator translator(*xml, choose, diags);
  if (!translator.run())
    return nullptr;
  std::vector<std::pair<uint64_t, uint64_t>> map;
  std::string text = translator.takeText(map);
  return SourceFile::translation(std::move(xml), std::move(text), std::move(map));
}

} // namespace stepnc::p28
