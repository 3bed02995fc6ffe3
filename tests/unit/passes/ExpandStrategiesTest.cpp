// Strategy expansion checked by the independent verifier: random polygonal
// pockets (seeded) must expand without gouge and with less than 0.1 % uncut at
// the floor, for each strategy; and a move pushed 0.5 mm towards a wall must
// be caught.
#include "passes/PassManager.h"
#include "passes/PassRegistry.h"

#include "../ir/SampleModule.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>

using namespace stepnc;

namespace {

std::string fixed(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(4);
  s << (std::abs(v) < 5e-5 ? 0.0 : v);
  return s.str();
}

std::string point(double x, double y, double z) {
  return "(" + fixed(x) + "," + fixed(y) + "," + fixed(z) + ")mm";
}

/// A closed pocket of the given outline (counter-clockwise), 6 mm deep, cut by
/// one rough milling workingstep with a 10 mm end mill.
std::string pocketProgram(const std::vector<std::pair<double, double>> &outline, const std::string &strategy,
                          const std::string &operationExtra = "", bool finish = false) {
  std::string t = "project \"P\"\n  workpiece %wp \"WP\"\n"
                  "    closed_pocket %p \"P\" at=" + point(0, 0, 0) +
                  " axis=(0.000000,0.000000,1.000000) ref=(1.000000,0.000000,0.000000) depth=6.0000mm "
                  "bottom=planar\n      general_profile closed=true\n        polyline\n";
  for (size_t i = 0; i <= outline.size(); ++i) {
    const auto &[x, y] = outline[i % outline.size()];
    t += "          point at=" + point(x, y, 0) + "\n";
  }
  t += "  tool %mill \"MILL\" type=endmill diameter=10.0000mm\n"
       "  workplan @main \"MAIN\"\n"
       "    workingstep @rough \"ROUGH\" feature=%p secplane=20.0000mm\n"
       "      bottom_and_side_rough_milling \"ROUGH\" tool=%mill axial_depth=3.0000mm" + operationExtra + "\n"
       "        technology feed=1000.0mm/min spindle=-6000.0rev/min feed_reference=tcp\n"
       "        strategy type=" + strategy + "\n";
  if (finish)
    t += "    workingstep @finish \"FINISH\" feature=%p secplane=20.0000mm\n"
         "      bottom_and_side_finish_milling \"FINISH\" tool=%mill\n"
         "        technology feed=800.0mm/min spindle=-7000.0rev/min feed_reference=tcp\n"
         "        strategy type=contour_parallel cutmode=climb\n";
  return t;
}

struct Run {
  bool ok = false;
  std::vector<std::string> errors;
  std::unique_ptr<ir::Module> module;
  std::unique_ptr<SourceFile> source;
};

Run runPipeline(const std::string &text, const char *pipelineText, ir::Module *replace = nullptr) {
  Run r;
  auto parsed = ir::test::parse(text);
  REQUIRE(parsed.errors.empty());
  r.source = std::move(parsed.source);
  r.module = std::move(parsed.module);
  if (replace)
    *r.module = *replace;
  std::string error;
  auto pipeline = passes::parsePipeline(pipelineText, error);
  REQUIRE(pipeline);
  DiagnosticCollector sink;
  DiagnosticEngine diags(sink);
  passes::PassManager manager{passes::PassManagerOptions{}};
  manager.add(*pipeline);
  r.ok = manager.run(*r.module, diags);
  r.errors = ir::test::messages(sink);
  return r;
}

/// A random simple polygon: star-shaped about the origin, radii 20..45 mm.
std::vector<std::pair<double, double>> randomPocket(std::mt19937 &rng) {
  std::uniform_int_distribution<int> count(5, 14);
  std::uniform_real_distribution<double> radius(20, 45), jitter(-0.3, 0.3);
  const int n = count(rng);
  std::vector<std::pair<double, double>> pts;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * (i + 0.5 + jitter(rng)) / n;
    const double r = radius(rng);
    pts.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  return pts;
}

/// The uncut percentage the verifier wrote on the first `moves` node.
double uncutPercent(const ir::Module &m) {
  ir::Node root = m.root;
  const ir::Node &moves = ir::test::find(root, "moves");
  const size_t at = moves.comment.find("mm2 (", moves.comment.find("uncut"));
  REQUIRE(at != std::string::npos);
  return std::stod(moves.comment.substr(at + 5));
}

} // namespace

