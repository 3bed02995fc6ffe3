#include "ir/Program.h"

#include <algorithm>

namespace stepnc::ir {

namespace {

void collectExecutables(const Node &plan, std::vector<const Node *> &out) {
  for (const Node &e : plan.children) {
    if (e.kind == Kind::Workplan)
      collectExecutables(e, out);
    else if (e.kind == Kind::Workingstep || e.kind == Kind::RapidMovement || e.kind == Kind::ProgramStop ||
             e.kind == Kind::OptionalStop || e.kind == Kind::DisplayMessage)
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

} // namespace

std::vector<const Node *> programOrder(const Module &module) {
  std::vector<const Node *> out;
  for (const Node &n : module.root.children)
    if (n.kind == Kind::Workplan)
      collectExecutables(n, out);
  return out;
}

const Node *operationOf(const Node &step) { return step.childIn(Category::Operation); }

Node *operationOf(Node &step) { return const_cast<Node *>(step.childIn(Category::Operation)); }

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
