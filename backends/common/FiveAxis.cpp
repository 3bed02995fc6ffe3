#include "backends/common/FiveAxis.h"

#include "backends/common/Indexing.h"
#include "ir/geom/MoveWalk.h"
#include "runtime/Kinematics.h"
#include "support/Format.h"

#include <cmath>
#include <memory>

namespace stepnc::backends {

namespace {

/// Halvings of one move at most: a rotary axis turning half a turn at
/// 100 mm from the tip needs 8 to stay within 0.002 mm.
constexpr int kMaxHalvings = 16;
/// deg a rotary axis may turn within one block at feed: more is a flip.
constexpr double kFlipDeg = 90;

std::string pointText(const Vec3 &p) { return formatTuple({p.x(), p.y(), p.z()}, 4) + " mm"; }
std::string axisText(const Vec3 &a) { return formatTuple({a.x(), a.y(), a.z()}, 6); }

/// Whether a setup places the workpiece as it is (its workpiece_setup at
/// the origin, unturned): the frame the program's joints are reckoned in.
bool placedAsIs(const ir::Node *setup) {
  const ir::Node *ws = setup ? setup->child(ir::Kind::WorkpieceSetup) : nullptr;
  if (!ws)
    return true;
  return ws->vec("at").value_or(Vec3::Zero()).norm() <= 1e-9 &&
         (ws->vec("axis").value_or(Vec3::UnitZ()) - Vec3::UnitZ()).norm() <= 1e-9 &&
         (ws->vec("ref").value_or(Vec3::UnitX()) - Vec3::UnitX()).norm() <= 1e-9;
}

class Jointer {
public:
  /// `tcp`: for a controller with tool-centre-point control (the tip stays
  /// the program's point); `checkLinear`: the work offset is known, so the
  /// linear axes' travel is checked too.
  Jointer(Program &p, const runtime::Machine &machine, const runtime::Kinematics &kinematics, const Vec3 &workOffset,
          DiagnosticEngine &diags, bool tcp = false, bool checkLinear = true)
      : p_(p), machine_(machine), kin_(kinematics), offset_(workOffset), diags_(diags), tcp_(tcp),
        checkLinear_(checkLinear) {
    for (size_t k = 0; k < machine.axes.size(); ++k)
      if (machine.axes[k].rotary)
        rotary_.push_back(k);
    retractZ_ = machine.axes.at(2).travelMax;
    near_ = runtime::Joints::Zero(static_cast<Eigen::Index>(kinematics.jointCount()));
  }

  bool run() {
    // The rotary axes stand off 0 (where the program starts they may): a
    // step with the tool upright turns them to 0 first.
    bool turned = true;
    for (Step &s : p_.steps) {
      if (s.kind != Step::Kind::Moves || s.moves.empty())
        continue;
      if (!s.tilted) {
        // (Under tool-centre-point control each tilted step turns its axes
        // back to 0 itself, with the transformation still on.)
        if (turned && !s.index && !tcp_) {
          s.index = turnTo(home());
          for (size_t k : rotary_)
            near_[static_cast<Eigen::Index>(k)] = 0;
        }
        turned = s.index && std::any_of(s.index->axes.begin(), s.index->axes.end(),
                                        [](const auto &a) { return std::abs(a.second) > 1e-9; });
        continue;
      }
      if (!placedAsIs(s.setup)) {
        error(s, "tilts the tool on another face of the workpiece (setup " + s.setup->symbol +
                     "), which stepnc does not write yet: give it in the first clamping's frame");
        return false;
      }
      if (!(tcp_ ? tcpStep(s) : step(s)))
        return false;
      turned = !tcp_;  // a TCP step turns its axes back to 0 itself
    }
    for (size_t k : rotary_)
      p_.rotaryAxes.push_back(axisAddress(machine_.axes[k]));
    if (tcp_) {
      std::string names;
      for (const std::string &n : p_.rotaryAxes)
        names += (names.empty() ? "" : " ") + n;
      p_.indexing.push_back("the steps that tilt the tool are written with the controller's tool-centre-point "
                            "control: X Y Z the tool tip in the workpiece, " + names + " the rotary axes of " +
                            machine_.name + " in deg, feeds along the tip's path");
      return true;
    }
    std::string names;
    for (const std::string &n : p_.rotaryAxes)
      names += (names.empty() ? "" : " ") + n;
    p_.indexing.push_back("the steps that tilt the tool are written as the joints of " + machine_.name +
                          " (no tool-centre-point control): X Y Z less the work offset, " + names +
                          " in deg, feeds in inverse time (G93) while the tool tilts");
    p_.indexing.push_back("the workpiece's origin at X" + formatShortest(offset_.x()) + " Y" +
                          formatShortest(offset_.y()) + " Z" + formatShortest(offset_.z()) +
                          " in machine coordinates with every axis at 0; before each turn the tool goes up to Z" +
                          formatShortest(retractZ_) + " (G53)");
    return true;
  }

private:
  runtime::Joints home() const {
    runtime::Joints q = near_;
    for (size_t k : rotary_)
      q[static_cast<Eigen::Index>(k)] = 0;
    return q;
  }

