#include "support/OutputFile.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <csignal>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace stepnc;
namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path &p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
fs::path scratchDir() {
  fs::path d = fs::temp_directory_path() / ("stepnc-output-test-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}
} // namespace

TEST_CASE("an output file appears only when committed", "[support]") {
  fs::path dir = scratchDir();
  fs::path target = dir / "out.txt";
  std::string error;
  {
    OutputFile out;
    REQUIRE(out.open(target.string(), error));
    out.write("partial");
    CHECK_FALSE(fs::exists(target));
    // destroyed without commit: nothing is left behind
  }
  CHECK_FALSE(fs::exists(target));
  CHECK(fs::is_empty(dir));
  {
    OutputFile out;
    REQUIRE(out.open(target.string(), error));
    out.write("complete\n");
    REQUIRE(out.commit(error));
  }
  CHECK(slurp(target) == "complete\n");
  fs::remove_all(dir);
}

TEST_CASE("a failed write keeps the previous file intact", "[support]") {
  fs::path dir = scratchDir();
  fs::path target = dir / "keep.txt";
  { std::ofstream(target) << "old\n"; }
  std::string error;
  {
    OutputFile out;
    REQUIRE(out.open(target.string(), error));
    out.write("new but abandoned");
    out.discard();
  }
  CHECK(slurp(target) == "old\n");
  fs::remove_all(dir);
}

TEST_CASE("opening in a missing directory reports the path", "[support]") {
  OutputFile out;
  std::string error;
  CHECK_FALSE(out.open("/nonexistent-dir-for-stepnc/x.stp", error));
  CHECK(error.find("/nonexistent-dir-for-stepnc/x.stp") != std::string::npos);
}

TEST_CASE("a device target is written in place, never replaced", "[support]") {
  std::string error;
  OutputFile out;
  REQUIRE(out.open("/dev/null", error));
  out.write("discarded\n");
  REQUIRE(out.commit(error));
  struct stat st {};
  REQUIRE(::stat("/dev/null", &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
  fs::path dir = scratchDir();
  OutputFile toDir;
  CHECK_FALSE(toDir.open(dir.string(), error));
  CHECK(error.find("is a directory") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("output files open at the same time keep their own bytes", "[support]") {
  fs::path dir = scratchDir();
  // More than one stream buffer each, written alternately.
  const std::string a(100000, 'a'), b(100000, 'b');
  std::string error;
  OutputFile first, second;
  REQUIRE(first.open((dir / "a.txt").string(), error));
  REQUIRE(second.open((dir / "b.txt").string(), error));
  for (size_t i = 0; i < a.size(); i += 1000) {
    first.write(std::string_view(a).substr(i, 1000));
    second.write(std::string_view(b).substr(i, 1000));
  }
  REQUIRE(first.commit(error));
  REQUIRE(second.commit(error));
  CHECK(slurp(dir / "a.txt") == a);
  CHECK(slurp(dir / "b.txt") == b);
  fs::remove_all(dir);
}

TEST_CASE("a read-only target is refused, not renamed over", "[support]") {
  fs::path dir = scratchDir();
  fs::path target = dir / "protected.txt";
  { std::ofstream(target) << "old\n"; }
  ::chmod(target.c_str(), 0444);
  std::string error;
  // Refused when asked first and when opened; for root too, since no one
  // may write the file.
  CHECK_FALSE(OutputFile::writable(target.string(), error));
  CHECK(error == "cannot write '" + target.string() + "': the file is read-only; it is left as it is");
  OutputFile out;
  error.clear();
  CHECK_FALSE(out.open(target.string(), error));
  CHECK(error.find("read-only") != std::string::npos);
  CHECK(slurp(target) == "old\n");
  struct stat st {};
  REQUIRE(::stat(target.c_str(), &st) == 0);
  CHECK((st.st_mode & 07777) == 0444);
  // No temporary file was left beside it.
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  fs::remove_all(dir);
}

TEST_CASE("what may be written is known before any work", "[support]") {
  fs::path dir = scratchDir();
  std::string error;
  CHECK(OutputFile::writable("-", error));
  CHECK(OutputFile::writable((dir / "new.txt").string(), error));
  CHECK(OutputFile::writable("/dev/null", error));
  CHECK_FALSE(OutputFile::writable((dir / "no" / "x.txt").string(), error));
  CHECK(error == "cannot create '" + (dir / "no" / "x.txt").string() + "': the folder '" + (dir / "no").string() +
                     "' does not exist");
  CHECK_FALSE(OutputFile::writable(dir.string(), error));
  CHECK(error.find("is a directory") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("a replaced file keeps its permissions", "[support]") {
  fs::path dir = scratchDir();
  fs::path target = dir / "shared.txt";
  { std::ofstream(target) << "old\n"; }
  ::chmod(target.c_str(), 0640);
  std::string error;
  OutputFile out;
  REQUIRE(out.open(target.string(), error));
  out.write("new\n");
  REQUIRE(out.commit(error));
  CHECK(slurp(target) == "new\n");
  struct stat st {};
  REQUIRE(::stat(target.c_str(), &st) == 0);
  CHECK((st.st_mode & 07777) == 0640);
  fs::remove_all(dir);
}

TEST_CASE("a kill while writing leaves no temporary file", "[support]") {
  // In a child, so that the signal ends the child and not the test run.
  for (int sig : {SIGTERM, SIGINT}) {
    const fs::path dir = scratchDir() / ("killed-" + std::to_string(sig));
    fs::create_directories(dir);
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      // A process of its own: the signal does what it does by default (the
      // test runner's handlers, inherited, would report it instead).
      std::signal(SIGTERM, SIG_DFL);
      std::signal(SIGINT, SIG_DFL);
      OutputFile out;
      std::string error;
      if (!out.open((dir / "out.ngc").string(), error))
        ::_exit(3);
      out.write("partial");
      ::kill(::getpid(), sig);
      ::_exit(4);  // not reached: the signal ends the child
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == sig);
    CHECK(fs::is_empty(dir));  // neither the target nor its .tmp.XXXXXX
    fs::remove_all(dir);
  }
}
