// An independent check of a deflection-compensated program against the
// cutting model: for every wall a finishing move cuts in the program as it
// was (one-sided engagement at a sample of the cutting model), find the
// move of the compensated program whose predicted path (`nominal`) passes
// there, read its offset where the programmed move runs beside the sample
// (along the wall's normal) and its feed, and evaluate the
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
  for (const ir::Node *e : ir::programOrder(after))
    if (const ir::Node *m = e->child(ir::Kind::Moves))
      moved.push_back(m);
  if (moved.size() != analysis.steps.size()) {
    out.failures.push_back("the programs have different workingsteps");
    return out;
  }
  for (size_t i = 0; i < analysis.steps.size(); ++i) {
    const CutStep &step = analysis.steps[i];
    if (!finishesWalls(step) || !step.tool || !step.tool->mill || !step.material)
      continue;
    const std::vector<ir::Move> programmed = ir::walkMoves(*moved[i]);
    const std::vector<ir::Move> predicted = ir::walkMoves(*moved[i], std::nullopt, ir::PathKind::Predicted);
    const double perFz = step.cutter.flutes * step.spindle; // mm/min per mm of fz
    for (const CutMove &cm : step.moves)
      for (const CutSample &s : cm.samples) {
        if (!engagesPartWall(analysis, step, s, cm.move.to.z()))
          continue;
        ++out.walls;
        const double z = cm.move.to.z();
        size_t found = predicted.size();
        for (size_t j = 0; j < predicted.size() && found == predicted.size(); ++j) {
          const ir::Move &m = predicted[j];
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
        // Where the programmed move runs beside the sample, along the
        // wall's normal: a line where it crosses the normal (its offset
        // may change along it), an arc at its radius about its centre.
        const ir::Move &p = programmed[found];
        const geom::Vec2 n = s.intoWall();
        double offset = 0;
        if (p.kind == ir::MoveKind::Arc) {
          // s.at + offset n on the circle: the root nearest the sample.
          const geom::Vec2 w = s.at - p.center.head<2>();
          const double r = (p.to - p.center).head<2>().norm(), half = w.dot(n);
          const double disc = half * half - (w.squaredNorm() - r * r);
          if (disc < 0) {
            out.failures.push_back(where.str() + ": the programmed arc does not pass beside the wall");
            continue;
          }
          offset = half >= 0 ? -half + std::sqrt(disc) : -half - std::sqrt(disc);
        } else {
          const geom::Vec2 a = p.from->head<2>(), d = (p.to - *p.from).head<2>();
          const double den = geom::cross(n, d);
          if (std::abs(den) < 1e-12) {
            out.failures.push_back(where.str() + ": the programmed move runs along the wall's normal");
            continue;
          }
          offset = geom::cross(a - s.at, d) / den; // s.at + offset n lies on the line
        }
        if (offset < -1e-9)
          out.failures.push_back(where.str() + ": offset away from the wall");
        if (offset > 1e-9)
          ++out.offsetWalls;
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
