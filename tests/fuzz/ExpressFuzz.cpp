// express-fuzz: a replay and mutation harness for the EXPRESS reader.
//
// libFuzzer cannot build the ANTLR-generated EXPRESS lexer with clang 14 (see
// README.md), so this is an ordinary program, built with the project's own
// compiler and, in the ASan build, its sanitizers. It reads seed schemas,
// mutates them deterministically from --seed (byte flips, invalid UTF-8,
// token duplication, deletion and renaming, splices between seeds, deep
// nesting, windows of large schemas) and runs every mutant in process
// through readExpress, Model::resolve and the binder, on a small Part 21
// file made for the mutant's first schema (whether it resolved or not). A watchdog thread stops the
// run when one input takes longer than --timeout-ms or the process grows
// beyond --rss-mb; fatal signals and sanitizer reports are caught too. Each
// of those writes the input to --out (timeout-*, oom-*, crash-*) first.
// Inputs that break the oracle without crashing (an error without a place,
// a failure without an error, an uncaught exception) are written there as
// well (finding-*) and the run goes on.
//
//   express-fuzz [--seed N] [--iterations N] [--minutes M] [--out DIR]
//                [--timeout-ms MS] [--rss-mb MB] SEED_FILE_OR_DIR...
//   express-fuzz --replay FILE_OR_DIR...   each input once, unmutated
//
// Directories are searched recursively for *.exp files, read in place.
// Exit status: 0 clean, 1 findings, 3 timeout, 4 memory, other: the crash.
#include "frontend/binding/Binder.h"
#include "frontend/express/SchemaReader.h"
#include "frontend/part21/Part21File.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#endif

namespace fs = std::filesystem;
using namespace stepnc;

namespace {

// ---- what the watchdog and the signal handlers need ------------------------

// The input being run, for the handlers (written with write(2) only).
std::string g_input;
char g_crashPath[4096];
std::atomic<int64_t> g_startedNs{0};  // 0: nothing running
int64_t g_timeoutNs = 5'000'000'000;
uint64_t g_rssLimitBytes = 2048ull << 20;
std::string g_outDir = "express-fuzz-out";

int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void writeInput(const char *path) {
  const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0)
    return;
  size_t done = 0;
  while (done < g_input.size()) {
    const ssize_t n = ::write(fd, g_input.data() + done, g_input.size() - done);
    if (n <= 0)
      break;
    done += static_cast<size_t>(n);
  }
  ::close(fd);
}

void say(const char *text) { [[maybe_unused]] ssize_t n = ::write(2, text, std::strlen(text)); }

void onFatalSignal(int sig) {
  writeInput(g_crashPath);
  say("express-fuzz: crash (fatal signal); input written to ");
  say(g_crashPath);
  say("\n");
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

#if defined(__SANITIZE_ADDRESS__)
void onSanitizerDeath() {
  writeInput(g_crashPath);
  say("express-fuzz: sanitizer report; input written to ");
  say(g_crashPath);
  say("\n");
}
#endif

uint64_t rssBytes() {
  std::ifstream statm("/proc/self/statm");
  uint64_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<uint64_t>(::sysconf(_SC_PAGESIZE));
}

std::string hexHash(std::string_view s) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (unsigned char c : s)
    h = (h ^ c) * 1099511628211ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string saveFinding(const std::string &kind, std::string_view input) {
  const fs::path path = fs::path(g_outDir) / (kind + "-" + hexHash(input) + ".exp");
  std::ofstream(path, std::ios::binary) << input;
  return path.string();
}

void watchdog() {
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const int64_t started = g_startedNs.load();
    if (started != 0 && nowNs() - started > g_timeoutNs) {
      const std::string path = saveFinding("timeout", g_input);
      std::fprintf(stderr, "express-fuzz: input ran longer than %lld ms; written to %s\n",
                   static_cast<long long>(g_timeoutNs / 1'000'000), path.c_str());
      std::_Exit(3);
    }
    if (started != 0 && rssBytes() > g_rssLimitBytes) {
      const std::string path = saveFinding("oom", g_input);
      std::fprintf(stderr, "express-fuzz: memory above %llu MB; input written to %s\n",
                   static_cast<unsigned long long>(g_rssLimitBytes >> 20), path.c_str());
      std::_Exit(4);
    }
  }
}

