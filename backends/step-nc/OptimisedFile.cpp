// Machine-optimised STEP-NC (see OptimisedFile.h): the input's canonical Part
// 21 text, one line per instance, patched line by line (FILE_DESCRIPTION, the
// operations that get a toolpath) with the new instances appended to the last
// DATA section.
//
// Values must read back bit for bit, so that lowering the written file makes
// the same moves: points are written in the feature's frame as the local
// coordinates whose mapping back gives the workpiece coordinates exactly (a
// few units in the last place are searched; exact for frames along the axes),
// and feeds and spindle speeds as the speed measures whose conversion by
// lowering gives them exactly (the canonical writer writes shortest
// round-trip reals).
#include "backends/step-nc/OptimisedFile.h"

#include "frontend/part21/Writer.h"
#include "ir/Kinds.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "support/Preimage.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>

namespace stepnc::backends {

namespace {

using ir::Node;
using ir::Vec3;
using p21::InstanceId;
using ir::PlaneFrame;

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

/// `p` (workpiece coordinates) in the frame `f`: the local point that
/// expand-strategies maps back to exactly `p` where one is found.
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

/// New instances, numbered from the first free id, as canonical Part 21 lines.
class Instances {
public:
  explicit Instances(InstanceId first) : next_(first) {}

  InstanceId add(std::string_view entity, std::string_view params) {
    const InstanceId id = next_++;
    text_ += '#' + std::to_string(id) + '=' + std::string(entity) + '(' + std::string(params) + ");\n";
    return id;
  }

  InstanceId point(const Vec3 &p) {
    return shared(points_, {p.x(), p.y(), p.z()}, [&] { return add("CARTESIAN_POINT", "''," + reals(p)); });
  }

  InstanceId direction(const Vec3 &d) {
    return shared(directions_, {d.x(), d.y(), d.z()}, [&] { return add("DIRECTION", "''," + reals(d)); });
  }

  /// An axis2_placement_3d at `at` with the frame's own axes.
  InstanceId placement(const Vec3 &at) {
    const InstanceId location = point(at);
    return add("AXIS2_PLACEMENT_3D",
               "''," + ref(location) + ',' + ref(direction(Vec3::UnitZ())) + ',' + ref(direction(Vec3::UnitX())));
  }

  static std::string ref(InstanceId id) { return '#' + std::to_string(id); }
  static std::string real(double v) {
    std::string s;
    p21::appendReal(s, v);
    return s;
  }
  static std::string reals(const Vec3 &v) { return '(' + real(v.x()) + ',' + real(v.y()) + ',' + real(v.z()) + ')'; }

  InstanceId firstFree() const { return next_; }
  const std::string &text() const { return text_; }

private:
  using Key = std::array<double, 3>;
  template <class Make> InstanceId shared(std::map<Key, InstanceId> &pool, const Key &key, Make make) {
    if (auto it = pool.find(key); it != pool.end())
      return it->second;
    const InstanceId id = make();
    pool.emplace(key, id);
    return id;
  }

  InstanceId next_;
  std::string text_;
  std::map<Key, InstanceId> points_, directions_;
};

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

/// Writes the moves of workingsteps as toolpath lists.
class ToolpathWriter {
public:
  ToolpathWriter(Instances &out, const ir::SourceUnits &units, DiagnosticEngine &diags)
      : out_(out), units_(units), diags_(diags) {}

  /// The TOOLPATH_LIST of `ws`'s `moves`, in the frame of its feature; none
  /// (after an error) when a move cannot be written, or (silently) when the
  /// moves are a single positioning.
  std::optional<InstanceId> write(const Node &ws, const Node &moves, const ir::PlaneFrame &frame,
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
        fail(m, "a dwell has no ISO 14649 toolpath form");
        return std::nullopt;
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
    for (size_t i = 0; i < trajectories_.size(); ++i)
      list += (i ? "," : "") + Instances::ref(trajectories_[i]);
    return out_.add("TOOLPATH_LIST", list + ')');
  }

  bool failed() const { return failed_; }

private:
  /// A run of straight moves of one kind, type and feed: one polyline.
  struct Run {
    bool rapid = false;
    std::string type;
    double feed = 0;
    std::vector<Vec3> points; ///< workpiece coordinates, from the run's start
  };

