// Machine-optimised STEP-NC (see OptimisedFile.h): the input's canonical Part
// 21 text, one line per instance, patched line by line (FILE_DESCRIPTION, the
// operations that get a toolpath) with the new instances appended to the last
// DATA section.
//
// Values must read back bit for bit, so that lowering the written file makes
// the same moves: points are written in the feature's frame as the local
// coordinates whose mapping back gives the workpiece coordinates exactly (a
// few units in the last place are searched; exact for frames along the axes),
// and feeds and spindle speeds as the speed measures whose conversion by
// lowering gives them exactly (the canonical writer writes shortest
// round-trip reals).
#include "backends/step-nc/OptimisedFile.h"

#include "backends/step-nc/ArmFromIr.h"
#include "backends/step-nc/Toolpaths.h"

#include "frontend/part21/Writer.h"
#include "ir/Kinds.h"
#include "ir/Program.h"
#include "ir/geom/FeatureShape.h"
#include "ir/geom/MoveWalk.h"
#include "support/Preimage.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>

namespace stepnc::backends {

namespace {

using ir::Node;
using ir::Vec3;
using p21::InstanceId;
using ir::PlaneFrame;

/// Every machining workingstep with moves, in program order.
void workingsteps(const Node &n, std::vector<const Node *> &out) {
  for (const Node &c : n.children)
    if (c.kind == ir::Kind::Workplan)
      workingsteps(c, out);
    else if (c.kind == ir::Kind::Workingstep && c.child(ir::Kind::Moves))
      out.push_back(&c);
}

InstanceId largestId(const p21::Part21File &file) {
  InstanceId largest = 0;
  for (const p21::InstanceEntry &e : file.entries())
    largest = std::max(largest, e.id);
  for (const p21::ExternalReference &r : file.references())
    largest = std::max(largest, r.id);
  return largest;
}

/// The id of a canonical instance line `#id=...`.
InstanceId instanceIdOf(std::string_view line) { return std::stoull(std::string(line.substr(1, line.find('=') - 1))); }

/// Where parameter `index` (0-based, at the top level of its list) of
/// `#id=NAME(p0,p1,...);` lies in the line: [begin, end); none when the line
/// has no such parameter (a complex instance, too few parameters).
std::optional<std::pair<size_t, size_t>> parameterSpan(std::string_view line, size_t index) {
  const size_t eq = line.find('=');
  const size_t open = line.find('(');
  if (open == std::string_view::npos || eq == std::string_view::npos || open == eq + 1)
    return std::nullopt;
  // Top-level parameter boundaries: commas outside nested lists and strings.
  size_t begin = open + 1, current = 0;
  int depth = 0;
  bool inString = false;
  for (size_t i = open + 1; i < line.size(); ++i) {
    const char c = line[i];
    if (inString) {
      if (c == '\'' && i + 1 < line.size() && line[i + 1] == '\'')
        ++i;  // a doubled quote stays in the string
      else if (c == '\'')
        inString = false;
      continue;
    }
    if (c == '\'') {
      inString = true;
    } else if (c == '(') {
      ++depth;
    } else if ((c == ',' && depth == 0) || (c == ')' && depth == 0)) {
      if (current == index)
        return std::pair(begin, i);
      if (c == ')')
        return std::nullopt;
      ++current;
      begin = i + 1;
    } else if (c == ')') {
      --depth;
    }
  }
  return std::nullopt;
}

/// The line with its parameter `index` replaced by `value`, or with `value`
/// appended when `index` is one past its last parameter (a subtype's
/// attributes after its supertype's); empty when the line has no such
/// parameter.
std::string withParameter(std::string_view line, size_t index, std::string_view value) {
  const auto span = parameterSpan(line, index);
  if (!span) {
    const auto last = index > 0 ? parameterSpan(line, index - 1) : std::nullopt;
    if (!last || last->second >= line.size() || line[last->second] != ')')
      return {};
    return std::string(line.substr(0, last->second)) + ',' + std::string(value) +
           std::string(line.substr(last->second));
  }
  return std::string(line.substr(0, span->first)) + std::string(value) + std::string(line.substr(span->second));
}

/// Whether parameter `index` of the line gives no value: `$`, or a number
/// that is 0 (what generators write for a feed or speed they leave out).
bool givesNothing(std::string_view line, size_t index) {
  const auto span = parameterSpan(line, index);
  if (!span)
    return false;
  const std::string text(line.substr(span->first, span->second - span->first));
  if (text == "$")
    return true;
  char *end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' && v == 0;
}

} // namespace

/// A feed or spindle speed the operation's technology leaves out (`$` or 0,
/// and nothing it follows from: resolve-feeds assumed it from the tool and
/// the material, and said so), written into it in the file's own
/// units, so that the optimised file needs no assumption there; an operation
/// with no technology gets one. A technology shared by operations whose
/// values differ gets a copy per operation.
using Patches = std::map<InstanceId, std::vector<std::pair<size_t, std::string>>>;
void writeResolvedTechnology(const Node &op, const std::map<InstanceId, std::string_view> &lines,
                             const ir::SourceUnits &units, Instances &out, Patches &patches) {
  constexpr size_t kItsTechnology = 6;  // machining_operation's 7th attribute
  const Node *tech = op.child(ir::Kind::Technology);
  if (!tech || op.origin.entityId == 0)
    return;
  const double feed = tech->number("feed").value_or(0), spindle = tech->number("spindle").value_or(0);
  // The values that read back as the ones used, in the file's units.
  const std::string feedText = Instances::real(
      preimage(feed, feed / units.feedToMmPerMin, [&](double v) { return v * units.feedToMmPerMin; }));
  const std::string spindleText = Instances::real(preimage(
      spindle, spindle / units.spindleToRevPerMin, [&](double v) { return v * units.spindleToRevPerMin; }));
  // The technology the file gives: the operation's its_technology.
  InstanceId id = 0;
  if (const auto op_ = lines.find(op.origin.entityId); op_ != lines.end())
    if (const auto span = parameterSpan(op_->second, kItsTechnology)) {
      const std::string_view ref = op_->second.substr(span->first, span->second - span->first);
      if (ref.size() > 1 && ref[0] == '#')
        id = std::strtoull(std::string(ref.substr(1)).c_str(), nullptr, 10);
    }
  const auto line = lines.find(id);
  if (id == 0 || line == lines.end()) {
    // No technology in the file: one with what was assumed.
    if (feed <= 0 || spindle == 0)
      return;
    const std::string reference = tech->text("feed_reference") == "ccp" ? "CCP" : "TCP";
    const InstanceId made = out.add("MILLING_TECHNOLOGY", feedText + ",." + reference + ".,$," + spindleText +
                                                              ",$,.F.,.F.,.F.,$");
    patches[op.origin.entityId].emplace_back(kItsTechnology, Instances::ref(made));
    return;
  }
  if (line->second.find("=MILLING_TECHNOLOGY(") == std::string_view::npos)
    return;
  // MILLING_TECHNOLOGY(feedrate, feedrate_reference, cutspeed, spindle,
  // feedrate_per_tooth, ...): a feed derived from the feed per tooth, a
  // spindle speed from the cutting speed, follow from what the file gives.
  std::vector<std::pair<size_t, std::string>> mine;
  if (feed > 0 && givesNothing(line->second, 0) && givesNothing(line->second, 4))
    mine.emplace_back(0, feedText);
  if (spindle != 0 && givesNothing(line->second, 3) && givesNothing(line->second, 2))
    mine.emplace_back(3, spindleText);
  if (mine.empty())
    return;
  std::vector<std::pair<size_t, std::string>> &given = patches[id];
  const bool conflicts = std::any_of(mine.begin(), mine.end(), [&](const auto &m) {
    return std::any_of(given.begin(), given.end(),
                       [&](const auto &g) { return g.first == m.first && g.second != m.second; });
  });
  if (!conflicts) {
    for (auto &m : mine)
      if (std::find(given.begin(), given.end(), m) == given.end())
        given.push_back(std::move(m));
    return;
  }
  // Shared with an operation that resolved other values: this one's own copy.
  std::string copy(line->second);
  for (const auto &[index, value] : mine)
    copy = withParameter(copy, index, value);
  const size_t open = copy.find('('), close = copy.rfind(')');
  const InstanceId made = out.add("MILLING_TECHNOLOGY", copy.substr(open + 1, close - open - 1));
  patches[op.origin.entityId].emplace_back(kItsTechnology, Instances::ref(made));
}

std::string writeOptimisedPart21(const p21::Part21File &input, const ir::Module &module,
                                 const OptimisedFileOptions &options, DiagnosticEngine &diags) {
  bool ok = true;
  const std::string canonical = p21::writePart21ToString(input, diags, &ok);
  if (!ok)
    return {};
  Instances out(largestId(input) + 1);
  ToolpathWriter writer(out, module.sourceUnits, diags);
  // Parameters to replace: instance -> (parameter index, new value). An
  // operation gets its toolpath list (its first parameter), a workingstep
  // whose moves travel above its file's security plane (expand-strategies
  // raised it, said so) a plane at that height (its second).
  Patches patches;
  std::map<InstanceId, const Node *> writtenBy;
  std::vector<const Node *> steps;
  workingsteps(module.root, steps);
  // Where each executable starts: where the one before it left the tool.
  std::map<const Node *, Vec3> starts;
  std::optional<Vec3> position;
  for (const Node *e : ir::programOrder(module))
    if (const Node *moves = e->child(ir::Kind::Moves)) {
      if (position)
        starts[e] = *position;
      for (const ir::Move &m : ir::walkMoves(*moves, position))
        position = m.to;
    }
  // The canonical line of every instance, to read what the file gives.
  std::map<InstanceId, std::string_view> lines;
  for (size_t pos = 0, eol; pos < canonical.size(); pos = eol + 1) {
    eol = canonical.find('\n', pos);
    const std::string_view line(canonical.data() + pos, eol - pos);
    if (line.starts_with("#"))
      lines.emplace(instanceIdOf(line), line);
  }
  for (const Node *ws : steps) {
    const Node *op = ir::operationOf(*ws);
    const Node *feature = ir::findFeature(module, ws->text("feature").value_or(""));
    if (!op || !feature || op->origin.entityId == 0)
      continue;
    const Node &moves = *ws->child(ir::Kind::Moves);
    // Moves that travel above the file's security plane (expand-strategies
    // raised it, and said so): that plane, written as the step's.
    const double travel = moves.number("secplane").value_or(0);
    // (Not for a step on another face: its plane is the file's, turned, and
    // read again it is raised again.)
    if (ws->origin.entityId != 0 && !ws->has("setup") && travel != ws->number("secplane").value_or(travel))
      patches[ws->origin.entityId].emplace_back(
          1, Instances::ref(out.add("PLANE", "'security plane (raised)'," +
                                                 Instances::ref(out.placement(Vec3(0, 0, travel))))));
    // A step that is canned cycles keeps its operation as written: read
    // again, it expands to the same cycles, with the dwells and reduced
    // feeds a cutter-location toolpath cannot carry. Steps that share such
    // an operation share its technology too.
    if (!moves.children.empty() && std::all_of(moves.children.begin(), moves.children.end(),
                                               [](const Node &c) { return c.kind == ir::Kind::Cycle; })) {
      if (writtenBy.emplace(op->origin.entityId, ws).second)
        writeResolvedTechnology(*op, lines, module.sourceUnits, out, patches);
      continue;
    }
    if (auto [it, fresh] = writtenBy.emplace(op->origin.entityId, ws); !fresh) {
      diags
          .error(ws->origin.loc, "workingstep " + ws->symbol + " shares its operation #" +
                                     std::to_string(op->origin.entityId) + " with " + it->second->symbol +
                                     ": one its_toolpath cannot hold the toolpaths of both")
          .entity(ws->origin.entityId);
      ok = false;
      continue;
    }
    const ir::FrameResult frame = ir::planeFrame(*feature);
    if (!frame.frame) {
      diags.error(ws->origin.loc, "workingstep " + ws->symbol + ": " + frame.error).entity(ws->origin.entityId);
      ok = false;
      continue;
    }
    writeResolvedTechnology(*op, lines, module.sourceUnits, out, patches);
    const Node *tech = op->child(ir::Kind::Technology);
    const std::string reference = tech && tech->text("feed_reference") == "ccp" ? "CCP" : "TCP";
    const auto start = starts.find(ws);
    if (auto list = writer.write(*ws, moves, *frame.frame, reference,
                                 start == starts.end() ? std::nullopt : std::optional(start->second)))
      patches[op->origin.entityId].emplace_back(0, Instances::ref(*list));
  }
  if (!ok || writer.failed())
    return {};
  // What reading the file assumed, said explicitly: read again, it needs no
  // assumption (ir::SourceFix).
  std::vector<InstanceId> made;
  const auto resolve = [&made](std::string text) {
    for (size_t at = text.find("#@"); at != std::string::npos; at = text.find("#@", at)) {
      size_t end = at + 2;
      while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end])))
        ++end;
      const size_t k = std::stoul(text.substr(at + 2, end - at - 2));
      const std::string ref = Instances::ref(made.at(k));
      text.replace(at, end - at, ref);
      at += ref.size();
    }
    return text;
  };
  for (const std::string &instance : module.sourceInstances) {
    const std::string resolved = resolve(instance);
    const size_t open = resolved.find('(');
    made.push_back(out.add(resolved.substr(0, open), resolved.substr(open + 1, resolved.size() - open - 2)));
  }
  std::map<InstanceId, std::string> renames;
  for (const ir::SourceFix &f : module.sourceFixes) {
    if (f.parameter < 0)
      renames[f.entityId] = f.text;
    else
      patches[f.entityId].emplace_back(static_cast<size_t>(f.parameter), resolve(f.text));
  }

  // Patch the canonical text: one header entity or instance per line.
  const std::string description = fileDescription(
      input, options.description,
      "kept: every instance of the input with its id and values; changed: the its_toolpath of each expanded "
      "operation, now a TOOLPATH_LIST of required CUTTER_LOCATION_TRAJECTORY in the frame of the feature; "
      "added: the instances above the largest id of the input");
  const bool hasDescription = input.headerEntity("FILE_DESCRIPTION") != nullptr;
  const size_t lastEndsec = canonical.rfind("ENDSEC;\n");
  std::string text;
  text.reserve(canonical.size() + out.text().size() + description.size());
  for (size_t pos = 0, eol; pos < canonical.size(); pos = eol + 1) {
    eol = canonical.find('\n', pos);
    const std::string_view line(canonical.data() + pos, eol - pos);
    if (pos == lastEndsec)
      text += out.text();
    std::string patched(line);
    if (line.starts_with("FILE_DESCRIPTION(")) {
      patched = description;
    } else if (line == "HEADER;" && !hasDescription) {
      patched += "\n" + description;
    } else if (line.starts_with("#")) {
      const InstanceId id = instanceIdOf(line);
      if (auto it = renames.find(id); it != renames.end())
        if (const size_t eq = patched.find('='), open = patched.find('(');
            eq != std::string::npos && open != std::string::npos && eq < open)
          patched = patched.substr(0, eq + 1) + it->second + patched.substr(open);
      if (auto it = patches.find(id); it != patches.end()) {
        for (const auto &[index, value] : it->second) {
          patched = withParameter(patched, index, value);
          if (patched.empty()) {
            diags.error({}, "#" + std::to_string(id) + " is a complex instance: stepnc cannot set its parameter " +
                                std::to_string(index + 1));
            return {};
          }
        }
      }
    }
    text += patched;
    text += '\n';
  }
  return text;
}

std::unique_ptr<p21::Part21File> buildOptimisedFile(const p21::Part21File &input, const ir::Module &module,
                                                    const OptimisedFileOptions &options,
                                                    std::unique_ptr<SourceFile> &text, DiagnosticEngine &diags) {
  if (!ir::requireThreeAxisMilling(module, "the STEP-NC writer", diags, ir::ArcPlanes::Principal))
    return nullptr;
  // An ARM file is patched; an AP238 AIM file has no ARM instances to patch:
  // its write-back is an ARM file written from the IR (docs/ap238.md).
  std::string written = module.aimSchema.empty() ? writeOptimisedPart21(input, module, options, diags)
                                                 : writeArmFromIr(input, module, options, diags);
  if (written.empty())
    return nullptr;
  text = SourceFile::fromString(std::string(input.source().name()) + " (optimised)", written);
  auto file = p21::readPart21(*text, diags);
  if (diags.hasErrors())
    return nullptr;
  return file;
}

} // namespace stepnc::backends
