// An ISO 10303-21 exchange file read into an instance table.
//
// Reading is two-level, for speed. readPart21() scans the file once and builds
// the instance table: for each `#id=...;` its id, entity name and byte range,
// without decoding any parameter. Parameters are decoded on demand by
// decodeInstance() into a ValueArena. The header, the ed. 3 ANCHOR and
// REFERENCE sections and the DATA section parameters are small and decoded
// eagerly. The file's bytes stay mapped for the lifetime of the Part21File,
// which keeps a reference to its SourceFile.
#pragma once

#include "frontend/part21/Names.h"
#include "frontend/part21/Values.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::p21 {

/// Marks an instance-table entry whose instance is complex: `#1=(A()B());`.
inline constexpr NameId kComplexInstance = UINT32_MAX - 1;

/// One `#id=...;` in the instance table: 16 bytes, its id, the offset of its
/// '#' (40 bits: files up to 1 TiB) and its entity name (24 bits).
struct InstanceEntry {
  static constexpr uint64_t kMaxBegin = (uint64_t{1} << 40) - 1;
  static constexpr uint32_t kComplexCode = (1u << 24) - 1;
  static constexpr uint32_t kMaxNames = kComplexCode;

  InstanceId id = 0;
  uint64_t packed = 0;

  InstanceEntry() = default;
  InstanceEntry(InstanceId instanceId, uint64_t beginOffset, NameId entityName)
      : id(instanceId),
        packed(beginOffset | (uint64_t{entityName == kComplexInstance ? kComplexCode : entityName} << 40)) {}

  /// Offset of the instance's '#' in the file.
  uint64_t begin() const { return packed & kMaxBegin; }
  /// Entity name, or kComplexInstance.
  NameId name() const {
    const auto n = static_cast<uint32_t>(packed >> 40);
    return n == kComplexCode ? kComplexInstance : n;
  }
};
static_assert(sizeof(InstanceEntry) == 16);

/// Maps instance ids to instance-table entries. For ids up to a few times the
/// number of instances (the usual case) it is a bitmap of the ids present with
/// a rank count per 64 ids (about 0.2 bytes per id); when the entries are in
/// ascending id order, as writers emit them, the rank is the entry index and
/// nothing else is stored. Otherwise a rank -> entry table is added, and very
/// sparse ids fall back to sorted pairs.
class IdIndex {
public:
  /// Builds the index; calls `duplicate(first, second)` (entry indexes) for
  /// each repeated id.
  void build(const std::vector<InstanceEntry> &entries,
             const std::function<void(uint32_t first, uint32_t second)> &duplicate);
  /// Entry index of `id`, or -1.
  int64_t find(InstanceId id) const {
    if (!sparse_.empty() || bits_.empty())
      return findSparse(id);
    if (id > maxId_)
      return -1;
    const uint64_t word = bits_[static_cast<size_t>(id >> 6)];
    const uint64_t bit = uint64_t{1} << (id & 63);
    if (!(word & bit))
      return -1;
    const uint32_t rank = ranks_[static_cast<size_t>(id >> 6)] +
                          static_cast<uint32_t>(__builtin_popcountll(word & (bit - 1)));
    return order_.empty() ? rank : order_[rank];
  }
  /// Bytes used, for reports.
  size_t bytes() const {
    return bits_.size() * 8 + ranks_.size() * 4 + order_.size() * 4 + sparse_.size() * 16;
  }

private:
  int64_t findSparse(InstanceId id) const;

  InstanceId maxId_ = 0;
  std::vector<uint64_t> bits_;
  std::vector<uint32_t> ranks_;
  std::vector<uint32_t> order_;
  std::vector<std::pair<InstanceId, uint32_t>> sparse_;
};

/// A header entity such as FILE_NAME(...) with its decoded parameters.
struct HeaderEntity {
  Record record;
  uint64_t begin = 0;  ///< offset of the name in the file
};

/// One DATA section: its optional ed. 3 parameters and its instances.
struct DataSection {
  uint64_t begin = 0;  ///< offset of the DATA keyword
  /// Ed. 3 `DATA('name', ('SCHEMA'));` parameters; empty for plain `DATA;`.
  std::vector<Value> params;
  uint32_t firstEntry = 0;  ///< index into entries()
  uint32_t endEntry = 0;
};

/// An ed. 3 ANCHOR section line: `<name>=value;`.
struct Anchor {
  std::string name;
  uint64_t begin = 0;
  Value value;  ///< children, if any, live in the file's metadata arena
};

