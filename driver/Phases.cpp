#include "driver/Phases.h"

#include "ir/Program.h"
#include "ir/geom/TurnedShape.h"

#include <algorithm>
#include <map>
#include <set>

namespace stepnc::driver {

std::string processOf(const ir::Node &e) {
  if (e.kind != ir::Kind::Workingstep)
    return "";
  if (ir::isTurningStep(e) || ir::drillsOnTurningAxis(e))
    return "turning";
  if (ir::isAdditiveStep(e))
    return "deposition";
  return "milling";
}

namespace {

bool does(const runtime::Machine &m, const std::string &process) {
  return std::find(m.processes.begin(), m.processes.end(), process) != m.processes.end();
}

/// The setup a step runs in: its own (a face), else its moves', else "".
std::string setupOf(const ir::Node &e) {
  if (auto s = e.text("setup"))
    return *s;
  if (const ir::Node *m = e.child(ir::Kind::Moves))
    return m->text("setup").value_or("");
  return "";
}

} // namespace

std::optional<std::vector<Phase>> splitIntoPhases(const ir::Module &module, const std::vector<NamedMachine> &machines,
                                                  DiagnosticEngine &diags) {
  const std::vector<const ir::Node *> order = ir::programOrder(module);
  // The processes of each setup's steps.
  std::map<std::string, std::set<std::string>> setupProcesses;
  for (const ir::Node *e : order)
    if (const std::string p = processOf(*e); !p.empty())
      setupProcesses[setupOf(*e)].insert(p);
  // Per setup: the first machine that does all of them, if one does.
  std::map<std::string, size_t> setupMachine;
  for (const auto &[setup, processes] : setupProcesses)
    for (size_t i = 0; i < machines.size(); ++i)
      if (std::all_of(processes.begin(), processes.end(), [&](const std::string &p) { return does(machines[i].machine, p); })) {
        setupMachine[setup] = i;
        break;
      }
  std::vector<Phase> phases;
  bool ok = true;
  std::vector<const ir::Node *> pending;  // executables without a process before the first step
  for (const ir::Node *e : order) {
    const std::string process = processOf(*e);
    if (process.empty()) {
      if (phases.empty())
        pending.push_back(e);
      else
        phases.back().executables.push_back(e);
      continue;
    }
    std::optional<size_t> machine;
    if (auto it = setupMachine.find(setupOf(*e)); it != setupMachine.end())
      machine = it->second;
    else
      for (size_t i = 0; i < machines.size() && !machine; ++i)
        if (does(machines[i].machine, process))
          machine = i;
    if (!machine) {
      std::string names;
      for (const NamedMachine &m : machines)
        names += (names.empty() ? "" : ", ") + m.name;
      diags.error(e->origin.loc, "workingstep " + e->symbol + " is " + process + ", which none of the machines given (" +
                                     names + ") does (docs/additive.md: the processes a machine does)")
          .entity(e->origin.entityId);
      ok = false;
      continue;
    }
    if (phases.empty() || phases.back().machine != *machine)
      phases.push_back({*machine, {}});
    if (!pending.empty()) {
      phases.back().executables.insert(phases.back().executables.end(), pending.begin(), pending.end());
      pending.clear();
    }
    phases.back().executables.push_back(e);
  }
  if (!ok)
    return std::nullopt;
  return phases;
}

namespace {

/// Drops the executables not in `keep` from the workplans under `n`; false
/// when `n` (a workplan) is left with none.
bool prune(ir::Node &n, const std::set<const ir::Node *> &keep) {
  std::vector<ir::Node> children;
  bool any = false;
  for (ir::Node &c : n.children) {
    if (c.kind == ir::Kind::Workplan) {
      if (prune(c, keep)) {
        any = true;
        children.push_back(std::move(c));
      }
      continue;
    }
    if (c.category() == ir::Category::Executable) {
      if (keep.count(&c)) {
        any = true;
        children.push_back(std::move(c));
      }
      continue;
    }
    children.push_back(std::move(c));
  }
  n.children = std::move(children);
  return any;
}

} // namespace

ir::Module phaseModule(const ir::Module &module, const Phase &phase) {
  ir::Module copy = module;
  // The copy's executables in the same program order as the original's.
  const std::vector<const ir::Node *> original = ir::programOrder(module), copied = ir::programOrder(copy);
  std::set<const ir::Node *> wanted(phase.executables.begin(), phase.executables.end()), keep;
  for (size_t i = 0; i < original.size() && i < copied.size(); ++i)
    if (wanted.count(original[i]))
      keep.insert(copied[i]);
  for (ir::Node &c : copy.root.children)
    if (c.kind == ir::Kind::Workplan)
      prune(c, keep);
  return copy;
}

} // namespace stepnc::driver