void installHandlers() {
  // Stack overflows are among the bugs looked for: handle them on a stack of
  // their own.
  static std::vector<char> altStack(1 << 16);
  stack_t ss{};
  ss.ss_sp = altStack.data();
  ss.ss_size = altStack.size();
  ::sigaltstack(&ss, nullptr);
  for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL}) {
    struct sigaction sa{};
    sa.sa_handler = onFatalSignal;
    sa.sa_flags = SA_ONSTACK;
    ::sigaction(sig, &sa, nullptr);
  }
#if defined(__SANITIZE_ADDRESS__)
  __sanitizer_set_death_callback(onSanitizerDeath);
#endif
}

// ---- the oracle ------------------------------------------------------------

// A Part 21 file with one instance per entity of `schema` (the first 40),
// each attribute a value picked from a fixed list: right and wrong kinds,
// `$` and `*`, references, nested lists and typed values naming the schema's
// own types, so the binder follows every kind of type the mutant declares.
std::string part21For(const express::Model &model, const express::Schema &schema, std::mt19937_64 &rng) {
  std::vector<std::string> typeNames;
  for (express::DeclTypeId t : schema.types)
    typeNames.push_back(express::upper(model.typeDecl(t).name));
  const size_t count = std::min<size_t>(schema.entities.size(), 40);
  auto value = [&]() -> std::string {
    static const char *fixed[] = {"1", "2.5", "'x'", ".T.", ".U.", "$", "*", "#1", "(1,2)", "((1),(#2))", "()",
                                  ".NOPE.", "\"0A\""};
    const size_t pick = rng() % (std::size(fixed) + 2);
    if (pick < std::size(fixed))
      return fixed[pick];
    if (!typeNames.empty())
      return typeNames[rng() % typeNames.size()] + (pick % 2 ? "(1)" : "((#1,'x'))");
    std::string ref = "#";
    ref += std::to_string(1 + rng() % (count + 1));
    return ref;
  };
  std::string out = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
                    "FILE_NAME('m.stp','2026-01-01T00:00:00',(''),(''),'','','');\nFILE_SCHEMA(('" +
                    express::upper(schema.name) + "'));\nENDSEC;\nDATA;\n";
  for (size_t i = 0; i < count; ++i) {
    const express::Entity &e = model.entity(schema.entities[i]);
    out += '#';
    out += std::to_string(i + 1);
    out += '=';
    out += express::upper(e.name);
    out += '(';
    const size_t n = std::min<size_t>(e.slots.size(), 64);
    for (size_t k = 0; k < n; ++k) {
      if (k > 0)
        out += ',';
      out += value();
    }
    out += ");\n";
  }
  return out + "ENDSEC;\nEND-ISO-10303-21;\n";
}

// Checks what readExpress and resolve reported; returns the oracle's
// complaint, empty if none.
std::string checkDiagnostics(const DiagnosticCollector &collected, const SourceFile &src, bool failed) {
  bool anyError = false;
  for (const Diagnostic &d : collected.diags) {
    if (d.severity != Severity::Error)
      continue;
    anyError = true;
    if (!d.loc.valid())
      return "[loc] error without a place: " + d.message;
    if (d.loc.file == &src && d.loc.offset > src.text().size())
      return "[loc] error placed beyond the end of the input: " + d.message;
  }
  if (failed && !anyError)
    return "[silent] the reader or resolve failed without an error";
  return {};
}

struct Stats {
  uint64_t runs = 0, parsed = 0, resolved = 0, bound = 0, findings = 0;
};

void runOne(const std::string &input, std::mt19937_64 &rng, Stats &stats) {
  g_input = input;
  g_startedNs = nowNs();
  std::string complaint;
  try {
    express::Model model;
    DiagnosticCollector collected;
    DiagnosticEngine diags(collected);
    auto owned = SourceFile::fromString("fuzz.exp", input);
    const SourceFile &src = *owned;
    const bool read = express::readExpress(std::move(owned), model, diags);
    const bool resolved = read && model.resolve(diags);
    stats.parsed += read;
    stats.resolved += resolved;
    complaint = checkDiagnostics(collected, src, !resolved);
    // Bound even when resolve() failed: the commands stop there, but the
    // binder must not loop or crash on any model (cycles, names left
    // unresolved, entities without attribute lists).
    if (complaint.empty() && read && !model.schemas().empty()) {
      const express::Schema &schema = model.schemas().front();
      auto p21src = SourceFile::fromString("fuzz.stp", part21For(model, schema, rng));
      DiagnosticCollector p21collected;
      DiagnosticEngine p21diags(p21collected);
      p21diags.setMaxErrors(50);
      auto file = p21::readPart21(*p21src, p21diags);
      if (file) {
        binding::BindOptions options;
        options.lenient = rng() % 2 == 0;
        binding::bind(*file, model, schema, p21diags, options);
        ++stats.bound;
      }
    }
  } catch (const std::exception &e) {
    complaint = std::string("[exception] uncaught: ") + e.what();
  } catch (...) {
    complaint = "[exception] uncaught, not a std::exception";
  }
  g_startedNs = 0;
  ++stats.runs;
  if (!complaint.empty()) {
    ++stats.findings;
    std::fprintf(stderr, "express-fuzz: %s\n  input written to %s\n", complaint.c_str(),
                 saveFinding("finding", input).c_str());
  }
}