  /// The moves of `moves`, those of its canned cycles in place.
  static std::vector<const Node *> moveNodes(const Node &moves) {
    std::vector<const Node *> out;
    for (const Node &m : moves.children)
      if (m.kind == ir::Kind::Cycle)
        for (const Node &c : m.children)
          out.push_back(&c);
      else if (m.category() == ir::Category::Move)
        out.push_back(&m);
    return out;
  }

  void fail(const Node &move, const std::string &why) {
    const std::optional<Vec3> to = move.vec("to");
    diags_
        .error(ws_->origin.loc, "workingstep " + ws_->symbol + ": cannot write its toolpath as STEP-NC: " + why + " (" +
                                    move.kindName() + (to ? " to " + Instances::reals(*to) : "") + ")")
        .entity(ws_->origin.entityId);
    failed_ = true;
  }

  void flush() {
    if (run_.points.size() < 2)
      return;
    std::string points = "(";
    for (size_t i = 0; i < run_.points.size(); ++i)
      points += (i ? "," : "") + Instances::ref(out_.point(localPoint(*frame_, run_.points[i])));
    const InstanceId curve = out_.add("POLYLINE", "''," + points + ')');
    trajectory(run_.type, run_.rapid, run_.feed, curve);
    run_ = {};
  }

  /// An arc from `from` as a trimmed circle, or a trimmed helix when it changes height.
  bool arc(const Vec3 &from, const Node &m, std::string_view type, double feed) {
    const ir::PlaneFrame &f = *frame_;
    const Vec3 a = localPoint(f, from), b = localPoint(f, *m.vec("to"));
    const Vec3 centre = *m.vec("center");
    const Vec3 c = localPoint(f, Vec3(centre.x(), centre.y(), from.z()));
    const bool ccw = (m.text("dir") == "ccw") != f.mirrored();
    const int64_t turns = m.count("turns").value_or(0);
    const double radius = std::hypot(a.x() - c.x(), a.y() - c.y());
    if (!(radius > 0)) {
      fail(m, "an arc of radius 0");
      return false;
    }
    InstanceId basis = 0;
    if (b.z() == a.z()) {
      if (turns > 0) {
        fail(m, "a flat arc of more than one turn");
        return false;
      }
      basis = out_.add("CIRCLE", "''," + Instances::ref(out_.placement(c)) + ',' + Instances::real(radius));
    } else {
      // The pitch that gives back the turns: lowering counts them from the
      // rise, the pitch and the last partial arc (ir/geom/Curves.cpp).
      double partial = std::atan2(b.y() - c.y(), b.x() - c.x()) - std::atan2(a.y() - c.y(), a.x() - c.x());
      partial = std::fmod(std::fmod(partial, kTwoPi) + kTwoPi, kTwoPi);
      if (!ccw && partial > 0)
        partial = kTwoPi - partial;
      if (partial < 1e-9)
        partial = kTwoPi;
      const double pitch = std::abs(b.z() - a.z()) / (static_cast<double>(turns) + partial / kTwoPi);
      // The pitch is positive (the IR's rule); the trimming points say which way the arc rises.
      basis = out_.add("HELIX", "''," + Instances::ref(out_.placement(c)) + ',' + Instances::real(radius) + ',' +
                                    Instances::real(pitch));
    }
    const InstanceId curve =
        out_.add("TRIMMED_CURVE", "''," + Instances::ref(basis) + ",(" + Instances::ref(out_.point(a)) + "),(" +
                                      Instances::ref(out_.point(b)) + ")," + (ccw ? ".T." : ".F.") + ",.CARTESIAN.");
    trajectory(type, false, feed, curve);
    return true;
  }

  void trajectory(std::string_view type, bool rapid, double feed, InstanceId curve) {
    const std::string speed = rapid ? "SPEED_NAME(.RAPID.)" : "$";
    const std::string technology = rapid ? "$" : Instances::ref(this->technology(feed));
    trajectories_.push_back(out_.add("CUTTER_LOCATION_TRAJECTORY", ".T.,." + std::string(type) + ".," + speed + ',' +
                                                                       technology + ",$,$," + Instances::ref(curve) +
                                                                       ",$,$"));
  }

