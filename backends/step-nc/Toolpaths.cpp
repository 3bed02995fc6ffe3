// Moves written as ISO 14649 toolpaths (see Toolpaths.h).
#include "backends/step-nc/Toolpaths.h"

#include "frontend/part21/Writer.h"
#include "geom/ArcPlane.h"
#include "ir/Kinds.h"
#include "support/Preimage.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::backends {

namespace {

using ir::Node;
using ir::Vec3;
using p21::InstanceId;

constexpr double kTwoPi = 2 * std::numbers::pi;
/// Units in the last place searched either side of a first guess for a value
/// that reads back exactly.
constexpr int kUlpSearch = kPreimageUlps;

/// Candidates within kUlpSearch units in the last place of `x`, nearest first.
std::vector<double> around(double x) {
  std::vector<double> out{x};
  double up = x, down = x;
  for (int i = 0; i < kUlpSearch; ++i) {
    up = std::nextafter(up, INFINITY);
    down = std::nextafter(down, -INFINITY);
    out.push_back(up);
    out.push_back(down);
  }
  return out;
}

/// The ISO 14649 toolpath type that gives a move of `role` back on lowering
/// (expand-strategies reads the pair type, rapid); empty when none does.
std::string_view toolpathType(std::string_view role, bool rapid) {
  struct Row {
    std::string_view role, rapidType, feedType;
  };
  static constexpr Row kTypes[] = {{"position", "NON_CONTACT", "NON_CONTACT"},
                                   {"approach", "APPROACH", ""},
                                   {"plunge", "", "APPROACH"},
                                   {"cut", "CONTACT", "CONTACT"},
                                   {"link", "CONNECT", "CONNECT"},
                                   {"retract", "LIFT", "LIFT"}};
  for (const Row &r : kTypes)
    if (r.role == role)
      return rapid ? r.rapidType : r.feedType;
  return {};
}

/// The moves of `moves`, those of its canned cycles in place.
std::vector<const Node *> moveNodes(const Node &moves) {
  std::vector<const Node *> out;
  for (const Node &m : moves.children)
    if (m.kind == ir::Kind::Cycle)
      for (const Node &c : m.children)
        out.push_back(&c);
    else if (m.category() == ir::Category::Move)
      out.push_back(&m);
  return out;
}

/// Whether `f` only moves its points (no turn about z, no mirror).
bool onlyMoves(const ir::PlaneFrame &f) {
  return (f.x - geom::Vec2::UnitX()).norm() < 1e-9 && (f.y - geom::Vec2::UnitY()).norm() < 1e-9;
}

} // namespace

Vec3 localPoint(const ir::PlaneFrame &f, const Vec3 &p) {
  const geom::Vec2 d = p.head<2>() - f.origin;
  const double lx = d.dot(f.x), ly = d.dot(f.y);
  const double lz = preimage(p.z(), p.z() - f.z, [&](double z) { return f.z + z; });
  for (double x : around(lx))
    for (double y : around(ly))
      if (f.map(geom::Vec2(x, y)) == p.head<2>())
        return {x, y, lz};
  return {lx, ly, lz};
}

std::string fileDescription(const p21::Part21File &input, const std::vector<std::string> &lines,
                            std::string_view holds) {
  std::vector<std::string> all = lines;
  all.insert(all.begin() + (all.empty() ? 0 : 1), std::string(holds));
  for (std::string &line : all)
    std::replace(line.begin(), line.end(), '\'', '"');
  std::string level = "2;1";
  if (const p21::HeaderEntity *h = input.headerEntity("FILE_DESCRIPTION")) {
    const auto params = input.metadata().params(h->record);
    if (!params.empty() && params[0].kind == p21::ValueKind::List)
      for (const p21::Value &v : input.metadata().children(params[0]))
        if (v.kind == p21::ValueKind::String)
          all.push_back("input: " + std::string(v.str()));
    if (params.size() > 1 && params[1].kind == p21::ValueKind::String)
      level = std::string(params[1].str());
  }
  std::string out = "FILE_DESCRIPTION((";
  for (size_t i = 0; i < all.size(); ++i) {
    if (i)
      out += ',';
    p21::appendString(out, all[i]);
  }
  out += "),";
  p21::appendString(out, level);
  return out + ");";
}

// --- Instances ------------------------------------------------------------------

InstanceId Instances::add(std::string_view entity, std::string_view params) {
  const InstanceId id = next_++;
  text_ += '#' + std::to_string(id) + '=' + std::string(entity) + '(' + std::string(params) + ");\n";
  return id;
}

InstanceId Instances::shared(std::map<Key, InstanceId> &pool, const Vec3 &v, std::string_view entity) {
  const Key key{v.x(), v.y(), v.z()};
  if (auto it = pool.find(key); it != pool.end())
    return it->second;
  const InstanceId id = add(entity, "''," + reals(v));
  pool.emplace(key, id);
  return id;
}

