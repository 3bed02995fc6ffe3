// Writing an instance graph as Part 28 XML (docs/part28.md).
//
// The writer needs the schema (attribute names and types are not in the Part
// 21 data), so it takes a bound file. The output is deterministic: the same
// graph always gives the same bytes. Instances are written in id order, flat,
// each reference by `ref`; what Part 28 has no place for goes into `stepnc-p21`
// processing instructions, so reading the XML back gives the same graph.
#pragma once

#include "frontend/binding/Binder.h"
#include "frontend/part21/Writer.h"

namespace stepnc::p28 {

/// Writes `bound`'s file as Part 28. A value the mapping cannot express (an
/// unknown entity, a wrong number of attributes, a SELECT value without its
/// type, a control character XML 1.0 forbids) is reported with its instance
/// and makes the call fail; the caller then discards the output.
bool writePart28(const binding::BoundFile &bound, const p21::ByteSink &sink, DiagnosticEngine &diags);

/// Convenience for tests: the XML as a string.
std::string writePart28ToString(const binding::BoundFile &bound, DiagnosticEngine &diags, bool *ok = nullptr);

} // namespace stepnc::p28
