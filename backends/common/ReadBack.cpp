#include "backends/common/ReadBack.h"

#include "backends/common/Words.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>

namespace stepnc::backends {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
/// Arcs: how far the path of a written arc may leave the planned circle
/// (and, with the printed precision, arcPathTol()). Its centre is written for
/// the printed end points (balanced between them, or found from CR=), a few
/// units of the last decimal from the planned one, and further across a
/// short chord, where the bisector turns with the rounding of the ends: the
/// pieces are matched by a centre tolerance that grows with radius over
/// chord, and judged by their path.
constexpr double kArcPathTolMm = 0.005;
/// Units of the last decimal an arc's path may stray by where they exceed kArcPathTolMm.
constexpr double kArcPathUnits = 3;
/// How far the angle a written arc turns may be from the plan's (radians).
/// Its path keeps to the plan's circle and it ends where the plan's ends
/// (both checked), so the angle can only be off by whole turns, or by the
/// rounding of its ends and centre: the check rules out a whole circle for
/// a sliver, or a turn too many or too few.
constexpr double kSweepTol = std::numbers::pi / 2;
/// Points along each written arc at which its distance to the planned circle is measured.
constexpr int kArcSamples = 8;
/// Dwells are written in seconds with 3 decimals.
constexpr double kDwellTolS = 0.0005 + 1e-9;
/// 1/min: inverse-time feeds are written with 4 decimals.
constexpr double kInverseTimeTol = 0.00005 + 1e-9;

/// The angles a turn of the rotary axes goes to, in its order.
std::vector<double> anglesOf(const Index &turn) {
  std::vector<double> out;
  for (const auto &a : turn.axes)
    out.push_back(a.second);
  return out;
}
/// Points along a spline piece at which its distance to the chord is measured.
constexpr int kSplineSamples = 16;

double unitOf(const TargetDescriptor &d) { return std::pow(10.0, -d.coordDecimals); }

/// How far a printed position may be from the planned one.
double positionTol(const TargetDescriptor &d) { return std::max(1e-3, unitOf(d)) + 1e-9; }

double arcPathTol(const TargetDescriptor &d) { return std::max(kArcPathTolMm, kArcPathUnits * unitOf(d)); }

double feedTol(const TargetDescriptor &d) { return 0.5 * std::pow(10.0, -d.feedDecimals) + 1e-6; }

/// How far a printed rotary angle (deg) may be from the planned one.
double angleTol(const TargetDescriptor &d) { return 0.5 * unitOf(d) + 1e-9; }

std::string point(const Vec3 &p) {
  auto c = [](double v) { return std::isfinite(v) ? formatFixed(v, 4) : std::string("?"); };
  return word("(", c(p.x())) + ", " + c(p.y()) + ", " + c(p.z()) + ")";
}

const char *kindName(Move::Kind k) {
  switch (k) {
  case Move::Kind::Rapid:
    return "rapid";
  case Move::Kind::Linear:
    return "linear";
  case Move::Kind::Arc:
    return "arc";
  case Move::Kind::Dwell:
    return "dwell";
  }
  return "move";
}

/// The planned move in words, for a report.
std::string describe(const Move &m) {
  std::string s = std::string(kindName(m.kind));
  if (m.kind == Move::Kind::Dwell)
    return s + " " + formatFixed(m.dwell, 3) + " s";
  s += " to " + point(m.to);
  if (m.kind == Move::Kind::Arc)
    s += std::string(m.ccw ? " ccw" : " cw") + (m.plane.isXY() ? "" : std::string(" in the ") + m.plane.name() + " plane") +
         " about (" + formatFixed(m.centre.x(), 4) + ", " + formatFixed(m.centre.y(), 4) + ")";
  if (m.kind != Move::Kind::Rapid)
    s += " at " + formatFixed(m.feed, 1) + " mm/min";
  return s;
}

/// Every coordinate the program sets agrees with the plan's.
bool samePlace(const Vec3 &read, const Vec3 &planned, double tol) {
  for (int k = 0; k < 3; ++k)
    if (std::isfinite(read[k]) && !(std::abs(read[k] - planned[k]) <= tol))
      return false;
  return true;
}

/// The distance from `p` to the segment a-b.
double toSegment(const geom::Vec2 &p, const geom::Vec2 &a, const geom::Vec2 &b) {
  const geom::Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// The step of program `p` whose text holds `line`: the last that starts at
/// or before it (none before the first step: the header).
std::optional<size_t> stepAt(const StepLines &lines, size_t line) {
  const auto after = std::upper_bound(lines.begin(), lines.end(), line);  // the lines never decrease
  if (after == lines.begin())
    return std::nullopt;
  return static_cast<size_t>(after - lines.begin() - 1);
}

class Comparison {
public:
  Comparison(const Program &p, const TargetDescriptor &d, const StepLines &lines, const std::string &text,
             double tolerance, DiagnosticEngine &diags)
      : p_(p), d_(d), lines_(lines), text_(text), tolerance_(tolerance), diags_(diags), posTol_(positionTol(d)) {}

  bool run(const ProgramReading &r) {
    if (!r.problems.empty()) {
      const auto &[line, why] = r.problems.front();
      std::string more;
      if (r.problems.size() > 1)
        more = " (and " + std::to_string(r.problems.size() - 1) + " more)";
      return fail(stepAt(lines_, line), line, why + more);
    }
    const std::vector<std::vector<Move>> planned = expectedMoves(p_, d_);
    std::vector<std::vector<const ReadMove *>> read(p_.steps.size());
    for (const ReadMove &m : r.moves) {
      const std::optional<size_t> step = stepAt(lines_, m.line);
      if (!step || p_.steps[*step].kind != Step::Kind::Moves)
        return fail(step, m.line, "a " + std::string(kindName(m.kind)) + " outside any workingstep's moves");
      read[*step].push_back(&m);
    }
    for (size_t i = 0; i < p_.steps.size(); ++i) {
      std::vector<const Move *> moves;
      for (const Move &m : planned[i])
        moves.push_back(&m);
      if (!step(i, moves, read[i]))
        return false;
    }
    return true;
  }

private:
  bool step(size_t i, const std::vector<const Move *> &planned, const std::vector<const ReadMove *> &read) {
    const bool cycle = std::any_of(read.begin(), read.end(), [](const ReadMove *m) { return m->cycle; });
    if (cycle)
      return cycleStep(i, planned, read);
    size_t a = 0, b = 0;
    while (a < planned.size() || b < read.size()) {
      if (a == planned.size())
        return fail(i, read[b]->line, "the program makes a " + std::string(kindName(read[b]->kind)) + " to " +
                                          point(read[b]->to) + " that the plan does not have");
      const Move &m = *planned[a];
      const size_t line = b < read.size() ? read[b]->line : lastLine(i, read);
      if (b == read.size())
        return fail(i, line, "the plan's " + describe(m) + " is not in the program");
      const ReadMove &w = *read[b];
      if (m.kind == Move::Kind::Rapid) {
        // A run of rapids is compared by where it ends: the emitter may
        // write one as several (Z alone first) or leave out what is not a motion.
        size_t a2 = a, b2 = b;
        while (a2 < planned.size() && planned[a2]->kind == Move::Kind::Rapid)
          ++a2;
        while (b2 < read.size() && read[b2]->kind == Move::Kind::Rapid)
          ++b2;
        if (b2 == b)
          return fail(i, w.line, "the plan's " + describe(*planned[a2 - 1]) + " is written as a " +
                                     kindName(w.kind));
        if (!samePlace(read[b2 - 1]->to, planned[a2 - 1]->to, posTol_))
          return fail(i, read[b2 - 1]->line, "the rapids end at " + point(read[b2 - 1]->to) + ", the plan's at " +
                                                 point(planned[a2 - 1]->to));
        if (!sameRotary(i, *planned[a2 - 1], *read[b2 - 1]))
          return false;
        a = a2;
        b = b2;
        continue;
      }
      if (m.kind == Move::Kind::Arc && w.kind == Move::Kind::Linear && m.turns == 0 && chordHolds(m)) {
        // An arc that keeps within the contour tolerance of its chord may
        // be written as the chord (the TNC's flat and tiny arcs).
        if (!feedMove(i, m, w))
          return false;
        ++a, ++b;
        continue;
      }
      if (w.kind != m.kind && !(m.kind == Move::Kind::Linear && w.spline))
        return fail(i, w.line, "a " + std::string(kindName(w.kind)) + " where the plan has a " + describe(m));
      switch (m.kind) {
      case Move::Kind::Dwell:
        if (!(std::abs(w.dwell - m.dwell) <= kDwellTolS))
          return fail(i, w.line, "a dwell of " + formatFixed(w.dwell, 3) + " s where the plan has " +
                                     formatFixed(m.dwell, 3) + " s");
        ++a, ++b;
        continue;
      case Move::Kind::Linear:
        if (!feedMove(i, m, w) || !splineBend(i, m, w))
          return false;
        ++a, ++b;
        continue;
      case Move::Kind::Arc:
        if (!arc(i, m, read, b))
          return false;
        ++a;
        continue;
      case Move::Kind::Rapid:
        break;
      }
    }
    return true;
  }

  /// A step written as a canned cycle: the cycle's rapids are the
  /// controller's, its feed moves and dwells must be the plan's.
  bool cycleStep(size_t i, const std::vector<const Move *> &planned, const std::vector<const ReadMove *> &read) {
    std::vector<const Move *> feeds;
    std::vector<const ReadMove *> made;
    for (const Move *m : planned)
      if (m->kind != Move::Kind::Rapid)
        feeds.push_back(m);
    for (const ReadMove *m : read)
      if (m->kind != Move::Kind::Rapid)
        made.push_back(m);
    for (size_t k = 0; k < std::max(feeds.size(), made.size()); ++k) {
      if (k == made.size())
        return fail(i, lastLine(i, read), "the canned cycle does not make the plan's " + describe(*feeds[k]));
      if (k == feeds.size())
        return fail(i, made[k]->line, "the canned cycle makes a " + std::string(kindName(made[k]->kind)) + " to " +
                                          point(made[k]->to) + " that the plan does not have");
      const Move &m = *feeds[k];
      const ReadMove &w = *made[k];
      if (w.kind != m.kind)
        return fail(i, w.line, "the canned cycle makes a " + std::string(kindName(w.kind)) + " where the plan has a " +
                                   describe(m));
      if (m.kind == Move::Kind::Dwell) {
        if (!(std::abs(w.dwell - m.dwell) <= kDwellTolS))
          return fail(i, w.line, "the canned cycle dwells " + formatFixed(w.dwell, 3) + " s where the plan dwells " +
                                     formatFixed(m.dwell, 3) + " s");
      } else if (!feedMove(i, m, w)) {
        return false;
      }
    }
    return true;
  }

  bool feedMove(size_t i, const Move &m, const ReadMove &w) {
    if (!samePlace(w.to, m.to, posTol_))
      return fail(i, w.line, "a " + std::string(kindName(w.kind)) + " to " + point(w.to) + " where the plan has a " +
                                 describe(m));
    if (m.inverseTime > 0 || w.inverseTime) {
      if (!w.inverseTime || !(m.inverseTime > 0) || !(std::abs(w.feed - m.inverseTime) <= kInverseTimeTol))
        return fail(i, w.line, (w.inverseTime ? "an inverse-time feed of " + formatFixed(w.feed, 4) + "/min"
                                              : "a feed of " + formatFixed(w.feed, 3) + " mm/min") +
                                   " where the plan has " +
                                   (m.inverseTime > 0 ? "an inverse-time feed of " + formatFixed(m.inverseTime, 4) +
                                                            "/min"
                                                      : "a feed of " + formatFixed(m.feed, 3) + " mm/min"));
      return sameRotary(i, m, w);
    }
    if (!(std::abs(w.feed - m.feed) <= feedTol(d_)))
      return fail(i, w.line, "a feed of " + formatFixed(w.feed, 3) + " mm/min where the plan has a " + describe(m));
    return sameRotary(i, m, w);
  }

  /// The rotary axes where a move of a step that tilts the tool leaves them.
  bool sameRotary(size_t i, const Move &m, const ReadMove &w) {
    for (size_t k = 0; k < m.rotary.size() && k < p_.rotaryAxes.size(); ++k) {
      const size_t axis = static_cast<size_t>(p_.rotaryAxes[k].front() - 'A');
      if (axis < 3 && !(std::abs(w.abc[axis] - m.rotary[k]) <= angleTol(d_)))
        return fail(i, w.line, p_.rotaryAxes[k] + (std::isfinite(w.abc[axis]) ? formatFixed(w.abc[axis], 4)
                                                                                : std::string(" not written")) +
                                   " where the plan has " + p_.rotaryAxes[k] + formatFixed(m.rotary[k], 4));
    }
    return true;
  }

  /// A Bézier spline piece keeps within the tolerance of the planned chord.
  bool splineBend(size_t i, const Move &m, const ReadMove &w) {
    if (!w.bezier || !std::isfinite(w.from.x()) || !std::isfinite(w.from.y()))
      return true;
    const geom::Vec2 p0 = w.from.head<2>(), p3 = w.to.head<2>();
    const auto &[p1, p2] = *w.bezier;
    double worst = 0;
    for (int k = 1; k < kSplineSamples; ++k) {
      const double t = double(k) / kSplineSamples, u = 1 - t;
      const geom::Vec2 q = u * u * u * p0 + 3 * u * u * t * p1 + 3 * u * t * t * p2 + t * t * t * p3;
      worst = std::max(worst, toSegment(q, m.from.head<2>(), m.to.head<2>()));
    }
    if (worst > tolerance_ + posTol_)
      return fail(i, w.line, "the spline piece leaves the plan's chord by " + formatFixed(worst, 4) +
                                 " mm, beyond the tolerance " + formatFixed(tolerance_, 4) + " mm");
    return true;
  }

  /// The planned arc against the read arcs from `b` on (an arc may be written
  /// in pieces about one centre); advances `b` past them. Pieces are taken
  /// until one ends where the plan's arc ends, within its last half turn.
  bool arc(size_t i, const Move &m, const std::vector<const ReadMove *> &read, size_t &b) {
    // In the plane's coordinates (centres are), the written arcs in the plan's plane.
    const double radius = (m.fromInPlane() - m.centre).norm();
    const double sweep = m.sweep();
    const ReadMove &first = *read[b];
    double made = 0;
    const ReadMove *last = nullptr;
    auto centreTol = [&](const ReadMove &w) {
      const double chord = (m.plane.local(w.to).head<2>() - m.plane.local(w.from).head<2>()).norm();
      return arcPathTol(d_) + posTol_ + 2 * unitOf(d_) * radius / std::max(chord, unitOf(d_));
    };
    while (b < read.size() && read[b]->kind == Move::Kind::Arc && read[b]->ccw == m.ccw &&
           read[b]->plane == m.plane && (read[b]->centre - m.centre).norm() <= centreTol(*read[b])) {
      last = read[b];
      if (const std::optional<double> off = offCircle(*last, m); off && *off > arcPathTol(d_) + posTol_)
        return fail(i, last->line, "the arc leaves the plan's circle by " + formatFixed(*off, 4) + " mm (more than " +
                                       formatFixed(arcPathTol(d_), 3) + " mm) where the plan has an " + describe(m));
      made += read[b]->sweep;
      if (!(std::abs(last->feed - m.feed) <= feedTol(d_)))
        return fail(i, last->line, "a feed of " + formatFixed(last->feed, 3) + " mm/min where the plan has a " +
                                       describe(m));
      ++b;
      if (samePlace(last->to, m.to, posTol_) && made > sweep - std::numbers::pi)
        break;
    }
    if (!last)
      return fail(i, first.line, std::string(first.ccw ? "a ccw" : "a cw") + " arc in the " + first.plane.name() +
                                     " plane about " + formatTuple({first.centre.x(), first.centre.y()}, 4) +
                                     " where the plan has an " + describe(m));
    if (!(std::abs(made - sweep) <= kSweepTol))
      return fail(i, last->line, "the arc turns " + formatFixed(made * 180 / std::numbers::pi, 3) +
                                     " deg where the plan's " + describe(m) + " turns " +
                                     formatFixed(sweep * 180 / std::numbers::pi, 3) + " deg");
    if (!samePlace(last->to, m.to, posTol_))
      return fail(i, last->line, "an arc to " + point(last->to) + " where the plan has an " + describe(m));
    return true;
  }

  /// The arc `m` keeps within the contour tolerance of its chord.
  bool chordHolds(const Move &m) const {
    const double radius = (m.fromInPlane() - m.centre).norm();
    const double sweep = m.sweep();
    const double sagitta = sweep >= std::numbers::pi ? radius : radius * (1 - std::cos(sweep / 2));
    return sagitta <= tolerance_ + posTol_;
  }

  /// How far the written arc `w` gets from the planned arc's circle (points
  /// at its ends and between); nullopt when where it starts is not known.
  static std::optional<double> offCircle(const ReadMove &w, const Move &m) {
    const geom::Vec2 from = m.plane.local(w.from).head<2>();
    if (!from.allFinite())
      return std::nullopt;
    const double radius = (m.fromInPlane() - m.centre).norm();
    double worst = std::abs((from - m.centre).norm() - radius);
    for (const geom::Vec2 &p : arcSplitPoints(from, w.centre, w.ccw, w.sweep, kArcSamples))
      worst = std::max(worst, std::abs((p - m.centre).norm() - radius));
    return worst;
  }

  size_t lastLine(size_t i, const std::vector<const ReadMove *> &read) const {
    if (!read.empty())
      return read.back()->line;
    return i + 1 < lines_.size() ? lines_[i + 1] : (i < lines_.size() ? lines_[i] : 0);
  }

  bool fail(std::optional<size_t> step, size_t line, const std::string &why) {
    const Step *s = step && *step < p_.steps.size() ? &p_.steps[*step] : nullptr;
    const ir::Node *exec = s ? s->exec : nullptr;
    std::string where = exec ? exec->kindName() + " " + exec->symbol + ": " : std::string("the program's header: ");
    std::string block;
    if (line > 0) {
      size_t start = 0;
      for (size_t n = 1; n < line && start != std::string::npos; ++n) {
        start = text_.find('\n', start);
        if (start != std::string::npos)
          ++start;
      }
      if (start != std::string::npos && start < text_.size())
        block = " `" + text_.substr(start, text_.find('\n', start) - start) + "`";
    }
    diags_.error(exec ? exec->origin.loc : SourceLoc{},
                 where + "the " + d_.name + " program stepnc wrote does not read back (a bug in stepnc): line " +
                     std::to_string(line) + block + ": " + why)
        .entity(exec ? exec->origin.entityId : 0);
    return false;
  }

  const Program &p_;
  const TargetDescriptor &d_;
  const StepLines &lines_;
  const std::string &text_;
  double tolerance_;
  DiagnosticEngine &diags_;
  double posTol_;
};

} // namespace

std::vector<std::vector<Move>> expectedMoves(const Program &p, const TargetDescriptor &d) {
  std::vector<std::vector<Move>> out(p.steps.size());
  // Where the program has the tool as printed; unknown (NaN) in X and Y after
  // a tool change until a move sets them.
  const double nan = std::nan("");
  Vec3 at(nan, nan, nan);
  std::vector<double> turned;  // the rotary angles as printed
  auto printedAngles = [&](const std::vector<double> &v) {
    std::vector<double> out;
    for (double a : v)
      out.push_back(roundTo(a, d.coordDecimals));
    return out;
  };
  auto printed = [&](const Vec3 &v) {
    return Vec3(roundTo(v.x(), d.coordDecimals), roundTo(v.y(), d.coordDecimals), roundTo(v.z(), d.coordDecimals));
  };
  for (size_t i = 0; i < p.steps.size(); ++i) {
    const Step &s = p.steps[i];
    if (s.toolChange || s.workOffset > 0)
      at = Vec3(nan, nan, nan);
    if (s.index)
      turned = printedAngles(anglesOf(*s.index));
    for (Move m : s.moves) {
      const Vec3 to = printed(m.to);
      if (m.alongZOnly) {
        out[i].push_back(m);
        at = Vec3(nan, nan, to.z());
        continue;
      }
      if (m.kind == Move::Kind::Arc && arcPrintsClosed(m.fromInPlane(), m.toInPlane(), m.sweep(), d.coordDecimals))
        m.kind = Move::Kind::Linear;
      if (m.turn)
        turned = printedAngles(anglesOf(*m.turn));
      const bool rotates = !m.rotary.empty() && printedAngles(m.rotary) != turned;
      if (!m.rotary.empty())
        turned = printedAngles(m.rotary);
      if ((m.kind == Move::Kind::Rapid || m.kind == Move::Kind::Linear) && to == at && !rotates)
        continue;  // prints as no motion
      out[i].push_back(m);
      if (m.kind != Move::Kind::Dwell)
        at = to;
    }
  }
  return out;
}

bool checkReadBack(const Program &p, const TargetDescriptor &d, const StepLines &stepLines, const std::string &text,
                   const ProgramReading &reading, double tolerance, DiagnosticEngine &diags) {
  return Comparison(p, d, stepLines, text, tolerance, diags).run(reading);
}

double arcRadiusTolerance(const TargetDescriptor &d) { return std::max(1e-3, unitOf(d)) + 1e-9; }

bool wellFormedNumber(const std::string &text, bool needPoint, std::string &why) {
  if (text.find_first_of("eE") != std::string::npos) {
    why = "'" + text + "' is in exponent notation";
    return false;
  }
  // An optional sign, then digits with at most one point, at least one digit.
  std::string_view body(text);
  if (!body.empty() && (body.front() == '-' || body.front() == '+'))
    body.remove_prefix(1);
  if (body.empty() || body.find_first_not_of("0123456789.") != std::string_view::npos ||
      std::count(body.begin(), body.end(), '.') > 1 || body == ".") {
    why = "'" + text + "' is not a number";
    return false;
  }
  if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) {
    why = "'" + text + "' is a negative zero";
    return false;
  }
  if (needPoint && text.find('.') == std::string::npos) {
    why = "'" + text + "' has no decimal point (a whole number may be read in units of the last decimal)";
    return false;
  }
  return true;
}

std::string blankLines(const std::string &text, const std::vector<size_t> &lines) {
  if (lines.empty())
    return text;
  std::string out;
  out.reserve(text.size());
  size_t line = 1, next = 0, start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos)
      end = text.size();
    while (next < lines.size() && lines[next] < line)
      ++next;
    if (!(next < lines.size() && lines[next] == line))
      out.append(text, start, end - start);
    if (end < text.size())
      out += '\n';
    start = end + 1;
    ++line;
  }
  return out;
}

} // namespace stepnc::backends
