// Readers of the ISO 6983-style programs the ISO emitter writes: RS274NGC as
// LinuxCNC 2.9 reads it, and SINUMERIK 840D main programs. One reader with
// the two dialects' words: the frame, block numbers, well-formed numbers, the
// G and M codes each target writes, the modal state a move needs (absolute
// mm in the XY plane, a tool with its length offset, a feed and the spindle
// on for feed moves), the first move after the start and after each tool
// change up along Z alone, arcs whose radius agrees at both ends, splines
// (G5, CSPLINE) and canned cycles expanded into the motions their manuals
// describe (backends/rs274/README.md, backends/siemens-840d/README.md).
#pragma once

#include "backends/common/ReadBack.h"

#include <string>

namespace stepnc::backends {

/// LinuxCNC's G83 backs off this far above the previous peck before feeding
/// again (0.010 in).
inline constexpr double kLinuxCncG83Backoff = 0.254;

/// The motions and problems of an rs274 program (LinuxCNC).
ProgramReading readRs274(const std::string &text, const TargetDescriptor &d);

/// The motions and problems of a SINUMERIK 840D main program (.MPF).
ProgramReading readSiemens840d(const std::string &text, const TargetDescriptor &d);

} // namespace stepnc::backends