// Roughing with allowances then finishing: the verifier fails the pipeline on
// any gouge, and when both together leave 0.1 % or more of the pocket uncut.
// Contour roughing alone must also stay below 0.1 % beyond its allowance
// (a zigzag's scallops are the finishing step's work).
TEST_CASE("random polygonal pockets expand without gouge and leave < 0.1 % uncut", "[expand][property]") {
  std::mt19937 rng(20261121);
  // A few hundred pockets over the strategies (fewer under sanitizers: same seeds, same checks).
#if defined(__SANITIZE_ADDRESS__)
  const int cases = 60;
#else
  const int cases = 240;
#endif
  const char *strategies[] = {"contour_parallel", "contour_spiral", "bidirectional", "contour_bidirectional"};
  int failures = 0;
  for (int i = 0; i < cases; ++i) {
    const auto outline = randomPocket(rng);
    const std::string strategy = strategies[i % 4];
    Run r = runPipeline(pocketProgram(outline, strategy, " allowance_side=0.5000mm allowance_bottom=0.3000mm", true),
                        "expand-strategies,verify-toolpaths");
    INFO("case " << i << ", strategy " << strategy << ", " << outline.size() << " vertices");
    std::string all;
    for (const std::string &e : r.errors)
      all += e + "\n";
    INFO(all);
    if (!r.ok) {
      ++failures;
      CHECK(r.ok);
      continue;
    }
    if (strategy.starts_with("contour"))
      CHECK(uncutPercent(*r.module) < 0.1);
  }
  CHECK(failures == 0);
}

TEST_CASE("a move pushed 0.5 mm towards the wall is caught by the verifier", "[expand][mutation]") {
  const std::vector<std::pair<double, double>> square = {{0, 0}, {40, 0}, {40, 30}, {0, 30}};
  Run expanded = runPipeline(pocketProgram(square, "contour_parallel"), "expand-strategies,verify-toolpaths");
  REQUIRE(expanded.ok);
  // Every cutting move at the floor, one at a time, pushed outward from the
  // pocket's centre by 0.5 mm: each mutant must fail verification.
  ir::Node &moves = ir::test::find(expanded.module->root, "moves");
  int mutants = 0, caught = 0;
  for (size_t k = 0; k < moves.children.size(); ++k) {
    ir::Node &m = moves.children[k];
    if (m.kind != ir::Kind::Linear || m.text("role") != "cut" || m.vec("to")->z() > -5.9)
      continue;
    // Only moves ending on the outermost ring (a radius from the walls) can gouge when pushed out.
    const ir::Vec3 p = *m.vec("to");
    if (std::min({std::abs(p.x() - 5), std::abs(p.x() - 35), std::abs(p.y() - 5), std::abs(p.y() - 25)}) > 1e-6)
      continue;
    ir::Module mutant = *expanded.module;
    ir::Node &mm = ir::test::find(mutant.root, "moves").children[k];
    ir::Vec3 to = *mm.vec("to");
    const ir::Vec3 centre(20, 15, to.z());
    ir::Vec3 out = to - centre;
    out.z() = 0;
    to += out.normalized() * 0.5;
    mm.set("to", ir::Value::point(to));
    ir::test::find(mutant.root, "moves").comment.clear();
    Run r = runPipeline(pocketProgram(square, "contour_parallel"), "verify-toolpaths", &mutant);
    ++mutants;
    caught += r.ok ? 0 : 1;
  }
  CHECK(mutants > 0);
  CHECK(caught == mutants);
}

TEST_CASE("rings of a pocket with an arc corner stay arcs", "[expand]") {
  // A rounded rectangle pocket keeps circular corners in its rings.
  std::string text = "project \"P\"\n  workpiece %wp \"WP\"\n"
                     "    closed_pocket %p \"P\" at=(0.0000,0.0000,0.0000)mm axis=(0.000000,0.000000,1.000000) "
                     "ref=(1.000000,0.000000,0.000000) depth=4.0000mm bottom=planar orthogonal_radius=8.0000mm\n"
                     "      rectangular_profile width=40.0000mm length=60.0000mm\n"
                     "  tool %mill \"MILL\" type=endmill diameter=10.0000mm\n"
                     "  workplan @main \"MAIN\"\n"
                     "    workingstep @rough \"ROUGH\" feature=%p secplane=20.0000mm\n"
                     "      bottom_and_side_finish_milling \"FINISH\" tool=%mill\n"
                     "        technology feed=1000.0mm/min spindle=-6000.0rev/min feed_reference=tcp\n"
                     "        strategy type=contour_parallel cutmode=climb\n"
                     "        approach type=plunge_helix radius=2.0000mm angle=5.0000deg\n";
  Run r = runPipeline(text, "expand-strategies,verify-toolpaths");
  REQUIRE(r.ok);
  ir::Node &moves = ir::test::find(r.module->root, "moves");
  int arcs = 0, helices = 0;
  double lastZ = 20;
  for (const ir::Node &m : moves.children) {
    const double z = m.vec("to")->z();
    if (m.kind == ir::Kind::Arc) {
      ++arcs;
      if (std::abs(z - lastZ) > 1e-9)
        ++helices;
      else
        CHECK(m.text("dir") == "ccw");  // climb with an M3 spindle: outer rings counter-clockwise
    }
    lastZ = z;
  }
  CHECK(arcs >= 4);
  CHECK(helices == 1);
  CHECK(uncutPercent(*r.module) < 0.1);
}
