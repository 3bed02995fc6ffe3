// The material that remains as a program runs: per setup, a height field
// (cutting/HeightMap) that starts as the workpiece's block raw piece (else a
// block up to the highest feature top over the extent the setup's feed
// moves sweep) and loses what every feed move sweeps, in program order: a
// milling move the disc of its cutter, a hole-making move the disc of its
// tool down to where the point reaches full diameter.
//
// Read by the cutting model (engagement, measured on the stock a move meets),
// by expand-strategies (the file's own rapids below the security plane are
// kept where the stock shows them clear, lifted where it does not) and by
// verify-toolpaths (no rapid meets the stock).
#pragma once

#include "cutting/HeightMap.h"
#include "ir/Node.h"
#include "ir/geom/MoveWalk.h"

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::passes {

/// The workpiece a setup holds (its first workpiece_setup), else the only
/// workpiece; null when neither names one.
const ir::Node *setupWorkpiece(const ir::Module &module, const std::string &setup);

class InProcessStock {
public:
  /// Grids of `cell` mm (coarser where a setup's extent would pass about 25
  /// million cells).
  InProcessStock(const ir::Module &module, double cell);

  /// The stock of `setup` as the moves walked so far left it; built from
  /// the raw piece at first use.
  cutting::HeightMap &of(const std::string &setup);

  /// Cuts a feed move (its start known) into `stock`: the disc of `radius`
  /// with its lower face `point` mm above the tool's tip.
  static void cut(cutting::HeightMap &stock, const ir::Move &m, double radius, double point);

  /// Every setup's stock as the moves walked so far left it, taken out.
  std::map<std::string, cutting::HeightMap, std::less<>> take() { return std::move(stocks_); }

  /// What the stock's construction assumed (no block raw piece), once per setup.
  const std::vector<std::string> &notes() const { return notes_; }

private:
  const ir::Module &module_;
  double cell_;
  std::map<std::string, cutting::HeightMap, std::less<>> stocks_;
  std::vector<std::string> notes_;
};

/// Where a rapid meets the stock: the highest material the tool's disc meets
/// and where.
struct StockHit {
  double height = 0;
  geom::Vec2 at = geom::Vec2::Zero();
};

/// Whether the rapid `m` (its start known) meets `stock`: the disc of
/// `radius`, `point` mm above the lower of the rapid's two tip heights (as
/// the stock is cut: a hole-making tool's point fills the cone it cut),
/// swept from its start to its end, over material higher than that by more
/// than `tolerance`.
/// The disc is taken one cell narrower than the tool, which the grid cannot
/// tell apart. A rapid straight up along the axis meets nothing: the tool
/// leaves through the space its own body fills.
std::optional<StockHit> rapidMeetsStock(const cutting::HeightMap &stock, const ir::Move &m, double radius,
                                        double point, double tolerance);

/// What walkStock shows a visitor: a move of an executable with the stock
/// as the moves before it left it.
struct StockMove {
  const ir::Node *executable = nullptr;
  const ir::Move *move = nullptr;
  double radius = 0;                       ///< mm, the tool's
  double point = 0;                        ///< mm above its tip where it cuts its full disc
  const cutting::HeightMap *stock = nullptr;
};

/// Walks the program's moves in program order on a stock of `cell` mm,
/// calling `visit` for each move whose start is known (the position is
/// unknown after a tool change) before cutting it into the stock.
void walkStock(const ir::Module &module, double cell, const std::function<void(const StockMove &)> &visit);

/// A grid fine enough to tell a rapid beside a wall from one in it: a
/// twentieth of the smallest radius of the tools the program's moves name,
/// within 0.02 .. 0.25 mm.
double rapidCheckCell(const ir::Module &module);

} // namespace stepnc::passes
