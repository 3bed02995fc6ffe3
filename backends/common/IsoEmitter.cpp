#include "backends/common/IsoEmitter.h"

#include "geom/Spline.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::backends {

namespace {
/// The most an arc block in the radius form turns (radians).
constexpr double kMaxRadiusArcSweep = 2 * std::numbers::pi / 3;
} // namespace

std::vector<std::string> headerLines(const Program &p, const EmitOptions &o, const TargetDescriptor &d) {
  std::vector<std::string> lines;
  lines.push_back("stepnc: " + p.name + " from " + o.source);
  lines.push_back("target " + d.name + (o.optionsText.empty() ? "" : ", options " + o.optionsText));
  lines.push_back("units mm, feeds mm/min, spindle rev/min; coordinates are the workpiece's: set the work "
                  "offset to its origin");
  for (const std::string &line : p.indexing)
    lines.push_back(line);
  if (!p.clampings.empty()) {
    const auto stops = std::count_if(p.steps.begin(), p.steps.end(), [](const Step &s) { return s.reclamp; });
    lines.push_back("the program re-clamps the workpiece " + std::to_string(stops) +
                    " times, stopping for each; one work offset per clamping:");
    for (const auto &clamping : p.clampings)
      lines.push_back(clamping.second);
  }
  if (p.toolsFromTable)
    lines.push_back("tool numbers and lengths from the tool table");
  else
    lines.push_back("no tool table: tools numbered in order of first use");
  for (const ToolCall &t : p.tools)
    lines.push_back(word("T", std::to_string(t.number)) + " " + t.label + ", diameter " + formatFixed(t.diameter, 3) +
                    " mm" + (t.length ? ", length " + formatFixed(*t.length, 3) + " mm" : ""));
  return lines;
}

void IsoEmitter::turn(const Index &index) {
  // The tool up out of the way (machine coordinates), then the turn.
  out_.block("G53 G0 Z" + num(index.retractZ));
  std::string words = "G0";
  for (const auto &[axis, deg] : index.axes)
    words += " " + axis + num(deg);
  out_.block(words);
  for (const char *w : {"G", "X", "Y", "Z"})
    modal_.forget(w);
  for (const auto &[axis, deg] : index.axes) {
    modal_.forget(axis);
    modal_.change(axis, num(deg));
  }
}

void IsoEmitter::faceTurn(const Index &index, const std::optional<WorkingPlane> &) { turn(index); }

std::string IsoEmitter::rotaryWords(const Move &m) {
  std::string words;
  for (size_t k = 0; k < m.rotary.size() && k < program_->rotaryAxes.size(); ++k) {
    const std::string &name = program_->rotaryAxes[k];
    const std::string v = num(m.rotary[k]);
    if (modal_.change(name, v))
      words += " " + name + v;
  }
  return words;
}

void IsoEmitter::feedMode(bool inverseTime) {
  if (inverseTime == inverseTime_)
    return;
  out_.block(inverseTime ? "G93" : "G94");
  inverseTime_ = inverseTime;
  modal_.forget("F");  // the controller takes no feed over from the other mode
}

