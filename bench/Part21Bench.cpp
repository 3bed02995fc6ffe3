// Throughput benchmarks of the Part 21 reader (Google Benchmark).
//
//   stepnc-bench [--file=PATH] [benchmark flags...]
//
// The input is the file named by --file=PATH (or --stepnc_file=PATH), else by
// the STEPNC_BENCH_FILE environment variable, else a small synthetic file made
// in memory (a smoke test: figures worth recording come from a large file, see
// bench/run-part21-bench.sh and docs/performance.md). The file is mapped once,
// and every page is touched before any benchmark runs, so the timings measure
// the reader on a warm page cache, not the disk.
//
// Every benchmark reports the input size per iteration as bytes processed, so
// "bytes_per_second" is input throughput, computed (Google Benchmark's default)
// from the thread's CPU time: the machine is shared, and CPU time does not
// count the time the thread spends preempted. The JSON output has real time too.
//   BM_InstanceTable   readPart21: sections, header and the instance table
//   BM_DecodeAll       decodeInstance of every instance into one reused arena
//   BM_CheckAll        checkInstances: decode + reference checks
//   BM_WriteCanonical  writePart21 to /dev/null through OutputFile("-")
#include "frontend/part21/Part21File.h"
#include "frontend/part21/Writer.h"
#include "support/Diagnostics.h"
#include "support/OutputFile.h"
#include "support/SourceFile.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <iostream>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using namespace stepnc;

/// Counts diagnostics and drops them (benchmarks must not print).
class CountingConsumer final : public DiagnosticConsumer {
public:
  void handle(const Diagnostic &d) override {
    if (d.severity == Severity::Error)
      ++errors;
    else if (d.severity == Severity::Warning)
      ++warnings;
    if (first.empty())
      first = d.message;
  }
  unsigned errors = 0;
  unsigned warnings = 0;
  std::string first;
};

std::unique_ptr<SourceFile> g_source;
std::string g_description;

// A few kinds of instances typical of ISO 14649 files (geometry, placements,
// toolpath lists, strings with escapes, enumerations, typed and complex
// instances), repeated with fresh ids. About 2 MB.
std::string syntheticFile() {
  std::string s;
  s.reserve(3 << 20);
  s += "ISO-10303-21;\nHEADER;\n"
       "FILE_DESCRIPTION(('stepnc-bench synthetic input'),'2;1');\n"
       "FILE_NAME('synthetic.stp','2024-01-01T00:00:00',('stepnc'),(''),'','stepnc-bench','');\n"
       "FILE_SCHEMA(('MACHINING_SCHEMA','MILLING_SCHEMA'));\nENDSEC;\nDATA;\n";
  const int groups = 2500;
  char line[512];
  for (int g = 0; g < groups; ++g) {
    const int b = g * 10 + 1;  // ids b .. b+9
    const double x = g * 0.125, y = -g * 0.5, z = 1.0 / (g + 3);
    std::snprintf(line, sizeof line, "#%d=CARTESIAN_POINT('',(%.4f,%.4f,%.6f));\n", b, x, y, z);
    s += line;
    std::snprintf(line, sizeof line, "#%d=CARTESIAN_POINT('p%d',(%.1f,%.1f,-3.5E-02));\n", b + 1, g,
                  x + 1, y - 1);
    s += line;
    std::snprintf(line, sizeof line, "#%d=DIRECTION('',(0.,0.,1.));\n", b + 2);
    s += line;
    std::snprintf(line, sizeof line, "#%d=AXIS2_PLACEMENT_3D('placement %d',#%d,#%d,$);\n", b + 3, g,
                  b, b + 2);
    s += line;
    std::snprintf(line, sizeof line,
                  "#%d = POLYLINE('path \\X2\\00E900E8\\X0\\ it''s %d', (#%d, #%d, #%d));\n", b + 4,
                  g, b, b + 1, b);
    s += line;
    std::snprintf(line, sizeof line,
                  "#%d=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#%d);\n", b + 5, b + 4);
    s += line;
    std::snprintf(line, sizeof line,
                  "#%d=PLUS_MINUS_VALUE(LENGTH_MEASURE(0.01),LENGTH_MEASURE(-0.01),3);\n", b + 6);
    s += line;
    std::snprintf(line, sizeof line,
                  "#%d=MACHINING_WORKINGSTEP('WS %d',#%d,#%d,#%d,$);\n", b + 7, g, b + 3,
                  b + 5, b + 8);
    s += line;
    std::snprintf(line, sizeof line,
                  "#%d=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n", b + 8);
    s += line;
    std::snprintf(line, sizeof line,
                  "#%d=TOOLPATH_FEATURE('%d',#%d,(#%d,#%d,#%d,#%d),\"0FF\",%d);\n", b + 9, g, b + 3,
                  b + 4, b + 5, b + 7, b + 8, g);
    s += line;
  }
  s += "ENDSEC;\nEND-ISO-10303-21;\n";
  return s;
}

