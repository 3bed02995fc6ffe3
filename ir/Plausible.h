// What cutting data can be at all, whatever the machine: the bounds beyond
// which a value read from a file is not what a machine does. Lowering reads
// a file's speeds in the units that keep its values within them
// (Lowerer::chooseSpeedUnits) and warns about a value still outside;
// check-limits refuses a program that asks for one (without a machine to
// bound it more tightly). One table, so that what lowering takes as
// plausible check-limits does not refuse.
#pragma once

namespace stepnc::ir {

inline constexpr double kPlausibleMinFeedMmPerMin = 1;
inline constexpr double kPlausibleMaxFeedMmPerMin = 100000;
inline constexpr double kPlausibleMinCuttingSpeedMPerMin = 1;
inline constexpr double kPlausibleMaxCuttingSpeedMPerMin = 3000;
inline constexpr double kPlausibleMinSpindleRpm = 1;
inline constexpr double kPlausibleMaxSpindleRpm = 100000;
/// mm/rev: a lathe's feed per revolution (a thread's lead at most).
inline constexpr double kPlausibleMinFeedPerRev = 0.001;
inline constexpr double kPlausibleMaxFeedPerRev = 50;
/// Feed per tooth, at most this share of the tool's diameter.
inline constexpr double kPlausibleChipLoadShare = 0.1;
/// The largest magnitudes an IR value can have and still mean something on
/// a machine tool: no machine travels 100 m, dwells for days or turns a
/// spindle at a million rev/min. The IR verifier refuses values beyond
/// them, so that no pass computes with 1e308 (overflow to inf, endless
/// loops) whatever a file says.
inline constexpr double kMaxLengthMm = 1e5;
inline constexpr double kMaxAngleDeg = 1e5;
inline constexpr double kMaxTimeS = 1e6;
inline constexpr double kMaxRate = 1e7;  ///< mm/min, rev/min, W, g/min
/// s: the shortest dwell a controller resolves (G4 P0.001); a time between
/// 0 and this is no dwell a program can say, refused rather than dropped.
inline constexpr double kMinDwellS = 0.001;
/// mm: a workpiece's global_tolerance above this is no machining tolerance
/// (some generators write 50 mm); lowering does not use it...
inline constexpr double kPlausibleMaxTolerance = 1.0;
/// mm: nor below this, finer than any machine tool positions (a tenth of a
/// micrometre); a tolerance of 1e-300 made levels and chords without end.
inline constexpr double kPlausibleMinTolerance = 1e-4;
/// Whether a workpiece's global_tolerance is one lowering uses.
inline constexpr bool isPlausibleTolerance(double mm) {
  return mm >= kPlausibleMinTolerance && mm <= kPlausibleMaxTolerance;
}
/// mm: the tolerance toolpaths are verified to when neither the workpiece nor
/// an option gives one; a dimension the file gives no tolerance is written
/// back with it.
inline constexpr double kDefaultTolerance = 0.01;

} // namespace stepnc::ir
