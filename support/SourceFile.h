// Source files and locations shared by every layer.
//
// A SourceFile owns the bytes of one input (memory-mapped from disk, or a copy of
// a string for tests and generated text). The mapped text is always followed by
// at least one NUL byte, so scanners may use NUL as a sentinel instead of checking
// bounds on every byte. Line and column numbers are derived lazily from byte
// offsets: the line table is built only when a diagnostic first asks for one.
//
// A source may also be a translation of another one (Part 28 XML read as Part
// 21 text): its text is the translation, while its name, line, column and
// line text are those of the original, through a map from translated offsets
// to original offsets. Every layer then reports at the original's positions
// without knowing a translation took place.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace stepnc {

/// 1-based line and column; the column counts bytes.
struct LineCol {
  uint32_t line = 0;
  uint32_t col = 0;
};

class SourceFile {
public:
  ~SourceFile();
  SourceFile(const SourceFile &) = delete;
  SourceFile &operator=(const SourceFile &) = delete;

  /// Maps `path` read-only. On failure returns null and sets `error` to a
  /// message naming the path and the reason.
  static std::unique_ptr<SourceFile> open(const std::string &path, std::string &error);
  /// Wraps a copy of `contents` under the display name `name`.
  static std::unique_ptr<SourceFile> fromString(std::string name, std::string_view contents);
  /// A translation of `original` into `text`. `originMap` pairs translated
  /// offsets (ascending) with the original offsets they came from; an offset
  /// maps to the original offset of the last pair at or before it.
  static std::unique_ptr<SourceFile> translation(std::unique_ptr<SourceFile> original, std::string text,
                                                 std::vector<std::pair<uint64_t, uint64_t>> originMap);

  std::string_view name() const { return name_; }
  /// The file's bytes; text().data()[text().size()] is always '\0'.
  std::string_view text() const { return {data_, size_}; }
  const char *begin() const { return data_; }
  const char *end() const { return data_ + size_; }

  /// Line and column of a byte offset (offsets past the end map to the end);
  /// for a translation, in the original.
  LineCol lineCol(uint64_t offset) const;
  /// The text of a 1-based line without its line terminator (for a
  /// translation, the original's line).
  std::string_view lineText(uint32_t line) const;
  /// Byte offset of a line and column (clamped to the file).
  uint64_t offsetOf(LineCol at) const;
  /// Lets the kernel drop the mapped pages wholly inside [0, offset) (a reader
  /// streaming through a large file is done with them); they read back from
  /// the file if touched again. No effect on files that are not mapped.
  void releaseBefore(uint64_t offset) const;
  /// The file this one translates, or null.
  const SourceFile *original() const { return original_.get(); }
  /// For a translation, the original offset a translated offset came from.
  uint64_t originalOffset(uint64_t offset) const;

private:
  SourceFile() = default;
  void buildLineTable() const;

  std::string name_;
  const char *data_ = nullptr;
  uint64_t size_ = 0;
  void *mapping_ = nullptr;  // mmap'd region (file pages plus a zero page), or null
  uint64_t mappingSize_ = 0;
  std::string owned_;        // contents when not mapped
  mutable std::vector<uint64_t> lineStarts_;
  std::unique_ptr<SourceFile> original_;
  std::vector<std::pair<uint64_t, uint64_t>> originMap_;
};

/// A position in a source file. Default-constructed locations are "unknown".
struct SourceLoc {
  const SourceFile *file = nullptr;
  uint64_t offset = 0;

  bool valid() const { return file != nullptr; }
  SourceLoc advanced(uint64_t by) const { return {file, offset + by}; }
};

} // namespace stepnc
