// Verifies a module in two walks over the tree: the first collects the symbols
// (reporting duplicates), the second checks each node against its kind's spec,
// its values, its references (which need every symbol) and its children. The
// few rules the kind table cannot express (which kind a reference must name,
// which children an operation has at most one of) are tables here.
#include "ir/Verifier.h"
#include "ir/Plausible.h"

#include "ir/Printer.h"
#include "support/Format.h"

#include <algorithm>
#include <iterator>
#include <cmath>
#include <unordered_map>
#include <vector>

namespace stepnc::ir {

namespace {

/// A kind, or any kind of a category.
struct KindOrCategory {
  constexpr KindOrCategory(Kind k) : kind(k), isCategory(false) {}
  constexpr KindOrCategory(Category c) : category(c), isCategory(true) {}
  bool matches(const KindSpec &k) const { return isCategory ? k.category == category : k.id == kind; }
  std::string_view name() const { return isCategory ? categoryName(category) : kindName(kind); }
  Kind kind = Kind::Project;
  Category category = Category::Root;
  bool isCategory;
};

/// A reference attribute whose target must be a node of a given kind or category.
struct RefRule {
  KindOrCategory owner;  ///< the node holding the attribute
  std::string_view attr;
  KindOrCategory target;  ///< the node referred to
};

const RefRule kRefRules[] = {
    {Category::Operation, "tool", Kind::Tool},
    {Kind::Workingstep, "feature", Category::Feature},
    {Kind::WorkpieceSetup, "workpiece", Kind::Workpiece},
    {Kind::Workplan, "setup", Kind::Setup},
    {Kind::Workingstep, "setup", Kind::Setup},
    {Kind::Island, "feature", Kind::Boss},
    {Kind::Moves, "tool", Kind::Tool},
    {Kind::Moves, "setup", Kind::Setup},
    {Kind::Assignment, "variable", Kind::NcVariable},
    {Kind::Read, "variable", Kind::NcVariable},
};

/// Children an operation has at most one of; the kinds of one entry count together.
const std::vector<Kind> kAtMostOnePerOperation[] = {
    {Kind::Technology},
    {Kind::MachineFunctions},
    {Kind::Strategy, Kind::DrillingStrategy, Kind::TrochoidalStrategy, Kind::PlungeStrategy},
    {Kind::Approach},
    {Kind::Retract},
};

constexpr double kUnitTolerance = 1e-6;

/// True if `word` is one of the space-separated words of `list`.
bool isRadius(std::string_view name) { return name == "radius" || name.ends_with("_radius"); }

/// Lengths that must be positive; radii may also be 0.
bool isDimension(std::string_view name) {
  return isRadius(name) || name == "depth" || name == "diameter" || name == "width" || name == "length" ||
         name == "pitch" || name == "travel" || name == "step" || name == "radial_step" || name == "holder_diameter" ||
         name == "overall_length" || name == "cutting_edge_length";
}

bool isNumber(ValueType t) {
  return t == ValueType::Length || t == ValueType::Angle || t == ValueType::Feed || t == ValueType::Spindle ||
         t == ValueType::Time || t == ValueType::Ratio || t == ValueType::Real || t == ValueType::FeedPerRev ||
         t == ValueType::Power || t == ValueType::MassFlow;
}

std::string quoted(std::string_view s) {
  std::string out = "'";
  out += s;
  return out + "'";
}

std::string attribute(std::string_view name) { return "attribute " + quoted(name); }

std::string printed(const Value &v) {
  std::string out;
  printValue(v, out);
  return out;
}

/// How messages name a node: its kind and its symbol, or its label when it has no symbol.
std::string nameOf(const Node &n) {
  std::string out(n.kindName());
  if (!n.symbol.empty())
    return out + " " + n.symbol;
  if (!n.label.empty())
    return out + " \"" + n.label + "\"";
  return out;
}

class Verifier {
public:
  explicit Verifier(DiagnosticEngine &diags) : diags_(diags) {}

