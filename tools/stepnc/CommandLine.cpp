#include "tools/stepnc/CommandLine.h"

#include "support/OutputFile.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <span>
#include <vector>

namespace stepnc::tool {

namespace {

/// The engine of the JSON diagnostic session open now, if any: the command's
/// own messages go into its array, which must stay the whole of stderr.
DiagnosticEngine *jsonSession = nullptr;

} // namespace

void addDiagnosticOptions(CLI::App &cmd, DiagnosticOptions &opts) {
  cmd.add_option("--diagnostics", opts.format,
                 "Diagnostic output: 'text' (file:line:col: error: ..., with the source line) or "
                 "'json' (one JSON array on stderr)")
      ->check(CLI::IsMember({"text", "json"}))
      ->default_str("text");
  cmd.add_option("--max-errors", opts.maxErrors,
                 "Stop after this many errors (0: no limit)")
      ->default_str("50");
  cmd.add_flag("--warnings-as-errors", opts.warningsAsErrors, "Treat warnings as errors");
}

void addStrictOption(CLI::App &cmd, DiagnosticOptions &opts) {
  cmd.add_flag("--strict", opts.strict,
               "Make every assumption an error: '$' where the schema wants a value, an alias for an\n"
               "entity name, an abstract entity instantiated, a value lowering had to assume (without\n"
               "--strict each is a warning that ends '--strict makes it an error')");
}

namespace {

std::vector<std::string> unitNames(std::span<const lowering::UnitReading> readings) {
  std::vector<std::string> names = {"auto"};
  for (const lowering::UnitReading &r : readings)
    names.emplace_back(r.name);
  return names;
}

/// The factor of unit `name` among `readings`; 0 (chosen per file) for "auto".
double factorOf(std::span<const lowering::UnitReading> readings, const std::string &name) {
  for (const lowering::UnitReading &r : readings)
    if (r.name == name)
      return r.factor;
  return 0.0;
}

} // namespace

lowering::UnitConventions UnitOptions::conventions() const {
  lowering::UnitConventions u;
  u.feedToMmPerMin = factorOf(lowering::speedReadings(), feed);
  u.cutspeedToMmPerMin = factorOf(lowering::speedReadings(), cuttingSpeed);
  u.rotSpeedToRevPerMin = factorOf(lowering::spindleReadings(), spindle);
  using Angle = lowering::UnitConventions::Angle;
  u.angles = angle == "deg" ? Angle::Degree : angle == "rad" ? Angle::Radian : Angle::Auto;
  return u;
}

void addUnitOptions(CLI::App &cmd, UnitOptions &opts) {
  const std::vector<std::string> speeds = unitNames(lowering::speedReadings());
  cmd.add_option("--feed-unit", opts.feed,
                 "Read the file's feedrates in this unit instead of choosing by plausibility (auto; "
                 "ISO 14649-11 reads m/s)")
      ->check(CLI::IsMember(speeds))
      ->default_str("auto");
  cmd.add_option("--cutting-speed-unit", opts.cuttingSpeed,
                 "Read the file's cutting speeds (cutspeed) in this unit instead of choosing by plausibility")
      ->check(CLI::IsMember(speeds))
      ->default_str("auto");
  cmd.add_option("--spindle-unit", opts.spindle,
                 "Read the file's spindle speeds in this unit instead of choosing by plausibility (ISO "
                 "14649-11 reads rev/s)")
      ->check(CLI::IsMember(unitNames(lowering::spindleReadings())))
      ->default_str("auto");
  cmd.add_option("--angle-unit", opts.angle,
                 "Read the file's angles in this unit instead of choosing (auto: radians when every angle "
                 "is below 2 pi and none a whole number of degrees)")
      ->check(CLI::IsMember({"auto", "deg", "rad"}))
      ->default_str("auto");
}

void addSchemaOptions(CLI::App &cmd, driver::SchemaOptions &opts) {
  cmd.add_option("--schema", opts.files,
                 "Check against the schema(s) in this EXPRESS file instead of the built-in ISO 14649 "
                 "ARM (repeatable: files are resolved together)");
  cmd.add_flag("--no-schema", opts.none, "Check Part 21 syntax and references only");
}

DiagnosticSession::DiagnosticSession(const DiagnosticOptions &opts) {
  if (opts.format == "json")
    consumer_ = std::make_unique<JsonDiagnosticPrinter>(std::cerr);
  else
    consumer_ = std::make_unique<TextDiagnosticPrinter>(std::cerr);
  engine_ = std::make_unique<DiagnosticEngine>(*consumer_);
  engine_->setMaxErrors(opts.maxErrors);
  engine_->setWarningsAsErrors(opts.warningsAsErrors);
  engine_->setStrict(opts.strict);
  if (opts.format == "json")
    jsonSession = engine_.get();
}

DiagnosticSession::~DiagnosticSession() {
  if (jsonSession == engine_.get())
    jsonSession = nullptr;
  engine_->finish();
}

int loadSchemas(driver::SchemaSelection &schemas, DiagnosticEngine &diags) {
  std::string error;
  if (schemas.load(diags, error))
    return kExitOk;
  if (error.empty())
    return kExitDiagnostics;
  printToolError(error);
  return kExitUsage;
}

void printToolError(const std::string &message) {
  std::cout.flush();
  if (jsonSession) {
    jsonSession->error(SourceLoc{}, message);
    return;
  }
  std::cerr << "stepnc: error: " << message << '\n';
}

void printStatus(const std::string &line) {
  if (jsonSession)
    return;
  std::cout.flush();
  std::cerr << "stepnc: " << line << '\n';
}

int checkOutput(std::string_view command, const std::string &input, const std::string &output) {
  if (output == "-")
    return kExitOk;
  std::error_code ec;
  if (std::filesystem::equivalent(input, output, ec)) {
    printToolError(std::string(command) + ": -o '" + output + "' is the input file " + input +
                   ", which would be replaced: give another output file");
    return kExitUsage;
  }
  std::string error;
  if (!OutputFile::writable(output, error)) {
    printToolError(error);
    return kExitUsage;
  }
  return kExitOk;
}

int writeText(const std::string &path, const std::string &text) {
  OutputFile out;
  std::string error;
  if (!out.open(path, error)) {
    printToolError(error);
    return kExitUsage;
  }
  out.write(text);
  if (!out.commit(error)) {
    printToolError(error);
    return kExitUsage;
  }
  return kExitOk;
}

bool isPart28Path(std::string_view path) {
  auto endsWith = [&](std::string_view suffix) {
    if (path.size() < suffix.size())
      return false;
    for (size_t i = 0; i < suffix.size(); ++i) {
      char c = path[path.size() - suffix.size() + i];
      if (c >= 'A' && c <= 'Z')
        c = static_cast<char>(c - 'A' + 'a');
      if (c != suffix[i])
        return false;
    }
    return true;
  };
  return endsWith(".stpx") || endsWith(".xml");
}

std::unique_ptr<SourceFile> openInput(const std::string &path) {
  std::string error;
  auto file = SourceFile::open(path, error);
  if (!file)
    printToolError(error);
  return file;
}

std::optional<Eigen::Vector3d> parseWorkOffset(const std::string &text) {
  Eigen::Vector3d v;
  size_t at = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = text.find(',', at);
    if ((k < 2) != (comma != std::string::npos))
      return std::nullopt;
    const std::string part = text.substr(at, k < 2 ? comma - at : std::string::npos);
    char *end = nullptr;
    v[k] = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(v[k]))
      return std::nullopt;
    at = comma + 1;
  }
  return v;
}

} // namespace stepnc::tool
