// Directed energy deposition (docs/additive.md): an added feature sliced into
// layers along its build direction, each layer filled with beads (contours
// half a bead inside the section, then infill lines a bead pitch apart),
// every bead reached at its layer's height by a lead-in with the energy
// off, deposited with it on, and left by a lead-out with it off again.
//
// The layer between heights z0 and z0 + t covers everything of the feature
// between those heights seen from above (AmShape::slab), grown by the
// operation's allowance, less the channels (voids) that cross it. The
// programmed point is the deposition point: the centre of the bead's base,
// on the layer below (the head's nozzle is its stand-off above).
#include "ir/geom/AmShape.h"
#include "passes/expand/Expand.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>

namespace stepnc::passes::expand {

namespace {

/// Most layers one step deposits: more come only from a layer thickness far
/// too small for the feature (a micrometre on a block).
constexpr long kMaxLayers = 20000;
/// The most bead one step lays (mm): 50 km, weeks of deposition; more comes
/// only from a feature far larger than a deposition cell builds.
constexpr double kMaxBeadLength = 5e7;
/// How far above the layer being deposited the head travels between beads,
/// over the bead height (mm).
constexpr double kHopClearance = 1.0;
/// The default turn of the contours' start from one layer to the next (deg):
/// the golden angle, so that no two layers' seams stack.
constexpr double kDefaultSeamShift = 137.50776405003785;

/// The layer's fill in the feature's frame: closed contours, then infill
/// paths (each an open chain deposited in one go).
struct LayerPaths {
  std::vector<Loop> contours;
  std::vector<Path2D> infill;
};

struct DepositionPlan {
  double width = 0, height = 0, layer = 0, pitch = 0, infillPitch = 0;
  double allowance = 0;
  double feed = 0, power = 0;
  std::optional<double> powder, wire;
  double dwell = 0;
  double leadIn = 0, leadOut = 0;
  std::string pattern = "contour_then_infill";
  std::string infill = "zigzag";
  int contours = 1;
  double infillAngle = 0, layerRotation = 90, seamShift = kDefaultSeamShift;  // deg
};

Vec2 unit(double deg) { return {std::cos(deg * kPi / 180), std::sin(deg * kPi / 180)}; }

/// Zigzag: each stroke joined to the next by a straight link when the link
/// lies inside the area (every quarter pitch along it inside, or on its
/// boundary within a micrometre: links run along the boundary, where a
/// clip would decide either way), and the bead goes on along it; parallel:
/// every stroke alone, all in one direction.
std::vector<Path2D> infillPaths(const Region &area, const Vec2 &dir, double pitch, bool zigzag) {
  std::vector<Path2D> strokesIn;
  // The outer strokes half a pitch inside the area's extremes across them
  // (a corner of the area is then within half a pitch of a bead); a stroke
  // shorter than a tenth of the pitch (a corner grazed) is no bead.
  for (Path2D &s : strokes(area, dir, pitch, zigzag, pitch / 2))
    if (geom::Chain{s}.length() >= pitch / 10)
      strokesIn.push_back(std::move(s));
  if (!zigzag)
    return strokesIn;
  const geom::SegIndex boundary = geom::SegIndex::of(area);
  auto inside = [&](const Vec2 &a, const Vec2 &b) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / (pitch / 4))));
    for (int k = 0; k <= n; ++k) {
      const Vec2 p = a + (b - a) * (static_cast<double>(k) / n);
      if (!area.contains(p) && !boundary.within(p, 1e-6))
        return false;
    }
    return true;
  };
  std::vector<Path2D> out;
  for (Path2D &s : strokesIn) {
    if (s.empty())
      continue;
    if (!out.empty()) {
      const Vec2 a = out.back().back().b, b = s.front().a;
      const double gap = (b - a).norm();
      if (gap <= 2.5 * pitch && inside(a, b)) {
        if (gap > geom::kEps)
          out.back().push_back(Seg::line(a, b));
        out.back().insert(out.back().end(), s.begin(), s.end());
        continue;
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

/// The beads of one layer in `region` (the feature's frame).
LayerPaths layerPaths(const Region &region, const DepositionPlan &d, long layer, const Vec2 &centre) {
  LayerPaths out;
  const bool contourOnly = d.pattern == "contour_only" || d.pattern == "spiral";
  const int rings = d.pattern == "infill_only" ? 0 : contourOnly ? kMaxRadialPasses : d.contours;
  const Vec2 seamAt = centre + 1e4 * unit(d.seamShift * static_cast<double>(layer));
  double inset = d.width / 2;
  int made = 0;
  for (; made < rings; ++made, inset += d.pitch) {
    Region ring = geom::offset(region, -inset);
    if (ring.empty())
      break;
    for (const Loop &l : ring.loops)
      out.contours.push_back(startNearest(l, seamAt));
    if (d.pattern == "spiral")
      break;
  }
  if (contourOnly)
    return out;
  // The infill strokes end half a pitch inside the last contour (the band
  // between them and it, and the corners of that band, lie within the
  // contour bead's reach: their ends overlap it by half a pitch more than
  // neighbours do), or half a bead inside the section.
  const double infillInset = made > 0 ? inset - d.pitch + d.pitch / 2 : d.width / 2;
  Region area = geom::offset(region, -infillInset);
  if (area.empty())
    return out;
  const Vec2 dir = unit(d.infillAngle + d.layerRotation * static_cast<double>(layer));
  out.infill = infillPaths(area, dir, d.infillPitch, d.infill == "zigzag");
  return out;
}

/// Beads that fill what the contours and the infill leave bare of the
/// feature's layer (`required`; `region` is it grown by the allowance: where
/// beads may go): concave corners of the infill area, slivers between a
/// channel's contours and the outer ones. The layer is sampled every quarter
/// bead width; a bare point (more than half a width from every bead's centre
/// line) is covered by a bead centred where a centre may go (half a width
/// inside the region): at the point, else at the nearest such place within
/// half a width of it. The bare points whose centres lie within a width of
/// each other get one bead along the longest extent of their centres; a
/// lone one a stub a quarter width long, in from the edge of where centres
/// may go. A bare point with no such place near it (a sharp convex corner)
/// stays bare: the allowance is for it.
/// Beads that fill what the contours and the infill leave bare of the
/// feature's layer (`required`; `region` is it grown by the allowance: where
/// beads may go): concave corners of the infill area, slivers between a
/// channel's contours and the outer ones. The layer is sampled every quarter
/// bead width, and a sample less than 0.71 spacings (its cell's half
/// diagonal) clear of being bare is looked at again in its four quarters,
/// down to cells of a hundredth of a bead: a point is bare when it is more
/// than half a width from every centre line (so every point of the layer a
/// bead can reach ends within half a width and 0.015 widths of one). Each bare point
/// not covered by a bead placed already gets one centred where a bead's
/// centre may go (half a width inside the region): at the point, else at the
/// nearest such place within half a width of it; the bead runs to the
/// furthest other bare point's centre within a width it may reach straight,
/// or is a stub in from its centre. A bare point with no such place near it
/// (a sharp convex corner) stays bare: the allowance is for it.
std::vector<Path2D> gapFill(const Region &region, const Region &required, const LayerPaths &laid,
                            const DepositionPlan &d) {
  std::vector<Seg> lines;
  for (const Loop &l : laid.contours)
    lines.insert(lines.end(), l.segs.begin(), l.segs.end());
  for (const Path2D &p : laid.infill)
    lines.insert(lines.end(), p.begin(), p.end());
  std::vector<Path2D> out;
  if (lines.empty())
    return out;
  const Region centres = geom::offset(region, -d.width / 2);
  if (centres.empty())
    return out;
  const geom::SegIndex laidIndex(lines), edge = geom::SegIndex::of(centres);
  const double step = d.width / 4, reach = d.width / 2, finest = d.width / 100;
  // A bare point, where the bead for it is centred, and which way is in there.
  struct Bare {
    Vec2 point, centre, in;
  };
  std::vector<Bare> bare;
  std::vector<uint32_t> near;
  auto add = [&](const Vec2 &p) {
    if (centres.contains(p)) {
      bare.push_back({p, p, Vec2::UnitX()});
      return;
    }
    // A centre on the edge may be as far as the bead's half width (less a
    // hundredth of a millimetre).
    const double pull = d.width / 2 - 0.01;
    edge.query(geom::Box{p, p}.grown(pull), near);
    double best = pull;
    std::optional<Bare> at;
    for (uint32_t k : near) {
      const Seg &sg = edge.segs()[k];
      const Vec2 q = geom::closestPoint(sg, p);
      if ((q - p).norm() < best) {
        best = (q - p).norm();
        const Vec2 t = sg.tangent(std::clamp((q - sg.a).norm() / std::max(sg.length(), 1e-12), 0.0, 1.0));
        // Centres' loops keep material on their left.
        at = Bare{p, q, Vec2(-t.y(), t.x())};
      }
    }
    if (at)
      bare.push_back(*at);
  };
  static const Vec2 kCorners[] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  // The cell of half size `half` about p: covered whole, or looked into.
  std::function<void(const Vec2 &, double)> look = [&](const Vec2 &p, double half) {
    if (laidIndex.within(p, reach - 1.42 * half))
      return;  // every point of the cell is within reach
    if (half <= finest) {
      if (!laidIndex.within(p, reach) && required.contains(p))
        add(p);
      return;
    }
    // A cell bare whole, inside the layer and where centres may go: a bead
    // through its centre covers all of it (its half diagonal is less than
    // half a width).
    if (!laidIndex.within(p, reach + 1.42 * half)) {
      if (1.42 * half < reach && centres.contains(p) &&
          std::all_of(std::begin(kCorners), std::end(kCorners),
                      [&](const Vec2 &c) { return required.contains(p + c * half); })) {
        add(p);
        return;
      }
      // No centre may go near any of it: nothing to do there.
      if (!centres.contains(p) && !edge.within(p, d.width / 2 + 1.42 * half))
        return;
    }
    for (double dx : {-0.5, 0.5})
      for (double dy : {-0.5, 0.5})
        look(p + Vec2(dx, dy) * half, half / 2);
  };
  const geom::Box box = required.box();
  for (double x = box.lo.x() + step / 2; x < box.hi.x() + step / 2; x += step)
    for (double y = box.lo.y() + step / 2; y < box.hi.y() + step / 2; y += step)
      look(Vec2(x, y), step / 2);
  // Inside where centres may go, or on its edge within a micrometre.
  auto allowed = [&](const Vec2 &a, const Vec2 &b) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k <= n; ++k) {
      const Vec2 q = a + (b - a) * (static_cast<double>(k) / n);
      if (!centres.contains(q) && !edge.within(q, 1e-6))
        return false;
    }
    return true;
  };
  // The bare points by cell of a bead width, for their neighbours.
  std::map<std::pair<long, long>, std::vector<size_t>> cells;
  auto cellOf = [&](const Vec2 &p) {
    return std::pair{std::lround(std::floor(p.x() / d.width)), std::lround(std::floor(p.y() / d.width))};
  };
  for (size_t i = 0; i < bare.size(); ++i)
    cells[cellOf(bare[i].centre)].push_back(i);
  // In order, each point not covered yet gets a bead from its centre to the
  // furthest neighbour's (within a width) that it may run to straight, else
  // a stub in from its centre.
  for (const Bare &b : bare) {
    if (std::any_of(out.begin(), out.end(), [&](const Path2D &g) { return geom::distance(g.front(), b.point) <= reach; }))
      continue;
    const Vec2 *to = nullptr;
    double far = step;
    const auto [cx, cy] = cellOf(b.centre);
    for (long i = cx - 1; i <= cx + 1; ++i)
      for (long j = cy - 1; j <= cy + 1; ++j)
        if (auto it = cells.find({i, j}); it != cells.end())
          for (size_t k : it->second) {
            const double dist = (bare[k].centre - b.centre).norm();
            if (dist > far && dist <= d.width && allowed(b.centre, bare[k].centre)) {
              far = dist;
              to = &bare[k].centre;
            }
          }
    if (to) {
      out.push_back({Seg::line(b.centre, *to)});
      continue;
    }
    const Vec2 stub = b.centre + b.in * step;
    if (allowed(b.centre, stub))
      out.push_back({Seg::line(b.centre, stub)});
    else if (allowed(b.centre, b.centre - b.in * step))
      out.push_back({Seg::line(b.centre, b.centre - b.in * step)});
  }
  return out;
}

/// The segment in workpiece coordinates.
Seg mapSeg(const Seg &s, const ir::SolidFrame &f) {
  const Vec2 o = f.origin.head<2>(), x = f.x.head<2>(), y = f.y.head<2>();
  auto map = [&](const Vec2 &p) -> Vec2 { return o + p.x() * x + p.y() * y; };
  Seg m = s;
  m.a = map(s.a);
  m.b = map(s.b);
  m.c = map(s.c);
  return m;
}

class Depositor {
public:
  Depositor(Node &moves, const DepositionPlan &d, const ir::SolidFrame &frame)
      : moves_(moves), e_(moves, *moves.number("secplane")), d_(d), frame_(frame) {}

  /// Deposits one bead along `path` (feature frame) at height z (workpiece
  /// coordinates); `rise`: the spiral's climb along it.
  void bead(const Path2D &path, double z, double rise) {
    if (path.empty())
      return;
    Path2D p;
    for (const Seg &s : path)
      p.push_back(mapSeg(s, frame_));
    const Vec2 start = p.front().a, end = p.back().b;
    const Vec2 t0 = p.front().tangent(0), t1 = p.back().tangent(1);
    const Vec2 in = start - t0 * d_.leadIn;
    const double hop = z + d_.height + kHopClearance;
    if (!e_.positioned()) {
      e_.travel(in, hop);
    } else {
      if (e_.position().z() < hop)
        e_.rapid(Vec3(e_.position().x(), e_.position().y(), hop), "link");
      e_.rapid(at(in, hop), "link");
    }
    e_.linear(at(in, z), d_.feed, "approach");
    e_.linear(at(start, z), d_.feed, "approach");
    energy(true);
    const double length = geom::Chain{p}.length();
    double along = 0;
    for (const Seg &s : p) {
      along += s.length();
      const double zEnd = z + (length > 0 ? rise * along / length : 0.0);
      if (s.isArc())
        e_.arc(at(s.b, zEnd), s.c, s.turn > 0, 0, d_.feed, "cut");
      else
        e_.linear(at(s.b, zEnd), d_.feed, "cut");
    }
    energy(false);
    ++beads_;
    deposited_ += length;
    if (d_.leadOut > 0)
      e_.linear(at(end + t1 * d_.leadOut, e_.position().z()), d_.feed, "retract");
  }

  void dwell(double seconds) { e_.dwell(seconds); }
  void material(bool on) {
    Node s(ir::Kind::State);
    if (d_.powder)
      s.set("powder_feed", Value::massFlow(on ? *d_.powder : 0.0));
    if (d_.wire)
      s.set("wire_feed", Value::feed(on ? *d_.wire : 0.0));
    moves_.add(std::move(s));
  }
  void retract() { e_.retract(); }
  long beads() const { return beads_; }
  double deposited() const { return deposited_; }

private:
  void energy(bool on) {
    Node s(ir::Kind::State);
    s.set("energy", Value::word(on ? "on" : "off"));
    if (on && !powerSet_) {
      s.set("power", Value::power(d_.power));
      powerSet_ = true;
    }
    moves_.add(std::move(s));
  }

  Node &moves_;
  Emitter e_;
  const DepositionPlan &d_;
  const ir::SolidFrame &frame_;
  bool powerSet_ = false;
  long beads_ = 0;
  double deposited_ = 0;
};

} // namespace