// ---- mutations -------------------------------------------------------------

// Inserted whole; the last entries are bytes that are not UTF-8 (and a NUL).
const std::string_view kTokens[] = {
    "SCHEMA s;", "END_SCHEMA;", "ENTITY", "END_ENTITY;", "TYPE", "END_TYPE;", "SUBTYPE OF (", "SUPERTYPE OF (",
    "ABSTRACT", "ONEOF (", "ANDOR", "AND", "OR", "NOT", "SELECT (", "ENUMERATION OF (", "EXTENSIBLE", "BASED_ON",
    "WITH", "LIST [0:?] OF", "SET OF", "BAG OF", "ARRAY [1:3] OF", "OF", "OPTIONAL", "UNIQUE", "DERIVE", "INVERSE",
    "WHERE", "SELF\\", "SELF", "RENAMED", "USE FROM", "REFERENCE FROM", "FUNCTION", "END_FUNCTION;", "RULE",
    "END_RULE;", "SUBTYPE_CONSTRAINT", "END_SUBTYPE_CONSTRAINT;", "CONSTANT", "END_CONSTANT;", "IF", "THEN",
    "END_IF;", "REPEAT", "END_REPEAT;", "QUERY (", "<*", "|", "(", ")", "[", "]", "{", "}", ";", ":", ":=", ",",
    ".", "(*", "*)", "--", "'", "\"", "?", "INTEGER", "REAL", "STRING", "BOOLEAN", "LOGICAL", "GENERIC",
    "AGGREGATE OF", "\n", "\xc3\xa9", "\xe9", "\xff", "\xed\xa0\x80", "\xc0\x80", "\xf4\x90\x80\x80",
    std::string_view("\0", 1)};

