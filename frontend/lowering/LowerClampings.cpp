// Features on other faces than +z (docs/setups.md). ISO 14649 places every
// feature in workpiece coordinates, its axis pointing out of the material; a
// feature on the side or the bottom of the part faces +x, -y, -z, ... A
// 3-axis machine reaches it by re-clamping the workpiece with that face up.
// Lowering makes that explicit: per face, a turned copy of the workpiece
// (its raw piece in the turned frame), of the features machined from that
// face and a setup that clamps the turned workpiece, with its own work
// offset; the workingstep refers to them, and a program stop with a message
// to the operator goes before the first step of each clamping. Every pass
// after lowering then sees features facing +z in their setup's frame.
#include "frontend/lowering/Lowerer.h"

#include "frontend/express/Schema.h"
#include "ir/Program.h"
#include "support/Format.h"

#include <array>
#include <cmath>
#include <limits>

namespace stepnc::lowering {

namespace {

constexpr double kAlong = 1e-6;

/// The five faces a box can be turned to have up besides its top, with the
/// rotation that brings each up: about y for +-x, about x for +-y and -z.
/// The rotation maps the face's outward normal to +z.
struct FaceTurn {
  const char *face;
  std::array<double, 3> normal;
  std::array<double, 9> rows;  // row-major rotation
};

constexpr FaceTurn kFaces[] = {
    {"+x", {1, 0, 0}, {0, 0, -1, 0, 1, 0, 1, 0, 0}},   // -90 deg about y
    {"-x", {-1, 0, 0}, {0, 0, 1, 0, 1, 0, -1, 0, 0}},  // +90 deg about y
    {"+y", {0, 1, 0}, {1, 0, 0, 0, 0, -1, 0, 1, 0}},   // +90 deg about x
    {"-y", {0, -1, 0}, {1, 0, 0, 0, 0, 1, 0, -1, 0}},  // -90 deg about x
    {"-z", {0, 0, -1}, {1, 0, 0, 0, -1, 0, 0, 0, -1}}, // 180 deg about x
};

/// The face in a symbol: "px" for +x, "nz" for -z.
std::string faceTag(const std::string &face) { return std::string(face[0] == '+' ? "p" : "n") + face[1]; }

/// "+Y" for the workpiece axis that a machine axis `k` runs along after `t`.
std::string workpieceAxisAlong(const Turn &t, int k) {
  const Vec3 back = t.rotation.transpose().col(k);  // the machine axis in workpiece coordinates
  for (int i = 0; i < 3; ++i)
    if (std::abs(std::abs(back[i]) - 1) < kAlong)
      return std::string(back[i] > 0 ? "+" : "-") + "XYZ"[i];
  return "?";
}

/// Turns every point and direction of `n` and its subtree (a raw piece
/// other than a block).
void turnSubtree(Node &n, const Turn &t) {
  for (ir::Attr &a : n.attrs) {
    if (a.value.type == ir::ValueType::Point)
      a.value.vec = t.point(a.value.vec);
    else if (a.value.type == ir::ValueType::Direction)
      a.value.vec = t.direction(a.value.vec);
  }
  for (Node &c : n.children)
    turnSubtree(c, t);
}

/// The box around `raw` turned by `t`: lowest and highest corners.
std::pair<Vec3, Vec3> turnedBox(const RawExtent &raw, const Turn &t) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner = t.point(Vec3((c & 1) ? raw.max.x() : raw.min.x(), (c & 2) ? raw.max.y() : raw.min.y(),
                                     (c & 4) ? raw.max.z() : raw.min.z()));
    lo = lo.cwiseMin(corner);
    hi = hi.cwiseMax(corner);
  }
  return {lo, hi};
}

} // namespace