// Reads the whole mapping once so later timings run on resident pages.
void touchPages(const SourceFile &f) {
  const long page = ::sysconf(_SC_PAGESIZE);
  unsigned sum = 0;
  for (size_t i = 0; i < f.text().size(); i += static_cast<size_t>(page))
    sum += static_cast<unsigned char>(f.text()[i]);
  benchmark::DoNotOptimize(sum);
}

// The file read once, for the benchmarks that need an instance table.
struct Loaded {
  CountingConsumer consumer;
  std::unique_ptr<DiagnosticEngine> diags;
  std::unique_ptr<p21::Part21File> file;
};

Loaded &loaded() {
  static Loaded l;
  if (!l.file) {
    l.diags = std::make_unique<DiagnosticEngine>(l.consumer);
    l.file = p21::readPart21(*g_source, *l.diags);
  }
  return l;
}

void setBytes(benchmark::State &state) {
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(g_source->text().size()));
  state.SetLabel(g_description);
}

void BM_InstanceTable(benchmark::State &state) {
  CountingConsumer consumer;
  DiagnosticEngine diags(consumer);
  size_t instances = 0;
  for (auto _ : state) {
    auto file = p21::readPart21(*g_source, diags);
    instances = file->entries().size();
    benchmark::DoNotOptimize(file->entries().data());
    benchmark::ClobberMemory();
  }
  if (consumer.errors)
    state.SkipWithError(("the input has errors: " + consumer.first).c_str());
  state.counters["instances"] = static_cast<double>(instances);
  state.counters["instances/s"] =
      benchmark::Counter(static_cast<double>(instances), benchmark::Counter::kIsIterationInvariantRate);
  setBytes(state);
}

void BM_DecodeAll(benchmark::State &state) {
  const p21::Part21File &file = *loaded().file;
  const size_t n = file.entries().size();
  p21::ValueArena arena;
  size_t values = 0, failed = 0;
  for (auto _ : state) {
    values = failed = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!file.decodeInstance(i, arena, nullptr))
        ++failed;
      values += arena.values().size();
    }
    benchmark::DoNotOptimize(values);
  }
  if (failed)
    state.SkipWithError((std::to_string(failed) + " instances failed to decode").c_str());
  state.counters["values"] = static_cast<double>(values);
  state.counters["instances/s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
  setBytes(state);
}

void BM_CheckAll(benchmark::State &state) {
  const p21::Part21File &file = *loaded().file;
  CountingConsumer consumer;
  DiagnosticEngine diags(consumer);
  size_t clean = 0;
  for (auto _ : state) {
    clean = p21::checkInstances(file, diags);
    benchmark::DoNotOptimize(clean);
  }
  if (consumer.errors)
    state.SkipWithError(("the input has errors: " + consumer.first).c_str());
  state.counters["instances/s"] = benchmark::Counter(
      static_cast<double>(file.entries().size()), benchmark::Counter::kIsIterationInvariantRate);
  setBytes(state);
}