  Index turnTo(const runtime::Joints &q) const {
    Index index;
    index.retractZ = retractZ_;
    for (size_t k : rotary_)
      index.axes.emplace_back(axisAddress(machine_.axes[k]), q[static_cast<Eigen::Index>(k)]);
    return index;
  }

  std::vector<double> rotaryOf(const runtime::Joints &q) const {
    std::vector<double> out;
    for (size_t k : rotary_)
      out.push_back(q[static_cast<Eigen::Index>(k)]);
    return out;
  }

  Vec3 programPoint(const runtime::Joints &q) const { return Vec3(q.head<3>()) - offset_; }

  void error(const Step &s, const std::string &why) {
    diags_.error(s.exec->origin.loc, "workingstep " + s.exec->symbol + ": " + why).entity(s.exec->origin.entityId);
  }

  /// The joints for a pose in the workpiece (tip, axis), nearest near_.
  std::optional<runtime::Joints> inverse(const Step &s, const Vec3 &tip, const Vec3 &axis,
                                         const runtime::Joints &near) {
    const runtime::InverseResult r = kin_.inverse({tip + offset_, axis}, &near);
    if (!r.joints) {
      error(s, "the machine cannot put the tool at " + pointText(tip) + " along " + axisText(axis) + ": " + r.why);
      return std::nullopt;
    }
    if (r.outsideTravel && (checkLinear_ || !outsideTravel(machine_, *r.joints, true).empty())) {
      error(s, "the tool at " + pointText(tip) + " along " + axisText(axis) +
                   " needs the machine's axes outside their travel (" + outsideTravel(machine_, *r.joints) +
                   ") with the workpiece's origin at " +
                   formatTuple({offset_.x(), offset_.y(), offset_.z()}, 3));
      return std::nullopt;
    }
    return r.joints;
  }

  /// A step for tool-centre-point control: the tip as the IR has it, the
  /// rotary angles on every move, moves halved where the angles' straight
  /// line would turn the tool off the IR's axis; the axes back to 0 after.
  bool tcpStep(Step &s) {
    std::vector<Move> out;
    bool placed = false;
    Vec3 at = Vec3::Zero();
    for (const Move &m : s.moves) {
      if (m.alongZOnly || m.kind == Move::Kind::Dwell) {
        Move c = m;
        if (m.kind == Move::Kind::Dwell)
          c.from = c.to = at;
        out.push_back(c);
        at = c.to;
        continue;
      }
      if (m.kind == Move::Kind::Arc) {
        error(s, "an arc among moves that tilt the tool is not written yet");
        return false;
      }
      const bool turning = !placed || (m.kind == Move::Kind::Rapid && ir::angleBetween(m.fromAxis, m.axis) > 1e-6);
      const std::optional<runtime::Joints> q = inverse(s, m.to, m.axis, turning ? home() : near_);
      if (!q)
        return false;
      placed = true;
      if (m.kind == Move::Kind::Rapid) {
        Move r = m;
        r.from = at;
        r.rotary = rotaryOf(*q);
        out.push_back(r);
        at = r.to;
        near_ = *q;
        continue;
      }
      // Halved until the rotary angles' straight line keeps the tool axis
      // within kJointAxisTolerance of the IR's halfway along each block.
      const bool written = halve(
          s, m, near_, *q,
          [&](double ta, double tb, const runtime::Joints &qa, const runtime::Joints &qb) {
            const Vec3 axis = kin_.forward((qa + qb) / 2).axis;
            return ir::angleBetween(axis, ir::turnAxis(m.fromAxis, m.axis, (ta + tb) / 2)) <= kJointAxisTolerance;
          },
          [&](const runtime::Joints &, const runtime::Joints &) {
            return "the rotary axes cannot follow the tool axis of the move to " + pointText(m.to) + " within " +
                   formatShortest(kJointAxisTolerance) + " deg (it passes near a rotary axis)";
          },
          [&](double ta, double tb, const runtime::Joints &qb) {
            Move b = m;
            b.from = at;
            b.to = poseAt(m, tb).first;
            b.rotary = rotaryOf(qb);
            b.fromAxis = ir::turnAxis(m.fromAxis, m.axis, ta);
            b.axis = ir::turnAxis(m.fromAxis, m.axis, tb);
            out.push_back(b);
            at = b.to;
          });
      if (!written)
        return false;
      near_ = *q;
    }
    if (placed) {
      // The rotary axes back to 0 with the tip still, before the transformation
      // goes off: the steps after run with them at 0.
      Move back = out.back();
      back.kind = Move::Kind::Rapid;
      back.feed = 0;
      back.inverseTime = 0;
      back.from = at;
      back.to = at;
      back.role = "position";
      back.fromAxis = back.axis;
      back.axis = Vec3::UnitZ();
      back.rotary = rotaryOf(home());
      back.turn.reset();
      out.push_back(back);
      near_ = home();
    }
    s.moves = std::move(out);
    return true;
  }