std::optional<std::string> IsoEmitter::run(const Program &p) {
  program_ = &p;
  header(p);
  for (const Step &s : p.steps) {
    stepLines_.push_back(out_.lines() + 1);
    switch (s.kind) {
    case Step::Kind::Message:
      message(s.label);
      continue;
    case Step::Kind::Stop:
    case Step::Kind::OptionalStop:
      if (s.index)
        faceTurn(*s.index, s.plane);
      if (s.reclamp)
        beforeReclamp();
      stop(s.kind == Step::Kind::OptionalStop);
      continue;
    case Step::Kind::Moves:
      break;
    }
    out_.block(comment(s.label));
    if (s.index)
      faceTurn(*s.index, s.plane);
    if (s.workOffset > 0) {
      const std::string offset = workOffsetWord(s.workOffset);
      if (offset.empty())
        diags_.error(s.exec->origin.loc, d_.name + " has no work offset " + std::to_string(s.workOffset) +
                                             " for workingstep " + s.exec->symbol + "'s setup");
      else
        out_.block(offset);
      // Where the axes are in the new offset is not where they were.
      for (const char *w : {"G", "X", "Y", "Z"})
        modal_.forget(w);
    }
    if (s.tool >= 0 && s.tool != tool_) {
      toolChange(p.tools[static_cast<size_t>(s.tool)]);
      tool_ = s.tool;
      spindle_ = 0;  // a tool change stops the spindle
      // Where the tool change left the axes is the machine's business: the
      // first move writes every axis and the feed again.
      for (const char *w : {"G", "X", "Y", "Z", "F"})
        modal_.forget(w);
    }
    if (s.spindle != 0 && s.spindle != spindle_) {
      out_.block(spindle(s.spindle));
      spindle_ = s.spindle;
    }
    if (s.coolant != coolant_) {
      out_.block(coolant(s.coolant));
      coolant_ = s.coolant;
    }
    const std::string whyNot = s.cycle ? whyNotCycle(d_, *s.cycle) : "its moves are not one canned cycle";
    if (whyNot.empty() && cycle(s, *s.cycle))
      continue;
    if (s.taps()) {
      // Written as moves, a tap would be driven out without the spindle reversed.
      diags_.error(s.exec->origin.loc, "workingstep " + s.exec->symbol + " (" + s.operationName() +
                                           ") can only be written as the controller's tapping cycle, and " +
                                           (whyNot.empty() ? "that cycle does not make its planned moves" : whyNot))
          .entity(s.exec->origin.entityId);
      continue;
    }
    bool tcp = false;  // the controller's tool-centre-point control on (a tilted step's)
    for (size_t i = 0; i < s.moves.size();) {
      if (s.tilted && !tcp && !d_.tcpOn.empty() && !s.moves[i].rotary.empty()) {
        out_.block(d_.tcpOn);
        tcp = true;
      }
      process(s, s.moves[i].before);
      const size_t end = smoothRunEnd(s.moves, i);
      if (end >= i + 2) {
        spline(s.moves, i, end);
        i = end;
      } else {
        move(s.moves[i++]);
      }
    }
    process(s, s.after);
    if (tcp)
      out_.block(d_.tcpOff);
    feedMode(false);
    if (const std::string g17 = selectPlane(geom::ArcPlane::xy()); !g17.empty())
      out_.block(g17);
  }
  footer(p);
  for (size_t line : out_.overlong())
    diags_.error(SourceLoc{}, "line " + std::to_string(line) + " of the " + d_.name + " program is longer than " +
                 std::to_string(d_.maxLineLength) + " characters, the most the controller reads");
  if (!out_.overlong().empty() || diags_.hasErrors())
    return std::nullopt;
  return out_.text();
}

