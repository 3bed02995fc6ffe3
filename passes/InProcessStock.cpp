// The in-process stock (see InProcessStock.h).
#include "passes/InProcessStock.h"

#include "ir/Kinds.h"
#include "ir/Program.h"
#include "geom/Boolean.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "ir/geom/TurnedShape.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <functional>
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

namespace {

/// The turning and deposition steps on `workpiece` that run before the
/// first milling step of `setup`, in program order: what the milling stock
/// starts from besides the raw piece.
std::vector<const ir::Node *> otherProcessesBefore(const ir::Module &module, const std::string &setup,
                                                   const ir::Node *workpiece) {
  std::vector<const ir::Node *> out;
  for (const ir::Node *e : ir::programOrder(module)) {
    if (const ir::Node *moves = ir::millingMoves(*e); moves && moves->text("setup").value_or("") == setup)
      break;
    if (!ir::isTurningStep(*e) && !ir::isAdditiveStep(*e))
      continue;
    const ir::Node *feature = ir::findFeature(module, e->text("feature").value_or(""));
    if (feature && ir::workpieceOf(module, *feature) == workpiece)
      out.push_back(e);
  }
  return out;
}

/// The body a cylinder raw piece about the z axis is turned into by
/// `steps` (their features' removals taken from it), as the height of its
/// top at each distance from the axis (-infinity beyond it); none without a
/// cylinder raw piece or a turning step.
std::optional<std::function<double(double)>> turnedBody(const ir::Module &module, const ir::Node *workpiece,
                                                       const std::vector<const ir::Node *> &steps, double step,
                                                       double &radius) {
  const ir::StockResult stock = ir::turnStock(workpiece);
  if (!stock.stock)
    return std::nullopt;
  std::vector<geom::Region> removals;
  for (const ir::Node *e : steps)
    if (ir::isTurningStep(*e))
      if (const ir::Node *f = ir::findFeature(module, e->text("feature").value_or("")))
        if (auto shape = ir::turnedShape(*f, *stock.stock).shape)
          removals.push_back(shape->removal);
  if (removals.empty())
    return std::nullopt;
  const geom::Region part = geom::subtract(stock.stock->region(), geom::uniteAll(removals));
  radius = stock.stock->radius;
  // The top at radii `step` apart: the highest z of the part at that radius.
  std::vector<double> tops;
  for (double r = step / 2; r < radius; r += step) {
    double top = -kInf;
    for (const geom::Seg &piece : geom::clip(part, Vec2(stock.stock->z0 - 1, r), Vec2(stock.stock->z1 + 1, r)))
      top = std::max({top, piece.a.x(), piece.b.x()});
    tops.push_back(top);
  }
  return [tops, step](double d) {
    const size_t k = static_cast<size_t>(d / step);
    return k < tops.size() ? tops[k] : -kInf;
  };
}

} // namespace

InProcessStock::InProcessStock(const ir::Module &module, double cell) : module_(module), cell_(cell) {}

cutting::HeightMap &InProcessStock::of(const std::string &setup) {
  if (auto it = stocks_.find(setup); it != stocks_.end())
    return it->second;
  // The stock's extent: the raw piece, what the other processes made of it
  // before (a turned body, deposited beads) and everything this setup's
  // moves sweep.
  const ir::Node *workpiece = setupWorkpiece(module_, setup);
  const std::optional<ir::RawBlock> raw = ir::rawBlock(workpiece);
  const std::vector<const ir::Node *> before = otherProcessesBefore(module_, setup, workpiece);
  double bodyRadius = 0;
  const std::optional<std::function<double(double)>> body =
      raw ? std::nullopt : turnedBody(module_, workpiece, before, std::max(cell_ / 2, 0.01), bodyRadius);
  geom::Box box = raw ? raw->box : geom::Box{};
  if (body)
    box.add(geom::Box{Vec2(-bodyRadius, -bodyRadius), Vec2(bodyRadius, bodyRadius)});
  // Beads: their centre lines, half their width, their tops.
  struct Bead {
    geom::Seg seg;
    double halfWidth, top;
  };
  std::vector<Bead> beads;
  for (const ir::Node *e : before) {
    const ir::Node *op = ir::operationOf(*e);
    const ir::Node *tech = op ? op->child(ir::Kind::DepositionTechnology) : nullptr;
    const ir::Node *moves = e->child(ir::Kind::Moves);
    if (!ir::isAdditiveStep(*e) || !tech || !moves)
      continue;
    const double w = tech->number("bead_width").value_or(0), t = tech->number("bead_height").value_or(0);
    for (const auto &[m, energy] : ir::walkWithEnergy(*moves))
      if (energy && m.isFeed() && m.from)
        for (const geom::Seg &seg : m.planar()) {
          beads.push_back({seg, w / 2, std::min(m.from->z(), m.to.z()) + t});
          box.add(seg.box().grown(w / 2));
        }
  }
  double top = raw ? raw->top : -kInf;
  for (const ir::Node *e : ir::programOrder(module_)) {
    const ir::Node *moves = ir::millingMoves(*e);
    if (!moves || moves->text("setup").value_or("") != setup)
      continue;
    const double r = toolRadius(ir::findTool(module_, moves->text("tool").value_or("")));
    for (const ir::Move &m : ir::walkMoves(*moves))
      if (m.isFeed())
        box.add(geom::Box{m.to.head<2>(), m.to.head<2>()}.grown(r + 1));
    // No raw piece nor material made before: up to the highest feature top.
    if (!raw && !body && beads.empty())
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
  if (raw)
    map.addBlock(raw->box.lo, raw->box.hi, raw->top);
  if (body)
    map.addRevolved(Vec2::Zero(), *body);
  for (const Bead &b : beads) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(b.seg.length() / std::max(cell, b.halfWidth / 2))));
    for (int k = 0; k < pieces; ++k)
      map.addCapsule(b.seg.at(static_cast<double>(k) / pieces), b.seg.at(static_cast<double>(k + 1) / pieces),
                     b.halfWidth, b.top);
  }
  if (raw || body || !beads.empty()) {
    if (body || !beads.empty())
      notes_.push_back("setup " + (setup.empty() ? std::string("(none)") : setup) + ": the stock is what " +
                       std::to_string(before.size()) + " turning and deposition steps before it made" +
                       (body ? " (a turned body" : " (") + (beads.empty() ? ")" : (body ? " and " : "") +
                       std::to_string(beads.size()) + " bead pieces)"));
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
  std::string lastTool, lastSetup;
  for (const ir::Node *e : ir::programOrder(module)) {
    const ir::Node *moves = ir::millingMoves(*e);
    if (!moves)
      continue;
    const std::string toolSymbol = moves->text("tool").value_or("");
    const ir::Node *tool = ir::findTool(module, toolSymbol);
    // Where a tool change leaves the tool is the machine's business; so is
    // where it is after the workpiece is re-clamped or turned to another
    // face (another setup: the program goes up along z first).
    const std::string setup = moves->text("setup").value_or("");
    if (toolSymbol != lastTool || setup != lastSetup)
      position.reset();
    lastTool = toolSymbol;
    lastSetup = setup;
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
