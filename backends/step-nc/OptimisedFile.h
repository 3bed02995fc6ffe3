// Machine-optimised STEP-NC: the input file written back with what the
// compiler decided for one machine (docs/feedback.md).
//
// Every instance of the input keeps its id and its values, except the
// operation of each expanded machining workingstep (a hole-making step, its
// moves canned cycles, keeps its operation: read again it makes the same
// cycles, dwells and reduced feeds included), whose `its_toolpath`
// (ISO 14649-10 operation, attribute 1) now names a new TOOLPATH_LIST: the
// workingstep's moves as cutter-location trajectories in the feature's frame,
// one per run of moves of one kind, role and feed, each feed in a technology
// of its own, rapids with the speed name `rapid`. New instances get ids above
// the input's largest, in program order. FILE_DESCRIPTION says what was
// defaulted or changed. Lowering reads the written toolpaths back to the same
// moves (expand-strategies, explicit toolpaths), and, being required, no pass
// changes them again.
#pragma once

#include "frontend/part21/Part21File.h"
#include "ir/Node.h"
#include "support/Diagnostics.h"

#include <memory>
#include <string>
#include <vector>

namespace stepnc::backends {

struct OptimisedFileOptions {
  /// Readable lines for FILE_DESCRIPTION: how the file was made and what was
  /// defaulted or changed. The writer says what the file holds after the
  /// first; the input's own description lines follow them all.
  std::vector<std::string> description;
};

/// The optimised file as Part 21 text (the input's canonical form, patched):
/// `input` is the file `module` was lowered from, `module` the toolpath IR
/// after the passes. Returns the empty string after reporting errors (a move
/// the toolpath model cannot carry, an operation shared by two workingsteps).
std::string writeOptimisedPart21(const p21::Part21File &input, const ir::Module &module,
                                 const OptimisedFileOptions &options, DiagnosticEngine &diags);

/// The same, read back into an instance graph (`text` keeps the bytes it
/// points into): what the canonical Part 21 writer, or a Part 28 writer,
/// writes out. Null after reporting errors.
std::unique_ptr<p21::Part21File> buildOptimisedFile(const p21::Part21File &input, const ir::Module &module,
                                                    const OptimisedFileOptions &options,
                                                    std::unique_ptr<SourceFile> &text, DiagnosticEngine &diags);

} // namespace stepnc::backends
