// Decoding of Part 21 parameters into a ValueArena (internal to frontend/part21;
// other layers call Part21File::decodeInstance).
#pragma once

#include "frontend/part21/Lexing.h"
#include "frontend/part21/Part21File.h"

#include <string>
#include <vector>

namespace stepnc::p21 {

class Decoder {
public:
  /// `base` is the position offsets are measured from (the instance's '#', or
  /// the file start for header and section data); `id` names the instance in
  /// diagnostics (0 for none); `context` says where we are ("header", ...).
  Decoder(const Part21File &file, ValueArena &arena, DiagnosticEngine *diags, const char *base,
          InstanceId id, const char *context);

  /// `NAME(params)` at `p`; returns the position after ')' or null on error.
  const char *parseRecord(const char *p, const char *end, Record &out);
  /// `(params)` at `p`, parameters appended to `out` (children live in the arena).
  const char *parseParamList(const char *p, const char *end, std::vector<Value> &out);
  /// One parameter at `p`.
  const char *parseSingleParam(const char *p, const char *end, Value &out);
  /// A whole data instance `#id = ... ;` starting at its '#'; `known` is its
  /// entity name from the instance table (kComplexInstance for complex ones).
  bool parseInstance(const char *p, const char *end, NameId known);

  /// Names the instance in diagnostics. An id, not a view: decoding may add
  /// names to the table, which may move the stored strings.
  void setEntityName(NameId name) { entityName_ = name; }

private:
  /// Skips white space and comments; the common case (none) stays inline.
  bool layout() {
    if (p_ < end_ && !lex::isSpace(*p_) && *p_ != '/')
      return true;
    return skipLayoutSlow();
  }
  bool skipLayoutSlow();
  bool parseParam(unsigned depth);
  bool parseListInto(unsigned depth, Value &list);
  bool parseRecordBody(Record &out, NameId known = kNoName);
  bool parseString(Value &v);
  bool parseNumber(Value &v);
  bool parseBinary(Value &v);
  bool parseEnum(Value &v);
  bool fail(const char *at, std::string message);
  uint32_t offsetOf(const char *q) const;

  const Part21File &file_;
  ValueArena &arena_;
  DiagnosticEngine *diags_;
  const char *base_;
  InstanceId id_;
  const char *context_;
  NameId entityName_ = kNoName;
  const char *p_ = nullptr;
  const char *end_ = nullptr;
  std::vector<Value> &scratch_;
  std::string decoded_;
};

} // namespace stepnc::p21
