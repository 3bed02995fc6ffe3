// An ISO 14649 ARM file written from the toolpath IR (see ArmFromIr.h).
//
// Instances are written bottom up, each after what it refers to, so that
// every id is known when it is written: tools, workpieces, then per step its
// technology, machine functions, toolpath list and operation, then the
// features (which list their operations), the steps, the workplans from the
// innermost out, the setup and the project.
#include "backends/step-nc/ArmFromIr.h"

#include "backends/step-nc/Toolpaths.h"
#include "frontend/express/Builtin.h"
#include "frontend/lowering/ToolBodies.h"
#include "frontend/part21/Writer.h"
#include "ir/Kinds.h"
#include "ir/Program.h"
#include "ir/geom/MoveWalk.h"
#include "support/Preimage.h"

#include <cstdlib>
#include <iostream>
#include <map>

namespace stepnc::backends {

namespace {

using ir::Node;
using ir::Vec3;
using p21::InstanceId;

/// One instance of the built-in ARM, its attributes given by name and
/// written in the schema's order (inherited ones first): an optional
/// attribute not given is `$`, an aggregate `()`, an attribute a subtype
/// derives `*`. Naming an attribute the entity does not have is a bug here.
class ArmRecord {
public:
  ArmRecord(const express::Model &model, const express::Schema &schema, std::string_view entity)
      : model_(model), entity_(model.findEntity(schema, entity)), name_(express::upper(entity)) {
    if (entity_ == express::kNone)
      bug("the ARM has no entity " + std::string(entity));
    values_.resize(model_.entity(entity_).slots.size());
  }

  bool has(std::string_view attribute) const { return slot(attribute) >= 0; }

  ArmRecord &set(std::string_view attribute, std::string value) {
    const int k = slot(attribute);
    if (k < 0)
      bug(name_ + " has no attribute " + std::string(attribute));
    values_[static_cast<size_t>(k)] = std::move(value);
    return *this;
  }

  /// The parameters, or empty with `missing` naming a mandatory attribute
  /// that was not given.
  std::string parameters(std::string &missing) const {
    const express::Entity &e = model_.entity(entity_);
    std::string out;
    for (size_t k = 0; k < e.slots.size(); ++k) {
      const express::Slot &s = e.slots[k];
      std::string value = values_[k];
      if (value.empty())
        value = s.derived ? "*" : s.optional ? "$" : aggregate(s.type) ? "()" : "";
      if (value.empty()) {
        missing = s.name;
        return {};
      }
      if (k)
        out += ',';
      out += value;
    }
    return out;
  }

  const std::string &name() const { return name_; }

private:
  /// Naming what the ARM does not have is a bug in this file, not in the input.
  [[noreturn]] static void bug(const std::string &what) {
    std::cerr << "stepnc: internal error: the ARM writer: " << what << '\n';
    std::abort();
  }

  int slot(std::string_view attribute) const {
    const std::vector<express::Slot> &slots = model_.entity(entity_).slots;
    for (size_t k = 0; k < slots.size(); ++k)
      if (slots[k].name == attribute)
        return static_cast<int>(k);
    return -1;
  }

  /// Whether a type is an aggregate, through the defined types it names.
  bool aggregate(express::TypeId id) const {
    for (int depth = 0; id != express::kNone && depth < 64; ++depth) {
      const express::TypeExpr &t = model_.type(id);
      if (t.kind == express::TypeExpr::Aggregate)
        return true;
      if (t.kind != express::TypeExpr::Named || t.declared == express::kNone)
        return false;
      id = model_.typeDecl(t.declared).underlying;
    }
    return false;
  }

