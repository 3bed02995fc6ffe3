// Lowering: from a bound STEP-NC file (ISO 14649 ARM) to the feature IR.
//
// Lowering reads instances by attribute name (binding::Instance), converts to
// the IR's units once (mm, deg, mm/min, rev/min, s) and builds one `project`
// node: workpieces with their features, tools, setups, and the main workplan
// with its executables. Resources used by several workingsteps are lowered
// once. A construct that is not handled yet is reported as
// `not supported: <entity> at #id`, never dropped silently.
#pragma once

#include "frontend/binding/Binder.h"
#include "ir/Node.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

namespace stepnc::lowering {

/// How ISO 14649 quantities whose unit the ARM leaves implicit are read.
struct UnitConventions {
  /// speed_measure to mm/min, for feedrates and for cutting speeds: 60000
  /// reads m/s, the reading of ISO 14649-11's Example 1. 0: chosen per file
  /// by plausibility (feeds and cutting speeds separately: some generators
  /// write the feed in m/s and the cutting speed in m/min), reported when
  /// not m/s. Set by --feed-unit and --cutting-speed-unit.
  double feedToMmPerMin = 0.0;
  double cutspeedToMmPerMin = 0.0;
  /// rot_speed_measure (spindle) to rev/min: 60 reads rev/s. 0: chosen per
  /// file by plausibility (rev/s or rev/min), reported when not rev/s. Set
  /// by --spindle-unit.
  double rotSpeedToRevPerMin = 0.0;
  /// plane_angle_measure: ISO 14649 files are written in degrees, but some
  /// generators write radians. Auto reads radians when every angle the file
  /// gives is below 2 pi and none is a whole number of degrees (reported).
  /// Set by --angle-unit.
  enum class Angle : uint8_t { Auto, Degree, Radian };
  Angle angles = Angle::Auto;
};

/// The units a speed_measure may be read in ("m/s", "mm/min", "m/min",
/// "mm/s"), the standard's first, with their factor to mm/min; and those of
/// a rot_speed_measure ("rev/s", "rev/min") to rev/min.
struct UnitReading {
  std::string_view name;
  double factor;
};
std::span<const UnitReading> speedReadings();
std::span<const UnitReading> spindleReadings();

struct LowerOptions {
  UnitConventions units;
};

/// Lowers the file's project. Returns null (after reporting) when there is no
/// project to lower; otherwise a module, possibly incomplete when errors were
/// reported.
std::unique_ptr<ir::Module> lowerToFeatureIR(const binding::BoundFile &bound, DiagnosticEngine &diags,
                                             const LowerOptions &options = {});

} // namespace stepnc::lowering
