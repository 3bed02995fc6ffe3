#include "support/SourceFile.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iterator>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace stepnc {

SourceFile::~SourceFile() {
  if (mapping_)
    ::munmap(mapping_, mappingSize_);
}

std::unique_ptr<SourceFile> SourceFile::open(const std::string &path, std::string &error) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = "cannot open '" + path + "': " + std::strerror(errno);
    return nullptr;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    error = S_ISDIR(st.st_mode) ? "'" + path + "' is a directory"
                                : "cannot read '" + path + "': not a regular file";
    ::close(fd);
    return nullptr;
  }
  std::unique_ptr<SourceFile> file(new SourceFile());
  file->name_ = path;
  const auto size = static_cast<uint64_t>(st.st_size);
  if (size == 0) {
    ::close(fd);
    file->data_ = file->owned_.c_str();
    return file;
  }
  // Reserve the file's pages plus one more, then map the file over the front.
  // The tail of the last file page and the extra page read as zeros, which
  // gives the scanners their NUL sentinel without copying the file.
  const auto page = static_cast<uint64_t>(::sysconf(_SC_PAGESIZE));
  const uint64_t filePages = (size + page - 1) / page * page;
  const uint64_t total = filePages + page;
  void *region = ::mmap(nullptr, total, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (region == MAP_FAILED) {
    error = "cannot map '" + path + "': " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  void *mapped = ::mmap(region, size, PROT_READ, MAP_PRIVATE | MAP_FIXED, fd, 0);
  ::close(fd);
  if (mapped == MAP_FAILED) {
    error = "cannot map '" + path + "': " + std::strerror(errno);
    ::munmap(region, total);
    return nullptr;
  }
  ::madvise(mapped, size, MADV_SEQUENTIAL);
  file->mapping_ = region;
  file->mappingSize_ = total;
  file->data_ = static_cast<const char *>(mapped);
  file->size_ = size;
  return file;
}

std::unique_ptr<SourceFile> SourceFile::fromString(std::string name, std::string_view contents) {
  std::unique_ptr<SourceFile> file(new SourceFile());
  file->name_ = std::move(name);
  file->owned_.assign(contents.data(), contents.size());
  file->data_ = file->owned_.c_str();
  file->size_ = contents.size();
  return file;
}

std::unique_ptr<SourceFile> SourceFile::translation(std::unique_ptr<SourceFile> original, std::string text,
                                                    std::vector<std::pair<uint64_t, uint64_t>> originMap) {
  std::unique_ptr<SourceFile> file(new SourceFile());
  file->name_ = std::string(original->name());
  file->owned_ = std::move(text);
  file->data_ = file->owned_.c_str();
  file->size_ = file->owned_.size();
  file->original_ = std::move(original);
  file->originMap_ = std::move(originMap);
  return file;
}

uint64_t SourceFile::originalOffset(uint64_t offset) const {
  auto it = std::upper_bound(originMap_.begin(), originMap_.end(), offset,
                             [](uint64_t o, const std::pair<uint64_t, uint64_t> &p) { return o < p.first; });
  return it == originMap_.begin() ? 0 : std::prev(it)->second;
}

void SourceFile::buildLineTable() const {
  lineStarts_.push_back(0);
  const char *p = data_;
  const char *e = data_ + size_;
  while (p < e) {
    const void *nl = std::memchr(p, '\n', static_cast<size_t>(e - p));
    if (!nl)
      break;
    p = static_cast<const char *>(nl) + 1;
    lineStarts_.push_back(static_cast<uint64_t>(p - data_));
  }
}

LineCol SourceFile::lineCol(uint64_t offset) const {
  if (original_)
    return original_->lineCol(originalOffset(offset));
  if (lineStarts_.empty())
    buildLineTable();
  offset = std::min(offset, size_);
  auto it = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
  const auto line = static_cast<uint32_t>(it - lineStarts_.begin());
  const uint64_t start = lineStarts_[line - 1];
  return {line, static_cast<uint32_t>(offset - start + 1)};
}

void SourceFile::releaseBefore(uint64_t offset) const {
  if (!mapping_)
    return;
  const auto page = static_cast<uint64_t>(::sysconf(_SC_PAGESIZE));
  const uint64_t end = std::min(offset, size_) / page * page;
  if (end > 0)
    ::madvise(mapping_, end, MADV_DONTNEED);
}

uint64_t SourceFile::offsetOf(LineCol at) const {
  if (lineStarts_.empty())
    buildLineTable();
  if (at.line == 0)
    return 0;
  if (at.line > lineStarts_.size())
    return size_;
  const uint64_t start = lineStarts_[at.line - 1];
  return std::min(size_, start + (at.col > 0 ? at.col - 1 : 0));
}

std::string_view SourceFile::lineText(uint32_t line) const {
  if (original_)
    return original_->lineText(line);
  if (lineStarts_.empty())
    buildLineTable();
  if (line == 0 || line > lineStarts_.size())
    return {};
  const uint64_t start = lineStarts_[line - 1];
  uint64_t stop = line < lineStarts_.size() ? lineStarts_[line] : size_;
  while (stop > start && (data_[stop - 1] == '\n' || data_[stop - 1] == '\r'))
    --stop;
  return {data_ + start, stop - start};
}

} // namespace stepnc