  const express::Model &model_;
  express::EntityId entity_;
  std::string name_;
  std::vector<std::string> values_;
};

std::string text(std::string_view s) {
  std::string out;
  p21::appendString(out, s);
  return out;
}

std::string boolean(bool b) { return b ? ".T." : ".F."; }

/// A list of references `(#a,#b)`.
std::string refs(const std::vector<InstanceId> &ids) {
  std::string out = "(";
  for (size_t i = 0; i < ids.size(); ++i) {
    if (i)
      out += ',';
    out += Instances::ref(ids[i]);
  }
  return out + ')';
}

/// The label a node's STEP-NC instance had, else its symbol without sigil.
std::string idOf(const Node &n) {
  if (!n.label.empty())
    return n.label;
  return n.symbol.size() > 1 ? n.symbol.substr(1) : n.kindName();
}

class ArmWriter {
public:
  ArmWriter(const ir::Module &module, DiagnosticEngine &diags)
      : module_(module), diags_(diags), model_(express::builtinModel()),
        schema_(*express::builtinSchemaFor("MACHINING_SCHEMA")), out_(1), toolpaths_(out_, units_, diags) {}

  /// The DATA section's instances, or empty after errors.
  std::string write() {
    for (const Node &c : module_.root.children)
      if (c.kind == ir::Kind::Tool)
        tool(c);
    std::vector<InstanceId> workpieces;
    for (const Node &c : module_.root.children)
      if (c.kind == ir::Kind::Workpiece)
        workpieces.push_back(workpiece(c));
    for (const Node &c : module_.root.children)
      if (c.kind == ir::Kind::Setup)
        return fail(c, "a setup of its own (a feature on another face): the ARM writer writes one setup only");
    const std::vector<const Node *> plans = module_.root.childrenOf(ir::Kind::Workplan);
    if (plans.size() != 1)
      return fail(module_.root, "the project has " + std::to_string(plans.size()) +
                                    " workplans: an ISO 14649 project has one main workplan");
    if (failed_)
      return {};
    // Operations first: the features list them.
    std::vector<const Node *> steps;
    collectSteps(*plans.front(), steps);
    for (const Node *ws : steps)
      if (!operation(*ws))
        return {};
    for (const Node *ws : steps)
      if (!feature(*ws))
        return {};
    const std::optional<InstanceId> main = workplan(*plans.front(), &workpieces);
    if (!main || failed_ || toolpaths_.failed())
      return {};
    const Node &project = module_.root;
    ArmRecord p = record("project");
    p.set("its_id", text(idOf(project))).set("main_workplan", Instances::ref(*main)).set("its_workpieces",
                                                                                          refs(workpieces));
    if (!add(p, project))
      return {};
    return out_.text();
  }

private:
  ArmRecord record(std::string_view entity) const { return ArmRecord(model_, schema_, entity); }

  std::optional<InstanceId> add(const ArmRecord &r, const Node &from) {
    std::string missing;
    const std::string params = r.parameters(missing);
    if (params.empty() && !missing.empty()) {
      fail(from, "its " + r.name() + " would have no '" + missing + "'");
      return std::nullopt;
    }
    return out_.add(r.name(), params);
  }

  std::string fail(const Node &n, const std::string &why) {
    diags_.error(n.origin.loc, "cannot write " + n.kindName() + (n.symbol.empty() ? "" : " " + n.symbol) +
                                   " as ISO 14649 ARM: " + why)
        .entity(n.origin.entityId);
    failed_ = true;
    return {};
  }

  /// A number attribute as a Part 21 real; empty (not given) when absent.
  static std::string value(const Node &n, std::string_view attribute) {
    const std::optional<double> v = n.number(attribute);
    return v ? Instances::real(*v) : "";
  }

  /// A plane at height `z`, one per height.
  InstanceId plane(double z, std::string_view name) {
    if (auto it = planes_.find(z); it != planes_.end())
      return it->second;
    const InstanceId id = out_.add("PLANE", text(name) + ',' + Instances::ref(out_.placement(Vec3(0, 0, z))));
    planes_.emplace(z, id);
    return id;
  }

