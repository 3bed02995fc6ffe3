// What a turned feature is in the half plane of its turning axis: the
// material its machining removes and the finished surface it leaves, in
// coordinates (z, r) — z along the workpiece's z axis (the spindle axis),
// r the distance from it. Turning expansion cuts this shape and the lathe
// toolpath check measures moves against it; it is the one piece of
// interpretation the two share (docs/turning.md says how each ISO 14649-12
// attribute is read), so it is tested on its own.
//
// The turning axis is the workpiece's z axis; a feature placed off it, or
// with its axis across it, is reported as not supported.
#pragma once

#include "geom/Geometry.h"
#include "ir/Node.h"
#include "ir/Program.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::ir {

/// A point of the half plane: x() is z along the axis, y() the radius.
using HalfPlanePoint = geom::Vec2;

/// The workpiece's cylindrical raw piece in the half plane: a rectangle from
/// `z0` (the chuck side, the lower z) to `z1`, from the axis to `radius`.
struct TurnStock {
  double z0 = 0, z1 = 0, radius = 0;
  geom::Region region() const;
};

struct StockResult {
  std::optional<TurnStock> stock;
  std::string error;  ///< why there is none
};

/// The raw piece of `workpiece` as a lathe holds it: a cylinder about the z
/// axis (`rawpiece shape=cylinder`, axis ±z through x = y = 0).
StockResult turnStock(const ir::Node *workpiece);

struct TurnedShape {
  std::string symbol;
  ir::Kind kind = ir::Kind::OuterDiameter;
  /// The material the feature's machining removes: bounded by the finished
  /// surface on the part's side and, elsewhere, reaching `reach` (past the
  /// stock's radius and its free end), so that nothing limits the tool there.
  geom::Region removal;
  /// The finished surface: an open chain along the part, in the order a
  /// finishing pass follows it (from the free end towards the chuck, or
  /// from the outside in for a face). Every segment lies on the
  /// boundary of `removal`.
  std::vector<geom::Seg> contour;
  /// A groove's extent along the axis and its floor radius (grooving
  /// strategies plunge between the walls); a face groove's (faceGroove)
  /// extent across the axis (radii) and its floor's z.
  std::optional<std::pair<double, double>> grooveSpan;
  double grooveFloor = 0;
  /// A groove's corner radii where its floor meets the wall at the low end
  /// of its span (first_radius) and at the high end (second_radius).
  std::pair<double, double> grooveRadii{0, 0};
  bool faceGroove = false;
  /// A thread: its extent along the axis (lo < hi), its crest radius
  /// (where the tool starts: an outer thread's major, an inner one's minor)
  /// and its root radius (where the tool cuts to: an outer thread's minor,
  /// an inner one's major), its pitch and starts (docs/turning.md).
  struct ThreadSpan {
    double lo = 0, hi = 0;
    double crestRadius = 0, rootRadius = 0;
    double pitch = 0;
    int starts = 1;
    bool leftHand = false;
  };
  std::optional<ThreadSpan> thread;
  /// A knurl: its extent along the axis (lo < hi), the radius it is rolled
  /// on and its teeth's depth. Its band, that depth in from the radius over
  /// the extent, is its `removal`: the wheels press the teeth in there.
  struct KnurlSpan {
    double lo = 0, hi = 0, radius = 0, depth = 0;
  };
  std::optional<KnurlSpan> knurl;
  /// A face whose material is on the free end's side: it looks towards the
  /// chuck, and only parting off (cutting in) makes it.
  bool towardsChuck = false;
  /// An inner surface (a bore): it looks towards the axis, its material is
  /// outwards of it, and tools work it from inside, entering from the free
  /// end; the removal reaches in to the axis.
  bool inner = false;
  /// Where the feature is placed (its placement's origin in the half plane)
  /// and which way its axis runs along z (+1 or -1).
  HalfPlanePoint at = HalfPlanePoint::Zero();
  double axisSign = 1;
};

struct TurnedShapeResult {
  std::optional<TurnedShape> shape;
  std::string error;  ///< why the feature has no turned shape (not supported, missing data)
};

/// Whether `exec` is a hole-making workingstep whose moves all lie on the
/// turning axis (x = y = 0): a drill held on the spindle axis of a lathe
/// (centre drilling, drilling), which a lathe program writes among its
/// turning steps.
bool drillsOnTurningAxis(const ir::Node &exec);

/// The turned shape of `feature` on a workpiece cut from `stock`: the
/// window the removal reaches out to comes from the stock (its radius and
/// free end, plus `margin`).
TurnedShapeResult turnedShape(const ir::Node &feature, const TurnStock &stock, double margin = 10.0);

} // namespace stepnc::ir
