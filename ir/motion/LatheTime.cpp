#include "ir/motion/LatheTime.h"

#include "ir/motion/LatheSpindle.h"

#include "ir/geom/TurnedShape.h"

#include "ir/Program.h"
#include "ir/geom/MoveWalk.h"
#include "support/Format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace stepnc::ir {

namespace {

/// Length of the pieces a cut is timed in (mm): the spindle's speed is
/// taken at each piece's middle.
constexpr double kPiece = 0.1;

/// Time to move `d` mm from rest to rest at most `v` mm/s, accelerating at `a` mm/s^2.
double trapezoid(double d, double v, double a) {
  if (d <= 0 || v <= 0)
    return 0;
  if (a <= 0)
    return d / v;
  if (d >= v * v / a)
    return d / v + v / a;
  return 2 * std::sqrt(d / a);
}

class Timer {
public:
  Timer(const Module &m, const runtime::Machine &machine) : module_(m), machine_(machine) {
    if (const runtime::Axis *x = machine.axis("x"))
      x_ = *x;
    if (const runtime::Axis *z = machine.axis("z"))
      z_ = *z;
  }

  LatheTimeReport run() {
    for (const Node *e : programOrder(module_))
      if (isTurningStep(*e) || drillsOnTurningAxis(*e))
        if (const Node *moves = e->child(Kind::Moves))
          step(*e, *moves);
    travel("x", x_, xLo_, xHi_);
    travel("z", z_, zLo_, zHi_);
    return std::move(r_);
  }

private:
  /// The spindle's speed after `dt` s going towards `to`.
  double towards(double to, double dt) const {
    if (!machine_.spindleAcceleration)
      return to;
    const double most = *machine_.spindleAcceleration * dt;
    return spindle_ + std::clamp(to - spindle_, -most, most);
  }

  void step(const Node &ws, const Node &moves) {
    LatheStepTime st;
    st.step = &ws;
    st.minRpm = std::numeric_limits<double>::infinity();
    ask_ = LatheSpindle::of(moves, machine_);
    const double constant = std::abs(ask_.constant);
    if (!ask_.surfaceSpeed && (constant > machine_.spindleMax || (constant > 0 && constant < machine_.spindleMin)))
      violation(ws, "spindle " + formatFixed(constant, 0) + " rev/min is outside the machine's " +
                        formatFixed(machine_.spindleMin, 0) + ".." + formatFixed(machine_.spindleMax, 0) + " rev/min");
    double sinceCut = 0;  // rapids before this step's first cut: time the spindle has to get to speed
    bool cutting = false;
    for (const Move &m : walkMoves(moves, position_)) {
      const Vec3 to = m.to;
      extent(to);
      if (m.kind == MoveKind::Dwell) {
        st.seconds += m.dwell;
        r_.dwell += m.dwell;
        continue;
      }
      const Vec3 from = m.from.value_or(to);
      position_ = to;
      const double dx = std::abs(to.x() - from.x()), dz = std::abs(to.z() - from.z());
      if (m.kind == MoveKind::Rapid) {
        const double t = std::max(trapezoid(dx, x_.velocity / 60, x_.acceleration),
                                  trapezoid(dz, z_.velocity / 60, z_.acceleration));
        st.seconds += t;
        r_.rapid += t;
        if (!cutting)
          sinceCut += t;
        continue;
      }
      const bool thread = m.role == "thread";
      const double perRev = m.node ? m.node->number("feed_per_rev").value_or(0) : 0;
      const double length = (to - from).norm();
      if (!cutting) {
        // The first cut waits for the spindle to reach its speed there.
        bool clamped = false;
        const double n = thread ? constant : ask_.at(from.x(), &clamped);
        const double ramp = machine_.spindleAcceleration ? std::abs(n - spindle_) / *machine_.spindleAcceleration : 0;
        const double wait = std::max(0.0, ramp - sinceCut);
        st.seconds += wait;
        r_.spindleWait += wait;
        spindle_ = n;
        cutting = true;
      }
      const int pieces = std::max(1, static_cast<int>(std::ceil(length / kPiece)));
      const double ds = length / pieces;
      const Vec3 u = length > 0 ? Vec3((to - from) / length) : Vec3::Zero();
      double axisLimit = std::numeric_limits<double>::infinity();  // mm/min along the move
      if (std::abs(u.x()) > 1e-12)
        axisLimit = std::min(axisLimit, x_.velocity / std::abs(u.x()));
      if (std::abs(u.z()) > 1e-12)
        axisLimit = std::min(axisLimit, z_.velocity / std::abs(u.z()));
      for (int k = 0; k < pieces; ++k) {
        const Vec3 mid = from + u * (ds * (k + 0.5));
        bool clamped = false;
        const double want = thread ? constant : ask_.at(mid.x(), &clamped);
        // The time at the speed now, then the speed after that time.
        double n = spindle_ > 0 ? spindle_ : want;
        double feed = (m.feed > 0 ? m.feed : perRev * n);
        if (feed > axisLimit) {
          feed = axisLimit;
          r_.feedLimitedLength += ds;
        }
        const double dt = feed > 0 ? ds / (feed / 60) : 0;
        spindle_ = towards(want, dt);
        n = spindle_;
        st.seconds += dt;
        r_.cutting += dt;
        r_.cutLength += ds;
        if (clamped && ask_.surfaceSpeed)
          r_.clampedLength += ds;
        st.minRpm = std::min(st.minRpm, n);
        st.maxRpm = std::max(st.maxRpm, n);
        if (ask_.surfaceSpeed && !clamped && n < machine_.spindleMin - 1e-9 && !saidSlow_) {
          saidSlow_ = true;
          violation(ws, "its surface speed asks for " + formatFixed(n, 0) + " rev/min, below the machine's " +
                            formatFixed(machine_.spindleMin, 0));
        }
      }
    }
    if (!std::isfinite(st.minRpm))
      st.minRpm = st.maxRpm = 0;
    r_.total += st.seconds;
    r_.steps.push_back(st);
  }