  void tool(const Node &t) {
    const std::string type = t.text("type").value_or("");
    const std::string_view entity = lowering::toolBodyEntity(type);
    if (entity.empty() || model_.findEntity(schema_, entity) == express::kNone) {
      fail(t, "its type " + type + " is no ISO 14649-111 milling tool body");
      return;
    }
    if (!t.number("diameter")) {
      fail(t, "it has no diameter");
      return;
    }
    ArmRecord dim = record("milling_tool_dimension");
    dim.set("diameter", value(t, "diameter"))
        .set("tool_tip_half_angle", value(t, "tip_half_angle"))
        .set("tool_circumference_angle", value(t, "circumference_angle"))
        .set("cutting_edge_length", value(t, "cutting_edge_length"))
        .set("edge_radius", value(t, "corner_radius"))
        .set("edge_center_vertical", value(t, "edge_center_vertical"))
        .set("edge_center_horizontal", value(t, "edge_center_horizontal"));
    const std::optional<InstanceId> dimension = add(dim, t);
    if (!dimension)
      return;
    ArmRecord body = record(entity);
    body.set("dimension", Instances::ref(*dimension));
    if (auto flutes = t.count("flutes"))
      body.set("number_of_teeth", std::to_string(*flutes));
    if (auto hand = t.text("hand"))
      body.set("hand_of_cut", '.' + express::upper(*hand) + '.');
    if (auto through = t.flag("coolant_through"))
      body.set("coolant_through_tool", boolean(*through));
    if (body.has("taper_angle"))
      body.set("taper_angle", value(t, "taper_angle"));
    // Whether a boring tool may retract with the spindle turning: not
    // forbidden, what the program does.
    if (body.has("retract_movement_forbidden"))
      body.set("retract_movement_forbidden", boolean(false));
    const std::optional<InstanceId> b = add(body, t);
    // The cutting edge's offset length: the length from the gauge line to the tip.
    const std::optional<double> offset = t.number("offset_length") ? t.number("offset_length")
                                                                   : t.number("overall_length");
    if (!offset) {
      fail(t, "it has neither an offset length nor an overall length (its cutting edge's tool_offset_length)");
      return;
    }
    ArmRecord edge = record("cutting_component");
    edge.set("tool_offset_length", Instances::real(*offset));
    const std::optional<InstanceId> e = add(edge, t);
    if (!b || !e)
      return;
    ArmRecord tool = record("milling_cutting_tool");
    tool.set("its_id", text(idOf(t)))
        .set("its_tool_body", Instances::ref(*b))
        .set("its_cutting_edge", refs({*e}))
        .set("overall_assembly_length", value(t, "overall_length"))
        .set("tool_holder_diameter_for_spindle_orientation", value(t, "holder_diameter"));
    if (auto id = add(tool, t))
      tools_[t.symbol] = *id;
  }

  InstanceId workpiece(const Node &w) {
    ArmRecord r = record("workpiece");
    r.set("its_id", text(idOf(w)));
    if (auto material = w.text("material")) {
      ArmRecord m = record("material");
      m.set("standard_identifier", text(w.text("material_standard").value_or("")))
          .set("material_identifier", text(*material));
      if (auto id = add(m, w))
        r.set("its_material", Instances::ref(*id));
    }
    if (const Node *raw = w.child(ir::Kind::Rawpiece)) {
      const std::optional<Vec3> size = raw->vec("size");
      if (raw->text("shape") != "block" || !size) {
        fail(w, "its raw piece is not a block of known size (the ARM's bounding geometry the writer writes)");
      } else {
        ArmRecord block = record("block");
        block.set("name", text("stock"))
            .set("position", Instances::ref(out_.placement(*raw->vec("at"), *raw->vec("axis"), *raw->vec("ref"))))
            .set("x", Instances::real(size->x()))
            .set("y", Instances::real(size->y()))
            .set("z", Instances::real(size->z()));
        if (auto id = add(block, *raw))
          r.set("its_bounding_geometry", Instances::ref(*id));
      }
    }
    std::vector<InstanceId> clamps;
    for (const Node *c : w.childrenOf(ir::Kind::Clamp))
      clamps.push_back(out_.point(*c->vec("at")));
    r.set("clamping_positions", refs(clamps));
    const std::optional<InstanceId> id = add(r, w);
    if (id)
      workpieces_[&w] = *id;
    return id.value_or(0);
  }

