#include "support/OutputFile.h"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <signal.h>
#include <sys/stat.h>
#include <cstring>
#include <iterator>
#include <unistd.h>

namespace stepnc {

namespace {

// Temporary files that are open, for the signal handler to remove: a kill
// (SIGTERM, as `timeout` sends; SIGINT, Ctrl-C; SIGHUP) must not leave a
// `.tmp.XXXXXX` beside the target. Fixed slots of fixed size, because a
// handler may only touch memory that needs no allocation or lock; a slot is
// published by setting `used` last and retired by clearing it first.
constexpr int kSlots = 16;
constexpr size_t kPathMax = 4096;
struct Slot {
  volatile std::sig_atomic_t used = 0;
  char path[kPathMax] = {};
};
Slot gSlots[kSlots];

constexpr int kSignals[] = {SIGTERM, SIGINT, SIGHUP};
/// What each of kSignals did before removeTemporariesAndDie took it over.
struct sigaction gPrevious[std::size(kSignals)];

extern "C" void removeTemporariesAndDie(int sig) {
  for (Slot &slot : gSlots)
    if (slot.used)
      ::unlink(slot.path);  // async-signal-safe
  // Then what the signal did before: a handler the program had installed,
  // else end as the signal ends a process (the caller sees it).
  for (size_t i = 0; i < std::size(kSignals); ++i)
    if (kSignals[i] == sig && gPrevious[i].sa_handler != SIG_DFL && gPrevious[i].sa_handler != SIG_IGN &&
        !(gPrevious[i].sa_flags & SA_SIGINFO)) {
      gPrevious[i].sa_handler(sig);
      return;
    }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

/// Takes over kSignals where something else holds them now (checked at each
/// open: the program may have installed handlers since); a signal the
/// caller chose to ignore (nohup) stays ignored.
void installHandlers() {
  for (size_t i = 0; i < std::size(kSignals); ++i) {
    struct sigaction current {};
    if (::sigaction(kSignals[i], nullptr, &current) != 0 || current.sa_handler == SIG_IGN ||
        (!(current.sa_flags & SA_SIGINFO) && current.sa_handler == removeTemporariesAndDie))
      continue;
    gPrevious[i] = current;
    struct sigaction action {};
    action.sa_handler = removeTemporariesAndDie;
    sigemptyset(&action.sa_mask);
    ::sigaction(kSignals[i], &action, nullptr);
  }
}

/// The slot that now holds `path`, or -1 when none is free or it is too long
/// (the file is still removed on every ordinary exit, only not on a kill).
int track(const std::string &path) {
  if (path.size() >= kPathMax)
    return -1;
  installHandlers();
  for (int i = 0; i < kSlots; ++i)
    if (!gSlots[i].used) {
      std::memcpy(gSlots[i].path, path.c_str(), path.size() + 1);
      gSlots[i].used = 1;
      return i;
    }
  return -1;
}

void untrack(int slot) {
  if (slot >= 0)
    gSlots[slot].used = 0;
}

} // namespace

OutputFile::~OutputFile() { discard(); }

bool OutputFile::writable(const std::string &path, std::string &error) {
  if (path == "-")
    return true;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) {
      error = "cannot write '" + path + "': it is a directory";
      return false;
    }
    // access() answers for the user (root may write anything); a file with
    // no write permission at all is read-only for root too.
    const bool noOneWrites = (st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0;
    if (::access(path.c_str(), W_OK) != 0 || (S_ISREG(st.st_mode) && noOneWrites)) {
      error = "cannot write '" + path + "': the file is read-only; it is left as it is";
      return false;
    }
    return true;
  }
  // A new file: its folder must exist and take it.
  const size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  if (::stat(folder.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    error = "cannot create '" + path + "': the folder '" + folder + "' does not exist";
    return false;
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    error = "cannot create '" + path + "': " + std::strerror(errno);
    return false;
  }
  return true;
}

bool OutputFile::open(const std::string &path, std::string &error) {
  path_ = path;
  if (path == "-") {
    isStdout_ = true;
    file_ = stdout;
    return true;
  }
  if (!writable(path, error))
    return false;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode)) {
      error = "cannot write '" + path + "': it is a directory";
      return false;
    }
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) {
      error = "cannot write '" + path + "': " + std::strerror(errno);
      return false;
    }
    direct_ = true;
    return true;
  }
  tempPath_ = path + ".tmp.XXXXXX";
  int fd = ::mkstemp(tempPath_.data());
  if (fd < 0) {
    error = "cannot create '" + path + "': " + std::strerror(errno);
    tempPath_.clear();
    return false;
  }
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    ::close(fd);
    ::unlink(tempPath_.c_str());
    tempPath_.clear();
    return false;
  }
  slot_ = track(tempPath_);
  // A buffer of its own: several output files may be open at once.
  buffer_ = std::make_unique<char[]>(kBufferSize);
  std::setvbuf(file_, buffer_.get(), _IOFBF, kBufferSize);
  return true;
}

void OutputFile::write(std::string_view bytes) {
  if (!bytes.empty())
    std::fwrite(bytes.data(), 1, bytes.size(), file_);
}

bool OutputFile::commit(std::string &error) {
  if (!file_) {
    error = "no output file is open";
    return false;
  }
  if (direct_) {
    bool ok = std::fflush(file_) == 0 && !std::ferror(file_);
    ok = (std::fclose(file_) == 0) && ok;
    file_ = nullptr;
    if (!ok)
      error = "cannot write '" + path_ + "': " + std::strerror(errno);
    return ok;
  }
  if (isStdout_) {
    bool ok = std::fflush(file_) == 0 && !std::ferror(file_);
    file_ = nullptr;
    if (!ok)
      error = std::string("cannot write standard output: ") + std::strerror(errno);
    return ok;
  }
  bool ok = std::fflush(file_) == 0 && !std::ferror(file_) && ::fsync(::fileno(file_)) == 0;
  int saved = errno;
  ok = (std::fclose(file_) == 0) && ok;
  file_ = nullptr;
  if (!ok) {
    error = "cannot write '" + path_ + "': " + std::strerror(saved ? saved : errno);
    discard();
    return false;
  }
  // mkstemp creates 0600: a file replaced keeps its permissions, a new one
  // gets the usual ones.
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
    ::chmod(tempPath_.c_str(), st.st_mode & 07777);
  } else {
    mode_t mask = ::umask(0);
    ::umask(mask);
    ::chmod(tempPath_.c_str(), 0666 & ~mask);
  }
  if (std::rename(tempPath_.c_str(), path_.c_str()) != 0) {
    error = "cannot write '" + path_ + "': " + std::strerror(errno);
    discard();
    return false;
  }
  untrack(slot_);
  slot_ = -1;
  tempPath_.clear();
  return true;
}

void OutputFile::discard() {
  if (file_ && !isStdout_)
    std::fclose(file_);
  file_ = nullptr;
  if (!tempPath_.empty()) {
    untrack(slot_);
    slot_ = -1;
    ::unlink(tempPath_.c_str());
    tempPath_.clear();
  }
}

} // namespace stepnc
