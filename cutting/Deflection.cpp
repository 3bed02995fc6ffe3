#include "cutting/Deflection.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::cutting {

namespace {

double inertia(double d) { return std::numbers::pi * std::pow(d, 4) / 64; }

/// integral over [s0, s1] of (a - s)(x - s) ds.
double moment(double a, double x, double s0, double s1) {
  auto primitive = [&](double s) { return a * x * s - (a + x) * s * s / 2 + s * s * s / 3; };
  return primitive(s1) - primitive(s0);
}

} // namespace

double deflection(const ToolBeam &beam, double force, double loadFromTip, double pointFromTip) {
  const double length = beam.overhang;
  const double a = std::clamp(length - loadFromTip, 0.0, length); // from the clamp
  const double x = std::clamp(length - pointFromTip, 0.0, length);
  const double end = std::min(a, x);                                           // the unit moments overlap up to here
  const double step = std::clamp(length - beam.fluteLength, 0.0, length); // where the flutes begin
  const double shank = moment(a, x, 0, std::min(end, step)) / inertia(beam.diameter);
  const double fluted = end > step ? moment(a, x, step, end) / inertia(beam.fluteDiameter) : 0;
  return force / beam.modulus * (shank + fluted);
}

double deflectionUnderSpreadLoad(const ToolBeam &beam, double force, double height, double pointFromTip) {
  constexpr int kSlices = 16;
  double sum = 0;
  for (int i = 0; i < kSlices; ++i)
    sum += deflection(beam, force / kSlices, (i + 0.5) * height / kSlices, pointFromTip);
  return sum;
}

double forceForClampStress(const ToolBeam &beam, double stress, double loadFromTip) {
  const double arm = std::max(beam.overhang - loadFromTip, 1e-9);
  return stress * inertia(beam.diameter) / (arm * beam.diameter / 2);
}

} // namespace stepnc::cutting