  static void collectSteps(const Node &plan, std::vector<const Node *> &out) {
    for (const Node &c : plan.children)
      if (c.kind == ir::Kind::Workplan)
        collectSteps(c, out);
      else if (c.kind == ir::Kind::Workingstep)
        out.push_back(&c);
  }

  /// The step's technology, machine functions, toolpath list and freeform
  /// operation; false after an error.
  bool operation(const Node &ws) {
    const Node *op = ir::operationOf(ws);
    const Node *moves = ws.child(ir::Kind::Moves);
    const Node *feature = ir::findFeature(module_, ws.text("feature").value_or(""));
    if (!op || !moves || !feature) {
      fail(ws, !op ? "it has no operation" : !moves ? "it has no moves (run expand-strategies)" : "its feature is not "
                                                                                                   "listed");
      return false;
    }
    const auto tool = tools_.find(op->text("tool").value_or(""));
    if (tool == tools_.end()) {
      fail(ws, "its tool " + op->text("tool").value_or("") + " is not written");
      return false;
    }
    const ir::FrameResult frame = ir::planeFrame(*feature);
    if (!frame.frame) {
      fail(ws, frame.error);
      return false;
    }
    const Node *tech = op->child(ir::Kind::Technology);
    const std::string reference = tech && tech->text("feed_reference") == "ccp" ? "CCP" : "TCP";
    const std::optional<InstanceId> list = toolpaths_.write(ws, *moves, *frame.frame, reference, std::nullopt);
    if (!list) {
      if (!toolpaths_.failed())
        fail(ws, "its moves are a single positioning: nothing for a toolpath to say");
      return false;
    }
    // The operation's own technology: its feed (else the first feed of its
    // moves: the operation's applies to no move) and the spindle the moves run at.
    double feed = tech ? tech->number("feed").value_or(0) : 0;
    for (const ir::Move &m : ir::walkMoves(*moves, std::nullopt))
      if (!(feed > 0) && m.feed > 0)
        feed = m.feed;
    if (!(feed > 0)) {
      fail(ws, "it has no feed");
      return false;
    }
    const double spindle = moves->number("spindle").value_or(0);
    ArmRecord t = record("milling_technology");
    t.set("feedrate", Instances::real(preimage(feed, feed / units_.feedToMmPerMin,
                                               [&](double v) { return v * units_.feedToMmPerMin; })))
        .set("feedrate_reference", '.' + reference + '.')
        .set("spindle", Instances::real(preimage(spindle, spindle / units_.spindleToRevPerMin,
                                                 [&](double v) { return v * units_.spindleToRevPerMin; })))
        .set("synchronize_spindle_with_feed", boolean(false))
        .set("inhibit_feedrate_override", boolean(tech && tech->flag("inhibit_feed_override").value_or(false)))
        .set("inhibit_spindle_override", boolean(tech && tech->flag("inhibit_spindle_override").value_or(false)));
    const std::optional<InstanceId> technology = add(t, *op);
    const Node *mf = op->child(ir::Kind::MachineFunctions);
    const auto flag = [&](std::string_view name) { return boolean(mf && mf->flag(name).value_or(false)); };
    ArmRecord f = record("milling_machine_functions");
    f.set("coolant", flag("coolant")).set("through_spindle_coolant", flag("through_spindle_coolant"));
    f.set("chip_removal", flag("chip_removal"));
    if (mf && mf->flag("mist"))
      f.set("mist", flag("mist"));
    const std::optional<InstanceId> functions = add(f, *op);
    if (!technology || !functions)
      return false;
    ArmRecord o = record("freeform_operation");
    o.set("its_toolpath", Instances::ref(*list))
        .set("its_id", text(idOf(*op)))
        .set("retract_plane", value(*op, "retract_plane"))
        .set("its_tool", Instances::ref(tool->second))
        .set("its_technology", Instances::ref(*technology))
        .set("its_machine_functions", Instances::ref(*functions));
    const std::optional<InstanceId> id = add(o, *op);
    if (!id)
      return false;
    operations_[&ws] = *id;
    operationsOf_[feature].push_back(*id);
    return true;
  }

