#include "cutting/HeightMap.h"

#include <algorithm>
#include <cmath>

namespace stepnc::cutting {

HeightMap::HeightMap(const geom::Box &box, double cell) : box_(box), cell_(cell), inv_(1 / cell) {
  nx_ = std::max(1, int(std::ceil((box.hi.x() - box.lo.x()) * inv_)));
  ny_ = std::max(1, int(std::ceil((box.hi.y() - box.lo.y()) * inv_)));
  h_.assign(size_t(nx_) * ny_, kAir);
}

void HeightMap::addBlock(const Vec2 &lo, const Vec2 &hi, double top) {
  // Cells whose centres lie in the rectangle.
  const int i0 = std::max(0, int(std::ceil((lo.x() - box_.lo.x()) * inv_ - 0.5)));
  const int i1 = std::min(nx_ - 1, int(std::floor((hi.x() - box_.lo.x()) * inv_ - 0.5)));
  const int j0 = std::max(0, int(std::ceil((lo.y() - box_.lo.y()) * inv_ - 0.5)));
  const int j1 = std::min(ny_ - 1, int(std::floor((hi.y() - box_.lo.y()) * inv_ - 0.5)));
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      float &h = h_[size_t(j) * nx_ + i];
      h = std::max(h, float(top));
    }
}

void HeightMap::cutDisc(const Vec2 &c, double r, double z) { cutCapsule(c, c, r, z); }

void HeightMap::addRevolved(const Vec2 &axis, const std::function<double(double)> &top) {
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const Vec2 p(box_.lo.x() + (i + 0.5) * cell_, box_.lo.y() + (j + 0.5) * cell_);
      float &h = h_[size_t(j) * nx_ + i];
      h = std::max(h, float(top((p - axis).norm())));
    }
}

/// Calls f(cell height, cell centre) for every cell whose centre lies in the
/// area a disc of radius r sweeps from a to b.
template <class F> void HeightMap::forCapsule(const Vec2 &a, const Vec2 &b, double r, F &&f) const {
  const Vec2 lo = a.cwiseMin(b) - Vec2(r, r), hi = a.cwiseMax(b) + Vec2(r, r);
  const int i0 = std::max(0, int(std::floor((lo.x() - box_.lo.x()) * inv_ - 0.5)));
  const int i1 = std::min(nx_ - 1, int(std::ceil((hi.x() - box_.lo.x()) * inv_ - 0.5)));
  const int j0 = std::max(0, int(std::floor((lo.y() - box_.lo.y()) * inv_ - 0.5)));
  const int j1 = std::min(ny_ - 1, int(std::ceil((hi.y() - box_.lo.y()) * inv_ - 0.5)));
  const Vec2 d = b - a;
  const double dd = d.squaredNorm();
  const double r2 = r * r;
  for (int j = j0; j <= j1; ++j) {
    const double y = box_.lo.y() + (j + 0.5) * cell_;
    for (int i = i0; i <= i1; ++i) {
      const size_t k = size_t(j) * nx_ + i;
      if (!f.wants(h_[k]))
        continue;
      const Vec2 p(box_.lo.x() + (i + 0.5) * cell_, y);
      double t = dd > 0 ? (p - a).dot(d) / dd : 0;
      t = std::clamp(t, 0.0, 1.0);
      if ((p - (a + t * d)).squaredNorm() <= r2)
        f(k, p);
    }
  }
}

void HeightMap::cutCapsule(const Vec2 &a, const Vec2 &b, double r, double z) {
  struct Cut {
    HeightMap &map;
    float z;
    bool wants(float h) const { return h > z; }
    void operator()(size_t k, const Vec2 &) const { map.h_[k] = z; }
  };
  forCapsule(a, b, r, Cut{*this, float(z)});
}

void HeightMap::addCapsule(const Vec2 &a, const Vec2 &b, double r, double top) {
  struct Raise {
    HeightMap &map;
    float top;
    bool wants(float h) const { return h < top; }
    void operator()(size_t k, const Vec2 &) const { map.h_[k] = top; }
  };
  forCapsule(a, b, r, Raise{*this, float(top)});
}

HeightMap::Peak HeightMap::highest(const Vec2 &a, const Vec2 &b, double r) const {
  struct Highest {
    const HeightMap &map;
    Peak &peak;
    bool wants(float h) const { return h > peak.height; }
    void operator()(size_t k, const Vec2 &p) const { peak = {map.h_[k], p}; }
  };
  Peak peak;
  forCapsule(a, b, r, Highest{*this, peak});
  return peak;
}

void HeightMap::cutAlong(const geom::Seg &s, double r, double z0, double z1, double step) {
  int pieces = 1;
  if (s.isArc()) {
    // Chord sagitta r_arc (1 - cos(dphi / 2)) <= step.
    const double ra = s.radius();
    const double dphi = step < ra ? 2 * std::acos(1 - step / ra) : M_PI;
    pieces = std::max(pieces, int(std::ceil(std::abs(s.sweep()) / dphi)));
  }
  if (z0 != z1)
    pieces = std::max(pieces, int(std::ceil(std::abs(z1 - z0) / step)));
  // Long pieces make big bounding boxes of mostly untouched cells.
  pieces = std::max(pieces, int(std::ceil(s.length() / std::max(4 * r, 4 * cell_))));
  Vec2 prev = s.a;
  for (int k = 1; k <= pieces; ++k) {
    const double t = double(k) / pieces;
    const Vec2 next = k == pieces ? s.b : s.at(t);
    // A piece whose tip descends is cut at its lower end: the tool reaches
    // that height there, and the disc between is at most `step` higher.
    const double z = std::min(z0 + (z1 - z0) * (k - 1) / pieces, z0 + (z1 - z0) * t);
    cutCapsule(prev, next, r, z);
    prev = next;
  }
}

} // namespace stepnc::cutting
