// The IR text form, reading side: parses exactly what ir/Printer.h writes.
//
// Anything else is rejected with a located error (`file:line:col: error: ...`,
// the column at the offending token): an unknown kind or attribute, bad
// indentation, a child its parent's kind does not allow, a symbol with the
// wrong sigil, a label on a kind without one, a value not of its attribute's
// type or not spelled as the printer spells it (`3.0mm` for `3.0000mm`). Rules
// that span nodes (required attributes, references, unique symbols) belong to
// the verifier (ir/Verifier.h). Lines starting with `;` and blank lines are
// skipped. After an error the parser goes on with the next line, skipping the
// subtree of a line it could not place, so one run reports many errors.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <memory>

namespace stepnc::ir {

/// Parses IR text. Each node's origin.loc points at its kind in `src` (which
/// must outlive the module); origin.entityId comes from `loc(... #id)`; the
/// trailing `; comment` becomes Node::comment. Null when there were errors.
std::unique_ptr<Module> parseModule(const SourceFile &src, DiagnosticEngine &diags);

} // namespace stepnc::ir
