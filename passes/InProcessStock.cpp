// The in-process stock (see InProcessStock.h).
#include "passes/InProcessStock.h"

#include "ir/Kinds.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stepnc::passes {

namespace {

using geom::Vec2;

constexpr double kInf = std::numeric_limits<double>::infinity();

double toolRadius(const ir::Node *tool) { return tool ? tool->number("diameter").value_or(0) / 2 : 0; }

/// How far above its tip a tool cuts its full disc: a hole-making tool's
/// point; a milling cutter cuts to its tip.
double toolPoint(const ir::Node *tool) {
  if (!tool || tool->text("type").value_or("").find("mill") != std::string::npos)
    return 0;
  return ir::pointLength(*tool);
}

} // namespace

const ir::Node *setupWorkpiece(const ir::Module &module, const std::string &setup) {
  if (const ir::Node *s = ir::findResource(module, ir::Kind::Setup, setup))
    for (const ir::Node *ws : s->childrenOf(ir::Kind::WorkpieceSetup))
      if (auto w = ws->text("workpiece"))
        if (const ir::Node *wp = ir::findResource(module, ir::Kind::Workpiece, *w))
          return wp;
  const ir::Node *only = nullptr;
  for (const ir::Node &n : module.root.children)
    if (n.kind == ir::Kind::Workpiece) {
      if (only)
        return nullptr;
      only = &n;
    }
  return only;
}

InProcessStock::InProcessStock(const ir::Module &module, double cell) : module_(module), cell_(cell) {}

cutting::HeightMap &InProcessStock::of(const std::string &setup) {
  if (auto it = stocks_.find(setup); it != stocks_.end())
    return it->second;
  // The stock's extent: the raw piece and everything this setup's moves sweep.
  const std::optional<ir::RawBlock> raw = ir::rawBlock(setupWorkpiece(module_, setup));
  geom::Box box = raw ? raw->box : geom::Box{};
  double top = raw ? raw->top : -kInf;
  for (const ir::Node *e : ir::programOrder(module_)) {
    const ir::Node *moves = ir::millingMoves(*e);
    if (!moves || moves->text("setup").value_or("") != setup)
      continue;
    const double r = toolRadius(ir::findTool(module_, moves->text("tool").value_or("")));
    for (const ir::Move &m : ir::walkMoves(*moves))
      if (m.isFeed())
        box.add(geom::Box{m.to.head<2>(), m.to.head<2>()}.grown(r + 1));
    // No block raw piece: material up to the highest feature top.
    if (!raw)
      if (auto f = e->text("feature"))
        if (const ir::Node *feature = ir::findFeature(module_, *f))
          if (auto shape = ir::featureShape(module_, *feature).shape)
            top = std::max(top, shape->top);
  }
  if (box.empty())
    box = geom::Box{Vec2(0, 0), Vec2(1, 1)};
  // Keep the grid within about 25 million cells.
  double cell = cell_;
  const Vec2 size = box.hi - box.lo;
  while (size.x() / cell * size.y() / cell > 25e6)
    cell *= 1.25;
  cutting::HeightMap map(box.grown(2 * cell), cell);
  if (raw) {
    map.addBlock(raw->box.lo, raw->box.hi, raw->top);
  } else if (std::isfinite(top)) {
    map.addBlock(box.lo, box.hi, top);
    notes_.push_back("setup " + (setup.empty() ? std::string("(none)") : setup) +
                     ": no block raw piece; material assumed up to the highest feature "
                     "top, z=" +
                     formatFixed(top, 3) + " mm, over the toolpath's extent");
  }
  return stocks_.emplace(setup, std::move(map)).first->second;
}

void InProcessStock::cut(cutting::HeightMap &stock, const ir::Move &m, double radius, double point) {
  if (!m.isFeed() || !m.from || radius <= 0)
    return;
  const double cutStep = std::max(stock.cell(), 0.05);
  if (m.kind == ir::MoveKind::Arc && !m.plane.isXY()) {
    // An arc in the ZX or YZ plane: along its chords, each at the heights of its ends.
    const std::vector<ir::Vec3> points = m.chordPoints(ir::kOutOfPlaneArcChord);
    for (size_t k = 1; k < points.size(); ++k) {
      const Vec2 a = points[k - 1].head<2>(), b = points[k].head<2>();
      if ((b - a).norm() <= 1e-9)
        stock.cutDisc(b, radius, std::min(points[k - 1].z(), points[k].z()) + point);
      else
        stock.cutAlong(geom::Seg::line(a, b), radius, points[k - 1].z() + point, points[k].z() + point, cutStep);
    }
    return;
  }
  const std::vector<geom::Seg> segs = m.planar();
  if (segs.empty()) {
    stock.cutDisc(m.to.head<2>(), radius, std::min(m.from->z(), m.to.z()) + point);
    return;
  }
  double zAt = m.from->z(), total = 0, run = 0;
  for (const geom::Seg &seg : segs)
    total += seg.length();
  for (const geom::Seg &seg : segs) {
    const double z0 = zAt;
    run += seg.length();
    zAt = m.from->z() + (m.to.z() - m.from->z()) * std::min(1.0, run / std::max(total, 1e-12));
    stock.cutAlong(seg, radius, z0 + point, zAt + point, cutStep);
  }
}

std::optional<StockHit> rapidMeetsStock(const cutting::HeightMap &stock, const ir::Move &m, double radius,
                                        double point, double tolerance) {
  if (!m.from)
    return std::nullopt;
  const Vec2 a = m.from->head<2>(), b = m.to.head<2>();
  if ((b - a).norm() <= 1e-9 && m.to.z() >= m.from->z())
    return std::nullopt;
  const cutting::HeightMap::Peak peak = stock.highest(a, b, std::max(0.0, radius - stock.cell()));
  const double low = std::min(m.from->z(), m.to.z()) + point;
  if (!(peak.height > low + tolerance))
    return std::nullopt;
  return StockHit{peak.height, peak.at};
}

double rapidCheckCell(const ir::Module &module) {
  double smallest = kInf;
  for (const ir::Node *e : ir::programOrder(module))
    if (const ir::Node *m = ir::millingMoves(*e))
      if (const double r = toolRadius(ir::findTool(module, m->text("tool").value_or(""))); r > 0)
        smallest = std::min(smallest, r);
  return std::clamp(std::isfinite(smallest) ? smallest / 20 : 0.25, 0.02, 0.25);
}

void walkStock(const ir::Module &module, double cell, const std::function<void(const StockMove &)> &visit) {
  InProcessStock stocks(module, cell);
  std::optional<ir::Vec3> position;
  std::string lastTool;
  for (const ir::Node *e : ir::programOrder(module)) {
    const ir::Node *moves = ir::millingMoves(*e);
    if (!moves)
      continue;
    const std::string toolSymbol = moves->text("tool").value_or("");
    const ir::Node *tool = ir::findTool(module, toolSymbol);
    // Where a tool change leaves the tool is the machine's business.
    if (toolSymbol != lastTool)
      position.reset();
    lastTool = toolSymbol;
    const double radius = toolRadius(tool), point = toolPoint(tool);
    cutting::HeightMap &stock = stocks.of(moves->text("setup").value_or(""));
    for (const ir::Move &m : ir::walkMoves(*moves, position)) {
      if (m.from)
        visit({e, &m, radius, point, &stock});
      InProcessStock::cut(stock, m, radius, point);
      position = m.to;
    }
  }
}

} // namespace stepnc::passes