std::vector<std::string_view> tokensOf(std::string_view s) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < s.size()) {
    size_t j = i + 1;
    const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    if (word(s[i]))
      while (j < s.size() && word(s[j]))
        ++j;
    else if (std::isspace(static_cast<unsigned char>(s[i])))
      while (j < s.size() && std::isspace(static_cast<unsigned char>(s[j])))
        ++j;
    out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

class Mutator {
public:
  Mutator(const std::vector<std::string> &seeds, std::mt19937_64 &rng) : seeds_(seeds), rng_(rng) {}

  std::string mutant() {
    std::string s = pickSeed();
    // Mostly one step: most mutations break the syntax, and a mutant that
    // still parses reaches resolution and binding.
    const int steps = below(2) == 0 ? 1 : 1 + static_cast<int>(below(4));
    for (int i = 0; i < steps; ++i)
      mutate(s);
    if (s.size() > (4u << 20))
      s.resize(4u << 20);
    return s;
  }

private:
  size_t below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(rng_() % n); }

  // Large schemas are fuzzed in windows (declarations from a few KB of one,
  // put in a schema of their own): whole, the 1.6 MB AP238 AIM long form
  // takes 2.5 s to read, over 10 s with ASan.
  std::string pickSeed() {
    const std::string &seed = seeds_[below(seeds_.size())];
    if (seed.size() <= 128 * 1024)
      return seed;
    const size_t len = 2000 + below(30000);
    const size_t from = below(seed.size() - len);
    size_t at = std::min(seed.find("\nENTITY", from), seed.find("\nTYPE", from));
    if (at == std::string::npos)
      at = from;
    size_t end = std::min(at + len, seed.size()), cut = at;
    for (std::string_view close : {"END_ENTITY;", "END_TYPE;"}) {
      const size_t last = seed.rfind(close, end);
      if (last != std::string::npos && last > at)
        cut = std::max(cut, last + close.size());
    }
    if (cut > at)
      end = cut;
    return "SCHEMA window;\n" + seed.substr(at, end - at) + "\nEND_SCHEMA;\n";
  }

  // The bytes of a random run of at most `most` tokens of `s`.
  std::pair<size_t, size_t> tokenRun(const std::string &s, const std::vector<std::string_view> &tokens, size_t most) {
    const size_t from = below(tokens.size());
    const size_t to = std::min(tokens.size(), from + 1 + below(most));
    return {static_cast<size_t>(tokens[from].data() - s.data()),
            static_cast<size_t>(tokens[to - 1].data() + tokens[to - 1].size() - s.data())};
  }

  void mutate(std::string &s) {
    auto tokens = tokensOf(s);
    switch (below(16)) {
    case 0: {  // flip bits of a few bytes
      for (size_t n = 1 + below(4); n > 0 && !s.empty(); --n)
        s[below(s.size())] ^= static_cast<char>(1u << below(8));
      break;
    }
    case 1:  // delete a range of bytes
      if (!s.empty()) {
        const size_t at = below(s.size());
        s.erase(at, 1 + below(std::min<size_t>(64, s.size() - at)));
      }
      break;
    case 2:  // insert a token of the dictionary
    case 3: {
      const std::string_view t = kTokens[below(std::size(kTokens))];
      s.insert(below(s.size() + 1), std::string(t) + " ");
      break;
    }
    case 4: {  // duplicate a run of tokens, sometimes many times
      if (tokens.empty())
        break;
      const auto [begin, end] = tokenRun(s, tokens, 12);
      const std::string run = s.substr(begin, end - begin);
      const size_t times = below(4) == 0 ? 1 + below(3000) : 1 + below(3);
      std::string copies;
      for (size_t i = 0; i < times && copies.size() < (1u << 20); ++i)
        copies += run;
      s.insert(end, copies);
      break;
    }
    case 5: {  // delete a run of tokens
      if (tokens.empty())
        break;
      const auto [begin, end] = tokenRun(s, tokens, 8);
      s.erase(begin, end - begin);
      break;
    }
    case 6:  // rename one identifier to another of the file: self-references, cycles, clashes
    case 7:
    case 12:
    case 13:
    case 14: {
      std::vector<size_t> words;
      for (size_t i = 0; i < tokens.size(); ++i)
        if (std::isalpha(static_cast<unsigned char>(tokens[i][0])))
          words.push_back(i);
      if (words.size() < 2)
        break;
      const std::string_view a = tokens[words[below(words.size())]];
      const std::string b(tokens[words[below(words.size())]]);
      const size_t at = static_cast<size_t>(a.data() - s.data());
      s.replace(at, a.size(), b);
      break;
    }
    case 8: {  // splice in a piece of another seed
      const std::string &other = seeds_[below(seeds_.size())];
      if (other.empty())
        break;
      const size_t from = below(other.size());
      s.insert(below(s.size() + 1), other.substr(from, 1 + below(4000)));
      break;
    }
    case 9: {  // deep nesting around a point
      static const std::pair<const char *, const char *> kNest[] = {
          {"(", ")"}, {"[", "]"}, {"{", "}"}, {"f(", ")"}, {"LIST OF ", ""}, {"(*", "*)"},
          {"IF a THEN ", " END_IF;"}, {"BEGIN ", " END;"}, {"ONEOF (", ")"}, {"-", ""}, {"NOT ", ""}};
      const auto &[open, close] = kNest[below(std::size(kNest))];
      const size_t depth = below(3) == 0 ? 1 + below(20000) : 1 + below(300);
      const size_t at = below(s.size() + 1);
      const size_t end = std::min(s.size(), at + below(40));
      std::string opens, closes;
      for (size_t i = 0; i < depth; ++i) {
        opens += open;
        closes += close;
      }
      s.insert(end, closes);
      s.insert(at, opens);
      break;
    }
    case 10: {  // swap two tokens
      if (tokens.size() < 2)
        break;
      std::vector<std::string_view> t = tokens;
      std::swap(t[below(t.size())], t[below(t.size())]);
      std::string out;
      out.reserve(s.size());
      for (std::string_view v : t)
        out += v;
      s = std::move(out);
      break;
    }
    default: {  // truncate
      if (!s.empty())
        s.resize(below(s.size()));
      break;
    }
    }
  }

  const std::vector<std::string> &seeds_;
  std::mt19937_64 &rng_;
};

// ---- driver ----------------------------------------------------------------

