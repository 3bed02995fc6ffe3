// The native motion format: a trajectory as versioned, self-describing text
// (docs/native-format.md) that an open controller or a script can play
// without stepnc. Each segment is written with its geometry and the phases
// of its speed profile.
#pragma once

#include "runtime/Trajectory.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <optional>
#include <string>

namespace stepnc::runtime {

/// The trajectory in the native text format. `source` names what it was
/// planned from (written in the header).
std::string writeNative(const Trajectory &trajectory, const std::string &source);

/// Reads the native text format; every problem is reported at its line and
/// column. Returns nullopt when there was one.
std::optional<Trajectory> readNative(const SourceFile &file, DiagnosticEngine &diags);

} // namespace stepnc::runtime
