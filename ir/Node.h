// The process IR: a tree of nodes with typed, unit-carrying attributes.
//
// Every level of the IR (feature, toolpath, motion) is made of the same Node:
// a kind ("workingstep", "closed_pocket", "tool", ...), an optional symbol
// (`%pocket1` for resources, `@ws_rough_pocket1` for executables), an optional
// label (the STEP-NC id string), attributes in the order the kind's spec gives
// them, and children. What a kind may hold is declared once, in the kind table
// (ir/Kinds.def): the printer, the parser and the verifier all read it, so a
// new kind (a turning feature, an additive operation) is one table entry.
//
// Units are part of the value type and fixed: lengths in mm, angles in
// degrees, feeds in mm/min, spindle speeds in rev/min, times in s. Lowering
// converts once; nothing downstream converts again.
#pragma once

#include "ir/Kinds.h"
#include "support/SourceFile.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::ir {

using Vec3 = Eigen::Vector3d;



struct Value {
  ValueType type = ValueType::Length;
  double number = 0;   ///< Length, Angle, Feed, Spindle, Time, Ratio, Real, FeedPerRev, Power, MassFlow
  int64_t count = 0;   ///< Count
  bool flag = false;   ///< Flag
  std::string text;    ///< Word, Text, Ref (with its sigil)
  Vec3 vec = Vec3::Zero();  ///< Point, Direction
  std::vector<double> numbers;  ///< Reals

  static Value length(double mm) { return makeNumber(ValueType::Length, mm); }
  static Value angle(double deg) { return makeNumber(ValueType::Angle, deg); }
  static Value feed(double mmPerMin) { return makeNumber(ValueType::Feed, mmPerMin); }
  static Value spindle(double revPerMin) { return makeNumber(ValueType::Spindle, revPerMin); }
  static Value time(double s) { return makeNumber(ValueType::Time, s); }
  static Value ratio(double r) { return makeNumber(ValueType::Ratio, r); }
  static Value feedPerRev(double mmPerRev) { return makeNumber(ValueType::FeedPerRev, mmPerRev); }
  static Value power(double watts) { return makeNumber(ValueType::Power, watts); }
  static Value massFlow(double gPerMin) { return makeNumber(ValueType::MassFlow, gPerMin); }
  static Value integer(int64_t n);
  static Value boolean(bool b);
  static Value word(std::string w);
  static Value string(std::string s);
  static Value ref(std::string symbol);
  static Value point(const Vec3 &p);
  static Value direction(const Vec3 &d);
  static Value real(double v) { return makeNumber(ValueType::Real, v); }
  static Value reals(std::vector<double> v);

  bool operator==(const Value &o) const;

private:
  static Value makeNumber(ValueType t, double v);
};

struct Attr {
  std::string name;
  Value value;
};

/// Where a node came from: the STEP-NC instance and its place in the file.
struct Origin {
  uint64_t entityId = 0;
  SourceLoc loc;
};

struct Node {
  Kind kind = Kind::Project;
  std::string symbol;  ///< with its sigil ('%' or '@'), or empty
  std::string label;   ///< the STEP-NC id string, or empty
  std::vector<Attr> attrs;
  std::vector<Node> children;
  Origin origin;
  /// Facts derived by passes, printed as a trailing comment, never parsed as data.
  std::string comment;

  explicit Node(Kind k = Kind::Project) : kind(k) {}

  const KindSpec &spec() const { return specOf(kind); }
  /// The kind as the text form writes it, for messages.
  std::string kindName() const { return std::string(specOf(kind).name); }
  Category category() const { return specOf(kind).category; }
  /// True if the node's kind has every trait in `t` (ir/Kinds.h).
  bool is(Traits t) const { return specOf(kind).is(t); }

  /// Adds or replaces an attribute, keeping the kind table's attribute order.
  /// Setting an attribute the kind does not declare is a bug in the caller:
  /// it stops the program with an internal error instead of writing a value
  /// that nothing would read.
  Node &set(std::string name, Value v);
  const Value *get(std::string_view name) const;
  bool has(std::string_view name) const { return get(name) != nullptr; }
  /// Typed reads; empty when absent (the verifier checks types against the kind table).
  std::optional<double> number(std::string_view name) const;
  std::optional<int64_t> count(std::string_view name) const;
  std::optional<bool> flag(std::string_view name) const;
  std::optional<std::string> text(std::string_view name) const;  ///< Word, Text or Ref
  std::optional<Vec3> vec(std::string_view name) const;

  Node &add(Node child) {
    children.push_back(std::move(child));
    return children.back();
  }
  /// Children of one kind, in order.
  std::vector<const Node *> childrenOf(Kind k) const;
  const Node *child(Kind k) const;
  /// The first child of a category (a workingstep's operation, a feature's profile), or null.
  const Node *childIn(Category c) const;
};

/// A whole program: the root node (`project`) and the file it came from.
/// How lowering read the source file's implicit units (ISO 14649 leaves the
/// unit of speed_measure and rot_speed_measure to the file): the factors to
/// the IR's mm/min and rev/min. What writes values back into the file (the
/// machine-optimised STEP-NC) writes them in the file's own units.
struct SourceUnits {
  double feedToMmPerMin = 60000;      ///< a technology's feedrate (m/s)
  double cutspeedToMmPerMin = 60000;  ///< its cutspeed (m/s)
  double spindleToRevPerMin = 60;     ///< its spindle (rev/s)
};

/// A value the reading of the source file assumed, as the Part 21 text that
/// says it explicitly: parameter `parameter` (0-based) of instance
/// `entityId`, or with `parameter` -1 its entity name (an alias read as the
/// schema's entity). The machine-optimised STEP-NC writes them, so that the
/// file it writes needs none of these assumptions. `#@k` in `text` refers to
/// the Module's new source instance k.
struct SourceFix {
  uint64_t entityId = 0;
  int parameter = 0;
  std::string text;
};

struct Module {
  Node root{Kind::Project};
  std::string sourceName;
  /// The AP238 AIM schema the source was read through (lower case), empty
  /// for an ISO 14649 ARM file or IR text. Not part of the IR text.
  std::string aimSchema;
  /// Set by lowering; not part of the IR text (IR read from text has the
  /// standard's units).
  SourceUnits sourceUnits;
  /// Set by binding and lowering, in the order met; not part of the IR text.
  std::vector<SourceFix> sourceFixes;
  /// Instances a fix needs that the source file lacks, as Part 21 text
  /// `ENTITY(parameters)` (a depth plane, a cutting component): `#@k` in a
  /// fix or in a later one of these refers to the k-th. Not part of the IR text.
  std::vector<std::string> sourceInstances;
};

/// Structural equality (kinds, symbols, labels, attributes, children; not origins).
bool equal(const Node &a, const Node &b);

/// Passes that report figures in a node's comment keep them as parts joined
/// by "; ": this drops the parts that start with any of `prefixes` (a
/// pass's figures from an earlier run) and appends `text`, keeping the rest.
void replaceCommentPart(Node &node, std::initializer_list<std::string_view> prefixes, std::string_view text);

} // namespace stepnc::ir