InstanceId Instances::point(const Vec3 &p) { return shared(points_, p, "CARTESIAN_POINT"); }

InstanceId Instances::direction(const Vec3 &d) { return shared(directions_, d, "DIRECTION"); }

InstanceId Instances::placement(const Vec3 &at, const Vec3 &axis, const Vec3 &refDirection) {
  const InstanceId location = point(at);
  return add("AXIS2_PLACEMENT_3D", "''," + ref(location) + ',' + ref(direction(axis)) + ',' + ref(direction(refDirection)));
}

std::string Instances::real(double v) {
  std::string s;
  p21::appendReal(s, v);
  return s;
}

std::string Instances::reals(const Vec3 &v) { return '(' + real(v.x()) + ',' + real(v.y()) + ',' + real(v.z()) + ')'; }

// --- ToolpathWriter -------------------------------------------------------------

std::optional<InstanceId> ToolpathWriter::write(const Node &ws, const Node &moves, const ir::PlaneFrame &frame,
                                                const std::string &feedReference, std::optional<Vec3> start) {
  ws_ = &ws;
  frame_ = &frame;
  spindle_ = moves.number("spindle").value_or(0);
  feedReference_ = feedReference;
  trajectories_.clear();
  run_ = {};
  bool smooth = false;
  std::optional<Vec3> at;
  for (const Node *move : moveNodes(moves)) {
    const Node &m = *move;
    if (m.kind == ir::Kind::Dwell) {
      // A feedstop: the tool waits where the path before it ended.
      if (!at) {
        fail(m, "a dwell before the first move");
        return std::nullopt;
      }
      flush();
      trajectories_.push_back(out_.add("FEEDSTOP", ".T.,.CONTACT.,$,$,$," + Instances::real(*m.number("time"))));
      continue;
    }
    const Vec3 to = *m.vec("to");
    const std::string role = m.text("role").value_or(m.kind == ir::Kind::Rapid ? "position" : "cut");
    smooth = smooth || m.flag("smooth").value_or(false);
    if (!at) {
      // The first move takes the tool to the first point of the first
      // toolpath: lowering makes it again, from wherever the tool is. A
      // step that goes on from where the one before left the tool (the
      // file's paths joined) starts its toolpath there.
      const bool positions =
          m.kind == ir::Kind::Rapid && role == "position" && to.z() == moves.number("secplane").value_or(0);
      if (positions) {
        at = to;
        continue;
      }
      if (!start) {
        fail(m, "the first move is not a rapid to the security plane");
        return std::nullopt;
      }
      at = start;
    }
    const bool rapid = m.kind == ir::Kind::Rapid;
    const double feed = rapid ? 0 : m.number("feed").value_or(0);
    const std::string_view type = toolpathType(role, rapid);
    if (type.empty()) {
      fail(m, "a " + m.kindName() + " move with role " + role + " has no ISO 14649 toolpath type");
      return std::nullopt;
    }
    if (m.kind == ir::Kind::Arc) {
      flush();
      if (!arc(*at, m, type, feed))
        return std::nullopt;
    } else {
      if (run_.points.empty() || run_.rapid != rapid || run_.type != type || run_.feed != feed) {
        flush();
        run_ = {rapid, std::string(type), feed, {*at}};
      }
      run_.points.push_back(to);
    }
    at = to;
  }
  flush();
  if (smooth)
    diags_
        .warning(ws.origin.loc, "workingstep " + ws.symbol +
                                    ": the chords of its smooth curves are written as polylines; a target "
                                    "with splines writes them as lines when this file is compiled")
        .entity(ws.origin.entityId);
  if (trajectories_.empty())
    return std::nullopt;
  std::string list = "(";
  for (size_t i = 0; i < trajectories_.size(); ++i) {
    if (i)
      list += ',';
    list += Instances::ref(trajectories_[i]);
  }
  return out_.add("TOOLPATH_LIST", list + ')');
}

void ToolpathWriter::fail(const Node &move, const std::string &why) {
  const std::optional<Vec3> to = move.vec("to");
  diags_
      .error(ws_->origin.loc, "workingstep " + ws_->symbol + ": cannot write its toolpath as STEP-NC: " + why + " (" +
                                  move.kindName() + (to ? " to " + Instances::reals(*to) : "") + ")")
      .entity(ws_->origin.entityId);
  failed_ = true;
}

void ToolpathWriter::flush() {
  if (run_.points.size() < 2)
    return;
  std::string points = "(";
  for (size_t i = 0; i < run_.points.size(); ++i) {
    if (i)
      points += ',';
    points += Instances::ref(out_.point(localPoint(*frame_, run_.points[i])));
  }
  const InstanceId curve = out_.add("POLYLINE", "''," + points + ')');
  trajectory(run_.type, run_.rapid, run_.feed, curve);
  run_ = {};
}

