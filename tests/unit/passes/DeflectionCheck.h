// An independent check of a deflection-compensated program against the
// cutting model: for every wall a finishing move cuts in the program as it
// was (one-sided engagement at a sample of the cutting model), find the
// move of the compensated program whose predicted path (`nominal`) passes
// there, read its offset from its geometry and its feed, and evaluate the
// bend of the tool at mid-height of the cut on the model (passes::wallBend). The residual |bend - offset| is
// the position error the compensated program is predicted to leave.
#pragma once

#include "passes/CuttingModel.h"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace stepnc::test {

struct DeflectionCheck {
  size_t walls = 0;         ///< wall samples checked
  size_t offsetWalls = 0;   ///< of which on an offset move
  double worstResidual = 0; ///< mm
  double worstBefore = 0;   ///< mm, the position error of the nominal program
  double largestOffset = 0; ///< mm
  std::vector<std::string> failures;
};

inline DeflectionCheck checkDeflection(const ir::Module &before, const ir::Module &after,
                                       const cutting::CuttingData &data) {
  using namespace passes;
  DeflectionCheck out;
  const CutAnalysis analysis = analyseCuts(before, {&data, nullptr});
  std::vector<const ir::Node *> moved;
  for (const ir::Node *e : programOrder(after))
    if (const ir::Node *m = e->child("moves"))
      moved.push_back(m);
  if (moved.size() != analysis.steps.size()) {
    out.failures.push_back("the programs have different workingsteps");
    return out;
  }
  for (size_t i = 0; i < analysis.steps.size(); ++i) {
    const CutStep &step = analysis.steps[i];
    if (!finishesWalls(step) || !step.tool || !step.tool->mill || !step.material)
      continue;
    const std::vector<Move> programmed = walkMoves(*moved[i]);
    const std::vector<Move> predicted = walkMoves(*moved[i], std::nullopt, PathKind::Predicted);
    const double perFz = step.cutter.flutes * step.spindle; // mm/min per mm of fz
    for (const CutMove &cm : step.moves)
      for (const CutSample &s : cm.samples) {
        if (!engagesPartWall(analysis, step, s, cm.move.to.z()))
          continue;
        ++out.walls;
        const double z = cm.move.to.z();
        size_t found = predicted.size();
        for (size_t j = 0; j < predicted.size() && found == predicted.size(); ++j) {
          const Move &m = predicted[j];
          if (!m.isFeed() || !m.from || m.changesHeight() || std::abs(m.to.z() - z) > 1e-9)
            continue;
          for (const geom::Seg &seg : m.planar())
            if (geom::distance(seg, s.at) < 1e-6)
              found = j;
        }
        std::ostringstream where;
        where << step.executable->symbol << " at (" << s.at.x() << ", " << s.at.y() << ", " << z << ")";
        if (found == predicted.size()) {
          out.failures.push_back(where.str() + ": no move of the predicted path passes the wall");
          continue;
        }
        const Move &p = programmed[found];
        // How far the programmed move stands from the predicted one at the
        // sample: a line's shift, an arc's change of radius along its radius.
        geom::Vec2 shift = (p.to - predicted[found].to).head<2>();
        if (p.kind == MoveKind::Arc) {
          const geom::Vec2 c = p.center.head<2>();
          shift = ((p.to.head<2>() - c).norm() - (predicted[found].to.head<2>() - c).norm()) * (s.at - c).normalized();
        }
        const double offset = shift.norm();
        if (offset > 0) {
          ++out.offsetWalls;
          if (shift.dot(s.intoWall()) < 0.99 * offset)
            out.failures.push_back(where.str() + ": offset away from the wall");
        }
        if (p.feed > cm.move.feed)
          out.failures.push_back(where.str() + ": feed raised");
        const double bend = wallBend(step, s, offset, p.feed / perFz).mid;
        out.worstResidual = std::max(out.worstResidual, std::abs(bend - offset));
        out.worstBefore = std::max(out.worstBefore, wallBend(step, s, 0, cm.fz).mid);
        out.largestOffset = std::max(out.largestOffset, offset);
      }
  }
  return out;
}

} // namespace stepnc::test
