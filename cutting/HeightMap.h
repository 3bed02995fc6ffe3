// The in-process stock of 2.5D milling as a height field: over a grid of
// square cells in the workpiece's xy plane, the height of the material's top
// (mm, workpiece coordinates). A flat end mill fed from +z removes everything
// above its tip within its disc, so cutting is `height = min(height, tip)`
// over the cells the disc sweeps; nothing a 3-axis flat or drilling tool does
// leaves an overhang, so one height per cell is exact up to the cell size.
//
// A cell is cut when its centre lies within the tool's disc. Queries read the
// cell containing the point, so a position is known to half a cell; the cell
// size is chosen from the smallest tool radius (passes/CuttingModel.cpp).
#pragma once

#include "geom/Geometry.h"

#include <functional>
#include <limits>
#include <vector>

namespace stepnc::cutting {

using geom::Vec2;

class HeightMap {
public:
  /// No material anywhere.
  static constexpr float kAir = -std::numeric_limits<float>::infinity();

  /// A grid covering `box` with cells of `cell` mm, all air.
  HeightMap(const geom::Box &box, double cell);

  double cell() const { return cell_; }
  const geom::Box &box() const { return box_; }
  int columns() const { return nx_; }
  int rows() const { return ny_; }

  /// Material from below up to `top` over the axis-aligned rectangle [lo, hi]
  /// (a block raw piece); raises cells, never lowers them.
  void addBlock(const Vec2 &lo, const Vec2 &hi, double top);

  /// Material from below up to `top` over the area a disc of radius r
  /// sweeps from a to b (a deposited bead); raises cells, never lowers them.
  void addCapsule(const Vec2 &a, const Vec2 &b, double r, double top);

  /// Material from below up to `top(d)` at each cell whose centre is d from
  /// `axis` (a body of revolution standing on its axis: -infinity for
  /// none); raises cells, never lowers them.
  void addRevolved(const Vec2 &axis, const std::function<double(double)> &top);

  /// The material's top at p (the cell containing p); kAir outside the grid.
  float at(const Vec2 &p) const {
    const int i = int((p.x() - box_.lo.x()) * inv_);
    const int j = int((p.y() - box_.lo.y()) * inv_);
    if (p.x() < box_.lo.x() || p.y() < box_.lo.y() || i >= nx_ || j >= ny_)
      return kAir;
    return h_[size_t(j) * nx_ + i];
  }

  /// The highest material within the area a disc of radius r sweeps from a
  /// to b (cells whose centres lie in it) and where; kAir when none.
  struct Peak {
    float height = kAir;
    Vec2 at = Vec2::Zero();
  };
  Peak highest(const Vec2 &a, const Vec2 &b, double r) const;

  /// Cuts to height z the disc of radius r about c.
  void cutDisc(const Vec2 &c, double r, double z);
  /// Cuts to height z the area a disc of radius r sweeps from a to b.
  void cutCapsule(const Vec2 &a, const Vec2 &b, double r, double z);
  /// Cuts along a plane segment (line or arc) with the tip going linearly
  /// from z0 to z1; arcs and height changes are split so that no piece
  /// strays from the segment, or changes height, by more than `step`.
  void cutAlong(const geom::Seg &s, double r, double z0, double z1, double step);

private:
  template <class F> void forCapsule(const Vec2 &a, const Vec2 &b, double r, F &&f) const;

  geom::Box box_;
  double cell_ = 1, inv_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<float> h_;
};

} // namespace stepnc::cutting
