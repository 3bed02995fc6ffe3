// resolve-feeds: completes each operation's cutting data from what the file
// gives. STEP-NC technology may give the feed per minute or per tooth, the
// spindle speed or the cutting speed; later passes want the feed per minute.
//   feed [mm/min]          = feed per tooth [mm] x flutes x |spindle| [rev/min]
//   cutting speed [mm/min] = pi x tool diameter [mm] x |spindle| [rev/min]
// Each value computed is marked in the technology node's comment; values the
// file gives are never changed.
//
// A spindle speed the file does not give is assumed (reported; an error with
// --strict) from the cutting speed, the file's or else the typical one of the
// workpiece material for coated carbide (cutting/materials.toml), half of it
// for hole-making tools:
//   spindle [rev/min] = cutting speed [mm/min] / (pi x tool diameter [mm])
// A feed the file gives as 0 or not at all (with no feed per tooth either)
// is assumed the same way from the material's target chip thickness h*:
//   feed [mm/min] = h* [mm] x flutes x |spindle| [rev/min]
#include "passes/Pass.h"

#include "cutting/CuttingData.h"
#include "ir/Kinds.h"
#include "ir/Program.h"
#include "passes/CuttingModel.h"
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
    module_ = &module;
    visit(module.root, nullptr, tools, diags, stats, result);
    return result;
  }

