// resolve-feeds: completes each operation's cutting data from what the file
// gives. STEP-NC technology may give the feed per minute or per tooth, the
// spindle speed or the cutting speed; later passes want the feed per minute.
//   feed [mm/min]          = feed per tooth [mm] x flutes x |spindle| [rev/min]
//   cutting speed [mm/min] = pi x tool diameter [mm] x |spindle| [rev/min]
// Each value computed is marked in the technology node's comment; values the
// file gives are never changed.
#include "passes/Pass.h"

#include "ir/Kinds.h"
#include "support/Format.h"

#include <cmath>
#include <map>
#include <numbers>

namespace stepnc::passes {

namespace {

class ResolveFeedsPass final : public Pass {
public:
  std::string_view name() const override { return "resolve-feeds"; }

  PassResult run(ir::Module &module, DiagnosticEngine &diags, PassStats &stats) override {
    std::map<std::string, const ir::Node *, std::less<>> tools;
    for (const ir::Node &n : module.root.children)
      if (n.kind == ir::Kind::Tool)
        tools[n.symbol] = &n;
    PassResult result;
    visit(module.root, tools, diags, stats, result);
    return result;
  }

private:
  void visit(ir::Node &node, const std::map<std::string, const ir::Node *, std::less<>> &tools,
             DiagnosticEngine &diags, PassStats &stats, PassResult &result) {
    for (ir::Node &child : node.children) {
      if (ir::isOperation(child.kind)) {
        const ir::Node *tool = nullptr;
        if (auto symbol = child.text("tool"))
          if (auto it = tools.find(*symbol); it != tools.end())
            tool = it->second;
        resolve(child, tool, diags, stats, result);
      }
      visit(child, tools, diags, stats, result);
    }
  }

  void resolve(ir::Node &op, const ir::Node *tool, DiagnosticEngine &diags, PassStats &stats, PassResult &result) {
    ir::Node *tech = nullptr;
    for (ir::Node &c : op.children)
      if (c.kind == ir::Kind::Technology)
        tech = &c;
    if (!tech)
      return;
    const std::optional<double> spindle = tech->number("spindle");
    // 0 stands for "not known" (a tool has positive flutes and diameter).
    const int64_t flutes = tool ? tool->count("flutes").value_or(0) : 0;
    const double diameter = tool ? tool->number("diameter").value_or(0.0) : 0.0;
    std::string derived;
    auto note = [&](const std::string &text) {
      derived += derived.empty() ? "" : "; ";
      derived += text;
    };
    const double n = spindle ? std::abs(*spindle) : 0.0;
    if (!tech->has("feed")) {
      if (auto fz = tech->number("feed_per_tooth"); fz && flutes > 0 && n > 0) {
        tech->set("feed", ir::Value::feed(*fz * static_cast<double>(flutes) * n));
        note("feed = " + formatFixed(*fz, 4) + " mm x " + std::to_string(flutes) + " flutes x " +
             formatFixed(n, 1) + " rev/min");
        ++stats["feeds computed"];
      } else {
        diags.warning(op.origin.loc, op.kindName() + " '" + op.label +
                                         "' has no feed: neither a feed nor a feed per tooth with the tool's "
                                         "flutes and a spindle speed")
            .entity(op.origin.entityId);
        ++stats["operations without a feed"];
      }
    } else if (!tech->has("feed_per_tooth") && flutes > 0 && n > 0) {
      tech->set("feed_per_tooth", ir::Value::length(*tech->number("feed") / (static_cast<double>(flutes) * n)));
      note("feed_per_tooth = feed / (" + std::to_string(flutes) + " flutes x " + formatFixed(n, 1) + " rev/min)");
      ++stats["feeds per tooth computed"];
    }
    if (!tech->has("cutting_speed") && diameter > 0 && n > 0) {
      tech->set("cutting_speed", ir::Value::feed(std::numbers::pi * diameter * n));
      note("cutting_speed = pi x " + formatFixed(diameter, 4) + " mm x " + formatFixed(n, 1) + " rev/min");
      ++stats["cutting speeds computed"];
    }
    if (!derived.empty()) {
      tech->comment = derived;
      result.changed = true;
    }
  }
};

} // namespace

std::unique_ptr<Pass> createResolveFeedsPass(const PassOptions &) { return std::make_unique<ResolveFeedsPass>(); }

} // namespace stepnc::passes
