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
  const double x = std::clamp(length - std::min(pointFromTip, loadFromTip), a, length);
  const double step = std::clamp(length - beam.fluteLength, 0.0,
                                 length); // where the flutes begin
  const double shank = moment(a, x, 0, std::min(a, step)) / inertia(beam.diameter);
  const double fluted = a > step ? moment(a, x, step, a) / inertia(beam.fluteDiameter) : 0;
  return force / beam.modulus * (shank + fluted);
}

double forceForClampStress(const ToolBeam &beam, double stress, double loadFromTip) {
  const double arm = std::max(beam.overhang - loadFromTip, 1e-9);
  return stress * inertia(beam.diameter) / (arm * beam.diameter / 2);
}

} // namespace stepnc::cutting