private:
  void visit(ir::Node &node, const ir::Node *step, const std::map<std::string, const ir::Node *, std::less<>> &tools,
             DiagnosticEngine &diags, PassStats &stats, PassResult &result) {
    for (ir::Node &child : node.children) {
      if (ir::isOperation(child.kind)) {
        const ir::Node *tool = nullptr;
        if (auto symbol = child.text("tool"))
          if (auto it = tools.find(*symbol); it != tools.end())
            tool = it->second;
        resolve(child, step, tool, diags, stats, result);
      }
      visit(child, child.kind == ir::Kind::Workingstep ? &child : step, tools, diags, stats, result);
    }
  }

  /// The spindle speed (rev/min, signed) assumed for `op` when its
  /// technology gives none, with why; nullopt when there is
  /// nothing to assume it from.
  std::optional<double> assumeSpindle(const ir::Node &op, const ir::Node *step, const ir::Node &tech,
                                      const ir::Node *tool, std::string &why) {
    const double diameter = tool ? tool->number("diameter").value_or(0.0) : 0.0;
    const std::string toolType = tool ? tool->text("type").value_or("") : "";
    if (diameter <= 0 || toolType.find("tap") != std::string::npos)
      return std::nullopt;  // no diameter to turn a speed into revolutions; a tap's speed is its pitch's
    double vc = tech.number("cutting_speed").value_or(0);  // mm/min
    std::string materialNote;
    if (vc > 0) {
      why = "from its cutting speed " + formatFixed(vc / 1000, 1) + " m/min";
    } else {
      const MaterialChoice material = materialOf(step);
      if (!material.material || material.material->cuttingSpeed <= 0)
        return std::nullopt;
      const bool holeMaking = ir::hasTraits(op.kind, ir::Trait::HoleMaking);
      vc = material.material->cuttingSpeed * 1000 * (holeMaking ? 0.5 : 1.0);
      why = "from a cutting speed of " + formatFixed(vc / 1000, 1) + " m/min (typical for coated carbide in " +
            material.material->key + (holeMaking ? ", halved for hole making" : "") + ")";
      materialNote = material.note;
    }
    const double n = vc / (std::numbers::pi * diameter);
    why += " and the tool's diameter " + formatFixed(diameter, 4) + " mm";
    if (!materialNote.empty())
      why += "; " + materialNote;
    // Clockwise (M3) for a right-hand tool, the usual cut.
    return tool->text("hand") == "left" ? n : -n;
  }

  /// The workpiece material of the feature `step` machines, as the shipped
  /// cutting data knows it.
  MaterialChoice materialOf(const ir::Node *step) const {
    const ir::Node *feature = step ? ir::findFeature(*module_, step->text("feature").value_or("")) : nullptr;
    const ir::Node *workpiece = feature ? ir::workpieceOf(*module_, *feature) : nullptr;
    return chooseMaterial(workpiece, cutting::shippedCuttingData());
  }

  /// The feed (mm/min) assumed for an operation whose technology gives a
  /// feed of 0 or none: the material's target chip thickness per tooth, with
  /// why; nullopt without flutes, a spindle speed or a material to take it from.
  std::optional<double> assumeFeed(const ir::Node *step, int64_t flutes, double n, std::string &why) const {
    if (flutes <= 0 || n <= 0)
      return std::nullopt;
    const MaterialChoice material = materialOf(step);
    if (!material.material || material.material->chipThickness <= 0)
      return std::nullopt;
    const double fz = material.material->chipThickness;
    why = "= " + formatFixed(fz, 4) + " mm per tooth (the target chip thickness of " + material.material->key +
          ") x " + std::to_string(flutes) + " flutes x " + formatFixed(n, 1) + " rev/min";
    if (!material.note.empty())
      why += "; " + material.note;
    return fz * static_cast<double>(flutes) * n;
  }

  void resolve(ir::Node &op, const ir::Node *step, const ir::Node *tool, DiagnosticEngine &diags,
               PassStats &stats, PassResult &result) {
    // A turning or deposition operation's speeds and feeds are its process's
    // (a feed per revolution, a constant cutting speed): not milling's rules.
    if (op.is(ir::Trait::Turning) || op.is(ir::Trait::Additive))
      return;
    ir::Node *tech = nullptr;
    for (ir::Node &c : op.children)
      if (c.kind == ir::Kind::Technology)
        tech = &c;
    if (!tech)
      return;
    std::optional<double> spindle = tech->number("spindle");
    // 0 stands for "not known" (a tool has positive flutes and diameter).
    const int64_t flutes = tool ? tool->count("flutes").value_or(0) : 0;
    const double diameter = tool ? tool->number("diameter").value_or(0.0) : 0.0;
    std::string derived;
    auto note = [&](const std::string &text) {
      derived += derived.empty() ? "" : "; ";
      derived += text;
    };
    if (!spindle) {
      std::string why;
      if ((spindle = assumeSpindle(op, step, *tech, tool, why))) {
        tech->set("spindle", ir::Value::spindle(*spindle));
        note("spindle assumed " + why);
        diags.assumption(tech->origin.loc.valid() ? tech->origin.loc : op.origin.loc,
                         op.kindName() + " '" + op.label + "' gives no spindle speed; assumed " +
                             formatFixed(std::abs(*spindle), 1) + " rev/min " +
                             (*spindle < 0 ? "clockwise " : "counter-clockwise ") + why)
            .entity(tech->origin.entityId ? tech->origin.entityId : op.origin.entityId);
        ++stats["spindle speeds assumed"];
      }
    }
    const double n = spindle ? std::abs(*spindle) : 0.0;
    // A feed of 0 moves nothing: generators write it for "not given".
    const bool zeroFeed = tech->number("feed") == 0.0;
    if ((!tech->has("feed") || zeroFeed) && ir::toolpathsGiveFeeds(op)) {
      // Every toolpath moving at feed gives its own: no move uses the
      // operation's, there is nothing to resolve.
    } else if (!tech->has("feed") || zeroFeed) {
      std::string why;
      if (auto fz = tech->number("feed_per_tooth"); fz && *fz > 0 && flutes > 0 && n > 0) {
        tech->set("feed", ir::Value::feed(*fz * static_cast<double>(flutes) * n));
        note("feed = " + formatFixed(*fz, 4) + " mm x " + std::to_string(flutes) + " flutes x " +
             formatFixed(n, 1) + " rev/min");
        ++stats["feeds computed"];
      } else if (auto feed = assumeFeed(step, flutes, n, why)) {
        tech->set("feed", ir::Value::feed(*feed));
        tech->set("feed_per_tooth", ir::Value::length(*feed / (static_cast<double>(flutes) * n)));
        note("feed assumed " + why);
        diags.assumption(tech->origin.loc.valid() ? tech->origin.loc : op.origin.loc,
                         op.kindName() + " '" + op.label + "' gives " + (zeroFeed ? "a feed of 0" : "no feed") +
                             "; assumed " + formatFixed(*feed, 1) + " mm/min " + why)
            .entity(tech->origin.entityId ? tech->origin.entityId : op.origin.entityId);
        ++stats["feeds assumed"];
      } else if (zeroFeed) {
        // expand-strategies refuses the step, naming it.
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

  const ir::Module *module_ = nullptr;
};

} // namespace

std::unique_ptr<Pass> createResolveFeedsPass(const PassOptions &) { return std::make_unique<ResolveFeedsPass>(); }

} // namespace stepnc::passes
