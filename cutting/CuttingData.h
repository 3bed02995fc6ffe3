// Cutting data the STEP-NC file does not carry: the cutting-force
// coefficients and recommended chip thickness of workpiece materials, the
// stiffness and strength of tool materials, and per-tool values (overhang,
// material). A file ships with stepnc (cutting/materials.toml, built in);
// a user file in the same format (`adapt-feed<data=FILE>`) replaces its
// values key by key and may describe tools. docs/cutting-data.md.
#pragma once

#include "cutting/Mechanics.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stepnc::cutting {

struct Material {
  std::string key;  ///< "steel_1045"
  std::string name; ///< "Carbon steel C45 / AISI 1045"
  std::vector<std::string> aliases;
  std::string group;          ///< ISO 513: P, M, K, N, S, H
  double ktc = 0, krc = 0;    ///< N/mm^2
  double kte = 0, kre = 0;    ///< N/mm
  double chipThickness = 0.1; ///< mm, the target maximum chip thickness h*
  double cuttingSpeed = 0;    ///< m/min, typical for coated carbide; 0: not known
  std::string source;

  CuttingCoefficients coefficients() const { return {ktc, krc, kte, kre}; }
};

struct ToolMaterial {
  std::string key;            ///< "carbide", "hss", ...
  double modulus = 600000;    ///< N/mm^2
  double allowedStress = 800; ///< N/mm^2 at the clamp
};

/// What a user file says about one tool (by its IR symbol, without '%').
struct ToolData {
  std::optional<std::string> material; ///< a tool material key
  std::optional<double> overhang;      ///< mm, clamp to tip
  std::optional<double> fluteLength;   ///< mm
  std::optional<double> maxForce;      ///< N
};

struct CuttingData {
  std::map<std::string, Material> materials;
  std::map<std::string, ToolMaterial> toolMaterials;
  std::string defaultMaterial;
  std::map<std::string, ToolData> tools;
  /// Where the values were read from (for reports): "shipped", or file names.
  std::vector<std::string> sources;

  /// The material a workpiece names: the one with the longest key or alias
  /// found in the identifier or the standard, compared upper-case with
  /// spaces, dashes, dots and underscores removed (aliases of three
  /// characters or fewer must be the whole text); materials whose key starts
  /// with "generic_" only when no other matches; else null.
  /// `matched` receives the alias that matched.
  const Material *match(const std::string &identifier, const std::string &standard, std::string &matched) const;
};

/// Reads a cutting-data file on top of `base` (values replace base values
/// key by key). Reports every problem at its place in the file.
std::optional<CuttingData> readCuttingData(const SourceFile &file, CuttingData base, DiagnosticEngine &diags);

/// The data shipped with stepnc.
const CuttingData &shippedCuttingData();

/// The shipped data with the user file `path` (if not empty) on top. `file`
/// keeps the text diagnostics point into.
std::optional<CuttingData> loadCuttingData(const std::string &path, std::unique_ptr<SourceFile> &file,
                                           DiagnosticEngine &diags);

} // namespace stepnc::cutting
