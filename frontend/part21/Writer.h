// Writing Part 21 in one canonical form.
//
// Canonical means: the same instance graph always gives the same bytes. The
// sections come in the order HEADER, ANCHOR, REFERENCE, DATA...; instances are
// sorted by id within their DATA section, one per line, with no spaces; names
// are upper case; reals use the shortest digits that read back to the same
// double (`0.01`, `1.E-05`); strings are re-encoded from UTF-8 with `''`, `\\`,
// `\X\hh` for control and Latin-1 characters and `\X2\`/`\X4\` runs beyond.
#pragma once

#include "frontend/part21/Part21File.h"
#include "support/OutputFile.h"

#include <functional>
#include <string>

namespace stepnc::p21 {

/// Appends the canonical text of one parameter.
void appendValue(std::string &out, const Value &v, const ValueArena &arena, const NameTable &names);
/// Appends `NAME(p1,p2,...)`.
void appendRecord(std::string &out, const Record &r, const ValueArena &arena, const NameTable &names);
/// Appends a Part 21 string literal (with quotes) for UTF-8 text.
void appendString(std::string &out, std::string_view utf8);
/// Appends a Part 21 real literal.
void appendReal(std::string &out, double value);

/// Receives the written text in chunks of about 64 KiB.
using ByteSink = std::function<void(std::string_view)>;

struct WriteOptions {
  /// Also report references to undefined ids (and fail on them), so a caller
  /// that writes what it reads needs to decode each instance only once.
  bool checkReferences = false;
};

/// Writes `file` in canonical form. Instances that fail to decode are reported
/// and make the call fail; the caller then discards the output.
bool writePart21(const Part21File &file, const ByteSink &sink, DiagnosticEngine &diags,
                 const WriteOptions &options = {});
bool writePart21(const Part21File &file, OutputFile &out, DiagnosticEngine &diags,
                 const WriteOptions &options = {});
/// Convenience for small files and tests: the canonical text as a string.
std::string writePart21ToString(const Part21File &file, DiagnosticEngine &diags, bool *ok = nullptr);

/// Maps an entity name of the first graph (upper case) to the name it must
/// have in the second, e.g. an alias to its schema name.
using NameMap = std::function<std::string(std::string_view)>;

/// Compares two files' instance graphs: header entities, sections, anchors,
/// references and every instance (ids, entity names, values; reals bit for
/// bit). `renameA`, if given, maps the entity names of `a`'s instance records
/// before they are compared. Returns an empty string when equal, else the
/// first difference.
std::string compareGraphs(const Part21File &a, const Part21File &b, const NameMap &renameA = {});

} // namespace stepnc::p21
