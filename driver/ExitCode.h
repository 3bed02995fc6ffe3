// How a driver step ends, as the command line's exit status: one contract
// for every stepnc command (README: 0 success, 1 the input has errors, 2 usage
// or I/O, 3 a defect of stepnc).
#pragma once

namespace stepnc::driver {

/// Process exit codes, the same for every subcommand; the driver's steps
/// return them too, so a command passes them on unchanged.
enum ExitCode : int {
  kExitOk = 0,          ///< success; warnings allowed
  kExitDiagnostics = 1, ///< the input has errors
  kExitUsage = 2,       ///< bad command line, or a file could not be read or written
  kExitInternal = 3,    ///< an exception no step caught: a defect of stepnc, said, never an abort
};

} // namespace stepnc::driver