std::optional<Turn> Lowerer::turnFor(const Vec3 &axis, const std::optional<RawExtent> &raw) {
  for (const FaceTurn &f : kFaces) {
    if ((axis - Vec3(f.normal[0], f.normal[1], f.normal[2])).norm() > kAlong)
      continue;
    Turn t;
    t.face = f.face;
    t.rotation = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(f.rows.data());
    if (raw)
      t.shift = raw->min - turnedBox(*raw, t).first;  // the turned box's lowest corner where the box's was
    return t;
  }
  return std::nullopt;
}

bool Lowerer::placeOnFace(const Instance &ws, Node &step) {
  const std::string featureSymbol = *step.text("feature");
  const Node *feature = ir::findFeature(*module_, featureSymbol);
  const Instance featureInstance = ws.ref("its_feature");
  const Vec3 axis = *feature->vec("axis");
  // The feature's workpiece (featureWorkpiece said what it assumed).
  Instance wpInstance = featureInstance.ref("its_workpiece");
  if (!wpInstance && projectWorkpieces_.size() == 1)
    wpInstance = projectWorkpieces_[0];
  const std::optional<RawExtent> raw = rawExtent(wpInstance);
  const std::optional<Turn> turn = turnFor(axis, raw);
  const Instance placementInstance = featureInstance.ref("feature_placement");
  if (!turn) {
    diags_.error(placementInstance ? placementInstance.loc() : featureInstance.loc(),
                 "the feature faces " + formatTuple({axis.x(), axis.y(), axis.z()}, 6) +
                     ", along no face of the workpiece: a 3-axis machine reaches features facing +z, or another "
                     "face of the raw piece (+x, -x, +y, -y, -z) by re-clamping; this one needs an indexed "
                     "(3+2) machine, which stepnc does not program yet")
        .entity(featureInstance.id(), std::string(featureInstance.entityName()));
    return false;
  }
  if (setupInForce_)
    for (const Instance &w : setupInForce_.refs("its_workpiece_setup"))
      if (auto p = placement(w.ref("its_origin")))
        if ((p->axis - Vec3::UnitZ()).norm() > kAlong || (p->ref - Vec3::UnitX()).norm() > kAlong)
          diags_.assumption(w.loc(), "the workpiece setup turns the workpiece; stepnc clamps workingstep " +
                                         hashId(ws.id()) + "'s feature with its " + express::upper(turn->face) +
                                         " face up by its own rule (docs/setups.md), not by this placement")
              .entity(w.id(), std::string(w.entityName()));
  const std::string workpiece = turnedWorkpiece(ir::workpieceOf(*module_, *feature)->symbol, *turn, raw);
  step.set("feature", Value::ref(turnedFeature(featureSymbol, *turn, workpiece)));
  step.set("setup", Value::ref(turnedSetup(workpiece, *turn, raw, ws)));
  if (auto h = turnedSecplane(ws, *turn, raw))
    step.set("secplane", Value::length(*h));
  // Explicit toolpaths are in the feature's frame: they turn with it.
  return true;
}

std::string Lowerer::turnedWorkpiece(const std::string &workpiece, const Turn &turn,
                                     const std::optional<RawExtent> &raw) {
  const std::string key = workpiece + " " + turn.face;
  if (auto it = turned_.find(key); it != turned_.end())
    return it->second;
  const Node *original = findResource(workpiece);
  Node copy(ir::Kind::Workpiece);
  copy.label = original->label;
  copy.origin = original->origin;
  copy.attrs = original->attrs;
  copy.symbol = symbolFor('%', original->symbol.substr(1) + " " + faceTag(turn.face) + " up", "workpiece");
  // The raw block in the turned frame: the box around its turned corners,
  // exact for a block whose axes are the workpiece's. The clamping points
  // are the first clamping's: not carried over.
  if (const Node *rawpiece = original->child(ir::Kind::Rawpiece)) {
    Node r = *rawpiece;
    if (raw && rawpiece->text("shape") == "block") {
      const auto [lo, hi] = turnedBox(*raw, turn);
      r.set("at", Value::point(lo));
      r.set("axis", Value::direction(Vec3::UnitZ()));
      r.set("ref", Value::direction(Vec3::UnitX()));
      r.set("size", Value::point(hi - lo));
    } else {
      turnSubtree(r, turn);
    }
    copy.add(std::move(r));
  }
  const std::string symbol = copy.symbol;
  module_->root.add(std::move(copy));
  return turned_[key] = symbol;
}

