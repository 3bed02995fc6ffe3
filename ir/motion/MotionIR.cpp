#include "ir/motion/MotionIR.h"

#include "ir/geom/MoveWalk.h"
#include "support/Format.h"

#include <algorithm>
#include <map>

namespace stepnc::ir {

using runtime::PathMove;
using runtime::Segment;
using runtime::SegmentKind;
using runtime::Vec3;

namespace {

std::vector<double> numbers(const Vec3 &v) { return {v.x(), v.y(), v.z()}; }

} // namespace

ProgramPath programPath(const ir::Module &module) {
  ProgramPath out;
  std::optional<Vec3> position;
  bool stop = false;
  std::string tool, setup;
  std::optional<double> spindle;
  struct Added {
    PathMove move;
    const ir::Node *owner = nullptr, *node = nullptr;
  };
  auto add = [&](const Added &a) {
    out.path.moves.push_back(a.move);
    out.owners.push_back(a.owner);
    out.nodes.push_back(a.node);
  };
  // Dwells before the first point the program names wait there, where the
  // tool starts: they go before the move that names it.
  std::vector<Added> leadingDwells;
  for (const ir::Node *e : programOrder(module)) {
    if (e->kind == ir::Kind::ProgramStop || e->kind == ir::Kind::OptionalStop) {
      stop = true;
      continue;
    }
    const ir::Node *moves = e->child(ir::Kind::Moves);
    if (!moves)
      continue;
    // A change of tool, setup or spindle happens at rest.
    const std::string t = moves->text("tool").value_or(""), s = moves->text("setup").value_or("");
    const double sp = moves->number("spindle").value_or(0);
    if (!out.nodes.empty() && (t != tool || s != setup || !spindle || *spindle != sp))
      stop = true;
    tool = t;
    setup = s;
    spindle = sp;
    for (const Move &m : walkMoves(*moves, position)) {
      PathMove pm;
      pm.stopBefore = stop;
      stop = false;
      if (m.kind == MoveKind::Dwell) {
        pm.kind = PathMove::Kind::Dwell;
        pm.dwellS = m.dwell;
        if (position) {
          pm.to = *position;
          add({pm, e, m.node});
        } else {
          leadingDwells.push_back({pm, e, m.node});  // where, the first move says
        }
        continue;
      }
      if (!position) {
        out.path.start = m.to;  // the tool starts at rest at the first point named
        position = m.to;
        for (Added &d : leadingDwells) {
          d.move.to = m.to;
          add(d);
        }
      }
      pm.kind = m.kind == MoveKind::Arc ? PathMove::Kind::Arc : PathMove::Kind::Line;
      pm.to = m.to;
      pm.center = m.center;
      pm.ccw = m.ccw;
      pm.turns = m.turns;
      pm.feed = m.isFeed() ? m.feed : 0;
      pm.axis = m.axis;
      add({pm, e, m.node});
      position = m.to;
    }
  }
  return out;
}

void attachMotion(ir::Module &module, const ProgramPath &program, const runtime::Trajectory &trajectory) {
  // The owners point into `module`, which is ours to change. Old motion
  // goes first; only children of executables change, so the owners stay
  // valid (the move nodes of `program` do not).
  auto mutableNode = [](const ir::Node *n) { return const_cast<ir::Node *>(n); };
  for (const ir::Node *e : programOrder(module)) {
    auto &cs = mutableNode(e)->children;
    cs.erase(std::remove_if(cs.begin(), cs.end(), [](const ir::Node &c) { return c.kind == ir::Kind::Motion; }), cs.end());
  }
  std::map<const ir::Node *, ir::Node> motions;
  std::vector<const ir::Node *> order;
  std::map<const ir::Node *, double> times;
  for (size_t k = 0; k < trajectory.segments.size(); ++k) {
    const Segment &seg = trajectory.segments[k];
    const runtime::SegmentInfo &info = trajectory.info[k];
    const runtime::Profile &prof = trajectory.profiles[k];
    const ir::Node *owner = program.owners.at(info.move);
    auto [it, fresh] = motions.try_emplace(owner, ir::Node(ir::Kind::Motion));
    ir::Node &motion = it->second;
    if (fresh) {
      order.push_back(owner);
      motion.set("machine", ir::Value::string(trajectory.machine));
      motion.set("tolerance", ir::Value::length(trajectory.tolerance));
      motion.set("cycle_time", ir::Value::real(trajectory.cycleTime));
      motion.set("from", ir::Value::reals(numbers(seg.start)));
      if (trajectory.frame == runtime::Frame::Zxy)
        motion.set("frame", ir::Value::word("zxy"));
    }
    times[owner] += prof.duration();
    ir::Node s(ir::Kind::MotionSegment);
    s.set("to", ir::Value::reals(numbers(seg.end)));
    switch (seg.kind) {
    case SegmentKind::Line: s.set("shape", ir::Value::word("line")); break;
    case SegmentKind::Arc:
      s.set("shape", ir::Value::word("arc"));
      s.set("center", ir::Value::reals({seg.center.x(), seg.center.y()}));
      s.set("dir", ir::Value::word(seg.ccw ? "ccw" : "cw"));
      s.set("sweep", ir::Value::real(seg.sweep));
      break;
    case SegmentKind::Blend: {
      s.set("shape", ir::Value::word("blend"));
      std::vector<double> pts;
      for (int i = 1; i <= 4; ++i)
        for (int c = 0; c < 3; ++c)
          pts.push_back(seg.ctrl[i][c]);
      s.set("points", ir::Value::reals(std::move(pts)));
      break;
    }
    case SegmentKind::Dwell: s.set("shape", ir::Value::word("dwell")); break;  // its time is its phases'
    }
    s.set("length", ir::Value::real(seg.length));
    if (info.feed > 0)
      s.set("feed", ir::Value::real(info.feed * 60));
    s.set("move", ir::Value::integer(info.move));
    if (info.nextMove != info.move)
      s.set("next", ir::Value::integer(info.nextMove));
    if (info.stop != runtime::StopReason::None)
      s.set("stop", ir::Value::word(std::string(runtime::stopReasonName(info.stop))));
    s.set("limited_by", ir::Value::word(std::string(runtime::speedLimitName(info.limitedBy))));
    s.set("limits", ir::Value::reals({info.limits.v, info.limits.a, info.limits.j}));
    s.set("v0", ir::Value::real(prof.v0));
    if (prof.a0 != 0)
      s.set("a0", ir::Value::real(prof.a0));
    std::vector<double> phases;
    for (const runtime::Phase &ph : prof.phases) {
      phases.push_back(ph.duration);
      phases.push_back(ph.jerk);
    }
    s.set("phases", ir::Value::reals(std::move(phases)));
    if (trajectory.frame == runtime::Frame::Zxy) {
      s.set("spindle", ir::Value::reals({info.spindle0, info.spindle1}));
      if (info.sync)
        s.set("sync", ir::Value::boolean(true));
    }
    const size_t jointCount = trajectory.axisNames.size();
    if (jointCount > 0 && trajectory.joints.size() == trajectory.segments.size() * jointCount)
      s.set("joints", ir::Value::reals(std::vector<double>(trajectory.joints.begin() + long(k * jointCount),
                                                           trajectory.joints.begin() + long((k + 1) * jointCount))));
    if (seg.tilted())
      s.set("axes", ir::Value::reals({seg.axis0.x(), seg.axis0.y(), seg.axis0.z(), seg.axis1.x(), seg.axis1.y(),
                                      seg.axis1.z()}));
    if (seg.axisCubic())
      s.set("axis_rates", ir::Value::reals({seg.axisRate0.x(), seg.axisRate0.y(), seg.axisRate0.z(),
                                            seg.axisRate1.x(), seg.axisRate1.y(), seg.axisRate1.z()}));
    // The joint that capped the segment: on one that tilts the tool, and on
    // any whose limiting axis is not the tip's own coordinate (a
    // parallel-kinematic machine's slider; on the serial chains an upright
    // segment's x, y or z is that coordinate and says nothing more).
    if (info.axis >= 0 && size_t(info.axis) < trajectory.axisNames.size()) {
      const std::string &axis = trajectory.axisNames[size_t(info.axis)];
      const bool tipCoordinate = info.axis < 3 && axis == std::string(1, "xyz"[info.axis]);
      if (seg.tilted() || !tipCoordinate)
        s.set("limited_axis", ir::Value::word(axis));
    }
    motion.add(std::move(s));
  }
  for (const ir::Node *owner : order) {
    ir::Node &motion = motions.at(owner);
    motion.set("time", ir::Value::time(times[owner]));
    // After `moves`: the motion follows the moves it was planned from.
    mutableNode(owner)->add(std::move(motion));
  }
}

std::optional<runtime::Trajectory> readMotion(const ir::Module &module, DiagnosticEngine &diags) {
  runtime::Trajectory out;
  bool any = false, ok = true;
  Vec3 at = Vec3::Zero();
  auto fail = [&](const ir::Node &n, const std::string &message) {
    diags.error(n.origin.loc, message);
    ok = false;
  };
  auto numbersOf = [&](const ir::Node &n, std::string_view name, size_t size) -> std::optional<std::vector<double>> {
    const ir::Value *v = n.get(name);
    if (!v || v->type != ir::ValueType::Reals || v->numbers.size() != size) {
      fail(n, n.kindName() + " needs '" + std::string(name) + "' with " + std::to_string(size) + " numbers");
      return std::nullopt;
    }
    return v->numbers;
  };
  for (const ir::Node *e : programOrder(module)) {
    const ir::Node *motion = e->child(ir::Kind::Motion);
    if (!motion)
      continue;
    const auto from = numbersOf(*motion, "from", 3);
    if (!from)
      continue;
    const Vec3 start((*from)[0], (*from)[1], (*from)[2]);
    if (!any) {
      out.machine = motion->text("machine").value_or("");
      out.tolerance = motion->number("tolerance").value_or(0);
      out.cycleTime = motion->number("cycle_time").value_or(out.cycleTime);
      if (!(out.cycleTime > 0))
        fail(*motion, "the machine's cycle time must be more than 0 s, not " + formatExact(out.cycleTime));
      out.start = start;
      at = start;
      any = true;
      if (motion->text("frame") == "zxy")
        out.frame = runtime::Frame::Zxy;
    } else if ((start - at).norm() > 1e-9) {
      fail(*motion, "motion starts at " + formatTuple({start.x(), start.y(), start.z()}, 6) +
                        ", not where the previous motion ended, " + formatTuple({at.x(), at.y(), at.z()}, 6));
    }
    for (const ir::Node &s : motion->children) {
      const auto to = numbersOf(s, "to", 3);
      const auto limits = numbersOf(s, "limits", 3);
      const auto phases = numbersOf(s, "phases", 14);
      if (!to || !limits || !phases)
        continue;
      const Vec3 end((*to)[0], (*to)[1], (*to)[2]);
      std::optional<std::vector<double>> spindle;
      if (out.frame == runtime::Frame::Zxy && !(spindle = numbersOf(s, "spindle", 2)))
        continue;
      const std::string shape = s.text("shape").value_or("");
      Segment seg;
      if (shape == "line") {
        seg = Segment::line(at, end);
      } else if (shape == "arc") {
        const auto c = numbersOf(s, "center", 2);
        if (!c || !s.number("sweep") || !s.text("dir")) {
          fail(s, "an arc segment needs 'center', 'dir' and 'sweep'");
          continue;
        }
        seg = Segment::arc(at, end, Vec3((*c)[0], (*c)[1], 0), s.text("dir") == "ccw", *s.number("sweep"));
      } else if (shape == "dwell") {
        if ((end - at).norm() > 1e-9) {
          fail(s, "a dwell waits where the tool is: 'to' " + formatTuple({end.x(), end.y(), end.z()}, 6) +
                      " is not where the previous segment ends, " + formatTuple({at.x(), at.y(), at.z()}, 6));
          continue;
        }
        seg = Segment::dwell(at);
      } else {
        const auto pts = numbersOf(s, "points", 12);
        if (!pts)
          continue;
        std::array<Vec3, 6> ctrl;
        ctrl[0] = at;
        ctrl[5] = end;
        for (int i = 0; i < 4; ++i)
          ctrl[i + 1] = Vec3((*pts)[3 * i], (*pts)[3 * i + 1], (*pts)[3 * i + 2]);
        seg = Segment::blend(ctrl);
      }
      const double length = s.number("length").value_or(0);
      if (!(std::abs(seg.length - length) <= 1e-9 * std::max(1.0, length))) {
        fail(s, "segment length " + formatExact(length) + " mm does not match its geometry (" +
                    formatExact(seg.length) + " mm)");
        continue;
      }
      runtime::SegmentInfo info;
      info.feed = s.number("feed").value_or(0) / 60;
      info.move = uint32_t(s.count("move").value_or(0));
      info.nextMove = uint32_t(s.count("next").value_or(info.move));
      // The kind table allows only the names these read.
      info.stop = runtime::stopReasonNamed(s.text("stop").value_or("none")).value_or(runtime::StopReason::None);
      info.limitedBy =
          runtime::speedLimitNamed(s.text("limited_by").value_or("feed")).value_or(runtime::SpeedLimit::Feed);
      info.limits = {(*limits)[0], (*limits)[1], (*limits)[2]};
      if (spindle) {
        info.spindle0 = (*spindle)[0];
        info.spindle1 = (*spindle)[1];
        info.sync = s.flag("sync").value_or(false);
      }
      if (s.has("axes")) {
        const auto axes = numbersOf(s, "axes", 6);
        if (!axes)
          continue;
        const Vec3 a0((*axes)[0], (*axes)[1], (*axes)[2]), a1((*axes)[3], (*axes)[4], (*axes)[5]);
        if (!(std::abs(a0.norm() - 1) <= 1e-6 && std::abs(a1.norm() - 1) <= 1e-6)) {
          fail(s, "a segment's 'axes' are two unit vectors, its tool axis at its start and at its end");
          continue;
        }
        seg.axis0 = runtime::unitAsWritten(a0);
        seg.axis1 = runtime::unitAsWritten(a1);
      }
      if (s.has("axis_rates")) {
        const auto rates = numbersOf(s, "axis_rates", 6);
        if (!rates)
          continue;
        seg.axisRate0 = Vec3((*rates)[0], (*rates)[1], (*rates)[2]);
        seg.axisRate1 = Vec3((*rates)[3], (*rates)[4], (*rates)[5]);
      }
      if (const ir::Value *j = s.get("joints"); j && j->type == ir::ValueType::Reals)
        out.joints.insert(out.joints.end(), j->numbers.begin(), j->numbers.end());
      if (const std::optional<std::string> name = s.text("limited_axis")) {
        auto it = std::find(out.axisNames.begin(), out.axisNames.end(), *name);
        if (it == out.axisNames.end())
          it = out.axisNames.insert(out.axisNames.end(), *name);
        info.axis = static_cast<int8_t>(it - out.axisNames.begin());
      }
      runtime::Profile prof;
      prof.v0 = s.number("v0").value_or(0);
      prof.a0 = s.number("a0").value_or(0);
      for (size_t i = 0; i < prof.phases.size(); ++i)
        prof.phases[i] = {(*phases)[2 * i], (*phases)[2 * i + 1]};
      if (seg.kind == SegmentKind::Dwell) {
        // At rest throughout, for some time (its phases' durations).
        bool rests = info.stop == runtime::StopReason::Dwell && prof.v0 == 0 && prof.a0 == 0;
        for (const runtime::Phase &ph : prof.phases)
          rests = rests && ph.jerk == 0 && ph.duration >= 0;
        if (!rests || !(prof.duration() > 0)) {
          fail(s, "a dwell segment waits at rest: stop=dwell, v0 and a0 0, phases of jerk 0 that last more than 0 s");
          continue;
        }
      }
      out.segments.push_back(std::move(seg));
      out.info.push_back(info);
      out.profiles.push_back(prof);
      at = end;
    }
  }
  // A program with nothing that moves (an empty workplan) has an empty
  // trajectory: no segments, planned on no machine.
  if (!any && !hasMachiningSteps(module))
    return out;
  if (!any)
    diags.error({}, "no motion to play: the IR has no 'motion' nodes (run plan-motion first)");
  if (!any || !ok)
    return std::nullopt;
  return out;
}

} // namespace stepnc::ir