/// An ed. 3 REFERENCE section line: `#id=<uri>;` (an instance defined elsewhere).
struct ExternalReference {
  InstanceId id = 0;
  std::string uri;
  uint64_t begin = 0;
};

struct ReadOptions {
  /// Nesting depth of parameter lists beyond which input is rejected.
  unsigned maxNesting = 128;
};

class Part21File {
public:
  const SourceFile &source() const { return *source_; }
  SourceLoc loc(uint64_t offset) const { return {source_, offset}; }

  const NameTable &names() const { return names_; }
  /// Interns a name; decoding adds the names of typed parameters and complex
  /// records to the table, which is why this is const.
  NameId intern(std::string_view name) const { return names_.intern(name); }
  NameId internUpper(std::string_view name) const { return names_.internUpper(name); }

  const std::vector<HeaderEntity> &header() const { return header_; }
  /// The header entity named `name` (upper case), if present.
  const HeaderEntity *headerEntity(std::string_view name) const;
  /// Schema names listed in FILE_SCHEMA, in order.
  std::vector<std::string> schemaNames() const;

  const std::vector<DataSection> &sections() const { return sections_; }
  const std::vector<Anchor> &anchors() const { return anchors_; }
  const std::vector<ExternalReference> &references() const { return references_; }
  /// Arena holding the decoded header, DATA parameters and anchor values.
  const ValueArena &metadata() const { return metadata_; }

  /// Every instance in file order.
  const std::vector<InstanceEntry> &entries() const { return entries_; }
  /// Index into entries() of instance `id`, or -1.
  int64_t indexOf(InstanceId id) const { return index_.find(id); }
  const InstanceEntry *find(InstanceId id) const {
    int64_t i = indexOf(id);
    return i < 0 ? nullptr : &entries_[static_cast<size_t>(i)];
  }
  /// True if `id` is defined by an instance or by the REFERENCE section.
  bool isDefined(InstanceId id) const;

  /// Entity name of an entry as text ("(complex)" for complex instances).
  std::string_view entityName(const InstanceEntry &e) const;
  /// For complex instances, the record names joined as in Part 21: "A+B+C".
  std::string describe(const InstanceEntry &e) const;

  /// Decodes the parameters of entries()[index] into `arena` (which is cleared
  /// first). Syntax errors are reported to `diags` if given; returns false if
  /// the instance could not be decoded.
  bool decodeInstance(size_t index, ValueArena &arena, DiagnosticEngine *diags) const;

  const ReadOptions &options() const { return options_; }

private:
  friend class Reader;
  friend std::unique_ptr<Part21File> readPart21(const SourceFile &, DiagnosticEngine &,
                                                const ReadOptions &);
  void buildIndex(DiagnosticEngine &diags);

  const SourceFile *source_ = nullptr;
  ReadOptions options_;
  mutable NameTable names_;
  ValueArena metadata_;
  std::vector<HeaderEntity> header_;
  std::vector<DataSection> sections_;
  std::vector<Anchor> anchors_;
  std::vector<ExternalReference> references_;
  std::vector<InstanceId> referenceIds_;  ///< sorted ids of references_
  std::vector<InstanceEntry> entries_;
  IdIndex index_;
};

/// Reads the structure of a Part 21 file and builds its instance table.
/// Reports syntax errors in the file structure, the header and the instance
/// table (duplicate ids) to `diags`. Always returns a file object; it is usable
/// (possibly partial) even when errors were reported.
std::unique_ptr<Part21File> readPart21(const SourceFile &source, DiagnosticEngine &diags,
                                       const ReadOptions &options = {});

/// Reports references of instance `index` (decoded in `values`) to ids that are
/// not defined. Used by checkInstances and by the writer.
void checkReferences(const Part21File &file, size_t index, const ValueArena &values, DiagnosticEngine &diags);
/// Reports references in the ANCHOR section to ids that are not defined.
void checkAnchorReferences(const Part21File &file, DiagnosticEngine &diags);

/// Called with each instance that decoded cleanly (entry index, its values).
using InstanceVisitor = std::function<void(size_t index, const ValueArena &values)>;

/// Decodes every instance and checks every reference (in the DATA and ANCHOR
/// sections) against the instance table; `visit`, if given, sees each cleanly
/// decoded instance, so later checks need not decode it again. Returns the
/// number of instances that decoded cleanly.
size_t checkInstances(const Part21File &file, DiagnosticEngine &diags, const InstanceVisitor &visit = {});

} // namespace stepnc::p21
