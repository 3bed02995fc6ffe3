// The kind table: what each IR node kind holds. Every kind is declared once,
// in ir/Kinds.def, which makes the `Kind` enum, the table that serves the
// printer (attribute order), the parser (what may appear), the verifier
// (required attributes, value types, allowed children) and the traits that
// passes and backends ask about (which process an operation belongs to,
// roughing or finishing, its canned-cycle family). Code compares kinds as
// enumerators and asks traits; the names are for the text form and messages.
#pragma once

#include <bitset>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepnc::ir {

enum class ValueType : uint8_t {
  Length,     ///< mm
  Angle,      ///< degrees
  Feed,       ///< mm/min
  Spindle,    ///< rev/min; negative = clockwise seen from the spindle (M3)
  Time,       ///< s
  Ratio,      ///< plain number, 0.5 = 50 %
  Count,      ///< integer
  Flag,       ///< true / false
  Word,       ///< an identifier from a fixed set (cutmode=climb)
  Text,       ///< a quoted string
  Ref,        ///< a symbol: %resource or @executable
  Point,      ///< (x,y,z) mm
  Direction,  ///< (x,y,z) unit vector
  Real,       ///< a plain number written exactly (shortest round trip); planned motion
  Reals,      ///< (a,b,...) plain numbers written exactly
  FeedPerRev, ///< mm/rev
  Power,      ///< W
  MassFlow,   ///< g/min (powder fed to a deposition head)
};

const char *valueTypeName(ValueType t);

enum class Sigil : uint8_t { None, Resource, Executable };  ///< none, '%', '@'

/// What role a kind plays; children lists and reference rules name categories.
enum class Category : uint8_t {
  Root,
  Resource,
  Executable,
  Feature,
  Island,
  Profile,
  Path,
  Curve,
  Point,
  Segment,
  Knot,
  Operation,
  Technology,
  Strategy,
  Toolpath,
  Move,
  Motion,
  MotionSegment,
  State,       ///< a change of process state among moves
  Branch,      ///< a branch of control flow (then, else, branch)
  Expression,  ///< a numeric or boolean expression
};

/// Facts about a kind that several layers need, declared with it in Kinds.def.
using Traits = uint32_t;
inline constexpr Traits NoTraits = 0;
namespace Trait {
// The process an operation belongs to.
inline constexpr Traits Milling = 1u << 0;
inline constexpr Traits HoleMaking = 1u << 1;  ///< drilling, reaming, boring, tapping, ... (ISO 14649-11 4.7)
inline constexpr Traits Turning = 1u << 2;     ///< ISO 14649-12/121 (also on turned features)
inline constexpr Traits Additive = 1u << 3;    ///< ISO 14649-17 deposition (also on added features)
// Milling operations.
inline constexpr Traits Roughing = 1u << 5;
inline constexpr Traits Finishing = 1u << 6;
inline constexpr Traits SideOnly = 1u << 7;       ///< side milling: walls, no floor
inline constexpr Traits FaceOperation = 1u << 8;  ///< plane milling: faces, stepped over the whole area
inline constexpr Traits WallFinishing = 1u << 9;  ///< finishes a wall (corner radius, deflection matter)
// Hole-making operations: the canned-cycle family of their moves.
inline constexpr Traits DrillCycle = 1u << 12;  ///< feed down, rapid out
inline constexpr Traits PeckCycle = 1u << 13;   ///< feed down in steps, out between them
inline constexpr Traits BoreCycle = 1u << 14;   ///< feed down, feed out
inline constexpr Traits TapCycle = 1u << 15;    ///< feed down, spindle reversed, feed out
inline constexpr Traits Chamfers = 1u << 16;    ///< the tool is wider than the hole (spot drill, countersink)
// Features.
inline constexpr Traits Pocket = 1u << 20;
inline constexpr Traits FaceFeature = 1u << 21;
// Strategies.
inline constexpr Traits PatternStrategy = 1u << 24;  ///< a motif along a guide strategy (trochoidal, plunge)
// Program structure.
inline constexpr Traits ControlFlow = 1u << 26;  ///< an executable whose course is decided when the program runs
inline constexpr Traits Boolean = 1u << 27;      ///< an expression whose value is true or false
} // namespace Trait

enum class Kind : uint8_t {
#define KIND(Id, ...) Id,
#include "ir/Kinds.def"
};

inline constexpr size_t kKindCount = 0
#define KIND(Id, ...) +1
#include "ir/Kinds.def"
    ;

struct AttrSpec {
  std::string_view name;
  ValueType type;
  bool required = false;
  /// For Word attributes: the allowed words, space separated (empty: any).
  std::string_view words = {};
};

struct KindSpec {
  Kind id;
  std::string_view name;  ///< in the text form and in messages
  Category category;
  Sigil sigil = Sigil::None;
  bool label = false;  ///< carries the STEP-NC id string
  Traits traits = NoTraits;
  /// Kinds or categories allowed as children, space separated (for messages).
  std::string_view children;
  std::vector<AttrSpec> attrs;
  /// `children` resolved: the kinds allowed, and the categories.
  std::bitset<kKindCount> childKinds;
  uint32_t childCategories = 0;

  bool is(Traits t) const { return (traits & t) == t; }
  bool isAny(Traits t) const { return (traits & t) != 0; }
};

/// The spec of `kind`.
const KindSpec &specOf(Kind kind);
/// The kind written `name` in the text form, if any.
std::optional<Kind> kindNamed(std::string_view name);
/// Every kind, in declaration order.
const std::vector<KindSpec> &allKinds();

inline std::string_view kindName(Kind k) { return specOf(k).name; }
inline Category categoryOf(Kind k) { return specOf(k).category; }
/// The name of a category as children lists write it ("operation", "motion_segment").
std::string_view categoryName(Category c);
/// True if `kind` has every trait in `t`.
inline bool hasTraits(Kind kind, Traits t) { return specOf(kind).is(t); }
inline bool isOperation(Kind k) { return categoryOf(k) == Category::Operation; }

/// True if a child of kind `child` may appear under a node of kind `parent`.
bool childAllowed(const KindSpec &parent, const KindSpec &child);
/// The spec of attribute `name` of `kind`, or null.
const AttrSpec *findAttr(const KindSpec &kind, std::string_view name);
/// The position of attribute `name` in `kind`'s spec, or SIZE_MAX.
size_t attrIndex(const KindSpec &kind, std::string_view name);

/// True if the space-separated `list` contains `word`.
bool inList(std::string_view list, std::string_view word);
/// "a, b or c" from the space-separated "a b c", for messages.
std::string joinWords(std::string_view list);

// Rules of the text form and the table, shared by the parser and the verifier.

/// Letters, digits and '_': what kinds, attribute names, words and symbol names are made of.
bool isNameChar(char c);
/// '%' for resources, '@' for executables, '\0' for kinds without a symbol.
char sigilChar(Sigil s);
/// True for a sigil ('%' or '@') followed by one or more letters, digits or '_'.
bool isSymbol(std::string_view s);
/// True if `word` may be the value of the Word attribute `a`: one of its words,
/// or any run of letters, digits and '_' when the table lists none.
bool wordAllowed(const AttrSpec &a, std::string_view word);
/// The children `parent` takes, for messages: "rawpiece, clamp or feature", or "no children".
std::string allowedChildren(const KindSpec &parent);

} // namespace stepnc::ir