bool ToolpathWriter::arc(const Vec3 &from, const Node &m, std::string_view type, double feed) {
  const ir::PlaneFrame &f = *frame_;
  // The plane the arc turns in (about +z unless it says otherwise); an arc
  // about -y is the arc about +y the other way round.
  bool positive = true;
  const std::optional<geom::ArcPlane> plane = geom::ArcPlane::about(m.vec("normal").value_or(Vec3::UnitZ()), positive);
  if (!plane) {
    fail(m, "an arc about an axis other than x, y or z");
    return false;
  }
  if (!plane->isXY() && !onlyMoves(f)) {
    fail(m, std::string("an arc in the ") + plane->name() + " plane in a feature frame turned about z");
    return false;
  }
  const Vec3 a = localPoint(f, from), b = localPoint(f, *m.vec("to"));
  Vec3 centre = *m.vec("center");
  centre[plane->normal] = from[plane->normal];
  const Vec3 c = localPoint(f, centre);
  const bool ccw = ((m.text("dir") == "ccw") == positive) != f.mirrored();
  const int64_t turns = m.count("turns").value_or(0);
  // In the plane's coordinates: (first, second) in the plane, then along its normal.
  const Vec3 la = plane->local(a), lb = plane->local(b), lc = plane->local(c);
  const double radius = std::hypot(la.x() - lc.x(), la.y() - lc.y());
  if (!(radius > 0)) {
    fail(m, "an arc of radius 0");
    return false;
  }
  const Vec3 axis = plane->normalVector(), refDirection = Vec3::Unit(plane->first());
  InstanceId basis = 0;
  if (lb.z() == la.z()) {
    if (turns > 0) {
      fail(m, "a flat arc of more than one turn");
      return false;
    }
    basis = out_.add("CIRCLE", "''," + Instances::ref(out_.placement(c, axis, refDirection)) + ',' +
                                   Instances::real(radius));
  } else {
    // The pitch that gives back the turns: lowering counts them from the
    // rise, the pitch and the last partial arc (ir/geom/Curves.cpp).
    double partial = std::atan2(lb.y() - lc.y(), lb.x() - lc.x()) - std::atan2(la.y() - lc.y(), la.x() - lc.x());
    partial = std::fmod(std::fmod(partial, kTwoPi) + kTwoPi, kTwoPi);
    if (!ccw && partial > 0)
      partial = kTwoPi - partial;
    if (partial < 1e-9)
      partial = kTwoPi;
    const double pitch = std::abs(lb.z() - la.z()) / (static_cast<double>(turns) + partial / kTwoPi);
    // The pitch is positive (the IR's rule); the trimming points say which way the arc rises.
    basis = out_.add("HELIX", "''," + Instances::ref(out_.placement(c, axis, refDirection)) + ',' +
                                  Instances::real(radius) + ',' + Instances::real(pitch));
  }
  const InstanceId curve =
      out_.add("TRIMMED_CURVE", "''," + Instances::ref(basis) + ",(" + Instances::ref(out_.point(a)) + "),(" +
                                    Instances::ref(out_.point(b)) + ")," + (ccw ? ".T." : ".F.") + ",.CARTESIAN.");
  trajectory(type, false, feed, curve);
  return true;
}

void ToolpathWriter::trajectory(std::string_view type, bool rapid, double feed, InstanceId curve) {
  const std::string speed = rapid ? "SPEED_NAME(.RAPID.)" : "$";
  const std::string technology = rapid ? "$" : Instances::ref(this->technology(feed));
  trajectories_.push_back(out_.add("CUTTER_LOCATION_TRAJECTORY", ".T.,." + std::string(type) + ".," + speed + ',' +
                                                                     technology + ",$,$," + Instances::ref(curve) +
                                                                     ",$,$"));
}

InstanceId ToolpathWriter::technology(double feed) {
  // A milling technology with `feed` (mm/min) and the workingstep's spindle,
  // shared by every toolpath that has both, in the units the input was read
  // in, so that the file stays consistent.
  const auto key = std::make_tuple(feed, spindle_, feedReference_);
  if (auto it = technologies_.find(key); it != technologies_.end())
    return it->second;
  const double speed =
      preimage(feed, feed / units_.feedToMmPerMin, [&](double v) { return v * units_.feedToMmPerMin; });
  const double spindle = preimage(spindle_, spindle_ / units_.spindleToRevPerMin,
                                  [&](double v) { return v * units_.spindleToRevPerMin; });
  const InstanceId id = out_.add("MILLING_TECHNOLOGY", Instances::real(speed) + ",." + feedReference_ + ".,$," +
                                                           Instances::real(spindle) + ",$,.F.,.F.,.F.,$");
  technologies_.emplace(key, id);
  return id;
}

} // namespace stepnc::backends
