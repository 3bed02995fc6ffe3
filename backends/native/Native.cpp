// The native target: the planned motion (the `motion` nodes plan-motion
// wrote) in the native motion format of runtime/NativeFormat.h, for open
// controllers that play time-parameterised segments themselves.
#include "backends/Backend.h"
#include "ir/Program.h"
#include "ir/motion/MotionIR.h"
#include "runtime/NativeFormat.h"
#include "support/SourceFile.h"

#include <algorithm>

namespace stepnc::backends {

namespace {

class NativeBackend final : public Backend {
public:
  NativeBackend() : Backend(makeDescriptor()) {}

  static TargetDescriptor makeDescriptor() {
    TargetDescriptor d;
    d.name = "native";
    d.description = "stepnc native motion segments (docs/native-format.md); needs --machine";
    d.extension = ".motion";
    return d;
  }

  std::optional<std::string> emit(const ir::Module &module, const EmitOptions &options,
                                  DiagnosticEngine &diags) override {
    // A re-clamp is an operator's work between two motions; the native
    // format carries motion only.
    for (const ir::Node *e : ir::programOrder(module)) {
      if (ir::isAdditiveStep(*e)) {
        diags.error(e->origin.loc, "workingstep " + e->symbol + " deposits: the native motion format carries no "
                                   "deposition head's state yet (docs/additive.md): write a G-code target")
            .entity(e->origin.entityId);
        return std::nullopt;
      }
      if (e->kind == ir::Kind::ProgramStop && e->flag("reclamp").value_or(false)) {
        diags.error(e->origin.loc, "the program re-clamps the workpiece here, to reach features on another face "
                                   "(docs/setups.md); the native motion format has no stop for the operator: "
                                   "write a G-code target")
            .entity(e->origin.entityId);
        return std::nullopt;
      }
    }
    auto trajectory = ir::readMotion(module, diags);
    if (!trajectory)
      return std::nullopt;
    std::string text = runtime::writeNative(*trajectory, options.source);
    if (!readsBack(module, text, diags))
      return std::nullopt;
    return text;
  }

private:
  /// What is written is what `stepnc sim` and every reader of the format
  /// accept: the text is read back with the reader's own checks (profiles
  /// that cover their segments and start where the one before ended, limits
  /// held, finite numbers). A plan that fails them is stepnc's bug: an error
  /// at the workingstep whose segment failed, and nothing written.
  static bool readsBack(const ir::Module &module, const std::string &text, DiagnosticEngine &diags) {
    std::unique_ptr<SourceFile> file = SourceFile::fromString("native output", text);
    DiagnosticCollector collected;
    DiagnosticEngine check(collected);
    if (runtime::readNative(*file, check) && check.errorCount() == 0)
      return true;
    const auto failed = std::find_if(collected.diags.begin(), collected.diags.end(),
                                     [](const Diagnostic &d) { return d.severity == Severity::Error; });
    const std::string why = failed == collected.diags.end() ? std::string("no reason given") : failed->message;
    // Segments are written one a line after the `segments` line, in program
    // order, as the executables' motion nodes hold them.
    std::optional<size_t> segment;
    if (const size_t header = text.find("\nsegments ");
        failed != collected.diags.end() && failed->loc.valid() && header != std::string::npos) {
      const uint32_t line = file->lineCol(failed->loc.offset).line, segments = file->lineCol(header + 1).line;
      if (line > segments)
        segment = line - segments - 1;
    }
    const ir::Node *owner = nullptr;
    if (segment) {
      size_t count = 0;
      for (const ir::Node *e : ir::programOrder(module))
        if (const ir::Node *motion = e->child(ir::Kind::Motion)) {
          if (*segment < count + motion->children.size()) {
            owner = e;
            break;
          }
          count += motion->children.size();
        }
    }
    const std::string where = owner ? owner->kindName() + " " + owner->symbol + ": " : std::string();
    const std::string which = segment ? "segment " + std::to_string(*segment + 1) + " of " : std::string();
    diags.error(owner ? owner->origin.loc : SourceLoc{},
                where + "the native plan stepnc made does not read back (a bug in stepnc): " + which +
                    "the plan: " + why)
        .entity(owner ? owner->origin.entityId : 0);
    return false;
  }
};

} // namespace

std::unique_ptr<Backend> createNativeBackend() { return std::make_unique<NativeBackend>(); }

} // namespace stepnc::backends
