#include "backends/common/Indexing.h"

#include "ir/Program.h"
#include "runtime/Kinematics.h"
#include "support/Format.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

namespace stepnc::backends {

namespace {

/// Where a setup places the workpiece: q = at + turn p (p in workpiece
/// coordinates, q in the setup's frame), from its workpiece_setup.
struct Placement {
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  Vec3 at = Vec3::Zero();
};

Placement placementOf(const ir::Node *setup) {
  Placement out;
  const ir::Node *ws = setup ? setup->child(ir::Kind::WorkpieceSetup) : nullptr;
  if (!ws)
    return out;
  const Vec3 axis = ws->vec("axis").value_or(Vec3::UnitZ()).normalized();
  const Vec3 ref = ws->vec("ref").value_or(Vec3::UnitX()).normalized();
  out.turn.col(0) = ref;
  out.turn.col(1) = axis.cross(ref);
  out.turn.col(2) = axis;
  out.at = ws->vec("at").value_or(Vec3::Zero());
  return out;
}

/// "+X" for a direction along an axis, else its components.
std::string faceName(const Vec3 &d) {
  static constexpr const char *kNames[] = {"X", "Y", "Z"};
  for (int k = 0; k < 3; ++k)
    if (std::abs(std::abs(d[k]) - 1) < 1e-9)
      return std::string(d[k] > 0 ? "+" : "-") + kNames[k];
  return "(" + formatTuple({d.x(), d.y(), d.z()}, 6) + ")";
}


} // namespace

std::string axisAddress(const runtime::Axis &axis) {
  std::string s = axis.name;
  for (char &c : s)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string outsideTravel(const runtime::Machine &machine, const runtime::Joints &joints, bool rotaryOnly) {
  std::string axes;
  for (size_t k = 0; k < machine.axes.size(); ++k) {
    if (rotaryOnly && !machine.axes[k].rotary)
      continue;
    const double v = joints[static_cast<Eigen::Index>(k)];
    if (v < machine.axes[k].travelMin - 1e-9 || v > machine.axes[k].travelMax + 1e-9)
      axes += (axes.empty() ? "" : ", ") + axisAddress(machine.axes[k]) + formatShortest(v);
  }
  return axes;
}

namespace {

/// How high the raw block can reach while the table turns, in machine
/// coordinates: with one table axis each corner circles its foot on the
/// axis (no higher than the foot plus its distance times the axis's lean
/// from z); with two, the farthest corner from the inner axis's pivot plus
/// the distance between the pivots, above the outer pivot. None without a
/// block or a table axis.
std::optional<double> sweepTop(const Program &p, const runtime::Machine &machine, const Vec3 &workOffset) {
  std::vector<const runtime::Axis *> table;
  for (const std::string &name : machine.kinematics.table)
    for (const runtime::Axis &a : machine.axes)
      if (a.name == name)
        table.push_back(&a);
  if (!p.blank || table.empty())
    return std::nullopt;
  const auto &[lo, hi] = *p.blank;
  double corner = 0, top = -1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 q =
        Vec3((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z()) + workOffset;
    corner = std::max(corner, (q - table.back()->pivotMm).norm());
    const Vec3 d = table.front()->direction.normalized(), rel = q - table.front()->pivotMm;
    const Vec3 foot = table.front()->pivotMm + d * rel.dot(d);
    top = std::max(top, foot.z() + (q - foot).norm() * d.cross(Vec3::UnitZ()).norm());
  }
  if (table.size() == 1)
    return top;
  double reach = 0;
  for (size_t k = 0; k + 1 < table.size(); ++k)
    reach += (table[k + 1]->pivotMm - table[k]->pivotMm).norm();
  return table.front()->pivotMm.z() + reach + corner;
}

} // namespace

std::unique_ptr<runtime::Kinematics> turningKinematics(const Program &p, const runtime::Machine &machine,
                                                       const Vec3 &workOffset, DiagnosticEngine &diags) {
  std::string error;
  std::unique_ptr<runtime::Kinematics> kinematics = runtime::makeKinematics(machine, error);
  if (!kinematics) {
    diags.error(SourceLoc{}, "the machine's kinematics: " + error);
    return nullptr;
  }
  const double retractZ = machine.axes.at(2).travelMax;
  if (const std::optional<double> top = sweepTop(p, machine, workOffset); top && *top >= retractZ) {
    diags.error(SourceLoc{}, "the workpiece turning on the machine's table may reach up to z " + formatFixed(*top, 3) +
                                 " mm, above the top of z travel " + formatShortest(retractZ) +
                                 " mm where the tool waits while it turns (its raw block at --work-offset " +
                                 formatTuple({workOffset.x(), workOffset.y(), workOffset.z()}, 3) + ")");
    return nullptr;
  }
  return kinematics;
}

bool indexClampings(Program &p, const runtime::Machine &machine, const Vec3 &workOffset, bool arcPlanes,
                    bool workingPlanes, DiagnosticEngine &diags) {
  if (p.clampings.empty())
    return true;
  if (workingPlanes) {
    // Under a tilted working plane the coordinates of a step that tilts the
    // tool would be the plane's, and the 840D's TRAORI does not go with a
    // swivel: such a program keeps its re-clamps.
    const auto tilted = std::find_if(p.steps.begin(), p.steps.end(), [](const Step &s) { return s.tilted; });
    if (tilted != p.steps.end()) {
      diags.warning(tilted->exec->origin.loc,
                    "workingstep " + tilted->exec->symbol +
                        " tilts the tool, which stepnc does not write under a tilted working plane yet: the program "
                        "stops for the operator to re-clamp for each face instead")
          .entity(tilted->exec->origin.entityId);
      return true;
    }
  }
  const std::unique_ptr<runtime::Kinematics> kinematics = turningKinematics(p, machine, workOffset, diags);
  if (!kinematics)
    return false;
  std::vector<size_t> rotary;
  for (size_t k = 0; k < machine.axes.size(); ++k)
    if (machine.axes[k].rotary)
      rotary.push_back(k);
  const double retractZ = machine.axes.at(2).travelMax;

  // The re-clamp stops go, and the operator's message before each (on a
  // copy: a face out of reach keeps the program as it was).
  std::vector<Step> steps;
  for (size_t i = 0; i < p.steps.size(); ++i) {
    const bool message = p.steps[i].kind == Step::Kind::Message && i + 1 < p.steps.size() &&
                         p.steps[i + 1].kind == Step::Kind::Stop && p.steps[i + 1].reclamp;
    if (message || (p.steps[i].kind == Step::Kind::Stop && p.steps[i].reclamp))
      continue;
    steps.push_back(p.steps[i]);
  }

  // What stops the turns (a face out of reach): the re-clamps stay.
  struct Problem {
    const ir::Node *exec;
    std::string why;
  };
  std::optional<Problem> problem;
  runtime::Joints near = runtime::Joints::Zero(static_cast<Eigen::Index>(kinematics->jointCount()));
  std::optional<runtime::Joints> turned;  // the rotary axes' positions in force
  std::vector<std::string> faces;
  size_t clampingListed = 0;  // where the clamping in force starts in `faces`
  // One step turned to the tool with the workpiece clamped as `base`
  // places it; false (with why) when the machine cannot.
  auto turnStep = [&](Step &s, const Placement &base, const std::string &baseFace,
                      std::optional<Problem> &failure) -> bool {
    // With the controller's working plane the step is written as planned:
    // its moves go through the kinematics below only to find the turn and
    // check every point's reach.
    const Step planned = s;
    const Placement place = placementOf(s.setup);
    // The face's normal as the clamping holds the workpiece, and the name
    // of the face in the workpiece.
    const Vec3 tool = base.turn * (place.turn.transpose() * Vec3::UnitZ());
    const std::string face = faceName(place.turn.transpose() * Vec3::UnitZ());
    auto where = [&](const std::string &why) {
      if (!failure)
        failure = Problem{s.exec, why};
    };
    // The joints that put the tool tip at q (in the step's frame) with the
    // tool along the face's normal; the program's point is their x, y, z
    // less the work offset.
    auto toProgram = [&](const Vec3 &q) -> std::optional<Vec3> {
      const Vec3 pw = place.turn.transpose() * (q - place.at);
      const Vec3 clamped = base.at + base.turn * pw;
      const runtime::InverseResult r = kinematics->inverse({clamped + workOffset, tool}, &near);
      if (!r.joints) {
        where("the machine cannot turn face " + face + " to the tool: " + r.why);
        return std::nullopt;
      }
      if (r.outsideTravel) {
        const std::string axes = outsideTravel(machine, *r.joints);
        where("face " + face + " turned to the tool" + (baseFace == "+Z" ? "" : " (" + baseFace + " up)") +
              " puts the point " +
              formatTuple({pw.x(), pw.y(), pw.z()}, 4) + " of the workpiece outside the machine's travel (" + axes +
              ") with the workpiece's origin at " + formatTuple({workOffset.x(), workOffset.y(), workOffset.z()}, 3));
        return std::nullopt;
      }
      near = *r.joints;
      return Vec3(near.head<3>()) - workOffset;
    };
    const Vec3 probe = s.moves.empty() ? Vec3(s.cycle->at.x(), s.cycle->at.y(), s.cycle->surfaceZ) : s.moves.front().to;
    const std::optional<Vec3> probed = toProgram(probe);
    if (!probed)
      return false;
    // Heights along the tool shift by one amount for the whole face: what
    // the security plane and (the tool along z) the cycles need.
    const double dz = probed->z() - probe.z();
    bool changed = !turned;
    for (size_t k : rotary)
      changed = changed || std::abs((*turned)[static_cast<Eigen::Index>(k)] - near[static_cast<Eigen::Index>(k)]) > 1e-9;
    if (changed) {  // the first step too: nothing turned yet
      Index index;
      index.retractZ = retractZ;
      std::string text = "face " + face + (baseFace == "+Z" ? "" : " (clamped " + baseFace + " up)") + ":";
      for (size_t k : rotary) {
        index.axes.emplace_back(axisAddress(machine.axes[k]), near[static_cast<Eigen::Index>(k)]);
        text += " " + axisAddress(machine.axes[k]) + formatShortest(near[static_cast<Eigen::Index>(k)]);
      }
      s.index = std::move(index);
      if (workingPlanes) {
        // The face's frame in the clamping's coordinates: a point q of the
        // face is the workpiece's place.turn^T (q - place.at), which the
        // clamping puts at base.at + base.turn of that.
        WorkingPlane plane;
        plane.turn = base.turn * place.turn.transpose();
        plane.origin = base.at - plane.turn * place.at;
        s.plane = plane;
      }
      // Listed once per clamping.
      if (std::find(faces.begin() + static_cast<long>(clampingListed), faces.end(), text) == faces.end())
        faces.push_back(text);
      turned = near;
    }
    s.workOffset = s.workOffset == 1 ? 1 : 0;
    // For the whole face the map from its frame to the program's is a turn
    // and a shift: where it takes the face's axes.
    const std::optional<Vec3> origin = toProgram(probe), alongZ = toProgram(probe + Vec3::UnitZ());
    if (!origin || !alongZ)
      return false;
    const Vec3 toolAxis = (*alongZ - *origin).normalized();  // the tool, in the program's frame
    const bool upright = (toolAxis - Vec3::UnitZ()).norm() < 1e-9;
    auto direction = [&](const Vec3 &q, const Vec3 &v) -> std::optional<Vec3> {
      const std::optional<Vec3> a = toProgram(q), b = toProgram(q + v);
      if (!a || !b)
        return std::nullopt;
      return Vec3((*b - *a).normalized());
    };
    std::vector<Move> moves;
    for (const Move &given : s.moves) {
      Move m = given;
      const std::optional<Vec3> from = toProgram(m.from), to = toProgram(m.to);
      if (!from || !to)
        break;
      if (m.alongZOnly && !upright) {
        // Up along the tool axis is not along z: up along z alone to the top
        // of z (where the turn left the tool: the rule after a tool change
        // holds), across there, then down along z to the point over the
        // face (above its clearance plane all the way, the tool leaning no
        // more than 90 deg).
        const double top = retractZ - workOffset.z();
        m.from = *from;
        m.to = Vec3(from->x(), from->y(), top);
        moves.push_back(m);
        m.alongZOnly = false;
        m.from = m.to;
        m.to = Vec3(to->x(), to->y(), top);
        moves.push_back(m);
        m.from = m.to;
        m.to = *to;
        moves.push_back(m);
        continue;
      }
      if (m.kind == Move::Kind::Arc) {
        const Vec3 centre3 = m.plane.world(Vec3(m.centre.x(), m.centre.y(), m.plane.local(m.from).z()));
        const std::optional<Vec3> centre = toProgram(centre3);
        const std::optional<Vec3> normal = direction(centre3, m.plane.normalVector());
        if (!centre || !normal)
          break;
        bool positive = true;
        const std::optional<geom::ArcPlane> plane = geom::ArcPlane::about(*normal, positive);
        if (workingPlanes) {
          moves.push_back(m);  // stays in the face's frame, its reach checked by its ends and centre
          continue;
        }
        if (plane && (plane->isXY() || arcPlanes)) {
          m.plane = *plane;
          m.ccw = positive ? m.ccw : !m.ccw;
          m.from = *from;
          m.to = *to;
          m.centre = plane->local(*centre).head<2>();
          moves.push_back(m);
          continue;
        }
        // Faces turned to the tool bring their arcs into XY, ZX or YZ (the
        // turns are quarter turns for the faces lowering makes); an arc in
        // another plane, or in ZX or YZ for a target without them, is not
        // written yet.
        where("an arc on face " + face + " turned to the tool lies in no plane " +
              (arcPlanes ? std::string("the target writes (XY, ZX, YZ)") : std::string("but XY")));
        break;
      }
      m.from = *from;
      m.to = *to;
      moves.push_back(m);
    }
    s.moves = std::move(moves);
    if (s.cycle && !upright) {
      s.cycle.reset();  // a canned cycle drills along z: its moves are written instead
    } else if (s.cycle) {
      const std::optional<Vec3> at = toProgram(Vec3(s.cycle->at.x(), s.cycle->at.y(), s.cycle->surfaceZ));
      if (at) {
        s.cycle->at = at->head<2>();
        for (double *z : {&s.cycle->initialZ, &s.cycle->retractZ, &s.cycle->surfaceZ, &s.cycle->depthZ})
          *z += dz;
        for (double &z : s.cycle->pecks)
          z += dz;
      }
    }
    s.secplane += dz;
    if (workingPlanes && !failure) {
      // In the face's tilted working plane its moves, arcs and cycles are
      // as on a 3-axis machine.
      s.moves = planned.moves;
      s.cycle = planned.cycle;
      s.secplane = planned.secplane;
    }
    return !failure;
  };

  // Each step under the clamping in force; a face the machine cannot turn
  // to the tool so is re-clamped face up (its own setup: the tool along z),
  // the operator stopped with the table back at 0, and the faces after it
  // turned from that clamping while they can be.
  Placement base;
  std::string baseFace = "+Z";
  int reclamps = 0;
  std::vector<Step> out;
  for (Step &s : steps) {
    if (s.kind != Step::Kind::Moves || (s.moves.empty() && !s.cycle)) {
      out.push_back(std::move(s));
      continue;
    }
    Step attempt = s;
    const runtime::Joints nearBefore = near;
    const size_t listedBefore = faces.size();
    std::optional<Problem> failure;
    if (turnStep(attempt, base, baseFace, failure)) {
      out.push_back(std::move(attempt));
      continue;
    }
    faces.resize(listedBefore);  // what the failed turn listed
    // Re-clamped with this face up, the table back at 0 for the operator.
    near = nearBefore;
    for (size_t k : rotary)
      near[static_cast<Eigen::Index>(k)] = 0;
    turned.reset();  // the step states the turn again after the stop
    const Placement own = placementOf(s.setup);
    const std::string face = faceName(own.turn.transpose() * Vec3::UnitZ());
    attempt = s;
    std::optional<Problem> again;
    const size_t listed = faces.size();
    clampingListed = listed;
    if (face == baseFace || !turnStep(attempt, own, face, again)) {
      problem = failure ? failure : again;
      break;
    }
    ++reclamps;
    Step message;
    message.kind = Step::Kind::Message;
    message.exec = s.exec;
    std::string instruction = s.setup ? s.setup->text("instruction").value_or("") : "";
    if (const size_t colon = instruction.find(": "); instruction.starts_with("work offset") && colon != std::string::npos)
      instruction = instruction.substr(colon + 2);
    if (const size_t corner = instruction.find("; the raw block's lowest corner"); corner != std::string::npos)
      instruction = instruction.substr(0, corner);
    message.label = (instruction.empty() ? "re-clamp the workpiece with its " + face + " face up" : instruction) +
                    "; the raw block's lowest corner where it was (G54 unchanged)";
    Step stop;
    stop.kind = Step::Kind::Stop;
    stop.exec = s.exec;
    stop.reclamp = true;
    // The table back at 0 for the operator.
    Index home;
    home.retractZ = retractZ;
    for (size_t k : rotary)
      home.axes.emplace_back(axisAddress(machine.axes[k]), 0.0);
    stop.index = std::move(home);
    faces.insert(faces.begin() + static_cast<long>(listed), "re-clamped with its " + face + " face up:");
    out.push_back(std::move(message));
    out.push_back(std::move(stop));
    out.push_back(std::move(attempt));
    base = own;
    baseFace = face;
  }
  if (problem) {
    const std::string what = "the machine's rotary axes do not turn every face to the tool (" +
                             (problem->exec ? "workingstep " + problem->exec->symbol + ": " : std::string()) +
                             problem->why + "): the program stops for the operator to re-clamp for each face instead";
    if (problem->exec)
      diags.warning(problem->exec->origin.loc, what).entity(problem->exec->origin.entityId);
    else
      diags.warning(SourceLoc{}, what);
    return true;
  }
  p.steps = std::move(out);
  p.clampings.clear();
  p.indexing.push_back("the program turns the rotary axes to bring each face to the tool (3+2)" +
                       (reclamps > 0 ? ", re-clamping " + std::to_string(reclamps) +
                                           (reclamps == 1 ? " time" : " times") + " for faces it cannot turn there"
                                     : std::string()));
  const std::string origin = "the workpiece's origin at X" + formatShortest(workOffset.x()) + " Y" +
                             formatShortest(workOffset.y()) + " Z" + formatShortest(workOffset.z()) +
                             " in machine coordinates with every axis at 0";
  if (workingPlanes)
    p.indexing.push_back("one datum for all, " + origin + "; each face's moves in its own frame, the datum shifted to "
                         "the face's origin and the working plane tilted to it; before each turn the tool goes up "
                         "to Z" + formatShortest(retractZ) + " in machine coordinates");
  else
    p.indexing.push_back("one work offset for all: " + origin + "; before each turn the tool goes up to Z" +
                         formatShortest(retractZ) + " (G53)");
  for (const std::string &f : faces)
    p.indexing.push_back(f);
  return true;
}

std::array<double, 3> fixedAxisAngles(const Eigen::Matrix3d &turn) {
  const double degrees = 180 / std::numbers::pi;
  const double s = std::clamp(-turn(2, 0), -1.0, 1.0);
  if (std::abs(s) > 1 - 1e-12)
    return {std::atan2(-turn(1, 2), turn(1, 1)) * degrees, (s > 0 ? 90.0 : -90.0), 0.0};
  return {std::atan2(turn(2, 1), turn(2, 2)) * degrees, std::atan2(s, std::hypot(turn(0, 0), turn(1, 0))) * degrees,
          std::atan2(turn(1, 0), turn(0, 0)) * degrees};
}

} // namespace stepnc::backends
