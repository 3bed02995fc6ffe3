// The shop's tool table: which pocket (T number) holds each STEP-NC tool and,
// optionally, its length offset. A plain text file, one tool per line
// (docs/tool-table.md):
//
//   # tool                     number  length (mm, optional)  holder geometry (optional)
//   "T2 ENDMILL D12 Z3"        12      85.000                 holder=40 stickout=35
//   %t3_endmill_d10_z4         7
//
// `holder=D` (the holder's diameter) and `stickout=L` (from the tool's tip to
// the holder's face) go onto the tool before its toolpaths are verified
// (applyGeometry): the reach check walks the holder's disc from there.
//
// A tool is named by its STEP-NC id in double quotes or by its IR symbol.
//
// LinuxCNC's own tool table (tool.tbl) is read too, told apart by its first
// word (`T<number>`): one pocket per line, words T (number), P (pocket), D
// (diameter), X..W (offsets, Z the length) and the rest of the line after
// ';' a comment. Its values are read in mm. It names no STEP-NC tool but by
// its comments, so its tools are matched by number, or by a comment that is
// the tool's STEP-NC id (docs/tool-table.md).
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
  enum class Format { Stepnc, LinuxCnc };

  struct Entry {
    std::string key;  ///< the quoted id (without quotes) or the symbol (with '%'); LinuxCNC: the comment
    bool bySymbol = false;
    int number = 0;
    std::optional<double> length;    ///< mm (LinuxCNC: the Z offset)
    std::optional<double> diameter;  ///< mm (LinuxCNC's D)
    std::optional<double> holderDiameter;  ///< mm, `holder=`
    std::optional<double> stickout;        ///< mm, `stickout=`: from the tip to the holder's face
    SourceLoc loc;
    SourceLoc diameterLoc;  ///< where the D word is (LinuxCNC)
  };

  /// Reads a table; reports each bad line (file:line:col) and returns nullopt
  /// when there was one.
  static std::optional<ToolTable> parse(const SourceFile &file, DiagnosticEngine &diags);

  /// The entry for a tool node, or null: by id or symbol; in a LinuxCNC
  /// table, the entry whose comment is the tool's STEP-NC id.
  const Entry *find(const ir::Node &tool) const;
  /// Puts the table's holder geometry onto the module's tools: `holder=`
  /// as holder_diameter, `stickout=` as overall_length (replacing the
  /// file's). Tools the table does not list keep theirs.
  void applyGeometry(ir::Module &module) const;
  /// The entry for tool number `number`, or null.
  const Entry *findNumber(int number) const;
  const std::string &name() const { return name_; }
  Format format() const { return format_; }
  const std::vector<Entry> &entries() const { return entries_; }

private:
  /// One line of a LinuxCNC table, `line` without its comment; false after
  /// reporting an error.
  bool parseLinuxCncLine(const SourceFile &file, size_t lineStart, std::string_view line, std::string_view comment,
                         DiagnosticEngine &diags);

  std::string name_;
  Format format_ = Format::Stepnc;
  std::vector<Entry> entries_;
};

} // namespace stepnc::backends
