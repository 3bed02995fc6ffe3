#include "ir/Program.h"

#include <algorithm>
#include <cmath>

namespace stepnc::ir {

namespace {

void collectExecutables(const Node &plan, std::vector<const Node *> &out) {
  for (const Node &e : plan.children) {
    if (e.kind == Kind::Workplan)
      collectExecutables(e, out);
    else if (e.kind == Kind::Workingstep || e.kind == Kind::RapidMovement || e.kind == Kind::ProgramStop ||
             e.kind == Kind::OptionalStop || e.kind == Kind::DisplayMessage || e.is(Trait::ControlFlow))
      out.push_back(&e);
  }
}

/// The node named `symbol` among `n`'s children or its workpieces' children;
/// `parent`, when given, is set to the node that holds it.
const Node *findIn(const Node &n, std::string_view symbol, const Node **parent) {
  for (const Node &c : n.children) {
    if (c.symbol == symbol) {
      if (parent)
        *parent = &n;
      return &c;
    }
    if (c.kind == Kind::Workpiece)
      if (const Node *found = findIn(c, symbol, parent))
        return found;
  }
  return nullptr;
}

std::string quotedKind(const Node &n) { return "'" + n.kindName() + "'"; }

/// Whether `n` gives a tool axis other than +z (+z is what none means).
bool tiltedAxis(const Node &n) {
  const std::optional<Vec3> axis = n.vec("axis");
  return axis && (*axis - Vec3::UnitZ()).norm() > 1e-9;
}

/// What of `n` itself (not its subtree) a 3-axis milling reader cannot take.
std::optional<std::string> beyond(const Node &n, ArcPlanes planes, Deposition deposition, ToolAxes toolAxes) {
  if (n.is(Trait::ControlFlow))
    return "control flow (" + quotedKind(n) + ")";
  const bool deposits = deposition == Deposition::Take;
  if (n.category() == Category::Operation && !n.spec().isAny(Trait::Milling | Trait::HoleMaking) &&
      !(deposits && n.is(Trait::Additive)))
    return std::string("an operation of another process (") + quotedKind(n) + ")";
  switch (n.kind) {
  case Kind::Moves:
    if (tiltedAxis(n) && toolAxes != ToolAxes::Take)
      return std::string("a tool axis");
    if (n.has("x_mode"))
      return std::string("a lathe's X mode");
    break;
  case Kind::State:
    if (deposits && !n.has("spindle") && !n.has("surface_speed") && !n.has("spindle_max") && !n.has("coolant"))
      break;
    return std::string("a change of process state ('state')");
  case Kind::Rapid:
  case Kind::Linear:
  case Kind::Arc:
    if (tiltedAxis(n) && toolAxes != ToolAxes::Take)
      return std::string("a tool axis per move");
    if (n.has("feed_per_rev"))
      return std::string("a feed per revolution");
    if (auto normal = n.vec("normal"); normal && *normal != Vec3::UnitZ()) {
      const bool principal = std::abs(std::abs(normal->x()) - 1) <= 1e-9 ||
                             std::abs(std::abs(normal->y()) - 1) <= 1e-9 ||
                             std::abs(std::abs(normal->z()) - 1) <= 1e-9;
      if (!principal)
        return std::string("an arc about an axis along none of x, y and z");
      if (planes == ArcPlanes::XYOnly)
        return std::string("an arc out of the XY plane");
    }
    break;
  default: break;
  }
  return std::nullopt;
}

std::optional<Beyond> firstBeyond(const Node &n, ArcPlanes planes, OtherProcesses others, Deposition deposition,
                                  ToolAxes toolAxes, const Node *step = nullptr) {
  if (others == OtherProcesses::Skip && (isTurningStep(n) || isAdditiveStep(n)))
    return std::nullopt;
  if (toolAxes == ToolAxes::Skip && tiltsTool(n))
    return std::nullopt;
  if (n.kind == Kind::Workingstep || n.kind == Kind::RapidMovement)
    step = &n;
  if (auto what = beyond(n, planes, deposition, toolAxes)) {
    // A move the passes made has no place in the file: its step has.
    if (!n.origin.loc.valid() && step && n.category() != Category::Executable)
      return Beyond{step, *what};
    return Beyond{&n, *what};
  }
  for (const Node &c : n.children)
    if (auto found = firstBeyond(c, planes, others, deposition, toolAxes, step))
      return found;
  return std::nullopt;
}

/// Whether `n` or a node under it gives a tool axis other than +z.
bool tilted(const Node &n) {
  if (tiltedAxis(n))
    return true;
  return std::any_of(n.children.begin(), n.children.end(), [](const Node &c) { return tilted(c); });
}

} // namespace

bool isTurningStep(const Node &exec) {
  if (exec.kind != Kind::Workingstep)
    return false;
  const Node *op = operationOf(exec);
  return op && op->is(Trait::Turning);
}

bool isAdditiveStep(const Node &exec) {
  if (exec.kind != Kind::Workingstep)
    return false;
  const Node *op = operationOf(exec);
  return op && op->is(Trait::Additive);
}

bool tiltsTool(const Node &exec) {
  if (exec.kind != Kind::Workingstep && exec.kind != Kind::RapidMovement)
    return false;
  const Node *moves = exec.child(Kind::Moves);
  return moves && tilted(*moves);
}

const Node *millingMoves(const Node &exec) {
  return isTurningStep(exec) || isAdditiveStep(exec) || tiltsTool(exec) ? nullptr : exec.child(Kind::Moves);
}

std::optional<Beyond> beyondThreeAxisMilling(const Module &module, ArcPlanes planes, OtherProcesses others,
                                             Deposition deposition, ToolAxes toolAxes) {
  return firstBeyond(module.root, planes, others, deposition, toolAxes);
}

bool requireThreeAxisMilling(const Module &module, std::string_view consumer, DiagnosticEngine &diags,
                             ArcPlanes planes, OtherProcesses others, Deposition deposition, ToolAxes toolAxes) {
  const std::optional<Beyond> b = beyondThreeAxisMilling(module, planes, others, deposition, toolAxes);
  if (!b)
    return true;
  std::string subject = b->node->kindName();
  if (!b->node->symbol.empty())
    subject += " " + b->node->symbol;
  diags.error(b->node->origin.loc, subject + ": " + std::string(consumer) + " cannot take " + b->what + " yet")
      .entity(b->node->origin.entityId);
  return false;
}

namespace {

void visitSteps(Node &n, const std::string &setup,
                const std::function<void(Node &, const std::string &)> &visit) {
  for (Node &c : n.children) {
    if (c.kind == Kind::Workingstep || c.kind == Kind::RapidMovement)
      visit(c, c.text("setup").value_or(setup));  // a step on another face has a setup of its own
    else if (c.kind == Kind::Workplan)
      visitSteps(c, c.text("setup").value_or(setup), visit);
    else if (c.is(Trait::ControlFlow) || c.category() == Category::Branch)
      visitSteps(c, setup, visit);
  }
}

} // namespace

void forEachMachiningStep(Module &module, const std::function<void(Node &step, const std::string &setup)> &visit) {
  for (Node &n : module.root.children)
    if (n.kind == Kind::Workplan)
      visitSteps(n, n.text("setup").value_or(""), visit);
}

std::vector<const Node *> programOrder(const Module &module) {
  std::vector<const Node *> out;
  for (const Node &n : module.root.children)
    if (n.kind == Kind::Workplan)
      collectExecutables(n, out);
  return out;
}

bool hasMachiningSteps(const Module &module) {
  for (const Node *e : programOrder(module))
    if (e->kind == Kind::Workingstep || e->kind == Kind::RapidMovement || e->is(Trait::ControlFlow))
      return true;
  return false;
}

const Node *operationOf(const Node &step) { return step.childIn(Category::Operation); }

Node *operationOf(Node &step) { return const_cast<Node *>(step.childIn(Category::Operation)); }

bool toolpathsGiveFeeds(const Node &op) {
  const std::vector<const Node *> toolpaths = op.childrenOf(Kind::Toolpath);
  return !toolpaths.empty() && std::all_of(toolpaths.begin(), toolpaths.end(), [](const Node *tp) {
    if (tp->flag("rapid").value_or(false) || tp->has("dwell"))
      return true;
    const Node *tech = tp->child(Kind::Technology);
    return tech && tech->number("feed").value_or(0) > 0;
  });
}

const Node *findResource(const Module &module, Kind kind, std::string_view symbol) {
  for (const Node &n : module.root.children)
    if (n.kind == kind && n.symbol == symbol)
      return &n;
  return nullptr;
}

const Node *findFeature(const Module &module, std::string_view symbol) {
  const Node *n = findIn(module.root, symbol, nullptr);
  return n && n->category() == Category::Feature ? n : nullptr;
}

const Node *workpieceOf(const Module &module, const Node &feature) {
  const Node *parent = nullptr;
  findIn(module.root, feature.symbol, &parent);
  return parent && parent->kind == Kind::Workpiece ? parent : nullptr;
}

bool runsAsWritten(const Node &executable) {
  const Node *op = operationOf(executable);
  if (!op)
    return false;
  const std::vector<const Node *> toolpaths = op->childrenOf(Kind::Toolpath);
  return !toolpaths.empty() &&
         std::all_of(toolpaths.begin(), toolpaths.end(), [](const Node *tp) { return tp->flag("required").value_or(true); });
}

} // namespace stepnc::ir
