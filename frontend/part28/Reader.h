// Reading Part 28 XML (docs/part28.md): the XML is streamed (libxml2 SAX, no
// document tree) and translated into Part 21 text whose every instance and
// value remembers the XML element it came from. The result is a SourceFile
// that the Part 21 reader, binding, checking and lowering use unchanged; its
// diagnostics point at the XML file's lines and columns.
#pragma once

#include "frontend/express/Schema.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace stepnc::p28 {

/// True if `text` looks like XML (its first non-blank character, after an
/// optional byte order mark, is '<').
bool isXml(std::string_view text);

/// Chooses the schema for the schema names a document declares (its uos
/// `express` attribute; empty when it names none). Returns null when no schema
/// fits; `model` receives the schema's model.
using SchemaChooser =
    std::function<const express::Schema *(const std::vector<std::string> &names, const express::Model *&model)>;

/// Translates the Part 28 document `xml` into Part 21 text. On success returns
/// the translation, which takes `xml` over (leaving it null). Returns null
/// after reporting when the document cannot be translated (not well-formed,
/// not Part 28, its schema unknown, an element or attribute the schema does
/// not have); `xml` then stays with the caller, as the diagnostics point into it.
std::unique_ptr<SourceFile> translatePart28(std::unique_ptr<SourceFile> &xml, const SchemaChooser &choose,
                                            DiagnosticEngine &diags);

} // namespace stepnc::p28
