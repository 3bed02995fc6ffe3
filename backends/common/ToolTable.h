// The shop's tool table: which pocket (T number) holds each STEP-NC tool and,
// optionally, its length offset. A plain text file, one tool per line
// (docs/tool-table.md):
//
//   # tool                     number  length (mm, optional)
//   "T2 ENDMILL D12 Z3"        12      85.000
//   %t3_endmill_d10_z4         7
//
// A tool is named by its STEP-NC id in double quotes or by its IR symbol.
#pragma once

#include "ir/Node.h"
#include "support/Diagnostics.h"
#include "support/SourceFile.h"

#include <optional>
#include <string>
#include <vector>

namespace stepnc::backends {

class ToolTable {
public:
  struct Entry {
    std::string key;  ///< the quoted id (without quotes) or the symbol (with '%')
    bool bySymbol = false;
    int number = 0;
    std::optional<double> length;
    SourceLoc loc;
  };

  /// Reads a table; reports each bad line (file:line:col) and returns nullopt
  /// when there was one.
  static std::optional<ToolTable> parse(const SourceFile &file, DiagnosticEngine &diags);

  /// The entry for a tool node, or null.
  const Entry *find(const ir::Node &tool) const;
  const std::string &name() const { return name_; }

private:
  std::string name_;
  std::vector<Entry> entries_;
};

} // namespace stepnc::backends