  void extent(const Vec3 &p) {
    xLo_ = std::min(xLo_, p.x());
    xHi_ = std::max(xHi_, p.x());
    zLo_ = std::min(zLo_, p.z());
    zHi_ = std::max(zHi_, p.z());
  }

  void travel(const char *name, const runtime::Axis &a, double lo, double hi) {
    if (!(hi >= lo))
      return;
    const double length = a.travelMax - a.travelMin;
    if (hi - lo > length + 1e-6)
      r_.violations.push_back("the program spans " + formatFixed(hi - lo, 3) + " mm on " + name +
                              ", more than the axis's travel of " + formatFixed(length, 3) + " mm");
  }

  void violation(const Node &ws, const std::string &what) {
    r_.violations.push_back(ws.kindName() + " " + ws.symbol + ": " + what);
  }

  const Module &module_;
  const runtime::Machine &machine_;
  runtime::Axis x_, z_;
  LatheTimeReport r_;
  LatheSpindle ask_;      ///< what the step asks of the spindle
  double spindle_ = 0;   ///< the spindle's speed now, rev/min
  std::optional<Vec3> position_;
  bool saidSlow_ = false;
  double xLo_ = std::numeric_limits<double>::infinity(), xHi_ = -std::numeric_limits<double>::infinity();
  double zLo_ = std::numeric_limits<double>::infinity(), zHi_ = -std::numeric_limits<double>::infinity();
};

std::string percent(double part, double whole) { return formatFixed(whole > 0 ? 100 * part / whole : 0, 1) + " %"; }

} // namespace

LatheTimeReport timeLatheProgram(const Module &module, const runtime::Machine &machine) {
  return Timer(module, machine).run();
}

std::string formatLatheReport(const LatheTimeReport &r, const runtime::Machine &machine) {
  std::string out = "lathe program on \"" + machine.name + "\": " + std::to_string(r.steps.size()) + " lathe steps\n";
  out += "cycle time " + formatFixed(r.total, 3) + " s: cutting " + formatFixed(r.cutting, 3) + " s, rapids " +
         formatFixed(r.rapid, 3) + " s, dwells " + formatFixed(r.dwell, 3) + " s, waiting for the spindle " +
         formatFixed(r.spindleWait, 3) + " s (tool changes not counted)\n";
  out += "cutting length " + formatFixed(r.cutLength, 1) + " mm; the spindle at a limit (surface speed not held) on " +
         percent(r.clampedLength, r.cutLength) + " of it; the feed held down by an axis on " +
         percent(r.feedLimitedLength, r.cutLength) + "\n";
  for (const LatheStepTime &s : r.steps)
    out += "  " + s.step->kindName() + " " + s.step->symbol + (s.step->label.empty() ? "" : " \"" + s.step->label + "\"") +
           ": " + formatFixed(s.seconds, 3) + " s, spindle " + formatFixed(s.minRpm, 0) + ".." +
           formatFixed(s.maxRpm, 0) + " rev/min\n";
  if (r.violations.empty())
    out += "no limit broken\n";
  else {
    out += std::to_string(r.violations.size()) + " limits broken:\n";
    for (const std::string &v : r.violations)
      out += "  " + v + "\n";
  }
  return out;
}

} // namespace stepnc::ir