  /// The toolpath feature a step machines, written once per feature.
  bool feature(const Node &ws) {
    const Node *f = ir::findFeature(module_, ws.text("feature").value_or(""));
    if (features_.count(f))
      return true;
    const Node *wp = ir::workpieceOf(module_, *f);
    const auto workpiece = wp ? workpieces_.find(wp) : workpieces_.end();
    if (workpiece == workpieces_.end()) {
      fail(*f, "its workpiece is not written");
      return false;
    }
    const Vec3 at = f->vec("at").value_or(Vec3::Zero());
    const Vec3 axis = f->vec("axis").value_or(Vec3::UnitZ()), ref = f->vec("ref").value_or(Vec3::UnitX());
    const InstanceId placement = out_.placement(at, axis, ref);
    // A toolpath feature's depth says nothing (lowering keeps none): its
    // placement's own plane.
    const InstanceId depth = out_.add("PLANE", text(idOf(*f) + " depth") + ',' + Instances::ref(placement));
    ArmRecord r = record("toolpath_feature");
    r.set("its_id", text(idOf(*f)))
        .set("its_workpiece", Instances::ref(workpiece->second))
        .set("its_operations", refs(operationsOf_[f]))
        .set("feature_placement", Instances::ref(placement))
        .set("depth", Instances::ref(depth));
    const std::optional<InstanceId> id = add(r, *f);
    if (id)
      features_[f] = *id;
    return id.has_value();
  }

  std::optional<InstanceId> workingstep(const Node &ws) {
    const Node *moves = ws.child(ir::Kind::Moves);
    const Node *f = ir::findFeature(module_, ws.text("feature").value_or(""));
    ArmRecord r = record("machining_workingstep");
    r.set("its_id", text(idOf(ws)))
        .set("its_secplane", Instances::ref(plane(moves->number("secplane").value_or(0), "security plane")))
        .set("its_feature", Instances::ref(features_.at(f)))
        .set("its_operation", Instances::ref(operations_.at(&ws)));
    return add(r, ws);
  }

  std::optional<InstanceId> rapidMovement(const Node &rm) {
    const Node *moves = rm.child(ir::Kind::Moves);
    if (!moves) {
      fail(rm, "it has no moves (run expand-strategies)");
      return std::nullopt;
    }
    const ir::PlaneFrame workpiece;  // its points are in workpiece coordinates
    const std::optional<InstanceId> list = toolpaths_.write(rm, *moves, workpiece, "TCP", std::nullopt);
    if (!list)
      return std::nullopt;
    ArmRecord r = record("rapid_movement");
    r.set("its_id", text(idOf(rm)))
        .set("its_secplane", Instances::ref(plane(moves->number("secplane").value_or(0), "security plane")))
        .set("its_toolpath", Instances::ref(*list));
    return add(r, rm);
  }