  /// A milling technology with `feed` (mm/min) and the workingstep's spindle,
  /// shared by every toolpath that has both.
  InstanceId technology(double feed) {
    // In the units the input was read in, so that the file stays consistent.
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

  Instances &out_;
  const ir::SourceUnits &units_;
  DiagnosticEngine &diags_;
  const Node *ws_ = nullptr;
  const ir::PlaneFrame *frame_ = nullptr;
  double spindle_ = 0;
  std::string feedReference_;
  Run run_;
  std::vector<InstanceId> trajectories_;
  std::map<std::tuple<double, double, std::string>, InstanceId> technologies_;
  bool failed_ = false;
};

/// Every machining workingstep with moves, in program order.
void workingsteps(const Node &n, std::vector<const Node *> &out) {
  for (const Node &c : n.children)
    if (c.kind == ir::Kind::Workplan)
      workingsteps(c, out);
    else if (c.kind == ir::Kind::Workingstep && c.child(ir::Kind::Moves))
      out.push_back(&c);
}

InstanceId largestId(const p21::Part21File &file) {
  InstanceId largest = 0;
  for (const p21::InstanceEntry &e : file.entries())
    largest = std::max(largest, e.id);
  for (const p21::ExternalReference &r : file.references())
    largest = std::max(largest, r.id);
  return largest;
}

/// The id of a canonical instance line `#id=...`.
InstanceId instanceIdOf(std::string_view line) { return std::stoull(std::string(line.substr(1, line.find('=') - 1))); }

/// Where parameter `index` (0-based, at the top level of its list) of
/// `#id=NAME(p0,p1,...);` lies in the line: [begin, end); none when the line
/// has no such parameter (a complex instance, too few parameters).
std::optional<std::pair<size_t, size_t>> parameterSpan(std::string_view line, size_t index) {
  const size_t eq = line.find('=');
  const size_t open = line.find('(');
  if (open == std::string_view::npos || eq == std::string_view::npos || open == eq + 1)
    return std::nullopt;
  // Top-level parameter boundaries: commas outside nested lists and strings.
  size_t begin = open + 1, current = 0;
  int depth = 0;
  bool inString = false;
  for (size_t i = open + 1; i < line.size(); ++i) {
    const char c = line[i];
    if (inString) {
      if (c == '\'' && i + 1 < line.size() && line[i + 1] == '\'')
        ++i;  // a doubled quote stays in the string
      else if (c == '\'')
        inString = false;
      continue;
    }
    if (c == '\'') {
      inString = true;
    } else if (c == '(') {
      ++depth;
    } else if ((c == ',' && depth == 0) || (c == ')' && depth == 0)) {
      if (current == index)
        return std::pair(begin, i);
      if (c == ')')
        return std::nullopt;
      ++current;
      begin = i + 1;
    } else if (c == ')') {
      --depth;
    }
  }
  return std::nullopt;
}

/// The line with its parameter `index` replaced by `value`, or with `value`
/// appended when `index` is one past its last parameter (a subtype's
/// attributes after its supertype's); empty when the line has no such
/// parameter.
std::string withParameter(std::string_view line, size_t index, std::string_view value) {
  const auto span = parameterSpan(line, index);
  if (!span) {
    const auto last = index > 0 ? parameterSpan(line, index - 1) : std::nullopt;
    if (!last || last->second >= line.size() || line[last->second] != ')')
      return {};
    return std::string(line.substr(0, last->second)) + ',' + std::string(value) +
           std::string(line.substr(last->second));
  }
  return std::string(line.substr(0, span->first)) + std::string(value) + std::string(line.substr(span->second));
}

/// Whether parameter `index` of the line gives no value: `$`, or a number
/// that is 0 (what generators write for a feed or speed they leave out).
bool givesNothing(std::string_view line, size_t index) {
  const auto span = parameterSpan(line, index);
  if (!span)
    return false;
  const std::string text(line.substr(span->first, span->second - span->first));
  if (text == "$")
    return true;
  char *end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' && v == 0;
}

/// FILE_DESCRIPTION with `lines` first, then the input's own description.
/// Quotes in `lines` become double quotes: Open CASCADE 7.6's STEP reader
/// fails on a doubled quote followed by ',' or ')' inside a string.
std::string fileDescription(const p21::Part21File &input, const std::vector<std::string> &lines) {
  std::vector<std::string> all = lines;
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

} // namespace

/// A feed or spindle speed the operation's technology leaves out (`$` or 0,
/// and nothing it follows from: resolve-feeds assumed it from the tool and
/// the material, and said so), written into it in the file's own
/// units, so that the optimised file needs no assumption there; an operation
/// with no technology gets one. A technology shared by operations whose
/// values differ gets a copy per operation.
using Patches = std::map<InstanceId, std::vector<std::pair<size_t, std::string>>>;
void writeResolvedTechnology(const Node &op, const std::map<InstanceId, std::string_view> &lines,
                             const ir::SourceUnits &units, Instances &out, Patches &patches) {
  constexpr size_t kItsTechnology = 6;  // machining_operation's 7th attribute
  const Node *tech = op.child(ir::Kind::Technology);
  if (!tech || op.origin.entityId == 0)
    return;
  const double feed = tech->number("feed").value_or(0), spindle = tech->number("spindle").value_or(0);
  // The values that read back as the ones used, in the file's units.
  const std::string feedText = Instances::real(
      preimage(feed, feed / units.feedToMmPerMin, [&](double v) { return v * units.feedToMmPerMin; }));
  const std::string spindleText = Instances::real(preimage(
      spindle, spindle / units.spindleToRevPerMin, [&](double v) { return v * units.spindleToRevPerMin; }));
  // The technology the file gives: the operation's its_technology.
  InstanceId id = 0;
  if (const auto op_ = lines.find(op.origin.entityId); op_ != lines.end())
    if (const auto span = parameterSpan(op_->second, kItsTechnology)) {
      const std::string_view ref = op_->second.substr(span->first, span->second - span->first);
      if (ref.size() > 1 && ref[0] == '#')
        id = std::strtoull(std::string(ref.substr(1)).c_str(), nullptr, 10);
    }
  const auto line = lines.find(id);
  if (id == 0 || line == lines.end()) {
    // No technology in the file: one with what was assumed.
    if (feed <= 0 || spindle == 0)
      return;
    const std::string reference = tech->text("feed_reference") == "ccp" ? "CCP" : "TCP";
    const InstanceId made = out.add("MILLING_TECHNOLOGY", feedText + ",." + reference + ".,$," + spindleText +
                                                              ",$,.F.,.F.,.F.,$");
    patches[op.origin.entityId].emplace_back(kItsTechnology, Instances::ref(made));
    return;
  }
  if (line->second.find("=MILLING_TECHNOLOGY(") == std::string_view::npos)
    return;
  // MILLING_TECHNOLOGY(feedrate, feedrate_reference, cutspeed, spindle,
  // feedrate_per_tooth, ...): a feed derived from the feed per tooth, a
  // spindle speed from the cutting speed, follow from what the file gives.
  std::vector<std::pair<size_t, std::string>> mine;
  if (feed > 0 && givesNothing(line->second, 0) && givesNothing(line->second, 4))
    mine.emplace_back(0, feedText);
  if (spindle != 0 && givesNothing(line->second, 3) && givesNothing(line->second, 2))
    mine.emplace_back(3, spindleText);
  if (mine.empty())
    return;
  std::vector<std::pair<size_t, std::string>> &given = patches[id];
  const bool conflicts = std::any_of(mine.begin(), mine.end(), [&](const auto &m) {
    return std::any_of(given.begin(), given.end(),
                       [&](const auto &g) { return g.first == m.first && g.second != m.second; });
  });
  if (!conflicts) {
    for (auto &m : mine)
      if (std::find(given.begin(), given.end(), m) == given.end())
        given.push_back(std::move(m));
    return;
  }
  // Shared with an operation that resolved other values: this one's own copy.
  std::string copy(line->second);
  for (const auto &[index, value] : mine)
    copy = withParameter(copy, index, value);
  const size_t open = copy.find('('), close = copy.rfind(')');
  const InstanceId made = out.add("MILLING_TECHNOLOGY", copy.substr(open + 1, close - open - 1));
  patches[op.origin.entityId].emplace_back(kItsTechnology, Instances::ref(made));
}

std::string writeOptimisedPart21(const p21::Part21File &input, const ir::Module &module,
                                 const OptimisedFileOptions &options, DiagnosticEngine &diags) {
  bool ok = true;
  const std::string canonical = p21::writePart21ToString(input, diags, &ok);
  if (!ok)
    return {};
  Instances out(largestId(input) + 1);
  ToolpathWriter writer(out, module.sourceUnits, diags);
  // Parameters to replace: instance -> (parameter index, new value). An
  // operation gets its toolpath list (its first parameter), a workingstep
  // whose moves travel above its file's security plane (expand-strategies
  // raised it, said so) a plane at that height (its second).
  Patches patches;
  std::map<InstanceId, const Node *> writtenBy;
  std::vector<const Node *> steps;
  workingsteps(module.root, steps);
  // Where each executable starts: where the one before it left the tool.
  std::map<const Node *, Vec3> starts;
  std::optional<Vec3> position;
  for (const Node *e : ir::programOrder(module))
    if (const Node *moves = e->child(ir::Kind::Moves)) {
      if (position)
        starts[e] = *position;
      for (const ir::Move &m : ir::walkMoves(*moves, position))
        position = m.to;
    }
  // The canonical line of every instance, to read what the file gives.
  std::map<InstanceId, std::string_view> lines;
  for (size_t pos = 0, eol; pos < canonical.size(); pos = eol + 1) {
    eol = canonical.find('\n', pos);
    const std::string_view line(canonical.data() + pos, eol - pos);
    if (line.starts_with("#"))
      lines.emplace(instanceIdOf(line), line);
  }
  for (const Node *ws : steps) {
    const Node *op = ir::operationOf(*ws);
    const Node *feature = ir::findFeature(module, ws->text("feature").value_or(""));
    if (!op || !feature || op->origin.entityId == 0)
      continue;
    const Node &moves = *ws->child(ir::Kind::Moves);
    // Moves that travel above the file's security plane (expand-strategies
    // raised it, and said so): that plane, written as the step's.
    const double travel = moves.number("secplane").value_or(0);
    // (Not for a step on another face: its plane is the file's, turned, and
    // read again it is raised again.)
    if (ws->origin.entityId != 0 && !ws->has("setup") && travel != ws->number("secplane").value_or(travel))
      patches[ws->origin.entityId].emplace_back(
          1, Instances::ref(out.add("PLANE", "'security plane (raised)'," +
                                                 Instances::ref(out.placement(Vec3(0, 0, travel))))));
    // A step that is canned cycles keeps its operation as written: read
    // again, it expands to the same cycles, with the dwells and reduced
    // feeds a cutter-location toolpath cannot carry. Steps that share such
    // an operation share its technology too.
    if (!moves.children.empty() && std::all_of(moves.children.begin(), moves.children.end(),
                                               [](const Node &c) { return c.kind == ir::Kind::Cycle; })) {
      if (writtenBy.emplace(op->origin.entityId, ws).second)
        writeResolvedTechnology(*op, lines, module.sourceUnits, out, patches);
      continue;
    }
    if (auto [it, fresh] = writtenBy.emplace(op->origin.entityId, ws); !fresh) {
      diags
          .error(ws->origin.loc, "workingstep " + ws->symbol + " shares its operation #" +
                                     std::to_string(op->origin.entityId) + " with " + it->second->symbol +
                                     ": one its_toolpath cannot hold the toolpaths of both")
          .entity(ws->origin.entityId);
      ok = false;
      continue;
    }
    const ir::FrameResult frame = ir::planeFrame(*feature);
    if (!frame.frame) {
      diags.error(ws->origin.loc, "workingstep " + ws->symbol + ": " + frame.error).entity(ws->origin.entityId);
      ok = false;
      continue;
    }
    writeResolvedTechnology(*op, lines, module.sourceUnits, out, patches);
    const Node *tech = op->child(ir::Kind::Technology);
    const std::string reference = tech && tech->text("feed_reference") == "ccp" ? "CCP" : "TCP";
    const auto start = starts.find(ws);
    if (auto list = writer.write(*ws, moves, *frame.frame, reference,
                                 start == starts.end() ? std::nullopt : std::optional(start->second)))
      patches[op->origin.entityId].emplace_back(0, Instances::ref(*list));
  }
  if (!ok || writer.failed())
    return {};
  // What reading the file assumed, said explicitly: read again, it needs no
  // assumption (ir::SourceFix).
  std::vector<InstanceId> made;
  const auto resolve = [&made](std::string text) {
    for (size_t at = text.find("#@"); at != std::string::npos; at = text.find("#@", at)) {
      size_t end = at + 2;
      while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end])))
        ++end;
      const size_t k = std::stoul(text.substr(at + 2, end - at - 2));
      const std::string ref = Instances::ref(made.at(k));
      text.replace(at, end - at, ref);
      at += ref.size();
    }
    return text;
  };
  for (const std::string &instance : module.sourceInstances) {
    const std::string resolved = resolve(instance);
    const size_t open = resolved.find('(');
    made.push_back(out.add(resolved.substr(0, open), resolved.substr(open + 1, resolved.size() - open - 2)));
  }
  std::map<InstanceId, std::string> renames;
  for (const ir::SourceFix &f : module.sourceFixes) {
    if (f.parameter < 0)
      renames[f.entityId] = f.text;
    else
      patches[f.entityId].emplace_back(static_cast<size_t>(f.parameter), resolve(f.text));
  }

  // Patch the canonical text: one header entity or instance per line.
  const std::string description = fileDescription(input, options.description);
  const bool hasDescription = input.headerEntity("FILE_DESCRIPTION") != nullptr;
  const size_t lastEndsec = canonical.rfind("ENDSEC;\n");
  std::string text;
  text.reserve(canonical.size() + out.text().size() + description.size());
  for (size_t pos = 0, eol; pos < canonical.size(); pos = eol + 1) {
    eol = canonical.find('\n', pos);
    const std::string_view line(canonical.data() + pos, eol - pos);
    if (pos == lastEndsec)
      text += out.text();
    std::string patched(line);
    if (line.starts_with("FILE_DESCRIPTION(")) {
      patched = description;
    } else if (line == "HEADER;" && !hasDescription) {
      patched += "\n" + description;
    } else if (line.starts_with("#")) {
      const InstanceId id = instanceIdOf(line);
      if (auto it = renames.find(id); it != renames.end())
        if (const size_t eq = patched.find('='), open = patched.find('(');
            eq != std::string::npos && open != std::string::npos && eq < open)
          patched = patched.substr(0, eq + 1) + it->second + patched.substr(open);
      if (auto it = patches.find(id); it != patches.end()) {
        for (const auto &[index, value] : it->second) {
          patched = withParameter(patched, index, value);
          if (patched.empty()) {
            diags.error({}, "#" + std::to_string(id) + " is a complex instance: stepnc cannot set its parameter " +
                                std::to_string(index + 1));
            return {};
          }
        }
      }
    }
    text += patched;
    text += '\n';
  }
  return text;
}

std::unique_ptr<p21::Part21File> buildOptimisedFile(const p21::Part21File &input, const ir::Module &module,
                                                    const OptimisedFileOptions &options,
                                                    std::unique_ptr<SourceFile> &text, DiagnosticEngine &diags) {
  if (!ir::requireThreeAxisMilling(module, "the STEP-NC writer", diags))
    return nullptr;
  if (!module.aimSchema.empty()) {
    // The writer patches the source file's own ARM instances; an AIM file's
    // write-back has to be AIM, which is not written yet (docs/ap238.md).
    diags.error(input.loc(0), "machine-optimised STEP-NC is written for ISO 14649 ARM files; this file is an AP238 "
                              "AIM file (" + module.aimSchema +
                                  "), whose write-back stepnc does not write yet (docs/ap238.md)");
    return nullptr;
  }
  std::string written = writeOptimisedPart21(input, module, options, diags);
  if (written.empty())
    return nullptr;
  text = SourceFile::fromString(std::string(input.source().name()) + " (optimised)", written);
  auto file = p21::readPart21(*text, diags);
  if (diags.hasErrors())
    return nullptr;
  return file;
}

} // namespace stepnc::backends