  bool step(Step &s) {
    radius_ = s.tool >= 0 ? p_.tools[static_cast<size_t>(s.tool)].diameter / 2 : 0;
    std::vector<Move> out;
    bool placed = false;
    Vec3 at = Vec3::Zero();  // where the tool is, program coordinates
    for (const Move &m : s.moves) {
      if (m.alongZOnly)
        continue;  // the turn at the step's start takes the tool up instead
      if (m.kind == Move::Kind::Dwell) {
        Move d = m;
        d.from = d.to = at;
        out.push_back(d);
        continue;
      }
      if (m.kind == Move::Kind::Arc) {
        error(s, "an arc among moves that tilt the tool is not written as joints yet");
        return false;
      }
      const bool turns = ir::angleBetween(m.fromAxis, m.axis) > 1e-6;
      // Where the tool turns up out of the way, the rotary axes start again
      // from the solution nearest the middle of their travel (0): the path
      // after has the most travel either way (a boss gone round needs a
      // whole turn of C).
      const bool turning = !placed || (m.kind == Move::Kind::Rapid && turns);
      const std::optional<runtime::Joints> q = inverse(s, m.to, m.axis, turning ? home() : near_);
      if (!q)
        return false;
      if (turning) {
        // Up to the top of z, the rotary axes alone, across at the top, down.
        Index turn = turnTo(*q);
        Move across = m;
        across.kind = Move::Kind::Rapid;
        across.feed = 0;
        across.from = Vec3(at.x(), at.y(), retractZ_ - offset_.z());
        across.to = Vec3(programPoint(*q).x(), programPoint(*q).y(), retractZ_ - offset_.z());
        across.rotary = rotaryOf(*q);
        across.role = "position";
        // Z alone first, as after a tool change (where the turn leaves it).
        Move up = across;
        up.alongZOnly = true;
        up.role = "clearance";
        up.to = across.from;
        if (placed)
          up.turn = std::move(turn);
        else
          s.index = std::move(turn);
        Move down = across;
        down.from = across.to;
        down.to = programPoint(*q);
        out.push_back(std::move(up));
        out.push_back(std::move(across));
        out.push_back(std::move(down));
        at = programPoint(*q);
        near_ = *q;
        placed = true;
        continue;
      }
      if (m.kind == Move::Kind::Rapid) {
        Move r = m;
        r.from = at;
        r.to = programPoint(*q);
        r.rotary = rotaryOf(*q);
        out.push_back(std::move(r));
        at = r.to;
        near_ = *q;
        continue;
      }
      if (!feed(s, m, near_, *q, out, at))
        return false;
      near_ = *q;
    }
    s.moves = std::move(out);
    return true;
  }

  /// The IR's pose a fraction t along move m.
  static std::pair<Vec3, Vec3> poseAt(const Move &m, double t) {
    return {m.from + t * (m.to - m.from), ir::turnAxis(m.fromAxis, m.axis, t)};
  }