  /// A workplan and what it holds, innermost first; the main one gets the
  /// setup of `workpieces` (the writer's one setup: the workpiece
  /// coordinates are the IR's).
  std::optional<InstanceId> workplan(const Node &plan, const std::vector<InstanceId> *workpieces) {
    std::vector<InstanceId> elements;
    for (const Node &c : plan.children) {
      std::optional<InstanceId> id;
      if (c.kind == ir::Kind::Workplan) {
        id = workplan(c, nullptr);
      } else if (c.kind == ir::Kind::Workingstep) {
        id = workingstep(c);
      } else if (c.kind == ir::Kind::RapidMovement) {
        id = rapidMovement(c);
      } else if (c.kind == ir::Kind::ProgramStop || c.kind == ir::Kind::OptionalStop) {
        if (c.flag("reclamp").value_or(false)) {
          fail(c, "a stop to re-clamp the workpiece (a setup of its own)");
          return std::nullopt;
        }
        ArmRecord r = record(c.kind == ir::Kind::ProgramStop ? "program_stop" : "optional_stop");
        r.set("its_id", text(idOf(c)));
        id = add(r, c);
      } else if (c.kind == ir::Kind::DisplayMessage) {
        ArmRecord r = record("display_message");
        r.set("its_id", text(idOf(c))).set("its_text", text(c.text("message").value_or("")));
        id = add(r, c);
      } else {
        fail(c, "not written yet");
      }
      if (!id)
        return std::nullopt;
      elements.push_back(*id);
    }
    ArmRecord r = record("workplan");
    r.set("its_id", text(idOf(plan))).set("its_elements", refs(elements));
    if (workpieces) {
      // The security plane of the setup: the first step's (each step gives its own).
      double secplane = 0;
      for (const Node *e : ir::programOrder(module_))
        if (const Node *moves = e->child(ir::Kind::Moves)) {
          secplane = moves->number("secplane").value_or(0);
          break;
        }
      const InstanceId origin = out_.placement(Vec3::Zero());
      std::vector<InstanceId> placed;
      for (InstanceId w : *workpieces) {
        ArmRecord s = record("workpiece_setup");
        s.set("its_workpiece", Instances::ref(w)).set("its_origin", Instances::ref(origin));
        if (auto id = add(s, plan))
          placed.push_back(*id);
      }
      ArmRecord setup = record("setup");
      setup.set("its_id", text("setup"))
          .set("its_origin", Instances::ref(origin))
          .set("its_secplane", Instances::ref(plane(secplane, "security plane")))
          .set("its_workpiece_setup", refs(placed));
      if (auto id = add(setup, plan))
        r.set("its_setup", Instances::ref(*id));
    }
    return add(r, plan);
  }

  const ir::Module &module_;
  DiagnosticEngine &diags_;
  const express::Model &model_;
  const express::Schema &schema_;
  /// Feeds in m/s, spindle speeds in rev/s: the standard's units.
  const ir::SourceUnits units_{};
  Instances out_;
  ToolpathWriter toolpaths_;
  std::map<std::string, InstanceId> tools_;
  std::map<const Node *, InstanceId> workpieces_, features_, operations_;
  std::map<const Node *, std::vector<InstanceId>> operationsOf_;
  std::map<double, InstanceId> planes_;
  bool failed_ = false;
};

} // namespace

std::string writeArmFromIr(const p21::Part21File &input, const ir::Module &module,
                           const OptimisedFileOptions &options, DiagnosticEngine &diags) {
  ArmWriter writer(module, diags);
  const std::string data = writer.write();
  if (data.empty())
    return {};
  std::string out = "ISO-10303-21;\nHEADER;\n";
  out += fileDescription(
      input, options.description,
      "written: an ISO 14649 ARM file (the input is an AP238 AIM file, " + module.aimSchema +
          "): each workingstep a toolpath_feature at the placement of its feature machined by a freeform_operation "
          "whose TOOLPATH_LIST of required CUTTER_LOCATION_TRAJECTORY and FEEDSTOP is its moves (canned cycles "
          "as the moves they make); the features and strategies of the input are not written");
  out += '\n';
  if (const p21::HeaderEntity *name = input.headerEntity("FILE_NAME")) {
    p21::appendRecord(out, name->record, input.metadata(), input.names());
    out += ";\n";
  } else {
    out += "FILE_NAME(" + text(module.sourceName) + ",'',(''),(''),'stepnc','stepnc','');\n";
  }
  out += "FILE_SCHEMA(('MACHINING_SCHEMA'));\nENDSEC;\nDATA;\n";
  out += data;
  out += "ENDSEC;\nEND-ISO-10303-21;\n";
  return out;
}

} // namespace stepnc::backends
