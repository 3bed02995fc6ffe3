#include "backends/common/Program.h"

#include "ir/Kinds.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"

#include <cmath>
#include <map>
#include <numbers>

namespace stepnc::backends {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kSame = 1e-9;

std::optional<CycleKind> cycleKindOf(std::optional<ir::Kind> op) {
  if (!op)
    return std::nullopt;
  const ir::KindSpec &spec = ir::specOf(*op);
  if (spec.is(ir::Trait::DrillCycle))
    return CycleKind::Drill;
  if (spec.is(ir::Trait::PeckCycle))
    return CycleKind::Peck;
  if (spec.is(ir::Trait::BoreCycle))
    return CycleKind::Bore;
  if (spec.is(ir::Trait::TapCycle))
    return CycleKind::Tap;
  return std::nullopt;
}

/// The cycle a hole-making step's moves make, when they are exactly: to the
/// position at the security plane, down to R, feeds down (with rapids out to
/// R and back between pecks), then out (rapid, or at feed to R) and up to the
/// security plane.
std::optional<HoleCycle> recogniseCycle(const Step &s, CycleKind kind, double surfaceZ) {
  if (s.moves.size() < 3)
    return std::nullopt;
  const geom::Vec2 at = s.moves.front().to.head<2>();
  for (const Move &m : s.moves)
    if (m.kind == Move::Kind::Arc || (m.to.head<2>() - at).norm() > kSame)
      return std::nullopt;
  HoleCycle c;
  c.kind = kind;
  c.at = at;
  c.initialZ = s.secplane;
  c.surfaceZ = surfaceZ;
  size_t i = 0;
  // The position (and any other rapid at the security plane), then down to R.
  while (i < s.moves.size() && s.moves[i].kind == Move::Kind::Rapid && s.moves[i].role != "approach")
    ++i;
  if (i == s.moves.size() || std::abs(s.moves[i > 0 ? i - 1 : 0].to.z() - s.secplane) > kSame)
    return std::nullopt;
  c.retractZ = s.moves[i].to.z();
  ++i;
  // Feeds down; between them out to R at rapid and back down at rapid.
  while (i < s.moves.size() && s.moves[i].kind == Move::Kind::Linear && s.moves[i].role == "plunge") {
    if (c.feed == 0)
      c.feed = s.moves[i].feed;
    else if (std::abs(c.feed - s.moves[i].feed) > kSame)
      return std::nullopt;
    c.pecks.push_back(s.moves[i].to.z());
    ++i;
    if (i + 1 < s.moves.size() && s.moves[i].kind == Move::Kind::Rapid && s.moves[i].role == "retract" &&
        std::abs(s.moves[i].to.z() - c.retractZ) <= kSame && s.moves[i + 1].kind == Move::Kind::Rapid &&
        s.moves[i + 1].role == "approach" && i + 2 < s.moves.size() && s.moves[i + 2].kind == Move::Kind::Linear)
      i += 2;
  }
  if (c.pecks.empty())
    return std::nullopt;
  c.depthZ = c.pecks.back();
  // Out: at feed to R (bores, taps), then at rapid to the security plane.
  if (i < s.moves.size() && s.moves[i].kind == Move::Kind::Linear) {
    if (std::abs(s.moves[i].to.z() - c.retractZ) > kSame)
      return std::nullopt;
    c.feedOut = s.moves[i].feed;
    ++i;
  }
  if (i + 1 != s.moves.size() || s.moves[i].kind != Move::Kind::Rapid ||
      std::abs(s.moves[i].to.z() - s.secplane) > kSame)
    return std::nullopt;
  if ((kind == CycleKind::Bore || kind == CycleKind::Tap) != (c.feedOut > 0))
    return std::nullopt;
  if (kind != CycleKind::Peck && c.pecks.size() != 1)
    return std::nullopt;
  return c;
}

class Builder {
public:
  Builder(const ir::Module &m, const ToolTable *table, DiagnosticEngine &diags)
      : module_(m), table_(table), diags_(diags) {}

  std::optional<Program> build() {
    program_.name = module_.root.label.empty() ? module_.root.symbol : module_.root.label;
    program_.toolsFromTable = table_ != nullptr;
    for (const ir::Node &n : module_.root.children)
      if (n.kind == ir::Kind::Workpiece && !program_.blank)
        blank(n);
    for (const ir::Node *e : ir::programOrder(module_))
      executable(*e);
    if (!ok_)
      return std::nullopt;
    return std::move(program_);
  }

private:
  void blank(const ir::Node &workpiece) {
    const ir::Node *raw = workpiece.child(ir::Kind::Rawpiece);
    if (!raw || raw->text("shape") != "block" || !raw->has("size"))
      return;
    auto frame = ir::planeFrame(*raw);
    if (!frame.frame)
      return;
    const Vec3 size = *raw->vec("size");
    geom::Box box;
    for (const geom::Vec2 &c : {geom::Vec2(0, 0), geom::Vec2(size.x(), 0), geom::Vec2(size.x(), size.y()),
                                geom::Vec2(0, size.y())})
      box.add(frame.frame->map(c));
    program_.blank = std::pair(Vec3(box.lo.x(), box.lo.y(), frame.frame->z),
                               Vec3(box.hi.x(), box.hi.y(), frame.frame->z + size.z()));
  }

