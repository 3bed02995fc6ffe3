#include "cutting/Mechanics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace stepnc::cutting {

namespace {

constexpr double kStep = 2 * std::numbers::pi / Engagement::kAngles;

const std::array<Vec2, Engagement::kAngles> &directions() {
  static const std::array<Vec2, Engagement::kAngles> table = [] {
    std::array<Vec2, Engagement::kAngles> t;
    for (int k = 0; k < Engagement::kAngles; ++k)
      t[k] = Vec2(std::cos(k * kStep), std::sin(k * kStep));
    return t;
  }();
  return table;
}

} // namespace

bool Engagement::cutting() const {
  for (int k = 0; k < kAngles; ++k)
    if (depth[k] > 0 && directions()[k].dot(feedDir) > 0)
      return true;
  return false;
}

double Engagement::chipFactor() const {
  double best = 0;
  for (int k = 0; k < kAngles; ++k)
    if (depth[k] > 0)
      best = std::max(best, directions()[k].dot(feedDir));
  return best;
}

double Engagement::angle() const {
  int n = 0;
  for (int k = 0; k < kAngles; ++k)
    n += depth[k] > 0 && directions()[k].dot(feedDir) > 0;
  return n * kStep;
}

double Engagement::radialDepth(double radius) const {
  const double phi = angle();
  return phi >= std::numbers::pi ? 2 * radius : radius * (1 - std::cos(phi));
}

double Engagement::axialDepth() const { return *std::max_element(depth.begin(), depth.end()); }

int Engagement::side() const {
  double left = 0;
  for (int k = 0; k < kAngles; ++k)
    if (depth[k] > 0 && directions()[k].dot(feedDir) > 0)
      left += geom::cross(feedDir, directions()[k]) > 0 ? 1 : -1;
  return left > 0 ? 1 : left < 0 ? -1 : 0;
}

Engagement measureEngagement(const HeightMap &stock, const Vec2 &centre, double z, const Vec2 &feedDir,
                             const Cutter &cutter) {
  Engagement e;
  e.feedDir = feedDir;
  const double top = z + cutter.fluteLength;
  // The edge meets material where the cell under it holds some above the tip
  // (a twentieth of a cell above: what lies at the tip's height is the floor
  // the tool itself leaves), and so does the cell half a cell further in: a
  // wall the tool cut a moment ago stands at its radius to within half a
  // cell, and is not material to cut again.
  const double inner = std::max(0.0, cutter.radius - 0.5 * stock.cell());
  const double floor = z + 0.05 * stock.cell();
  for (int k = 0; k < Engagement::kAngles; ++k) {
    const float h = stock.at(centre + cutter.radius * directions()[k]);
    if (h > floor && stock.at(centre + inner * directions()[k]) > floor)
      e.depth[k] = float(std::min<double>(h, top) - z);
  }
  return e;
}

Engagement wallEngagement(const Vec2 &feedDir, int side, double ae, double ap, const Cutter &cutter) {
  Engagement e;
  e.feedDir = feedDir;
  // Engaged from the wall (theta = 90 deg on `side`) towards the front, down to
  // cos(theta) = 1 - ae / R ... measured as sin: the edge meets material where
  // its distance past the wall line, R (1 - cos(angle from the normal)), is
  // below ae.
  const Vec2 normal = side > 0 ? Vec2(-feedDir.y(), feedDir.x()) : Vec2(feedDir.y(), -feedDir.x());
  const double limit = 1 - std::min(ae, 2 * cutter.radius) / cutter.radius; // cos of the angle from the normal
  for (int k = 0; k < Engagement::kAngles; ++k) {
    const Vec2 &u = directions()[k];
    if (u.dot(feedDir) >= 0 && u.dot(normal) >= limit - 1e-12)
      e.depth[k] = float(std::min(ap, cutter.fluteLength));
  }
  return e;
}

ForceModel::ForceModel(const Engagement &e, const Cutter &cutter, const CuttingCoefficients &k) {
  const int flutes = std::max(1, cutter.flutes);
  // Per direction: the force on the tool from a tooth there, A fz + B.
  std::array<Vec2, Engagement::kAngles> ca, cb;
  double sumT1 = 0, sumT0 = 0;
  for (int i = 0; i < Engagement::kAngles; ++i) {
    ca[i] = cb[i] = Vec2::Zero();
    const Vec2 &u = directions()[i];
    const double c = u.dot(e.feedDir);
    if (e.depth[i] <= 0 || c <= 0)
      continue;
    // The tooth's velocity: clockwise (M3) or counter-clockwise about +z.
    const Vec2 v = cutter.clockwise ? Vec2(u.y(), -u.x()) : Vec2(-u.y(), u.x());
    const double a = e.depth[i];
    ca[i] = a * (-k.ktc * c * v - k.krc * c * u);
    cb[i] = a * (-k.kte * v - k.kre * u);
    sumT1 += a * k.ktc * c;
    sumT0 += a * k.kte;
  }
  // Mean torque: every direction visited by each of N teeth once per
  // revolution.
  const double perDirection = double(flutes) / Engagement::kAngles;
  ta_ = sumT1 * perDirection * cutter.radius / 1000;
  tb_ = sumT0 * perDirection * cutter.radius / 1000;
  // Tooth positions over one pitch, a direction apart.
  const int positions = std::max(1, int(std::lround(double(Engagement::kAngles) / flutes)));
  for (int p = 0; p < positions; ++p) {
    Vec2 a = Vec2::Zero(), b = Vec2::Zero();
    for (int j = 0; j < flutes; ++j) {
      const int i = (p + int(std::lround(j * double(Engagement::kAngles) / flutes))) % Engagement::kAngles;
      a += ca[i];
      b += cb[i];
    }
    a_.push_back(a);
    b_.push_back(b);
  }
}

double ForceModel::peakForce(double fz) const {
  double best = 0;
  for (size_t p = 0; p < a_.size(); ++p)
    best = std::max(best, (a_[p] * fz + b_[p]).norm());
  return best;
}

double ForceModel::peakPush(const Vec2 &normal, double fz) const {
  double best = -std::numeric_limits<double>::infinity();
  for (size_t p = 0; p < a_.size(); ++p)
    best = std::max(best, -(a_[p] * fz + b_[p]).dot(normal));
  return best;
}

double ForceModel::fzForForce(double limit) const {
  double best = std::numeric_limits<double>::infinity();
  for (size_t p = 0; p < a_.size(); ++p) {
    // |A x + B| = limit: (A.A) x^2 + 2 (A.B) x + (B.B - limit^2) = 0.
    const double aa = a_[p].squaredNorm(), ab = a_[p].dot(b_[p]), bb = b_[p].squaredNorm();
    if (bb > limit * limit)
      return 0;
    if (aa <= 0)
      continue;
    const double disc = ab * ab - aa * (bb - limit * limit);
    best = std::min(best, (-ab + std::sqrt(std::max(0.0, disc))) / aa);
  }
  return best;
}

double ForceModel::fzForTorque(double limit) const {
  if (tb_ > limit)
    return 0;
  return ta_ > 0 ? (limit - tb_) / ta_ : std::numeric_limits<double>::infinity();
}

} // namespace stepnc::cutting