std::vector<fs::path> inputsOf(const std::vector<std::string> &args, bool replay) {
  std::vector<fs::path> out;
  for (const std::string &arg : args) {
    std::error_code ec;
    if (fs::is_directory(arg, ec)) {
      std::vector<fs::path> here;
      // Replayed: every file but a README; mutated: the schemas only.
      for (const auto &e : fs::recursive_directory_iterator(arg, ec)) {
        const bool readme = e.path().filename().string().rfind("README", 0) == 0;
        if (e.is_regular_file() && (replay ? !readme : e.path().extension() == ".exp"))
          here.push_back(e.path());
      }
      std::sort(here.begin(), here.end());
      out.insert(out.end(), here.begin(), here.end());
    } else if (fs::is_regular_file(arg, ec)) {
      out.emplace_back(arg);
    } else {
      std::fprintf(stderr, "express-fuzz: no file or directory '%s'\n", arg.c_str());
      std::exit(2);
    }
  }
  return out;
}

std::string readFile(const fs::path &p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

} // namespace

int main(int argc, char **argv) {
  uint64_t seed = 1, iterations = 0;
  double minutes = 0;
  bool replay = false;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "express-fuzz: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--seed")
      seed = std::stoull(next());
    else if (a == "--iterations")
      iterations = std::stoull(next());
    else if (a == "--minutes")
      minutes = std::stod(next());
    else if (a == "--out")
      g_outDir = next();
    else if (a == "--timeout-ms")
      g_timeoutNs = std::stoll(next()) * 1'000'000;
    else if (a == "--rss-mb")
      g_rssLimitBytes = std::stoull(next()) << 20;
    else if (a == "--replay")
      replay = true;
    else
      paths.push_back(a);
  }
  if (paths.empty() || (!replay && iterations == 0 && minutes <= 0)) {
    std::fprintf(stderr, "usage: express-fuzz [--seed N] (--iterations N | --minutes M) [--out DIR] "
                         "[--timeout-ms MS] [--rss-mb MB] SEEDS...\n"
                         "       express-fuzz --replay FILE_OR_DIR...\n");
    return 2;
  }
  fs::create_directories(g_outDir);
  std::snprintf(g_crashPath, sizeof g_crashPath, "%s/crash-current.exp", g_outDir.c_str());
  installHandlers();
  std::thread(watchdog).detach();

  std::mt19937_64 rng(seed);
  Stats stats;
  const std::vector<fs::path> files = inputsOf(paths, replay);
  const int64_t start = nowNs();
  if (replay) {
    for (const fs::path &p : files) {
      std::snprintf(g_crashPath, sizeof g_crashPath, "%s/crash-%s", g_outDir.c_str(), p.filename().c_str());
      runOne(readFile(p), rng, stats);
    }
  } else {
    std::vector<std::string> seeds;
    for (const fs::path &p : files)
      seeds.push_back(readFile(p));
    if (seeds.empty()) {
      std::fprintf(stderr, "express-fuzz: no seeds (*.exp) found\n");
      return 2;
    }
    Mutator mutator(seeds, rng);
    const int64_t deadline = minutes > 0 ? start + static_cast<int64_t>(minutes * 60e9) : INT64_MAX;
    for (uint64_t n = 0; (iterations == 0 || n < iterations) && nowNs() < deadline; ++n) {
      std::string input = mutator.mutant();
      std::snprintf(g_crashPath, sizeof g_crashPath, "%s/crash-seed%llu-%llu.exp", g_outDir.c_str(),
                    static_cast<unsigned long long>(seed), static_cast<unsigned long long>(n));
      runOne(input, rng, stats);
      if ((n + 1) % 1000 == 0)
        std::fprintf(stderr, "express-fuzz: %llu mutants, %.1f min, %llu findings\n",
                     static_cast<unsigned long long>(n + 1), static_cast<double>(nowNs() - start) / 60e9,
                     static_cast<unsigned long long>(stats.findings));
    }
  }
  std::printf("express-fuzz: %llu inputs (%llu parsed, %llu resolved, %llu bound) in %.1f s, %llu findings\n",
              static_cast<unsigned long long>(stats.runs), static_cast<unsigned long long>(stats.parsed),
              static_cast<unsigned long long>(stats.resolved), static_cast<unsigned long long>(stats.bound),
              static_cast<double>(nowNs() - start) / 1e9, static_cast<unsigned long long>(stats.findings));
  return stats.findings == 0 ? 0 : 1;
}