void IsoEmitter::process(const Step &s, const std::vector<ProcessChange> &changes) {
  if (changes.empty())
    return;
  const runtime::DepositionCodes *codes = o_.deposition;
  auto refuse = [&](const ir::Node *at, const std::string &why) {
    const ir::Node &where = at && at->origin.loc.valid() ? *at : *s.exec;
    diags_.error(where.origin.loc, "workingstep " + s.exec->symbol + ": " + why).entity(where.origin.entityId);
  };
  if (!codes || codes->target != d_.name) {
    if (!saidNoCodes_)
      refuse(s.exec, !codes ? "deposits: the codes that switch the head's energy and material and set them are "
                              "machine data: give --machine with a [deposition] table (docs/additive.md)"
                            : "deposits: the [deposition] codes of --machine are written for " + codes->target +
                                  ", not " + d_.name);
    saidNoCodes_ = true;
    return;
  }
  auto write = [&](const std::string &code, const char *placeholder, std::optional<double> value) {
    std::string text = code;
    if (value)
      if (size_t at = text.find(placeholder); at != std::string::npos)
        text.replace(at, std::string_view(placeholder).size(), formatTrimmed(*value, 3));
    out_.block(text);
    processLines_.push_back(out_.lines());
  };
  for (const ProcessChange &c : changes) {
    if (c.energy && !*c.energy)
      write(codes->energyOff, "", std::nullopt);
    if (c.power) {
      if (*c.power > codes->maxPower)
        refuse(c.node, "a power of " + formatShortest(*c.power) + " W is more than the machine's head gives (" +
                           formatShortest(codes->maxPower) + " W)");
      else
        write(codes->power, "{power}", *c.power);
    }
    for (auto [value, code, limit, placeholder, what, unit] :
         {std::tuple{c.powder, &codes->powder, codes->maxPowder, "{powder}", "powder feed", "g/min"},
          {c.wire, &codes->wire, codes->maxWire, "{wire}", "wire feed", "mm/min"}}) {
      if (!value)
        continue;
      if (code->empty())
        refuse(c.node, std::string("the machine's [deposition] table has no code for the ") + what);
      else if (limit && *value > *limit)
        refuse(c.node, std::string("a ") + what + " of " + formatShortest(*value) + " " + unit +
                           " is more than the machine's feeder gives (" + formatShortest(*limit) + " " + unit + ")");
      else
        write(*code, placeholder, *value);
    }
    if (c.energy && *c.energy)
      write(codes->energyOn, "", std::nullopt);
  }
}

std::string IsoEmitter::spindle(double rpm) const {
  return word("S", formatNumber(std::abs(rpm), {d_.speedDecimals, false, false})) + (rpm < 0 ? " M3" : " M4");
}

std::string IsoEmitter::coolant(const std::string &mode) const { return coolantWord(mode); }

std::string IsoEmitter::radiusWord(double signedRadius) const { return word("R", num(signedRadius)); }

void IsoEmitter::stop(bool optional) { out_.block(optional ? "M1" : "M0"); }

void IsoEmitter::beforeReclamp() {
  out_.block("M5 M9");
  spindle_ = 0;
  coolant_ = "off";
}

std::string IsoEmitter::axes(const Vec3 &to, std::optional<geom::ArcPlane> force) {
  std::string words;
  const char *names[3] = {"X", "Y", "Z"};
  for (int k = 0; k < 3; ++k) {
    const std::string v = num(to[k]);
    if (modal_.change(names[k], v) || (force && k != force->normal)) {
      if (!words.empty())
        words += ' ';
      words += names[k] + v;
    }
  }
  return words;
}

std::string IsoEmitter::feedWord(double feed) {
  const std::string f = formatNumber(feed, {d_.feedDecimals, false, true});
  return modal_.change("F", f) ? " F" + f : "";
}

void IsoEmitter::assumeAt(const Vec3 &p) {
  modal_.forget("G");
  const char *names[3] = {"X", "Y", "Z"};
  for (int k = 0; k < 3; ++k) {
    modal_.forget(names[k]);
    modal_.change(names[k], num(p[k]));
  }
}

void IsoEmitter::positionFor(const Step &s) {
  for (const Move &m : s.moves) {
    if (!m.positions())
      break;
    move(m);
  }
}