std::string Lowerer::turnedFeature(const std::string &feature, const Turn &turn, const std::string &workpiece) {
  const std::string key = feature + " " + turn.face;
  if (auto it = turned_.find(key); it != turned_.end())
    return it->second;
  Node copy = *ir::findFeature(*module_, feature);
  copy.symbol = symbolFor('%', feature.substr(1) + " " + faceTag(turn.face) + " up", "feature");
  // The feature's placement turns; its profiles and paths are placed in it.
  for (const char *name : {"at"})
    if (auto v = copy.vec(name))
      copy.set(name, Value::point(turn.point(*v)));
  for (const char *name : {"axis", "ref"})
    if (auto v = copy.vec(name))
      copy.set(name, Value::direction(turn.direction(*v)));
  for (Node &c : copy.children)
    if (c.kind == ir::Kind::Island)
      if (auto boss = c.text("feature"))
        c.set("feature", Value::ref(turnedFeature(*boss, turn, workpiece)));
  const std::string symbol = copy.symbol;
  findResource(workpiece)->add(std::move(copy));
  return turned_[key] = symbol;
}

std::string Lowerer::turnedSetup(const std::string &workpiece, const Turn &turn, const std::optional<RawExtent> &raw,
                                 const Instance &stepInstance) {
  const std::string key = setupSymbolInForce_ + " " + workpiece + " " + turn.face;
  if (auto it = turned_.find(key); it != turned_.end())
    return it->second;
  Node s(ir::Kind::Setup);
  const Node *fileSetup = setupSymbolInForce_.empty() ? nullptr : findResource(setupSymbolInForce_);
  if (fileSetup) {
    s.origin = fileSetup->origin;
    s.label = fileSetup->label;
  } else {
    stamp(s, stepInstance, "");
  }
  s.symbol = symbolFor('%', (fileSetup ? fileSetup->symbol.substr(1) : std::string("setup")) + " " +
                                faceTag(turn.face) + " up",
                       "setup");
  s.set("at", Value::point(Vec3::Zero()));
  s.set("axis", Value::direction(Vec3::UnitZ()));
  s.set("ref", Value::direction(Vec3::UnitX()));
  // The security plane of the first workingstep on the face, when it gives
  // one for that face; else the file's setup's, turned.
  std::optional<double> secplane = stepInstance ? faceSecplane(stepInstance, turn, raw) : std::nullopt;
  if (!secplane && setupInForce_)
    secplane = turnedSecplane(setupInForce_, turn, raw);
  if (!secplane)
    secplane = raw ? turnedBox(*raw, turn).second.z() : 0.0;
  s.set("secplane", Value::length(*secplane));
  s.set("face_up", Value::word(turn.face));
  s.set("work_offset", Value::integer(++workOffsets_));
  const Vec3 corner = raw ? raw->min : Vec3::Zero();
  s.set("instruction",
        Value::string("work offset " + std::to_string(workOffsets_) + ": re-clamp the workpiece with its " +
                      express::upper(turn.face) + " face up, its " + workpieceAxisAlong(turn, 0) + " along X and " +
                      workpieceAxisAlong(turn, 1) + " along Y; the raw block's lowest corner at X" +
                      formatFixed(corner.x(), 3) + " Y" + formatFixed(corner.y(), 3) + " Z" +
                      formatFixed(corner.z(), 3)));
  // The workpiece placed in the setup as ISO 14649 has it: its origin and
  // axes turned (what writes the program back to workpiece coordinates
  // reads).
  Node w(ir::Kind::WorkpieceSetup);
  w.origin = s.origin;
  w.set("workpiece", Value::ref(workpiece));
  w.set("at", Value::point(turn.shift));
  w.set("axis", Value::direction(turn.direction(Vec3::UnitZ())));
  w.set("ref", Value::direction(turn.direction(Vec3::UnitX())));
  s.add(std::move(w));
  const std::string symbol = s.symbol;
  module_->root.add(std::move(s));
  return turned_[key] = symbol;
}

