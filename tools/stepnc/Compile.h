// What the `compile` and `opt` commands share: opt is compile with a pass
// pipeline of the user's and the IR written out, so both read the same
// options and run the same steps (Compile.cpp).
#pragma once

#include "tools/stepnc/CommandLine.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::tool {

struct CompileOptions {
  std::string command = "compile";  ///< the command run: compile or opt, for messages
  std::string input;
  std::string output = "-";
  std::string emit;  ///< feature-ir, toolpath-ir, motion-ir or program; empty: program with --target, else feature-ir
  bool printLocations = false;
  // compile only: the controller target
  std::string target;
  std::string toolTable;
  bool noCycles = false;
  std::optional<double> tolerance;
  std::vector<std::string> targetOptions;
  bool listTargets = false;
  std::string machine;  ///< for motion-ir and the native target; bounds adapt-feed (the first of `machines`)
  std::vector<std::string> machines;  ///< compile's --machine, each given; several: a program per phase
  bool noAdaptFeed = false;
  bool noCompensateDeflection = false;
  std::string cuttingData;
  bool allowFeedIncrease = false;
  bool allowOutOfRange = false;
  /// --work-offset: where the workpiece's origin is on --machine (X,Y,Z, machine
  /// coordinates with every axis at 0): a rotary table turns each face to the tool.
  std::string workOffset;
  // opt only
  std::string passes;
  std::vector<std::string> printAfter;
  bool printAfterAll = false;
  bool verifyEach = false;
  bool listPasses = false;
  bool stats = false;
  /// Match the diagnostics against the expectations in the input's comments
  /// instead of printing them (docs/diagnostics.md).
  bool verifyDiagnostics = false;
  driver::SchemaOptions schema;
  UnitOptions units;
  DiagnosticOptions diag;
};

/// Reads the input, lowers it, runs the pipeline (--passes, else the one
/// --emit and --target need) and writes what --emit asks for. Returns the
/// exit code.
int runCompile(const CompileOptions &opts);

/// Options compile and opt share: output, locations, statistics, expected
/// diagnostics, schema, diagnostics.
void addCommonOptions(CLI::App &cmd, CompileOptions &opts);

} // namespace stepnc::tool