void IsoEmitter::move(const Move &m) {
  if (m.turn)
    turn(*m.turn);
  if (m.kind == Move::Kind::Arc) {
    arc(m);
    return;
  }
  if (m.kind == Move::Kind::Dwell) {
    out_.block(dwell(m.dwell));
    return;
  }
  if (m.alongZOnly) {
    // Up from wherever the tool is: X and Y are not written (nor known).
    const std::string z = num(m.to.z());
    modal_.forget("Z");
    modal_.change("Z", z);
    out_.block((modal_.change("G", "G0") ? "G0 " : "") + word("Z", z));
    return;
  }
  const std::string g = m.kind == Move::Kind::Rapid ? "G0" : "G1";
  // Which axes change as printed; a move that prints as no motion is left out.
  std::string words = axes(m.to) + rotaryWords(m);
  if (!words.empty() && words.front() == ' ')
    words.erase(0, 1);
  if (words.empty())
    return;
  if (m.kind == Move::Kind::Linear)
    feedMode(m.inverseTime > 0);
  std::string text = modal_.change("G", g) ? g + " " + words : words;
  if (m.kind == Move::Kind::Linear && m.inverseTime > 0)
    text += " F" + formatNumber(m.inverseTime, {4, false, true});  // every block in G93
  else if (m.kind == Move::Kind::Linear)
    text += feedWord(m.feed);
  out_.block(text);
}

size_t IsoEmitter::smoothRunEnd(const std::vector<Move> &moves, size_t i) const {
  if (d_.splines == SplineForm::None)
    return i;
  size_t j = i;
  while (j < moves.size() && moves[j].kind == Move::Kind::Linear && moves[j].smooth &&
         moves[j].from.z() == moves[i].from.z() && moves[j].to.z() == moves[i].from.z() &&
         (moves[j].to - moves[j].from).norm() > 1e-9)
    ++j;
  return j;
}

void IsoEmitter::spline(const std::vector<Move> &moves, size_t begin, size_t end) {
  std::vector<geom::Vec2> points{moves[begin].from.head<2>()};
  for (size_t i = begin; i < end; ++i)
    points.push_back(moves[i].to.head<2>());
  if (d_.splines == SplineForm::CubicBezier) {
    // One G5 per piece: its end, and its two inner control points as offsets
    // from its start (I J) and from its end (P Q). The curve is the C2 spline
    // through the points, computed here, so the controller draws exactly it.
    const std::vector<geom::BezierPiece> pieces = geom::splineThrough(points);
    for (size_t k = 0; k < pieces.size(); ++k) {
      const Move &m = moves[begin + k];
      const geom::Vec2 from = points[k], to = points[k + 1];
      modal_.change("X", num(to.x()));
      modal_.change("Y", num(to.y()));
      const geom::Vec2 ij = pieces[k].c1 - from, pq = pieces[k].c2 - to;
      modal_.change("G", "G5"); // written on every block: LinuxCNC reads P as G2/G3's turns otherwise
      out_.block("G5 " + word("X", num(to.x())) + word(" Y", num(to.y())) + word(" I", num(ij.x())) +
                 word(" J", num(ij.y())) + word(" P", num(pq.x())) + word(" Q", num(pq.y())) + feedWord(m.feed));
    }
    return;
  }
  // The controller's cubic spline through the points, its ends set by the
  // first and last points alone (BAUTO EAUTO: the moves before and after
  // need not be tangent to it); the next straight move selects G1 again.
  for (size_t i = begin; i < end; ++i) {
    const Move &m = moves[i];
    const bool first = i == begin;
    modal_.change("X", num(m.to.x()));
    modal_.change("Y", num(m.to.y()));
    std::string text = first ? "CSPLINE BAUTO EAUTO " : "";
    text += word("X", num(m.to.x())) + word(" Y", num(m.to.y())) + feedWord(m.feed);
    out_.block(text);
  }
  modal_.change("G", "CSPLINE");
}

std::string IsoEmitter::selectPlane(geom::ArcPlane p) {
  if (p == plane_)
    return {};
  plane_ = p;
  modal_.forget("G");  // G2/G3 are written again in the new plane
  return p.isXY() ? "G17" : p.normal == 1 ? "G18" : "G19";
}