  /// The blocks of a feed move from joints qa to qb: halved until the
  /// joints' straight line keeps to the IR's move.
  bool feed(const Step &s, const Move &m, const runtime::Joints &qa, const runtime::Joints &qb, std::vector<Move> &out,
            Vec3 &at) {
    const double length = (m.to - m.from).norm();
    const double turn = ir::angleBetween(m.fromAxis, m.axis) * std::numbers::pi / 180;
    // Minutes the move takes: the tip's path at the feed; turning in place,
    // a point on the tool's side one radius from the axis.
    const double minutes = (length > 1e-9 ? length : turn * radius_) / m.feed;
    if (!(minutes > 0))
      return true;  // no motion
    auto swing = [&](const runtime::Joints &a, const runtime::Joints &b) {
      double most = 0;
      for (size_t k : rotary_)
        most = std::max(most, std::abs(b[static_cast<Eigen::Index>(k)] - a[static_cast<Eigen::Index>(k)]));
      return most;
    };
    return halve(
        s, m, qa, qb,
        [&](double ta, double tb, const runtime::Joints &a, const runtime::Joints &b) {
          // The IR's pose nearest the joints' middle: by where the tip is
          // along the move (halfway when it turns in place).
          const runtime::ToolPose mid = kin_.forward((a + b) / 2);
          double t = (ta + tb) / 2;
          if (length > 1e-9)
            t = std::clamp((mid.tipMm - offset_ - m.from).dot(m.to - m.from) / (length * length), ta, tb);
          const auto [tip, axis] = poseAt(m, t);
          return (mid.tipMm - offset_ - tip).norm() <= kJointTolerance &&
                 ir::angleBetween(mid.axis, axis) <= kJointAxisTolerance && swing(a, b) < kFlipDeg;
        },
        [&](const runtime::Joints &a, const runtime::Joints &b) {
          return "the machine's joints cannot follow the move to " + pointText(m.to) + " along " + axisText(m.axis) +
                 ": the rotary axes would turn " + formatFixed(swing(a, b), 3) +
                 " deg within one block (the tool axis passes near a rotary axis, where the other has to swing "
                 "round, or an axis runs out of travel and only the chain's other solution is left)";
        },
        [&](double ta, double tb, const runtime::Joints &b) {
          Move block = m;
          block.from = at;
          block.to = programPoint(b);
          block.rotary = rotaryOf(b);
          block.inverseTime = 1 / (minutes * (tb - ta));
          block.fromAxis = ir::turnAxis(m.fromAxis, m.axis, ta);
          block.axis = ir::turnAxis(m.fromAxis, m.axis, tb);
          out.push_back(block);
          at = block.to;
        });
  }

  /// Move m from joints qa to qb cut in halves, each half's end through the
  /// inverse kinematics at the IR's pose there, until `holds(ta, tb, qa, qb)`
  /// says the block between keeps to the move; `emit(ta, tb, qb)` writes the
  /// blocks in order. False (reported: `why(qa, qb)` of the block that still
  /// does not hold after kMaxHalvings) when it cannot be made to.
  template <class Holds, class Why, class Emit>
  bool halve(const Step &s, const Move &m, const runtime::Joints &qa, const runtime::Joints &qb, Holds holds, Why why,
             Emit emit) {
    struct Piece {
      double ta, tb;
      runtime::Joints qa, qb;
      int depth;
    };
    std::vector<Piece> stack{{0, 1, qa, qb, 0}};
    while (!stack.empty()) {
      Piece piece = std::move(stack.back());
      stack.pop_back();
      if (holds(piece.ta, piece.tb, piece.qa, piece.qb)) {
        emit(piece.ta, piece.tb, piece.qb);
        continue;
      }
      if (piece.depth >= kMaxHalvings) {
        error(s, why(piece.qa, piece.qb));
        return false;
      }
      const double tm = (piece.ta + piece.tb) / 2;
      const auto [tip, axis] = poseAt(m, tm);
      const std::optional<runtime::Joints> qm = inverse(s, tip, axis, piece.qa);
      if (!qm)
        return false;
      // The second half after the first: pushed first.
      stack.push_back({tm, piece.tb, *qm, piece.qb, piece.depth + 1});
      stack.push_back({piece.ta, tm, piece.qa, *qm, piece.depth + 1});
    }
    return true;
  }

  Program &p_;
  const runtime::Machine &machine_;
  const runtime::Kinematics &kin_;
  Vec3 offset_;
  DiagnosticEngine &diags_;
  std::vector<size_t> rotary_;
  double retractZ_ = 0;
  double radius_ = 0;
  runtime::Joints near_;
  bool tcp_ = false;
  bool checkLinear_ = true;
};

} // namespace

bool jointMoves(Program &p, const runtime::Machine &machine, const Vec3 &workOffset, DiagnosticEngine &diags) {
  if (std::none_of(p.steps.begin(), p.steps.end(), [](const Step &s) { return s.tilted; }))
    return true;
  const std::unique_ptr<runtime::Kinematics> kinematics = turningKinematics(p, machine, workOffset, diags);
  if (!kinematics)
    return false;
  return Jointer(p, machine, *kinematics, workOffset, diags).run();
}

bool tcpMoves(Program &p, const runtime::Machine &machine, const std::optional<Vec3> &workOffset,
              DiagnosticEngine &diags) {
  if (std::none_of(p.steps.begin(), p.steps.end(), [](const Step &s) { return s.tilted; }))
    return true;
  std::string error;
  const std::unique_ptr<runtime::Kinematics> kinematics = runtime::makeKinematics(machine, error);
  if (!kinematics) {
    diags.error(SourceLoc{}, "the machine's kinematics: " + error);
    return false;
  }
  return Jointer(p, machine, *kinematics, workOffset.value_or(Vec3::Zero()), diags, true, workOffset.has_value()).run();
}

} // namespace stepnc::backends
