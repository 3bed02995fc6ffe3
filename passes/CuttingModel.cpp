// The cutting model of a program (see CuttingModel.h).
//
// Stock: the in-process stock of passes/InProcessStock.h, cut by every feed
// move in program order. Each horizontal milling move is measured
// before it is cut, at samples along it, each sample on the stock as the
// move left it up to the sample before: the material in front of a line is
// never what the line itself removed.
#include "passes/CuttingModel.h"

#include "passes/InProcessStock.h"

#include "ir/Kinds.h"
#include "ir/geom/FeatureShape.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

namespace stepnc::passes {

namespace {

using geom::Vec2;

constexpr double kInf = std::numeric_limits<double>::infinity();

bool isMill(const std::string &type) { return type.find("mill") != std::string::npos; }

/// Samples along a move's plane path: (distance from start, point, direction).
struct PathPoint {
  double s;
  Vec2 at, dir;
};

std::vector<PathPoint> samplePath(const std::vector<geom::Seg> &segs, double step) {
  std::vector<PathPoint> out;
  double offset = 0;
  for (const geom::Seg &seg : segs) {
    const double len = seg.length();
    const int n = std::max(1, int(std::ceil(len / step)));
    for (int i = 0; i < n; ++i) {
      // The first sample a little past the start, so that the direction is the
      // move's own.
      const double t = std::min(1.0, (i + 0.5) / n);
      out.push_back({offset + t * len, seg.at(t), seg.tangent(t)});
    }
    offset += len;
  }
  return out;
}

/// The sample at `s` mm along a move's plane path.
PathPoint pathPointAt(const std::vector<geom::Seg> &segs, double s) {
  double offset = 0;
  for (size_t i = 0; i < segs.size(); ++i) {
    const double len = segs[i].length();
    if (s <= offset + len || i + 1 == segs.size()) {
      const double t = std::clamp(len > 0 ? (s - offset) / len : 0.0, 0.0, 1.0);
      return {s, segs[i].at(t), segs[i].tangent(t)};
    }
    offset += len;
  }
  return {s, Vec2::Zero(), Vec2::UnitX()};
}

std::optional<ir::Kind> operationKind(const ir::Node &executable) {
  const ir::Node *op = ir::operationOf(executable);
  return op ? std::optional<ir::Kind>(op->kind) : std::nullopt;
}

} // namespace

MaterialChoice chooseMaterial(const ir::Node *workpiece, const cutting::CuttingData &data) {
  MaterialChoice c;
  const std::string id = workpiece ? workpiece->text("material").value_or("") : "";
  const std::string standard = workpiece ? workpiece->text("material_standard").value_or("") : "";
  std::string alias;
  if (const cutting::Material *m = data.match(id, standard, alias)) {
    c.material = m;
    c.note = "material '" + id + (standard.empty() ? "" : "' ('" + standard) + (standard.empty() ? "'" : "')") +
             " read as " + m->key + " (" + m->name + ", matched '" + alias + "')";
    return c;
  }
  const auto it = data.materials.find(data.defaultMaterial);
  c.material = it != data.materials.end() ? &it->second : nullptr;
  c.note = (workpiece ? "material '" + id + "' ('" + standard + "') is not in the cutting data"
                      : std::string("no workpiece names a material")) +
           ": defaulted to " + data.defaultMaterial;
  return c;
}

double spindleTorqueLimit(const runtime::Machine &machine, double rpm) {
  double limit = machine.spindleTorque.value_or(kInf);
  const double omega = 2 * std::numbers::pi * rpm / 60; // rad/s
  if (omega > 0 && machine.spindlePower > 0)
    limit = std::min(limit, machine.spindlePower * 1000 / omega);
  return limit;
}

CutterSetup cutterSetup(const ir::Node &tool, const cutting::CuttingData &data) {
  CutterSetup t;
  t.symbol = tool.symbol;
  const std::string type = tool.text("type").value_or("");
  t.mill = isMill(type);
  const std::string key = tool.symbol.size() > 1 ? tool.symbol.substr(1) : tool.symbol;
  const cutting::ToolData *user = nullptr;
  if (auto it = data.tools.find(key); it != data.tools.end())
    user = &it->second;
  const double d = tool.number("diameter").value_or(0);
  t.cutter.radius = d / 2;
  if (auto n = tool.count("flutes"); n && *n > 0) {
    t.cutter.flutes = int(*n);
  } else {
    t.cutter.flutes = 2;
    t.defaulted.push_back("flutes 2 (the file gives none)");
  }
  double flute = tool.number("cutting_edge_length").value_or(0);
  if (user && user->fluteLength) {
    flute = *user->fluteLength;
  } else if (!(flute > 0)) {
    flute = 2 * d;
    t.defaulted.push_back("flute length " + formatShortest(flute) + " mm (2 x diameter)");
  }
  t.cutter.fluteLength = flute;
  double overhang = flute + d;
  if (user && user->overhang) {
    overhang = *user->overhang;
  } else {
    // STEP-NC gives the tool's length from its gauge line, not how far it
    // stands out of the holder; a tool is clamped as short as its flutes allow.
    const double length = tool.number("overall_length").value_or(tool.number("offset_length").value_or(0));
    if (length > flute)
      overhang = std::min(overhang, length);
    t.defaulted.push_back("overhang " + formatShortest(overhang) + " mm (flute length + diameter)");
  }
  t.beam.overhang = std::max(overhang, flute);
  t.beam.fluteLength = flute;
  t.beam.diameter = d;
  t.beam.fluteDiameter = 0.8 * d;
  t.toolMaterial = user && user->material ? *user->material : "carbide";
  if (!(user && user->material))
    t.defaulted.push_back("material carbide");
  cutting::ToolMaterial tm;
  if (auto it = data.toolMaterials.find(t.toolMaterial); it != data.toolMaterials.end())
    tm = it->second;
  t.beam.modulus = tm.modulus;
  if (user && user->maxForce) {
    t.maxForce = *user->maxForce;
  } else {
    // The force at mid-flute that stresses the shank at the clamp to the
    // material's allowed bending stress.
    t.maxForce = d > 0 ? cutting::forceForClampStress(t.beam, tm.allowedStress, flute / 2) : kInf;
    t.defaulted.push_back("max force " + formatFixed(t.maxForce, 0) + " N (" + formatShortest(tm.allowedStress) +
                          " N/mm2 bending at the clamp)");
  }
  return t;
}

CutAnalysis analyseCuts(const ir::Module &module, const CutOptions &options) {
  const cutting::CuttingData &data = *options.data;
  CutAnalysis out;
  for (const ir::Node &n : module.root.children)
    if (n.kind == ir::Kind::Tool)
      out.tools.emplace(n.symbol, cutterSetup(n, data));

  // The steps in program order, grouped by setup for the stock's extent.
  struct Pending {
    const ir::Node *exec;
    const ir::Node *moves;
    std::string setup;
  };
  std::vector<Pending> pending;
  double smallest = kInf;
  for (const ir::Node *e : ir::programOrder(module))
    if (const ir::Node *m = ir::millingMoves(*e)) {
      pending.push_back({e, m, m->text("setup").value_or("")});
      if (auto t = out.tools.find(m->text("tool").value_or(""));
          t != out.tools.end() && t->second.mill && t->second.cutter.radius > 0)
        smallest = std::min(smallest, t->second.cutter.radius);
    }
  out.cell = std::clamp(std::isfinite(smallest) ? smallest / 60 : 0.1, 0.02, 0.25);

  InProcessStock stocks(module, out.cell);
  std::map<std::string, MaterialChoice> materials;
  std::optional<ir::Vec3> position;
  for (const Pending &p : pending) {
    CutStep step;
    step.executable = p.exec;
    step.movesNode = p.moves;
    step.operation = operationKind(*p.exec);
    step.asWritten = ir::runsAsWritten(*p.exec);
    if (auto t = out.tools.find(p.moves->text("tool").value_or("")); t != out.tools.end())
      step.tool = &t->second;
    const double spindle = p.moves->number("spindle").value_or(0);
    step.spindle = std::abs(spindle);
    step.setup = p.setup;
    // One cut move per move of the IR (an arc out of the XY plane too: its
    // feed is kept as programmed, and the stock cut along its chords).
    for (const ir::Move &m : ir::walkMoves(*p.moves, position, ir::PathKind::Programmed, ir::OutOfPlaneArcs::Exact)) {
      CutMove cm;
      cm.move = m;
      step.moves.push_back(std::move(cm));
      position = m.to;
    }

    auto mat = materials.find(p.setup);
    if (mat == materials.end()) {
      const ir::Node *wp = setupWorkpiece(module, p.setup);
      mat = materials.emplace(p.setup, chooseMaterial(wp, data)).first;
      out.notes.push_back(mat->second.note);
    }
    step.material = mat->second.material;

    const size_t notesBefore = stocks.notes().size();
    cutting::HeightMap &map = stocks.of(p.setup);
    out.notes.insert(out.notes.end(), stocks.notes().begin() + long(notesBefore), stocks.notes().end());

    const CutterSetup *tool = step.tool;
    const double radius = tool ? tool->cutter.radius : 0;
    if (tool)
      step.cutter = tool->cutter;
    step.cutter.clockwise = spindle <= 0;
    const cutting::Cutter &cutter = step.cutter;
    const cutting::Material *material = step.material;
    const bool model = tool && tool->mill && radius > 0 && material && step.spindle > 0;
    const double torqueLimit = options.machine ? spindleTorqueLimit(*options.machine, step.spindle) : kInf;
    const double sampleStep = std::max(2 * map.cell(), std::min(radius / 4, 1.0));
    // Hole-making tools cut to where their point reaches full diameter.
    const double point = tool && !tool->mill ? ir::pointLength(*ir::findResource(module, ir::Kind::Tool, tool->symbol)) : 0;
    for (CutMove &cm : step.moves) {
      const ir::Move &m = cm.move;
      if (!m.isFeed() || !m.from || radius <= 0)
        continue;
      const std::vector<geom::Seg> segs = m.planar();
      if (model && !step.asWritten && !m.changesHeight() && !segs.empty() && m.plane.isXY()) {
        cm.measured = true;
        cm.fz = m.feed / (cutter.flutes * step.spindle);
        const cutting::CuttingCoefficients k = material->coefficients();
        const double z = m.to.z();
        auto measure = [&](const PathPoint &pp) {
          const cutting::Engagement e = cutting::measureEngagement(map, pp.at, z, pp.dir, cutter);
          CutSample s;
          s.s = pp.s;
          s.at = pp.at;
          s.dir = pp.dir;
          if (e.cutting()) {
            const cutting::ForceModel f(e, cutter, k);
            s.chipFactor = e.chipFactor();
            s.ae = e.radialDepth(radius);
            s.ap = e.axialDepth();
            s.side = e.side();
            s.fzForce = f.fzForForce(tool->maxForce);
            s.fzTorque = f.fzForTorque(torqueLimit);
            s.force = f.peakForce(cm.fz);
            s.torque = f.meanTorque(cm.fz);
          } else {
            s.fzForce = s.fzTorque = kInf;
          }
          return s;
        };
        // Where the chip changes by more than kFeedRatio between two
        // samples (entering and leaving material, corners), samples are
        // added halfway until they are two cells apart, so that the feeds
        // can follow the engagement there.
        const double finest = 2 * map.cell();
        auto refine = [&](auto &self, const CutSample &a, const CutSample &b) -> void {
          const double lo = std::min(a.chipFactor, b.chipFactor), hi = std::max(a.chipFactor, b.chipFactor);
          if (b.s - a.s <= finest || lo >= kFeedRatio * hi)
            return;
          const CutSample mid = measure(pathPointAt(segs, (a.s + b.s) / 2));
          self(self, a, mid);
          cm.samples.push_back(mid);
          self(self, mid, b);
        };
        for (const PathPoint &pp : samplePath(segs, sampleStep)) {
          CutSample s = measure(pp);
          if (!cm.samples.empty()) // a copy: refining appends to the samples
            refine(refine, CutSample(cm.samples.back()), s);
          cm.samples.push_back(std::move(s));
        }
      }
      InProcessStock::cut(map, m, radius, point);
    }
    out.steps.push_back(std::move(step));
  }
  out.finished = stocks.take();
  return out;
}

bool finishesWalls(const CutStep &step) {
  return step.operation && ir::hasTraits(*step.operation, ir::Trait::WallFinishing);
}

bool engagesPartWall(const CutAnalysis &analysis, const CutStep &step, const CutSample &sample, double z) {
  if (sample.side == 0 || !(sample.chipFactor > 0) || !step.tool)
    return false;
  const auto it = analysis.finished.find(step.setup);
  if (it == analysis.finished.end())
    return false;
  const cutting::HeightMap &part = it->second;
  // Just past the tool's edge, into the material.
  const Vec2 probe = sample.at + (step.cutter.radius + 1.5 * part.cell()) * sample.intoWall();
  return part.at(probe) > z + 0.05 * part.cell();
}

WallBend wallBend(const CutStep &step, const CutSample &sample, double offset, double fz) {
  const cutting::Engagement e =
      cutting::wallEngagement(sample.dir, sample.side, sample.ae + offset, sample.ap, step.cutter);
  const double push =
      cutting::ForceModel(e, step.cutter, step.material->coefficients()).peakPush(sample.intoWall(), fz);
  if (!(push > 0))
    return {};
  const cutting::ToolBeam &beam = step.tool->beam;
  const double h = std::min(sample.ap, step.cutter.fluteLength);
  return {cutting::deflectionUnderSpreadLoad(beam, push, h, 0),
          cutting::deflectionUnderSpreadLoad(beam, push, h, h / 2),
          cutting::deflectionUnderSpreadLoad(beam, push, h, h)};
}

} // namespace stepnc::passes