  void executable(const ir::Node &e) {
    if (e.kind == ir::Kind::DisplayMessage) {
      Step s;
      s.kind = Step::Kind::Message;
      s.exec = &e;
      s.label = e.text("message").value_or("");
      program_.steps.push_back(std::move(s));
      return;
    }
    if (e.kind == ir::Kind::ProgramStop || e.kind == ir::Kind::OptionalStop) {
      Step s;
      s.kind = e.kind == ir::Kind::ProgramStop ? Step::Kind::Stop : Step::Kind::OptionalStop;
      s.exec = &e;
      program_.steps.push_back(std::move(s));
      return;
    }
    const ir::Node *moves = e.child(ir::Kind::Moves);
    if (!moves) {
      diags_.error(e.origin.loc, e.kindName() + " " + e.symbol +
                                     " has no moves to write: expand-strategies made none (its warning says "
                                     "why)")
          .entity(e.origin.entityId);
      ok_ = false;
      return;
    }
    Step s;
    s.exec = &e;
    s.label = e.label.empty() ? e.symbol : e.label;
    if (const ir::Node *op = ir::operationOf(e))
      s.operation = op->kind;
    s.tool = toolIndex(*moves);
    s.spindle = moves->number("spindle").value_or(0);
    s.coolant = moves->text("coolant").value_or("off");
    s.secplane = moves->number("secplane").value_or(0);
    // The moves as every reader of the toolpath IR sees them (ir/geom/MoveWalk).
    for (const ir::Move &m : ir::walkMoves(*moves, position_)) {
      Move mv;
      mv.node = m.node;
      mv.from = m.from.value_or(position_);
      mv.to = m.to;
      mv.role = m.role;
      mv.kind = m.kind == ir::MoveKind::Rapid   ? Move::Kind::Rapid
                : m.kind == ir::MoveKind::Arc ? Move::Kind::Arc
                                                  : Move::Kind::Linear;
      mv.feed = m.feed;
      mv.smooth = mv.kind == Move::Kind::Linear && m.node && m.node->flag("smooth").value_or(false);
      mv.centre = m.center.head<2>();
      mv.ccw = m.ccw;
      mv.turns = m.turns;
      s.moves.push_back(std::move(mv));
    }
    if (!s.moves.empty())
      position_ = s.moves.back().to;
    if (auto kind = cycleKindOf(s.operation)) {
      const ir::Node *feature = ir::findFeature(module_, e.text("feature").value_or(""));
      auto frame = feature ? ir::planeFrame(*feature) : ir::FrameResult{};
      if (frame.frame)
        s.cycle = recogniseCycle(s, *kind, frame.frame->z);
    }
    program_.steps.push_back(std::move(s));
  }

  int toolIndex(const ir::Node &moves) {
    const std::string symbol = moves.text("tool").value_or("");
    if (auto it = toolIndex_.find(symbol); it != toolIndex_.end())
      return it->second;
    const ir::Node *tool = ir::findTool(module_, symbol);
    if (!tool)
      return -1;  // the IR verifier reports dangling references
    ToolCall t;
    t.node = tool;
    t.label = tool->label.empty() ? tool->symbol : tool->label;
    t.diameter = tool->number("diameter").value_or(0);
    if (table_) {
      const ToolTable::Entry *e = table_->find(*tool);
      if (!e) {
        diags_.error(tool->origin.loc, "tool " + tool->symbol + " (\"" + t.label + "\") is not in the tool table " +
                                           table_->name())
            .entity(tool->origin.entityId);
        ok_ = false;
        return -1;
      }
      t.number = e->number;
      t.length = e->length;
    } else {
      t.number = static_cast<int>(program_.tools.size()) + 1;
    }
    program_.tools.push_back(std::move(t));
    return toolIndex_[symbol] = static_cast<int>(program_.tools.size()) - 1;
  }

  const ir::Module &module_;
  const ToolTable *table_;
  DiagnosticEngine &diags_;
  Program program_;
  std::map<std::string, int> toolIndex_;
  Vec3 position_ = Vec3::Zero();
  bool ok_ = true;
};

} // namespace

double Move::sweep() const {
  const geom::Vec2 a = from.head<2>() - centre, b = to.head<2>() - centre;
  double angle = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));  // ccw from a to b, (-pi, pi]
  if (!ccw)
    angle = -angle;
  if (angle < 0)
    angle += kTwoPi;
  if ((to.head<2>() - from.head<2>()).norm() <= kSame)
    angle = kTwoPi;  // over the start: a whole turn
  return angle + kTwoPi * static_cast<double>(turns);
}

std::optional<Program> buildProgram(const ir::Module &module, const ToolTable *table, DiagnosticEngine &diags) {
  if (!ir::requireThreeAxisMilling(module, "the G-code targets", diags))
    return std::nullopt;
  return Builder(module, table, diags).build();
}

} // namespace stepnc::backends
