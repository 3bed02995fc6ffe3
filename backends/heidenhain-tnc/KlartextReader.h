// The reader of HEIDENHAIN TNC conversational (Klartext) programs, for the
// subset the Klartext emitter writes (HeidenhainTnc.cpp, README.md beside
// it): the frame and block numbers, the form of every block and number, the
// modal state a motion needs (a TOOL CALL, then Z alone first; a feed and a
// running spindle for feed moves; a pole for arcs) and the motions the
// program makes, cycle 200 expanded at each M99 as the TNC runs it. The C++
// port of tests/backends/check-heidenhain-tnc.py's structural checks.
#pragma once

#include "backends/common/ReadBack.h"

#include <string>

namespace stepnc::backends {

/// The motions and problems of a Klartext program (`.h`); `d` gives the
/// printed precision (a move that prints as no motion is none).
ProgramReading readKlartext(const std::string &text, const TargetDescriptor &d);

} // namespace stepnc::backends
