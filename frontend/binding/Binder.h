// Schema-checked binding of Part 21 data.
//
// bind() gives every instance of a Part21File its entity in an EXPRESS schema
// and checks it the way a compiler type-checks its input: known entity name
// (or an alias from the alias table, with a warning), not abstract, attribute
// count, each value against its attribute's type (simple types, enumerations,
// SELECTs with typed parameters, references to a compatible subtype,
// aggregates and their bounds), `$` only where OPTIONAL, `*` only where
// derived, and complex instances against the supertype constraints. Every
// error names the instance, the attribute, what was expected and what was found.
#pragma once

#include "frontend/binding/Aliases.h"
#include "frontend/express/Schema.h"
#include "frontend/part21/Part21File.h"

#include <memory>
#include <unordered_map>
#include <vector>

namespace stepnc::binding {

/// The result of binding: the entity (or entities, for a complex instance) of
/// every instance table entry. Simple instances are typed through their
/// entity name (one table entry per distinct name, not per instance), so
/// binding a large file adds little memory.
class BoundFile {
public:
  BoundFile(const p21::Part21File &file, const express::Model &model, const express::Schema &schema)
      : file_(file), model_(model), schema_(schema) {}

  const p21::Part21File &file() const { return file_; }
  const express::Model &model() const { return model_; }
  const express::Schema &schema() const { return schema_; }

  /// Entity of entry `index` (for a complex instance its most specific
  /// record's), or express::kNone when unknown.
  express::EntityId entity(size_t index) const;
  /// Every entity of entry `index` (one for a simple instance).
  std::vector<express::EntityId> entitySet(size_t index) const;
  /// True if the instance is `of` or a subtype of it.
  bool isA(size_t index, express::EntityId of) const;

  /// What the lenient reading assumed, as Part 21 text that says it (for
  /// simple instances): a `$` in a mandatory aggregate is `()`, in a
  /// mandatory string `''`, in a BOOLEAN `.F.`; an alias is the schema's
  /// entity name (parameter -1). The machine-optimised STEP-NC writes them.
  struct Fix {
    uint64_t id = 0;
    int parameter = 0;
    std::string text;
    /// A tolerance the file leaves out, read as the general tolerance:
    /// lowering, which knows the workpiece's, writes it (`text` is empty).
    bool generalTolerance = false;
  };
  const std::vector<Fix> &fixes() const { return fixes_; }

private:
  friend class Binder;
  struct Complex {
    express::EntityId mostSpecific = express::kNone;
    std::vector<express::EntityId> members;
  };
  const p21::Part21File &file_;
  const express::Model &model_;
  const express::Schema &schema_;
  std::vector<express::EntityId> byName_;  ///< NameId -> entity (kNone: unknown)
  std::unordered_map<uint32_t, Complex> complex_;  ///< entry index -> its records' entities
  std::vector<Fix> fixes_;
};

struct BindOptions {
  const AliasTable *aliases = &AliasTable::builtin();
  /// Report common drift as errors instead of warnings: `$` written for a
  /// mandatory aggregate that may be empty (read as empty), for a mandatory
  /// string such as a name or label (read as ''), or for a length's
  /// tolerance (read as the general tolerance), and an entity name from the
  /// alias table (--strict).
  bool strict = false;
  /// The commands' reading without --strict (driver::bindOptions): report as
  /// warnings what leaves the meaning clear enough to machine: `$` in any
  /// other mandatory attribute ("read as absent"; lowering reports an error
  /// where it needs the value) and an abstract entity instantiated (its
  /// attributes are still checked). Off, these are errors.
  bool lenient = false;
};

/// Binds and checks every instance of `file` against `schema` (which must
/// belong to the resolved `model`). Each instance is decoded once, for the
/// Part 21 reference check (p21::checkInstances) and the schema check
/// together, so callers do not run checkInstances themselves.
std::unique_ptr<BoundFile> bind(const p21::Part21File &file, const express::Model &model,
                                const express::Schema &schema, DiagnosticEngine &diags,
                                const BindOptions &options = {});

} // namespace stepnc::binding
