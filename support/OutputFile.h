// Atomic output files: a program or converted file is written to a temporary
// file beside the target and renamed over it only when complete, so a failure
// never leaves a partial file behind. "-" means standard output; a target that
// exists and is not a regular file (a device such as /dev/null, a FIFO) is
// written directly, since renaming over it would replace the device. A
// read-only target is refused rather than renamed over; a replaced file keeps
// its permissions. SIGTERM, SIGINT and SIGHUP remove the temporary files
// that are open before the process ends by the signal.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

namespace stepnc {

class OutputFile {
public:
  OutputFile() = default;
  ~OutputFile();  // discards the temporary file unless commit() succeeded
  OutputFile(const OutputFile &) = delete;
  OutputFile &operator=(const OutputFile &) = delete;

  /// Opens a temporary file next to `path` (or stdout for "-"); fails, with
  /// `error` saying why, where writable() does.
  bool open(const std::string &path, std::string &error);

  /// Whether `path` may be written, checked before any work: "-", a device or
  /// FIFO the user may write, a new file in an existing folder the user may
  /// write in, or an existing regular file the user may write. An existing
  /// file without write permission is refused, for root too when no one may
  /// write it: renaming over it would replace a file its owner protected.
  static bool writable(const std::string &path, std::string &error);
  void write(std::string_view bytes);
  void put(char c) { std::fputc(c, file_); }
  /// Flushes, syncs and renames the temporary file onto the target.
  bool commit(std::string &error);
  /// Removes the temporary file; the target is left untouched.
  void discard();

  std::FILE *stream() { return file_; }
  const std::string &path() const { return path_; }

private:
  std::string path_;
  std::string tempPath_;
  static constexpr size_t kBufferSize = 1 << 16;
  std::unique_ptr<char[]> buffer_;  ///< the stream's buffer; outlives file_
  std::FILE *file_ = nullptr;
  bool isStdout_ = false;
  bool direct_ = false;  ///< writing straight to a device or FIFO
  int slot_ = -1;        ///< where a kill's handler finds tempPath_ (OutputFile.cpp)
};

} // namespace stepnc