bool expandDeposition(Expander &x, Node &ws, const Node &op, const std::string &setup) {
  const Node *feature = ir::findFeature(*x.module, ws.text("feature").value_or(""));
  const Node *tool = ir::findTool(*x.module, op.text("tool").value_or(""));
  if (!feature || !tool)
    return false;  // the IR verifier reports dangling references
  if (feature->kind != ir::Kind::AmSimpleFeature) {
    x.report(ws, "its deposition operation builds a " + feature->kindName() + " (" + feature->symbol +
                     "): stepnc deposits added features (am_simple_feature)");
    return false;
  }
  if (tool->text("type").value_or("") != "deposition_head") {
    x.report(ws, op, "its deposition operation's tool " + tool->symbol + " is no deposition head");
    return false;
  }
  const Node *tech = op.child(ir::Kind::DepositionTechnology);
  if (!tech) {
    x.report(ws, op, "its deposition operation has no deposition technology (power, feed, bead)");
    return false;
  }
  ir::AmShapeResult sr = ir::amShape(*x.module, *feature);
  if (!sr.shape) {
    x.report(ws, *feature, sr.error);
    return false;
  }
  const ir::AmShape &shape = *sr.shape;
  if ((shape.frame.z - Vec3::UnitZ()).norm() > 1e-9) {
    x.unsupported(ws, "its feature " + feature->symbol + " is built along (" + formatShortest(shape.frame.z.x()) +
                          ", " + formatShortest(shape.frame.z.y()) + ", " + formatShortest(shape.frame.z.z()) +
                          "): stepnc deposits along +z of the setup (a tilted build needs 5-axis deposition)");
    return false;
  }
  if (auto n = op.vec("normal"); n && (n->normalized() - shape.frame.z).norm() > 1e-6) {
    x.report(ws, op, "its layers' normal is not its feature's build direction (its axis)");
    return false;
  }
  DepositionPlan d;
  d.width = tech->number("bead_width").value_or(0);
  d.height = tech->number("bead_height").value_or(0);
  d.layer = op.number("layer_thickness").value_or(d.height);
  d.pitch = d.width * (1 - tech->number("overlap").value_or(0));
  d.allowance = op.number("allowance").value_or(0);
  d.feed = tech->number("feed").value_or(0);
  d.power = tech->number("power").value_or(0);
  d.powder = tech->number("powder_feed");
  d.wire = tech->number("wire_feed");
  d.dwell = tech->number("layer_dwell").value_or(0);
  d.leadIn = d.leadOut = d.width;
  if (!(d.width > 0 && d.height > 0 && d.layer > 0 && d.pitch > 0 && d.feed > 0 && d.power > 0)) {
    x.report(ws, op, "its deposition technology needs a bead width and height, a layer thickness, a feed and a "
                     "power above 0");
    return false;
  }
  // The strategy, and the feature's construction.
  if (const Node *s = op.child(ir::Kind::DepositionStrategy)) {
    d.pattern = s->text("pattern").value_or(d.pattern);
    d.infill = s->text("infill").value_or(d.infill);
    d.infillAngle = s->number("infill_angle").value_or(d.infillAngle);
    d.layerRotation = s->number("layer_rotation").value_or(d.layerRotation);
    d.seamShift = s->number("seam_shift").value_or(d.seamShift);
    d.leadIn = s->number("lead_in").value_or(d.leadIn);
    d.leadOut = s->number("lead_out").value_or(d.leadOut);
    if (auto c = s->number("contours"))
      d.contours = static_cast<int>(*c);
    else if (auto skin = feature->number("skin_thickness"); skin && *skin > d.width)
      d.contours = 1 + static_cast<int>(std::ceil((*skin - d.width) / d.pitch - 1e-9));
  }
  if (auto dir = feature->vec("infill_dir"); dir && dir->head<2>().norm() > 1e-9 &&
                                             !(op.child(ir::Kind::DepositionStrategy) &&
                                               op.child(ir::Kind::DepositionStrategy)->has("infill_angle")))
    d.infillAngle = std::atan2(dir->y(), dir->x()) * 180 / kPi;
  d.infillPitch = d.pitch;
  if (feature->text("core").value_or("") == "infill")
    d.infillPitch = d.pitch / (feature->number("infill_percentage").value_or(100) / 100);
  if (auto pattern = feature->text("infill_pattern")) {
    std::string p = *pattern;
    std::transform(p.begin(), p.end(), p.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (p == "zigzag" || p == "parallel")
      d.infill = p;
    else
      x.assumed(ws, *feature, "its core's infill pattern '" + *pattern + "' is not one stepnc lays (zigzag, "
                              "parallel): laid as " + d.infill);
  }
  // Layers: as many as end within the allowance above the feature (its top
  // gets the allowance too), and at least up to its top.
  const double layers = std::floor((shape.height + d.allowance) / d.layer + 1e-9);
  if (layers > kMaxLayers) {
    x.report(ws, op, "its layer thickness " + formatShortest(d.layer) + " mm makes " + formatShortest(layers) +
                         " layers of its " + formatShortest(shape.height) + " mm feature, more than " +
                         std::to_string(kMaxLayers) + ": give the thickness in mm");
    return false;
  }
  const long n = static_cast<long>(layers);
  if (static_cast<double>(n) * d.layer < shape.height - 1e-6) {
    const double over = (static_cast<double>(n) + 1) * d.layer - shape.height;
    x.report(ws, op, "layers of " + formatShortest(d.layer) + " mm end " +
                         formatFixed(shape.height - static_cast<double>(n) * d.layer, 3) + " mm below or " +
                         formatFixed(over, 3) + " mm above its feature's height of " + formatShortest(shape.height) +
                         " mm, not within the allowance of " + formatShortest(d.allowance) +
                         " mm above it: give a layer thickness that divides the height, or an allowance of " +
                         formatFixed(over, 3) + " mm");
    return false;
  }
  // The beads' length, at most: the whole feature seen along its axis in
  // every layer, a pitch apart. Beyond kMaxBeadLength the feature is no
  // deposition cell's (a length in another unit), and slicing it would run
  // for hours.
  {
    const double widest = shape.slab(0, shape.height).area();
    const double length = widest * static_cast<double>(n) / d.pitch;
    if (!(length <= kMaxBeadLength)) {
      x.report(ws, *feature, "its beads would run about " + formatFixed(length / 1e6, 0) + " km (a " +
                                 formatFixed(widest / 1e6, 2) + " m2 section in " + std::to_string(n) +
                                 " layers), more than " + formatShortest(kMaxBeadLength / 1e6) +
                                 " km: check the feature's dimensions and the bead (a length in another unit?)");
      return false;
    }
  }
  Node moves = makeMoves(ws, tool->symbol, 0, "off", setup);
  Depositor dep(moves, d, shape.frame);
  dep.material(true);
  Vec2 centre = Vec2::Zero();
  {
    const geom::Box b = shape.section(0).box();
    if (!b.empty())
      centre = (b.lo + b.hi) / 2;
  }
  long emptyLayers = 0, gapBeads = 0;
  for (long k = 0; k < n; ++k) {
    const double z0 = static_cast<double>(k) * d.layer, z1 = z0 + d.layer;
    // The feature's layer, and where beads may go: it grown by the allowance.
    Region required = shape.slab(z0, std::min(z1, shape.height));
    Region region = d.allowance > 0 && !required.empty() ? geom::offset(required, d.allowance) : required;
    if (!shape.voids.empty()) {
      Region v = shape.voidsIn(z0, z1, 0);
      if (!v.empty()) {
        region = geom::subtract(region, v);
        required = geom::subtract(required, v);
      }
    }
    LayerPaths paths = layerPaths(region, d, k, centre);
    if (d.pattern != "spiral")
      for (Path2D &gap : gapFill(region, required, paths, d)) {
        paths.infill.push_back(std::move(gap));
        ++gapBeads;
      }
    if (paths.contours.empty() && paths.infill.empty()) {
      ++emptyLayers;
      continue;
    }
    const double z = shape.frame.origin.z() + z0;
    const double rise = d.pattern == "spiral" ? d.layer : 0.0;
    for (const Loop &l : paths.contours)
      dep.bead(l.segs, z, rise);
    for (const Path2D &p : paths.infill)
      dep.bead(p, z, 0);
    if (d.dwell > 0 && k + 1 < n)
      dep.dwell(d.dwell);
  }
  if (emptyLayers > 0)
    x.warning(ws, std::to_string(emptyLayers) + " of its " + std::to_string(n) +
                      " layers have no room for a bead of " + formatShortest(d.width) +
                      " mm: the feature is narrower there than a bead, and nothing is deposited");
  if (gapBeads * 4 > dep.beads())
    x.warning(ws, std::to_string(gapBeads) + " of its " + std::to_string(dep.beads()) +
                      " beads are short ones that fill what its strategy's contours and infill leave bare (around "
                      "channels, in corners): contour beads (contour_then_infill) would lay them in one go");
  dep.material(false);
  dep.retract();
  (*x.stats)["layers deposited"] += n - emptyLayers;
  (*x.stats)["beads deposited"] += dep.beads();
  (*x.stats)["gap-filling beads"] += gapBeads;
  (*x.stats)["bead length (mm)"] += static_cast<long long>(std::llround(dep.deposited()));
  if (!withinMachine(x, ws, *feature, moves))
    return false;
  x.attach(ws, std::move(moves));
  return true;
}

} // namespace stepnc::passes::expand