void IsoEmitter::arc(const Move &m) {
  // In the plane's coordinates (x, y for XY; geom/ArcPlane.h): the same
  // rules in every plane, the normal's coordinate as the helix's axis.
  const geom::ArcPlane &plane = m.plane;
  const double sweep = m.sweep();
  if (arcPrintsClosed(m.fromInPlane(), m.toInPlane(), sweep, d_.coordDecimals)) {
    Move line = m;
    line.kind = Move::Kind::Linear;
    move(line);
    return;
  }
  const Vec3 localFrom = plane.local(m.from), localTo = plane.local(m.to);
  const Vec3 from(roundTo(localFrom.x(), d_.coordDecimals), roundTo(localFrom.y(), d_.coordDecimals), localFrom.z());
  // Pieces: the radius form takes at most a third of a turn per block (the
  // controller finds the centre from R and the printed ends, which near half
  // a turn moves it by many times the rounding); a target without multi-turn
  // helices takes at most one turn per block.
  int pieces = 1;
  if (d_.arcs == ArcForm::Radius)
    pieces = std::max(1, static_cast<int>(std::ceil(sweep / kMaxRadiusArcSweep - 1e-9)));
  else if (!d_.helixTurns && m.turns > 0)
    pieces = static_cast<int>(m.turns) + 1;
  const bool oneBlockTurns = pieces == 1 && m.turns > 0;
  std::vector<geom::Vec2> ends = arcSplitPoints(m.fromInPlane(), m.centre, m.ccw, sweep, pieces);
  ends.back() = m.toInPlane();
  geom::Vec2 start = from.head<2>();
  // I J K: the offsets along the plane's first and second axes.
  const std::string firstOffset(1, "IJK"[plane.first()]), secondOffset(1, "IJK"[plane.second()]);
  for (int k = 0; k < pieces; ++k) {
    const double z = localFrom.z() + (localTo.z() - localFrom.z()) * (k + 1) / pieces;
    const Vec3 to(ends[k].x(), ends[k].y(), z);
    const geom::Vec2 printedTo(roundTo(to.x(), d_.coordDecimals), roundTo(to.y(), d_.coordDecimals));
    const std::string g = m.ccw ? "G3" : "G2";
    std::string text = selectPlane(plane);
    if (!text.empty())
      text += ' ';
    text += modal_.change("G", g) ? g + " " : "";
    text += axes(plane.world(to), plane);
    if (d_.arcs == ArcForm::Radius) {
      const double r = (m.centre - m.fromInPlane()).norm();
      const double pieceSweep = sweep / pieces;
      text += ' ';
      text += radiusWord(pieceSweep > std::numbers::pi ? -r : r);
    } else {
      // The centre on the printed chord's bisector, so that both printed
      // ends are as far from it; but over a chord much shorter than the
      // radius the bisector turns with the rounding of the ends, and
      // projecting moves the centre by far more than the rounding: there
      // the planned centre is kept when its radii to the printed ends
      // already agree within two units (0.0002 mm at 4 decimals; LinuxCNC
      // allows 0.00127 mm by default).
      const double unit = std::pow(10.0, -d_.coordDecimals);
      const bool agrees = std::abs((m.centre - start).norm() - (m.centre - printedTo).norm()) <= 2 * unit;
      const bool shortChord = (printedTo - start).norm() < 0.1 * (m.centre - start).norm();
      const geom::Vec2 centre = agrees && shortChord ? m.centre : geom::balancedCentre(start, printedTo, m.centre);
      const geom::Vec2 ij = roundedCentreOffset(start, printedTo, centre, d_.coordDecimals);
      // Written I, J, K in that order (ZX: I then K).
      const std::string a = word(" " + firstOffset, num(ij.x())), b = word(" " + secondOffset, num(ij.y()));
      text += plane.normal == 1 ? b + a : a + b;
    }
    if (oneBlockTurns) {
      const std::string w = turnsWord(m.turns);
      if (!w.empty())
        text += word(" ", w);
    }
    text += feedWord(m.feed);
    out_.block(text);
    start = printedTo;
  }
}

} // namespace stepnc::backends