// Standard output pointed at /dev/null while a benchmark writes to it. (An
// OutputFile opened on "/dev/null" itself would create its temporary file in
// /dev, so "-" with a redirected stdout is the way to write to the null device.)
class StdoutToDevNull {
public:
  StdoutToDevNull() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = ::dup(STDOUT_FILENO);
    int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    ok_ = saved_ >= 0 && null >= 0 && ::dup2(null, STDOUT_FILENO) >= 0;
    if (null >= 0)
      ::close(null);
  }
  ~StdoutToDevNull() {
    std::fflush(stdout);
    if (saved_ >= 0) {
      ::dup2(saved_, STDOUT_FILENO);
      ::close(saved_);
    }
  }
  bool ok() const { return ok_; }

private:
  int saved_ = -1;
  bool ok_ = false;
};

// Size of the canonical output (written once to a temporary file in /tmp).
long canonicalSize(const p21::Part21File &file) {
  OutputFile out;
  std::string error;
  if (!out.open("/tmp/stepnc-bench-size.stp", error))
    return -1;
  CountingConsumer consumer;
  DiagnosticEngine diags(consumer);
  if (!p21::writePart21(file, out, diags))
    return -1;
  std::fflush(out.stream());
  long size = std::ftell(out.stream());
  out.discard();
  return size;
}

void BM_WriteCanonical(benchmark::State &state) {
  const p21::Part21File &file = *loaded().file;
  const long outSize = canonicalSize(file);
  CountingConsumer consumer;
  DiagnosticEngine diags(consumer);
  bool ok = true;
  std::string error;
  {
    StdoutToDevNull redirect;
    if (!redirect.ok()) {
      state.SkipWithError("cannot redirect standard output to /dev/null");
      for (auto _ : state) {
      }
      return;
    }
    for (auto _ : state) {
      OutputFile out;
      out.open("-", error);
      ok &= p21::writePart21(file, out, diags);
      ok &= out.commit(error);
    }
  }
  if (!ok || consumer.errors)
    state.SkipWithError(("writing failed: " + consumer.first + error).c_str());
  state.counters["out_bytes"] = static_cast<double>(outSize);
  setBytes(state);
}

BENCHMARK(BM_InstanceTable)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeAll)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CheckAll)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteCanonical)->Unit(benchmark::kMillisecond);

} // namespace

int main(int argc, char **argv) {
  // Our own flag first: Google Benchmark rejects flags it does not know.
  std::string path;
  if (const char *env = std::getenv("STEPNC_BENCH_FILE"))
    path = env;
  std::vector<char *> args;
  for (int i = 0; i < argc; ++i) {
    std::string_view a = argv[i];
    bool ours = false;
    for (std::string_view flag : {"--file=", "--stepnc_file="})
      if (i > 0 && a.substr(0, flag.size()) == flag) {
        path = std::string(a.substr(flag.size()));
        ours = true;
      }
    if (!ours)
      args.push_back(argv[i]);
  }
  int n = static_cast<int>(args.size());
  args.push_back(nullptr);

  std::string error;
  if (!path.empty()) {
    g_source = SourceFile::open(path, error);
    if (!g_source) {
      std::cerr << "stepnc-bench: " << error << '\n';
      return 2;
    }
    g_description = path;
  } else {
    g_source = SourceFile::fromString("synthetic.stp", syntheticFile());
    g_description = "synthetic";
  }
  touchPages(*g_source);
  const double mb = static_cast<double>(g_source->text().size()) / 1e6;
  char size[64];
  std::snprintf(size, sizeof size, "%.1f MB", mb);
  benchmark::AddCustomContext("stepnc_input", g_description);
  benchmark::AddCustomContext("stepnc_input_bytes", std::to_string(g_source->text().size()));

  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data()))
    return 2;
  std::cerr << "stepnc-bench: input " << g_description << " (" << size << ")\n";
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
