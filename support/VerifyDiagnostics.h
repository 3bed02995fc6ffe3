// Checking diagnostics against expectations written in the input itself, in the
// style of MLIR's -verify-diagnostics. Inside comments of the checked file:
//
//   /* expected-error {{text}} */        on the comment's own line
//   /* expected-error@+1 {{text}} */     one line below (also @-2, @+3 ...)
//   /* expected-error@12 {{text}} */     on line 12
//   /* expected-error@+1:17 {{text}} */  ... and at column 17
//
// Kinds are error, warning, note and remark; `text` must occur in the message.
// Every expectation must be met by one diagnostic and every diagnostic located
// in the file must be expected.
#pragma once

#include "support/Diagnostics.h"

#include <iosfwd>
#include <vector>

namespace stepnc {

/// Checks `diags` (and their located notes) against the expectations in
/// `file`. Mismatches are printed to `os`; returns true when all match.
bool verifyDiagnostics(const SourceFile &file, const std::vector<Diagnostic> &diags, std::ostream &os);

} // namespace stepnc