  bool run(const Module &m) {
    collectSymbols(m.root);
    if (m.root.kind != Kind::Project)
      report(m.root, "expected the root node 'project', found " + quoted(m.root.kindName()));
    checkNode(m.root, nullptr, true);
    return errors_ == 0;
  }

private:
  void collectSymbols(const Node &n);
  /// `parent` is null for the root.
  void checkNode(const Node &n, const KindSpec *parent, bool isRoot);
  void checkPlace(const Node &n, const KindSpec &spec, const KindSpec *parent);
  void checkHead(const Node &n, const KindSpec &spec);
  void checkAttrs(const Node &n, const KindSpec &spec);
  void checkValue(const Node &n, const Attr &a);
  void checkRef(const Node &n, const KindSpec &spec, const Attr &a);
  void checkChildren(const Node &n, const KindSpec &spec);
  void checkFlow(const Node &n, const KindSpec &spec);
  void checkCycle(const Node &cycle);
  void checkToolFit(const Node &workingstep);
  const Node *lookup(const std::optional<std::string> &symbol) const;
  InFlightDiagnostic report(const Node &n, const std::string &message);

  DiagnosticEngine &diags_;
  std::unordered_map<std::string_view, const Node *> symbols_;
  std::vector<const Node *> enclosing_;  ///< the nodes checkNode is inside, outermost first
  unsigned errors_ = 0;
};

InFlightDiagnostic Verifier::report(const Node &n, const std::string &message) {
  ++errors_;
  // A node made without a place of its own (a technology lowering built
  // from several instances) is reported where its nearest placed
  // enclosing node is.
  const Origin *origin = &n.origin;
  for (auto it = enclosing_.rbegin(); !origin->loc.valid() && it != enclosing_.rend(); ++it)
    origin = &(*it)->origin;
  InFlightDiagnostic d = diags_.error(origin->loc, nameOf(n) + ": " + message);
  if (origin->entityId != 0)
    d.entity(origin->entityId);
  return d;
}

const Node *Verifier::lookup(const std::optional<std::string> &symbol) const {
  if (!symbol)
    return nullptr;
  auto it = symbols_.find(*symbol);
  return it == symbols_.end() ? nullptr : it->second;
}

// Where it is decidable from the feature IR alone, the tool must fit the
// feature: a finishing cutter must reach into a pocket's corners (its radius
// no larger than the corner radius), and a tool that makes a hole must not be
// wider than the hole. Roughing tools may be larger than the corners: they
// leave that material for finishing, which strategy expansion accounts for.
void Verifier::checkToolFit(const Node &ws) {
  const Node *feature = lookup(ws.text("feature"));
  const Node *op = nullptr;
  for (const Node &c : ws.children)
    if (isOperation(c.kind))
      op = &c;
  const Node *tool = op ? lookup(op->text("tool")) : nullptr;
  const std::optional<double> toolDiameter = tool ? tool->number("diameter") : std::nullopt;
  if (!feature || !toolDiameter)
    return;
  constexpr double eps = 1e-9;
  if (op->is(Trait::WallFinishing) && feature->is(Trait::Pocket)) {
    const std::optional<double> corner = feature->number("orthogonal_radius");
    if (corner && *corner > 0 && *toolDiameter / 2 > *corner + eps)
      report(*op, "tool " + tool->symbol + " of diameter " + formatFixed(*toolDiameter, 4) +
                      " mm does not fit the corners of " + feature->symbol + " (corner radius " +
                      formatFixed(*corner, 4) + " mm)");
  }
  // Spot drills and countersinks chamfer the hole: they are wider than it.
  if (feature->kind == Kind::RoundHole && op->is(Trait::HoleMaking) && !op->is(Trait::Chamfers)) {
    const std::optional<double> hole = feature->number("diameter");
    if (hole && *toolDiameter > *hole + eps)
      report(*op, "tool " + tool->symbol + " of diameter " + formatFixed(*toolDiameter, 4) +
                      " mm is wider than " + feature->symbol + " (diameter " + formatFixed(*hole, 4) + " mm)");
  }
}

void Verifier::collectSymbols(const Node &n) {
  if (!n.symbol.empty()) {
    auto [first, inserted] = symbols_.emplace(n.symbol, &n);
    if (!inserted)
      report(n, "symbol " + quoted(n.symbol) + " is defined twice")
          .note(first->second->origin.loc, "first defined by " + nameOf(*first->second));
  }
  for (const Node &c : n.children)
    collectSymbols(c);
}

void Verifier::checkNode(const Node &n, const KindSpec *parent, bool isRoot) {
  const KindSpec &spec = n.spec();
  if (!isRoot)
    checkPlace(n, spec, parent);
  checkHead(n, spec);
  checkAttrs(n, spec);
  checkChildren(n, spec);
  if (n.kind == Kind::Workingstep)
    checkToolFit(n);
  if (n.comment.find('\n') != std::string::npos)
    report(n, "the comment has a line break, expected one line");
  enclosing_.push_back(&n);
  for (const Node &c : n.children)
    checkNode(c, &spec, false);
  enclosing_.pop_back();
}

/// Below the root: never `project`, other kinds only where their parent's spec allows them.
void Verifier::checkPlace(const Node &n, const KindSpec &spec, const KindSpec *parent) {
  if (spec.id == Kind::Project)
    report(n, "'project' is only allowed as the root node");
  else if (parent && !childAllowed(*parent, spec))
    report(n, "not allowed under " + quoted(parent->name) + ", which takes " + allowedChildren(*parent));
}

/// The symbol, the label and the comment.
void Verifier::checkHead(const Node &n, const KindSpec &spec) {
  const char sigil = sigilChar(spec.sigil);
  if (!sigil && !n.symbol.empty())
    report(n, "takes no symbol, found " + quoted(n.symbol));
  else if (sigil && n.symbol.empty())
    report(n, std::string("missing its '") + sigil + "' symbol");
  else if (sigil && n.symbol[0] != sigil)
    report(n, std::string("expected a '") + sigil + "' symbol, found " + quoted(n.symbol));
  else if (sigil && !isSymbol(n.symbol))
    report(n, "symbol " + quoted(n.symbol) + " is not a sigil followed by letters, digits or '_'");
  if (!spec.label && !n.label.empty())
    report(n, "takes no label");
}

void Verifier::checkAttrs(const Node &n, const KindSpec &spec) {
  for (const AttrSpec &a : spec.attrs)
    if (a.required && !n.has(a.name))
      report(n, "missing required attribute " + quoted(a.name));
  for (auto it = n.attrs.begin(); it != n.attrs.end(); ++it) {
    const AttrSpec *a = findAttr(spec, it->name);
    if (std::any_of(n.attrs.begin(), it, [&](const Attr &earlier) { return earlier.name == it->name; }))
      report(n, attribute(it->name) + " is given twice");
    else if (!a)
      report(n, "unknown " + attribute(it->name) + " for " + quoted(spec.name));
    else if (it->value.type != a->type)
      report(n, attribute(it->name) + " is " + describeValue(*a) + ", found a value of type " +
                    valueTypeName(it->value.type));
    else if (a->type == ValueType::Word && !wordAllowed(*a, it->value.text))
      report(n, attribute(it->name) + " is " + describeValue(*a) + ", found " + quoted(it->value.text));
    else if (a->type == ValueType::Ref)
      checkRef(n, spec, *it);
    else
      checkValue(n, *it);
  }
}

namespace {

/// The largest magnitude a value of type `t` may have (ir/Plausible.h);
/// none for counts, words and unit-less numbers.
std::optional<double> magnitudeBound(ValueType t) {
  switch (t) {
  case ValueType::Length:
  case ValueType::Point: return kMaxLengthMm;
  case ValueType::Angle: return kMaxAngleDeg;
  case ValueType::Time: return kMaxTimeS;
  case ValueType::Feed:
  case ValueType::Spindle:
  case ValueType::Power:
  case ValueType::MassFlow: return kMaxRate;
  default: return std::nullopt;
  }
}

std::string_view unitOf(ValueType t) {
  switch (t) {
  case ValueType::Angle: return "deg";
  case ValueType::Time: return "s";
  case ValueType::Feed: return "mm/min";
  case ValueType::Spindle: return "rev/min";
  case ValueType::Power: return "W";
  case ValueType::MassFlow: return "g/min";
  default: return "mm";
  }
}

} // namespace

/// Numbers finite and within what a machine does, directions of unit
/// length, dimensions positive.
void Verifier::checkValue(const Node &n, const Attr &a) {
  const Value &v = a.value;
  auto attr = [&] { return attribute(a.name); };
  if (isNumber(v.type) && !std::isfinite(v.number))
    report(n, attr() + " must be a finite number, found " + formatShortest(v.number));
  else if (const std::optional<double> beyond = beyondMachine(v)) {
    const std::string unit(unitOf(v.type));
    report(n, attr() + (v.type == ValueType::Point ? std::string(" has the coordinate ") : std::string(" is ")) +
                  formatShortest(*beyond) + " " + unit + ", beyond what a machine tool does (at most " +
                  formatShortest(*magnitudeBound(v.type)) + " " + unit + " either way)");
  }
  else if (v.type == ValueType::Time && (n.kind == Kind::Dwell || a.name.starts_with("dwell")) && v.number > 0 &&
           v.number < kMinDwellS)
    report(n, attr() + " is " + formatShortest(v.number) + " s, shorter than a controller dwells (" +
                  formatShortest(kMinDwellS) + " s): give 0 for none");
  else if (v.type == ValueType::Length && isDimension(a.name) && (isRadius(a.name) ? v.number < 0 : v.number <= 0))
    report(n, attr() + (isRadius(a.name) ? " must not be negative" : " must be positive") + ", found " + printed(v));
  else if (v.type == ValueType::Reals &&
           !std::all_of(v.numbers.begin(), v.numbers.end(), [](double x) { return std::isfinite(x); }))
    report(n, attr() + " must hold finite numbers");
  else if (v.type == ValueType::Point && !v.vec.allFinite())
    report(n, attr() + " must have finite coordinates");
  else if (v.type == ValueType::Direction && !(std::abs(v.vec.norm() - 1) <= kUnitTolerance))
    report(n, attr() + " must be a unit vector, found length " + formatFixed(v.vec.norm(), 6));
  // An approach or retract angle is a slope: a ramp or helix at 0 deg never
  // gets down, one past 90 deg goes the wrong way.
  else if ((n.kind == Kind::Approach || n.kind == Kind::Retract) && a.name == "angle" &&
           !(v.number > 0 && v.number <= 90))
    report(n, attr() + " must be a slope, more than 0 and at most 90 deg, found " + printed(v));
  else if ((v.type == ValueType::FeedPerRev || (n.kind == Kind::Dwell && a.name == "time")) && v.number <= 0)
    report(n, attr() + " must be positive, found " + printed(v));
  // (A state's spindle speed keeps its sign: negative is clockwise, as everywhere.)
  else if ((v.type == ValueType::Power || v.type == ValueType::MassFlow ||
            (n.kind == Kind::State && v.type == ValueType::Feed)) &&
           v.number < 0)
    report(n, attr() + " must not be negative, found " + printed(v));
}

/// The reference resolves, and names the kind its rule asks for.
void Verifier::checkRef(const Node &n, const KindSpec &spec, const Attr &a) {
  auto found = symbols_.find(a.value.text);
  if (found == symbols_.end()) {
    report(n, attribute(a.name) + " refers to " + quoted(a.value.text) + ", which is not defined");
    return;
  }
  const Node &target = *found->second;
  for (const RefRule &rule : kRefRules)
    if (rule.attr == a.name && rule.owner.matches(spec) && !rule.target.matches(target.spec()))
      report(n, attribute(a.name) + " refers to " + quoted(a.value.text) + ", a " + std::string(target.kindName()) +
                    ", expected a " + std::string(rule.target.name()));
}

/// A workingstep has exactly one operation; an operation at most one of each of kAtMostOnePerOperation.
void Verifier::checkChildren(const Node &n, const KindSpec &spec) {
  auto count = [&](auto matches) { return std::count_if(n.children.begin(), n.children.end(), matches); };
  if (spec.id == Kind::Workingstep) {
    auto operations = count([](const Node &c) { return isOperation(c.kind); });
    if (operations != 1)
      report(n, "expected exactly one operation, found " + std::to_string(operations));
  }
  if (spec.category == Category::Executable) {
    auto moves = count([](const Node &c) { return c.kind == Kind::Moves; });
    if (moves > 1)
      report(n, "expected at most one 'moves', found " + std::to_string(moves));
  }
  if (spec.category == Category::Move && spec.id != Kind::Rapid && spec.id != Kind::Dwell &&
      n.has("feed") == n.has("feed_per_rev"))
    report(n, n.has("feed") ? "has both 'feed' and 'feed_per_rev', expected one"
                            : "missing its feed: expected 'feed' (mm/min) or 'feed_per_rev' (mm/rev)");
  if (spec.id == Kind::State && n.attrs.empty())
    report(n, "changes nothing: expected at least one attribute");
  checkFlow(n, spec);
  if (spec.id == Kind::Cycle)
    checkCycle(n);
  if (spec.is(Trait::PatternStrategy)) {
    auto guides = count([](const Node &c) { return c.kind == Kind::Strategy; });
    if (guides != 1)
      report(n, "expected exactly one guide 'strategy', found " + std::to_string(guides));
  }
  if (spec.category != Category::Operation)
    return;
  for (const std::vector<Kind> &kinds : kAtMostOnePerOperation) {
    auto found = count([&](const Node &c) { return std::find(kinds.begin(), kinds.end(), c.kind) != kinds.end(); });
    if (found > 1) {
      std::string names;
      for (Kind k : kinds) {
        if (!names.empty())
          names += ' ';
        names += kindName(k);
      }
      report(n, "expected at most one " + joinWords(names) + ", found " + std::to_string(found));
    }
  }
}

/// A canned cycle says what its moves do: they stay on its axis, reach its
/// bottom and no lower; its pecks go down to the bottom; a feed out is
/// given for the families that feed out; reduced feeds come with their
/// depths; the feeds and times are positive.
void Verifier::checkCycle(const Node &cycle) {
  constexpr double kSame = 1e-6;
  const std::optional<Vec3> at = cycle.vec("at");
  const std::optional<double> clearance = cycle.number("clearance"), bottom = cycle.number("bottom");
  if (!at || !clearance || !bottom)
    return;  // reported as missing attributes
  if (*bottom >= *clearance)
    report(cycle, "its bottom (z=" + formatShortest(*bottom) + ") is not below its clearance height (z=" +
                      formatShortest(*clearance) + ")");
  std::optional<double> lowest;
  for (const Node &m : cycle.children)
    if (std::optional<Vec3> to = m.vec("to")) {
      if ((to->head<2>() - at->head<2>()).norm() > kSame) {
        report(m, "leaves its cycle's axis: (" + formatShortest(to->x()) + "," + formatShortest(to->y()) +
                      ") is not the cycle's position (" + formatShortest(at->x()) + "," + formatShortest(at->y()) + ")");
        return;
      }
      lowest = std::min(lowest.value_or(to->z()), to->z());
    }
  if (lowest && std::abs(*lowest - *bottom) > kSame)
    report(cycle, "its moves reach z=" + formatShortest(*lowest) + ", not its bottom (z=" + formatShortest(*bottom) + ")");
  if (const Value *pecks = cycle.get("pecks")) {
    const std::vector<double> &z = pecks->numbers;
    if (z.empty() || std::abs(z.back() - *bottom) > kSame || !std::is_sorted(z.rbegin(), z.rend()) ||
        std::adjacent_find(z.begin(), z.end()) != z.end())
      report(cycle, "its pecks must go down, each deeper than the last, to its bottom");
  }
  const bool feedsOut = cycle.text("type") == "bore" || cycle.text("type") == "tap";
  if (feedsOut != cycle.has("feed_out"))
    report(cycle, feedsOut ? "a " + *cycle.text("type") + " cycle feeds out: expected 'feed_out'"
                           : "a " + cycle.text("type").value_or("") + " cycle leaves at rapid: 'feed_out' is not taken");
  for (auto [feed, depth] : {std::pair{"start_feed", "start_depth"}, std::pair{"end_feed", "end_depth"}}) {
    if (cycle.has(feed) != cycle.has(depth))
      report(cycle, attribute(feed) + " and " + attribute(depth) + " go together");
    if (cycle.number(depth).value_or(1) <= 0)
      report(cycle, attribute(depth) + " must be positive");
  }
  for (const char *a : {"feed", "feed_out", "start_feed", "end_feed", "dwell", "dwell_step", "reapproach"})
    if (cycle.number(a).value_or(1) <= 0)
      report(cycle, attribute(a) + " must be positive, found " + formatShortest(*cycle.number(a)));
}

/// Control flow and expressions: a condition first where one is taken, the
/// branches each kind needs, and expressions of the right arity and type.
void Verifier::checkFlow(const Node &n, const KindSpec &spec) {
  auto count = [&](auto matches) { return std::count_if(n.children.begin(), n.children.end(), matches); };
  const auto expressions = count([](const Node &c) { return c.category() == Category::Expression; });
  auto expectCondition = [&](bool boolean) {
    const char *what = boolean ? "a boolean condition" : "a numeric expression";
    if (expressions != 1)
      report(n, std::string("expected one expression, ") + what + ", found " + std::to_string(expressions));
    else if (n.children.front().category() != Category::Expression)
      report(n, std::string("expected ") + what + " as its first child");
    else if (n.children.front().is(Trait::Boolean) != boolean)
      report(n, std::string("expected ") + what + ", found " + quoted(n.children.front().kindName()));
  };
  auto expectOperands = [&](size_t least, size_t most, bool boolean) {
    const size_t found = n.children.size();
    const std::string amount = least == most ? std::to_string(least) : std::to_string(least) + " or more";
    if (found < least || found > most)
      report(n, "expected " + amount + (boolean ? " boolean" : " numeric") + " operand" + (most == 1 ? "" : "s") +
                    ", found " + std::to_string(found));
    for (const Node &c : n.children)
      if (c.is(Trait::Boolean) != boolean)
        report(n, std::string("expected ") + (boolean ? "boolean" : "numeric") + " operands, found " +
                      quoted(c.kindName()));
  };
  switch (spec.id) {
  case Kind::If: {
    expectCondition(true);
    const auto thens = count([](const Node &c) { return c.kind == Kind::Then; });
    const auto elses = count([](const Node &c) { return c.kind == Kind::Else; });
    if (thens != 1 || elses > 1)
      report(n, "expected one 'then' and at most one 'else', found " + std::to_string(thens) + " and " +
                    std::to_string(elses));
    break;
  }
  case Kind::While: expectCondition(true); break;
  case Kind::Assignment: expectCondition(false); break;
  case Kind::Parallel:
  case Kind::Selective: {
    const auto branches = count([](const Node &c) { return c.kind == Kind::Branch; });
    if (branches < 2)
      report(n, "expected two or more 'branch'es, found " + std::to_string(branches));
    break;
  }
  case Kind::Arith:
  case Kind::Compare: expectOperands(2, 2, false); break;
  case Kind::Logic: expectOperands(2, SIZE_MAX, true); break;
  case Kind::Not: expectOperands(1, 1, true); break;
  default: break;
  }
}

} // namespace

bool verifyModule(const Module &m, DiagnosticEngine &diags) { return Verifier(diags).run(m); }

std::optional<double> beyondMachine(const Value &v) {
  const std::optional<double> bound = magnitudeBound(v.type);
  if (!bound)
    return std::nullopt;
  if (v.type == ValueType::Point) {
    Eigen::Index at = 0;
    return v.vec.cwiseAbs().maxCoeff(&at) > *bound ? std::optional(v.vec[at]) : std::nullopt;
  }
  return std::abs(v.number) > *bound ? std::optional(v.number) : std::nullopt;
}

} // namespace stepnc::ir