std::optional<double> Lowerer::faceSecplane(const Instance &owner, const Turn &turn,
                                            const std::optional<RawExtent> &raw) {
  const Instance plane = owner.ref("its_secplane");
  if (!plane || !plane.isA("plane"))
    return std::nullopt;
  const std::optional<Placement> p = placement(plane.ref("position"));
  if (!p)
    return std::nullopt;
  const Vec3 up = turn.rotation.transpose() * Vec3::UnitZ();  // the face's normal in workpiece coordinates
  const std::optional<double> top = raw ? std::optional(turnedBox(*raw, turn).second.z()) : std::nullopt;
  if (std::abs(std::abs(p->axis.dot(up)) - 1) < kAlong && (!top || turn.point(p->at).z() > *top))
    return turn.point(p->at).z();
  return std::nullopt;
}

std::optional<double> Lowerer::turnedSecplane(const Instance &owner, const Turn &turn,
                                              const std::optional<RawExtent> &raw) {
  Instance plane = owner.ref("its_secplane");
  if (!plane) {
    missing(owner, "its_secplane");
    return std::nullopt;
  }
  if (!plane.isA("plane")) {
    unsupported(plane, "security plane must be a PLANE");
    return std::nullopt;
  }
  std::optional<Placement> p = placement(plane.ref("position"));
  if (!p) {
    missing(plane, "position");
    return std::nullopt;
  }
  // A plane parallel to the face, outside it: it turns with the workpiece.
  if (std::optional<double> h = faceSecplane(owner, turn, raw))
    return h;
  const std::optional<double> top = raw ? std::optional(turnedBox(*raw, turn).second.z()) : std::nullopt;
  if (std::abs(std::abs(p->axis.z()) - 1) < kAlong && raw) {
    // A plane over the workpiece's top, where the file gives one plane for
    // every face: as far above the turned raw piece as it is above the top.
    const double clearance = p->at.z() - raw->max.z();
    const double height = *top + clearance;
    if (secplanesAssumed_.insert({plane.index(), turn.face}).second)
      assumed(plane, "position",
              "is normal to the workpiece's z, not to its " + express::upper(turn.face) +
                  " face that workingsteps machine from; for them the security plane is taken " +
                  formatFixed(clearance, 3) + " mm above the raw piece turned " + express::upper(turn.face) +
                  " up (z " + formatFixed(height, 3) + " mm in that setup), as far as this plane is above its top");
    return height;
  }
  unsupported(plane, "security plane whose normal " + formatTuple({p->axis.x(), p->axis.y(), p->axis.z()}, 6) +
                         " is neither z nor the axis of the face (" + express::upper(turn.face) + ") the feature is on");
  return std::nullopt;
}

void Lowerer::reclampBefore(const Node &step, Node &parent) {
  const std::string clamping = step.text("setup").value_or(setupSymbolInForce_);
  const std::string before = clamping_;
  clamping_ = clamping;
  if (clamping == before)
    return;
  const Node *now = findResource(clamping);
  const Node *was = before.empty() ? nullptr : findResource(before);
  const bool turned = now && now->has("face_up");
  if (!turned && !(was && was->has("face_up")))
    return;  // between the file's own setups: as the file says
  std::string text;
  if (turned)
    text = *now->text("instruction");
  else
    text = "work offset 1: re-clamp the workpiece as clamped first, its top up";
  Node message(ir::Kind::DisplayMessage);
  message.origin = step.origin;
  message.set("message", Value::string(text));
  Node stop(ir::Kind::ProgramStop);
  stop.origin = step.origin;
  stop.set("reclamp", Value::boolean(true));
  parent.add(std::move(message));
  parent.add(std::move(stop));
}

} // namespace stepnc::lowering
