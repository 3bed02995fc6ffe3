#include "backends/common/LatheEmitter.h"

#include "backends/common/ToolTable.h"
#include "ir/Program.h"
#include "ir/geom/TurnedShape.h"
#include "support/Format.h"

#include <cmath>
#include <numbers>

namespace stepnc::backends {

bool hasTurningSteps(const ir::Module &module) {
  for (const ir::Node *e : ir::programOrder(module))
    if (ir::isTurningStep(*e))
      return true;
  return false;
}

std::string LatheEmitter::coolant(const std::string &mode) const { return coolantWord(mode); }

double LatheEmitter::readX(double radius) const {
  return diameterMode() ? roundTo(2 * radius, d_.coordDecimals) / 2 : roundTo(radius, d_.coordDecimals);
}

std::string LatheEmitter::xWord(double radius) const { return word("X", num(diameterMode() ? 2 * radius : radius)); }

std::string LatheEmitter::orientationNote(const ir::Node &tool, bool inside, bool axial) const {
  const std::string type = tool.text("type").value_or("");
  if (axial || (type != "turning_tool" && type != "grooving_tool"))
    return "";
  const std::string o = toolOrientation(inside);
  return o.empty() ? "" : ", " + o;
}

int LatheEmitter::toolNumber(const ir::Node &tool) {
  if (auto it = numbers_.find(tool.symbol); it != numbers_.end())
    return it->second;
  int n = 0;
  if (o_.toolTable) {
    const ToolTable::Entry *e = o_.toolTable->find(tool);
    if (!e) {
      diags_.error(tool.origin.loc, "tool " + tool.symbol + " (" + tool.label + ") is not in the tool table " +
                                        o_.toolTable->name())
          .entity(tool.origin.entityId);
      ok_ = false;
      return 0;
    }
    n = e->number;
  } else {
    n = nextNumber_++;
  }
  numbers_[tool.symbol] = n;
  return n;
}

std::string LatheEmitter::arcCentre(const geom::Vec2 &offsetXZ, double, bool) const {
  return word("I", num(offsetXZ.x())) + " " + word("K", num(offsetXZ.y()));
}

std::optional<std::string> LatheEmitter::run(const ir::Module &module) {
  opening();
  const ir::Node &root = module.root;
  out_.block(comment("stepnc: " + root.label + " from " + o_.source));
  out_.block(comment("target " + d_.name + (o_.optionsText.empty() ? "" : ", options " + o_.optionsText)));
  out_.block(comment(std::string("lathe program: X is the ") + (diameterMode() ? "diameter" : "radius") +
                     ", Z along the spindle axis; feeds mm/rev, cutting speeds m/min, spindle rev/min"));
  out_.block(comment("coordinates are the workpiece's: X0 on the spindle axis; set the work offset's Z to the "
                     "workpiece's origin"));
  out_.block(comment("moves stepnc plans program each turning or grooving insert's imaginary tip (its chuck-side "
                     "corner), a threading insert's point, touched off on X and Z, with the nose radius in the path "
                     "(G40); toolpaths the file gives are written as given"));
  out_.block(comment("the imaginary tip is on the axis' side of the corner, away from it for a tool marked inside"));
  if (d_.controllerNoseCompensation)
    out_.block(comment("finishing passes are the surface under the controller's nose radius compensation: the tool "
                       "table holds each insert's radius and orientation as listed"));
  out_.block(comment(o_.toolTable ? "tool numbers from the tool table" : "no tool table: tools numbered in order "
                                                                         "of first use"));
  // The tools, numbered in order of first use (or by the table).
  for (const ir::Node *e : ir::programOrder(module))
    if (const ir::Node *moves = e->child(ir::Kind::Moves))
      if (const ir::Node *tool = ir::findTool(module, moves->text("tool").value_or(""));
          tool && (ir::isTurningStep(*e) || ir::drillsOnTurningAxis(*e)))
        if (!numbers_.count(tool->symbol)) {
          const int n = toolNumber(*tool);
          const bool axial = !ir::isTurningStep(*e);
          const bool knurling = tool->text("type") == "knurling_tool";
          out_.block(comment(word("T", std::to_string(n)) + " " + tool->label + ", " +
                             tool->text("type").value_or("") +
                             (axial      ? ", diameter " + formatFixed(tool->number("diameter").value_or(0), 3) + " mm"
                              : knurling ? std::string()
                                         : ", corner radius " +
                                               formatFixed(tool->number("corner_radius").value_or(0), 3) + " mm") +
                             (tool->has("cutting_width")
                                  ? (knurling ? ", wheels " : ", width ") +
                                        formatFixed(*tool->number("cutting_width"), 3) + " mm" +
                                        (knurling ? " wide, programmed at their chuck-side end" : "")
                                  : std::string()) +
                             (tool->has("knurl_pitch")
                                  ? ", " + tool->text("knurl_pattern").value_or("knurl") + " pitch " +
                                        formatFixed(*tool->number("knurl_pitch"), 3) + " mm"
                                  : std::string()) +
                             (tool->has("thread_pitch")
                                  ? ", pitch " + formatFixed(*tool->number("thread_pitch"), 3) + " mm"
                                  : std::string()) +
                             (moves->text("tip") == "inside" ? ", inside: its tip on the side away from the axis"
                                                             : std::string()) +
                             orientationNote(*tool, moves->text("tip") == "inside", axial)));
        }
  if (!ok_)
    return std::nullopt;
  preamble();
  for (const ir::Node *e : ir::programOrder(module)) {
    switch (e->kind) {
    case ir::Kind::DisplayMessage: message(e->text("message").value_or(e->label)); break;
    case ir::Kind::ProgramStop: out_.block(stop(false)); break;
    case ir::Kind::OptionalStop: out_.block(stop(true)); break;
    case ir::Kind::Workingstep:
      if (ir::drillsOnTurningAxis(*e)) {
        // A drill on the spindle axis: Z first from where the last step
        // left the tool (outside the bar), then onto the axis.
        if (const ir::Node *moves = e->child(ir::Kind::Moves))
          step(module, *e, *moves, true);
        break;
      }
      if (!ir::isTurningStep(*e)) {
        diags_.error(e->origin.loc, "workingstep " + e->symbol + " mills or drills, in a lathe program: " + d_.name +
                                        " does not write turning and milling in one program yet (docs/turning.md)")
            .entity(e->origin.entityId);
        return std::nullopt;
      }
      if (const ir::Node *moves = e->child(ir::Kind::Moves))
        step(module, *e, *moves);
      break;
    default:
      diags_.error(e->origin.loc, e->kindName() + " " + e->symbol + " in a lathe program: " + d_.name +
                                      " does not write it there yet (docs/turning.md)")
          .entity(e->origin.entityId);
      return std::nullopt;
    }
    if (!ok_)
      return std::nullopt;
  }
  postamble();
  closing();
  if (!out_.overlong().empty()) {
    diags_.error(SourceLoc{}, "line " + std::to_string(out_.overlong().front()) + " of the " + d_.name +
                                  " program is longer than the controller reads");
    return std::nullopt;
  }
  return out_.text();
}

void LatheEmitter::step(const ir::Module &module, const ir::Node &ws, const ir::Node &moves, bool onAxis) {
  out_.block(comment(ws.label.empty() ? ws.symbol : ws.label));
  const ir::Node *tool = ir::findTool(module, moves.text("tool").value_or(""));
  if (!tool)
    return;
  if (tool_ != tool->symbol) {
    toolChange(toolNumber(*tool));
    tool_ = tool->symbol;
    modal_.clear();
    spindleWords_.clear();
  }
  // The spindle: the step's constant surface speed, else its speed.
  const double rpm = moves.number("spindle").value_or(0);
  std::string spindle;
  for (const ir::Node &c : moves.children)
    if (c.kind == ir::Kind::State && c.has("surface_speed")) {
      spindle = surfaceSpeed(*c.number("surface_speed") / 1000, c.number("spindle_max").value_or(0), rpm < 0);
      break;
    }
  if (spindle.empty())
    spindle = spindleSpeed(rpm);
  if (spindle != spindleWords_) {
    out_.block(spindle);
    spindleWords_ = spindle;
  }
  const std::string cool = moves.text("coolant").value_or("off");
  if (cool != coolant_) {
    out_.block(coolant(cool));
    coolant_ = cool;
  }
  if (d_.controllerNoseCompensation && moves.has("nose_side") && tool->text("type") == "turning_tool") {
    std::vector<ir::Move> all;
    for (const ir::Move &m : ir::walkMoves(moves, std::nullopt, ir::PathKind::Programmed, ir::OutOfPlaneArcs::Exact))
      all.push_back(m);
    if (compensated(ws, moves, all, *tool))
      return;
  }
  bool first = true;
  for (const ir::Move &m : ir::walkMoves(moves, std::nullopt, ir::PathKind::Programmed, ir::OutOfPlaneArcs::Exact)) {
    if (first && onAxis && m.kind == ir::MoveKind::Rapid) {
      // Along Z alone first: the tool comes from outside the bar's radius.
      if (modal_.change("G", "0"))
        out_.block("G0 " + word("Z", num(m.to.z())));
      else
        out_.block(word("Z", num(m.to.z())));
      modal_.change("Z", num(m.to.z()));
    }
    first = false;
    move(m);
  }
}

void LatheEmitter::move(const ir::Move &m) {
  if (m.kind == ir::MoveKind::Dwell) {
    out_.block(dwell(m.dwell));
    return;
  }
  std::string text;
  auto axis = [&](const std::string &name, const std::string &value) {
    if (!modal_.change(name, value))
      return;
    if (!text.empty())
      text += ' ';
    text += word(name, value);
  };
  const std::string x = xWord(m.to.x()).substr(1), z = num(m.to.z());
  if (m.kind == ir::MoveKind::Rapid) {
    if (modal_.change("G", "0"))
      text = "G0";
    axis("X", x);
    axis("Z", z);
    if (text != "G0" && !text.empty())
      out_.block(text);
    else if (text == "G0")
      modal_.forget("G");  // nothing moved: the next move says its own G
    return;
  }
  const double perRev = m.node ? m.node->number("feed_per_rev").value_or(0) : 0;
  if (m.role == "thread") {
    // Synchronised with the spindle: G33 with the lead as K (LinuxCNC and
    // the 840D alike); the feed is the lead, F stays as it was.
    modal_.change("G", "33");
    text = "G33";
    modal_.forget("X");
    modal_.forget("Z");
    axis("X", x);
    axis("Z", z);
    out_.block(text + " " + word("K", formatNumber(perRev, {4, false, true})));
    return;
  }
  const bool byRev = perRev > 0;
  if (!perRev_ || *perRev_ != byRev) {
    out_.block(feedMode(byRev));
    perRev_ = byRev;
    modal_.forget("F");
  }
  const double f = byRev ? perRev : m.feed;
  bool arc = m.kind == ir::MoveKind::Arc;
  if (arc) {
    // An arc under half a turn whose ends print as one point would read as
    // a whole circle: it is the line it is within the printed resolution.
    const geom::Vec2 a(m.from->z() - m.center.z(), m.from->x() - m.center.x());
    const geom::Vec2 b(m.to.z() - m.center.z(), m.to.x() - m.center.x());
    const double sweep = turnAngle(a, b, m.ccw);
    if (arcPrintsClosed(geom::Vec2(m.from->z(), readX(m.from->x())), geom::Vec2(m.to.z(), readX(m.to.x())), sweep,
                        d_.coordDecimals))
      arc = false;
  }
  if (arc) {
    // In the ZX plane (G18): I the radius offset of the centre, K its z offset, from the start as read.
    const geom::Vec2 from(readX(m.from->x()), roundTo(m.from->z(), d_.coordDecimals));
    const geom::Vec2 to(readX(m.to.x()), roundTo(m.to.z(), d_.coordDecimals));
    const geom::Vec2 centre(m.center.x(), m.center.z());
    const geom::Vec2 ik = roundedCentreOffset(from, to, centre, d_.coordDecimals);
    // Counter-clockwise seen from +y in (z, x) is G3.
    const bool g3 = m.ccw;
    modal_.change("G", g3 ? "3" : "2");
    text = g3 ? "G3" : "G2";
    modal_.forget("X");
    modal_.forget("Z");
    axis("X", x);
    axis("Z", z);
    // The sweep in (z, x), counter-clockwise seen from +y.
    const geom::Vec2 a(from.y() - centre.y(), from.x() - centre.x()), b(to.y() - centre.y(), to.x() - centre.x());
    const bool moreThanHalf = turnAngle(a, b, g3) > std::numbers::pi;
    text += " " + arcCentre(ik, (centre - from).norm(), moreThanHalf);
  } else {
    if (modal_.change("G", "1"))
      text = "G1";
    axis("X", x);
    axis("Z", z);
  }
  const std::string fw = formatNumber(f, {byRev ? 4 : d_.feedDecimals, false, true});
  if (modal_.change("F", fw)) {
    if (!text.empty())
      text += ' ';
    text += word("F", fw);
  }
  if (!prefix_.empty()) {
    text = prefix_ + (text.empty() ? "" : " " + text);
    prefix_.clear();
  }
  if (!text.empty() && text != "G1")
    out_.block(text);
}

namespace {

/// A piece of a surface in (z, r): a line from a to b, or an arc about o of radius r.
struct Piece {
  bool arc = false;
  geom::Vec2 a, b, o;
  double r = 0;
};

/// Where two pieces, the lines extended and the arcs as whole circles, meet
/// nearest `near`; nullopt when they do not.
std::optional<geom::Vec2> meetNearest(const Piece &p, const Piece &q, const geom::Vec2 &near) {
  std::vector<geom::Vec2> pts;
  auto lineCircle = [&](const Piece &l, const Piece &c) {
    const geom::Vec2 d = (l.b - l.a).normalized();
    const geom::Vec2 foot = l.a + d * (c.o - l.a).dot(d);
    const double h2 = c.r * c.r - (foot - c.o).squaredNorm();
    if (h2 < 0)
      return;
    const double h = std::sqrt(h2);
    pts.push_back(foot + d * h);
    pts.push_back(foot - d * h);
  };
  if (!p.arc && !q.arc) {
    const geom::Vec2 d1 = p.b - p.a, d2 = q.b - q.a;
    const double den = geom::cross(d1, d2);
    if (std::abs(den) > 1e-12)
      pts.push_back(p.a + d1 * (geom::cross(q.a - p.a, d2) / den));
  } else if (!p.arc) {
    lineCircle(p, q);
  } else if (!q.arc) {
    lineCircle(q, p);
  } else {
    const geom::Vec2 d = q.o - p.o;
    const double l = d.norm();
    if (l > 1e-12 && l <= p.r + q.r && l >= std::abs(p.r - q.r)) {
      const double x = (l * l + p.r * p.r - q.r * q.r) / (2 * l), h = std::sqrt(std::max(0.0, p.r * p.r - x * x));
      const geom::Vec2 u = d / l, mid = p.o + u * x, across(-u.y(), u.x());
      pts.push_back(mid + across * h);
      pts.push_back(mid - across * h);
    }
  }
  std::optional<geom::Vec2> best;
  for (const geom::Vec2 &x : pts)
    if (!best || (x - near).norm() < (*best - near).norm())
      best = x;
  return best;
}

} // namespace

bool LatheEmitter::compensated(const ir::Node &ws, const ir::Node &moves, const std::vector<ir::Move> &all,
                               const ir::Node &tool) {
  // The pass: a line onto the surface (approach), the cuts along it, a line
  // off it (retract), each at feed.
  size_t first = all.size(), last = all.size();
  for (size_t i = 0; i + 1 < all.size(); ++i)
    if (all[i].kind == ir::MoveKind::Linear && all[i].role == "approach" && all[i + 1].isFeed() &&
        all[i + 1].role == "cut") {
      first = i;
      break;
    }
  for (size_t i = first + 1; i < all.size(); ++i)
    if (all[i].role != "cut") {
      last = i;
      break;
    }
  if (first >= all.size() || last >= all.size() || all[last].kind != ir::MoveKind::Linear ||
      all[last].role != "retract")
    return false;
  const double rc = tool.number("corner_radius").value_or(0);
  const bool left = moves.text("nose_side") == "left";
  const bool inside = moves.text("tip") == "inside";
  // The nose's centre from the programmed point (docs/turning.md), in (z, r).
  const geom::Vec2 tipToCentre(rc, inside ? -rc : rc);
  auto centre = [&](const ir::Vec3 &p) -> geom::Vec2 { return geom::Vec2(p.z(), p.x()) + tipToCentre; };
  auto space = [](const geom::Vec2 &p) { return ir::Vec3(p.y(), 0, p.x()); };
  // The surface under each cut: lines moved back by the radius across
  // their direction, arcs about the same centre a radius farther or
  // nearer; an arc of the nose's radius about a corner is the corner.
  std::vector<ir::Move> surface;
  std::optional<geom::Vec2> at;  // where the surface so far ends
  std::optional<std::pair<Piece, bool>> previous;  // the last piece, and whether the surface ends with it
  const double s = left ? 1 : -1;
  for (size_t i = first + 1; i < last; ++i) {
    const ir::Move &m = all[i];
    const geom::Vec2 a = centre(*m.from), b = centre(m.to);
    geom::Vec2 sa, sb;
    ir::Move out = m;
    if (m.kind == ir::MoveKind::Linear) {
      const geom::Vec2 d = (b - a).normalized(), leftOf(-d.y(), d.x());
      sa = a - s * rc * leftOf;
      sb = b - s * rc * leftOf;
    } else {
      const geom::Vec2 o = centre(m.center);
      const double r = (a - o).norm();
      // The centre is on the arc's left when it turns counter-clockwise.
      const double rs = (m.ccw == left) ? r + rc : r - rc;
      if (rs < 1e-6) {
        if (at && (*at - o).norm() > 1e-6)
          return false;
        at = o;
        if (previous)
          previous->second = false;
        continue;
      }
      sa = o + (a - o) * (rs / r);
      sb = o + (b - o) * (rs / r);
      out.center = space(o);
    }
    const Piece here{m.kind == ir::MoveKind::Arc, sa, sb, m.kind == ir::MoveKind::Arc ? centre(m.center) : sa,
                     m.kind == ir::MoveKind::Arc ? (sa - centre(m.center)).norm() : 0};
    if (at && (*at - sa).norm() > 1e-6) {
      // A corner the nose cannot fill (the pass's offsets meet there): the
      // surface's corner is where the two pieces, extended, meet nearest it.
      if (!previous || !previous->second)
        return false;
      const std::optional<geom::Vec2> corner = meetNearest(previous->first, here, a);
      if (!corner)
        return false;
      surface.back().to = space(*corner);
      sa = *corner;
    }
    out.from = space(sa);
    out.to = space(sb);
    surface.push_back(out);
    at = sb;
    previous = {here, true};
  }
  if (surface.empty())
    return false;
  // A controller enters along the line onto the surface, the nose square to
  // it at its end: only a line along the surface's first tangent puts the
  // nose where the pass starts.
  {
    const geom::Vec2 from(all[first].from->z(), all[first].from->x());
    const geom::Vec2 onto(surface.front().from->z(), surface.front().from->x());
    const ir::Move &m = surface.front();
    geom::Vec2 t;
    if (m.kind == ir::MoveKind::Linear) {
      t = geom::Vec2(m.to.z(), m.to.x()) - onto;
    } else {
      const geom::Vec2 radial = onto - geom::Vec2(m.center.z(), m.center.x());
      t = m.ccw ? geom::Vec2(-radial.y(), radial.x()) : geom::Vec2(radial.y(), -radial.x());
    }
    const geom::Vec2 in = onto - from;
    if (in.norm() <= rc || std::abs(geom::cross(in.normalized(), t.normalized())) > 1e-6 || in.dot(t) <= 0) {
      diags_.warning(ws.origin.loc, "workingstep " + ws.symbol +
                                        ": its finishing pass is not entered along the surface: written with the "
                                        "nose radius in the path (G40), not under the controller's compensation")
          .entity(ws.origin.entityId);
      return false;
    }
  }
  for (size_t i = 0; i < first; ++i)
    move(all[i]);
  // Onto the surface's start with the compensation on; along it; off it
  // with the compensation off, to the programmed point.
  ir::Move onto = all[first];
  onto.to = *surface.front().from;
  modal_.forget("G");
  prefix_ = compensation(left);
  move(onto);
  for (const ir::Move &m : surface)
    move(m);
  modal_.forget("G");
  prefix_ = compensationOff();
  move(all[last]);
  for (size_t i = last + 1; i < all.size(); ++i)
    move(all[i]);
  return true;
}

} // namespace stepnc::backends
