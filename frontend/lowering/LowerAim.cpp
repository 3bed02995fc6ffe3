// Lowering of AP238 AIM files (ISO 10303-238, editions 1 and 3): the mapped
// form of the ISO 14649 ARM that commercial STEP-NC writers produce. The ARM's
// objects are generic STEP resources there, tied together by relationships:
//
//   machining_project (a product) <- product_definition <- process_product_association
//     -> product_definition_process -> machining_workplan (an action_method)
//   machining_workplan <- machining_process_sequence_relationship (sequence_position)
//     -> machining_workingstep | machining_workplan | machining_rapid_movement
//   machining_workingstep <- machining_operation_relationship -> machining_operation
//                         <- machining_feature_relationship -> machining_feature_process
//                            <- property_process <- process_property_association -> feature
//   machining_operation <- machining_toolpath_sequence_relationship -> machining_toolpath
//   operation/toolpath <- machining_technology_relationship -> machining_technology
//                      <- machining_functions_relationship -> machining_functions
//   machining_tool.usage -> the operations it cuts
//   properties: action_property (of an action_method) / resource_property (of a
//     tool) <- *_property_representation -> representation of
//     measure_representation_items (a value and its unit) and
//     descriptive_representation_items (a word)
//
// Every value is read in its own unit (a measure item's unit, a geometric
// representation's context) and converted to the IR's once. What is not
// mapped is a located "not supported", never dropped. docs/ap238.md.
#include "frontend/lowering/LowerAim.h"
#include "frontend/express/Builtin.h"
#include "support/Format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <unordered_map>

namespace stepnc::lowering {

namespace aim {

std::string dimsText(const Dims &d) {
  if (d == kLength)
    return "a length";
  if (d == kTime)
    return "a time";
  if (d == kAngle)
    return "an angle";
  if (d == kFeed)
    return "a speed (length per time)";
  if (d == kFeedPerRev)
    return "a feed per revolution";
  if (d == kRotation)
    return "a rotational speed";
  if (d == Dims{})
    return "a number";
  return "length^" + std::to_string(d.length) + " time^" + std::to_string(d.time) + " angle^" +
         std::to_string(d.angle) + " rev^" + std::to_string(d.revolution);
}

std::string normalName(std::string_view s) {
  std::string out;
  for (char c : s)
    out.push_back(c == '_' ? ' ' : static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  return out;
}

} // namespace aim

using namespace aim;

// --- index ---------------------------------------------------------------------

void AimLowerer::index() {
  const express::Model &model = bound_.model();
  auto entity = [&](std::string_view name) { return model.findEntity(bound_.schema(), name); };
  const express::EntityId relationship = entity("action_method_relationship"),
                          actionProperty = entity("action_property"), resourceProperty = entity("resource_property"),
                          actionPropRep = entity("action_property_representation"),
                          resourcePropRep = entity("resource_property_representation"),
                          machiningTool = entity("machining_tool"), association = entity("process_property_association"),
                          project = entity("machining_project"), pdProcess = entity("product_definition_process"),
                          projectWorkpiece = entity("machining_project_workpiece_relationship"),
                          repRelationship = entity("representation_relationship"),
                          resourceRelationship = entity("action_resource_relationship"),
                          sequence = entity("machining_process_sequence_relationship"),
                          executableEntity = entity("machining_process_executable"),
                          operationEntity = entity("machining_operation"), toolpathEntity = entity("machining_toolpath"),
                          propertyDefinition = entity("property_definition"),
                          definitionRep = entity("property_definition_representation"),
                          shapeAspect = entity("shape_aspect"), aspectRelationship = entity("shape_aspect_relationship");
  // Which of these an instance is depends on its entity alone: asked of the
  // model once per entity name in the file (per instance for the rare
  // complex instances), then read from a bit mask.
  const std::array<express::EntityId, 20> kinds = {
      relationship,   actionProperty,  resourceProperty, actionPropRep,    resourcePropRep,
      machiningTool,  association,     project,          pdProcess,        projectWorkpiece,
      repRelationship, resourceRelationship, sequence,   executableEntity, operationEntity,
      toolpathEntity, propertyDefinition, definitionRep, shapeAspect,      aspectRelationship};
  std::unordered_map<p21::NameId, uint32_t> maskByName;
  uint32_t mask = 0;  // the instance at hand's
  auto computeMask = [&](size_t i) {
    uint32_t m = 0;
    for (size_t k = 0; k < kinds.size(); ++k)
      if (kinds[k] != express::kNone && bound_.isA(i, kinds[k]))
        m |= 1u << k;
    return m;
  };
  auto is = [&](express::EntityId e) {
    for (size_t k = 0; k < kinds.size(); ++k)
      if (kinds[k] == e)
        return e != express::kNone && (mask >> k & 1u) != 0;
    return false;
  };
  const size_t n = bound_.file().entries().size();
  for (size_t i = 0; i < n; ++i) {
    const p21::NameId name = bound_.file().entries()[i].name();
    if (name == p21::kComplexInstance) {
      mask = computeMask(i);
    } else {
      auto [it, fresh] = maskByName.try_emplace(name, 0);
      if (fresh)
        it->second = computeMask(i);
      mask = it->second;
    }
    if (is(executableEntity) || is(operationEntity) || is(toolpathEntity))
      methods_.push_back(i);
    if (is(shapeAspect))
      if (Instance of = Instance(bound_, i).ref("of_shape"))
        aspectsOf_[of.index()].push_back(i);
    if (is(relationship)) {
      const Instance r(bound_, i);
      if (Instance from = r.ref("relating_method"))
        byRelating_[from.index()].push_back(i);
      if (Instance to = r.ref("related_method"))
        held_.insert(to.index());
      if (is(sequence))
        if (Instance to = r.ref("related_method"))
          sequenced_.insert(to.index());
    } else if (is(actionProperty)) {
      const Instance p(bound_, i);
      if (Instance of = p.ref("definition"))
        actionProps_[of.index()].push_back(i);
    } else if (is(resourceProperty)) {
      const Instance p(bound_, i);
      if (Instance of = p.ref("resource"))
        resourceProps_[of.index()].push_back(i);
    } else if (is(actionPropRep) || is(resourcePropRep)) {
      const Instance r(bound_, i);
      if (Instance p = r.ref("property"))
        propReps_[p.index()].push_back(i);
    } else if (is(machiningTool)) {
      const Instance t(bound_, i);
      for (const Instance &use : t.refs("usage"))
        toolOf_.emplace(use.index(), i);
    } else if (is(association)) {
      const Instance a(bound_, i);
      if (Instance process = a.ref("process"))
        if (Instance method = process.ref("chosen_method"))
          if (Instance feature = a.ref("property_or_shape"))
            featureOfProcess_.emplace(method.index(), feature.index());
    } else if (is(project)) {
      projects_.emplace_back(bound_, i);
    } else if (is(pdProcess)) {
      const Instance p(bound_, i);
      if (p.ref("chosen_method").isA("machining_workplan"))
        workplanProcesses_.push_back(p);
    } else if (is(projectWorkpiece)) {
      projectWorkpieces_.emplace_back(bound_, i);
    } else if (is(resourceRelationship)) {
      const Instance r(bound_, i);
      if (Instance from = r.ref("relating_resource"))
        if (Instance to = r.ref("related_resource"))
          componentsOf_[from.index()].push_back(to.index());
    } else if (is(propertyDefinition)) {
      if (Instance of = Instance(bound_, i).ref("definition"))
        propertyDefs_[of.index()].push_back(i);
    } else if (is(definitionRep)) {
      if (Instance of = Instance(bound_, i).ref("definition"))
        definitionReps_[of.index()].push_back(i);
    } else if (is(aspectRelationship)) {
      if (Instance to = Instance(bound_, i).ref("related_shape_aspect"))
        aspectRelationsTo_[to.index()].push_back(i);
    } else if (is(repRelationship)) {
      const Instance r(bound_, i);
      const Instance a = r.ref("rep_1"), b = r.ref("rep_2");
      if (a && b) {
        repRelated_[a.index()].push_back(b.index());
        repRelated_[b.index()].push_back(a.index());
      }
    }
  }
}

std::vector<Instance> AimLowerer::related(const Instance &from, std::string_view kind, std::string_view name) const {
  std::vector<std::pair<double, Instance>> found;
  if (auto it = byRelating_.find(from.index()); it != byRelating_.end())
    for (size_t i : it->second)
      if (const Instance r = at(i); r.isA(kind) && (name.empty() || normalName(r.string("name").value_or("")) == name))
        if (Instance to = r.ref("related_method"))
          found.emplace_back(r.real("sequence_position").value_or(0), to);
  std::stable_sort(found.begin(), found.end(), [](const auto &a, const auto &b) { return a.first < b.first; });
  std::vector<Instance> out;
  for (auto &[position, to] : found)
    out.push_back(std::move(to));
  return out;
}

std::vector<std::pair<std::string, Instance>> AimLowerer::properties(const Instance &of, bool resource) const {
  std::vector<std::pair<std::string, Instance>> out;
  const auto &table = resource ? resourceProps_ : actionProps_;
  auto it = table.find(of.index());
  if (it == table.end())
    return out;
  for (size_t p : it->second)
    if (auto reps = propReps_.find(p); reps != propReps_.end()) {
      const std::string name = normalName(at(p).string("name").value_or(""));
      for (size_t r : reps->second)
        if (Instance rep = at(r).ref("representation"))
          out.emplace_back(name, rep);
    }
  return out;
}

std::vector<Instance> AimLowerer::propertyRepresentations(const Instance &of, std::string_view property,
                                                          bool resource) const {
  std::vector<Instance> out;
  for (auto &[name, rep] : properties(of, resource))
    if (name == property)
      out.push_back(rep);
  return out;
}

std::vector<Instance> AimLowerer::withRelated(const Instance &rep) const {
  std::vector<Instance> out{rep};
  std::set<size_t> seen{rep.index()};
  for (size_t k = 0; k < out.size(); ++k)
    if (auto it = repRelated_.find(out[k].index()); it != repRelated_.end())
      for (size_t r : it->second)
        if (seen.insert(r).second)
          out.push_back(at(r));
  return out;
}

void AimLowerer::reportUnreached() {
  // Only what nothing holds: what an unreached method holds goes with it.
  for (size_t i : methods_) {
    if (reached_.count(i) || held_.count(i))
      continue;
    const Instance m = at(i);
    const char *why = m.isA("machining_toolpath")
                          ? "no machining_toolpath_sequence_relationship gives it to an operation"
                      : m.isA("machining_operation")
                          ? "no machining_operation_relationship gives it to a workingstep"
                          : "no machining_process_sequence_relationship puts it in a workplan";
    diags_.assumption(m.loc(), std::string(why) + "; left out of the program").entity(m.id(), entityUpper(m));
  }
}

void AimLowerer::report(const Instance &inst, SourceLoc at, std::string message) {
  diags_.error(at, std::move(message)).entity(inst.id(), entityUpper(inst));
}

void AimLowerer::wrongUnit(const Instance &inst, SourceLoc at, std::string_view what, const Dims &expected,
                           const Dims &found) {
  std::string message = "'";
  message += what;
  message += "': expected " + dimsText(expected) + ", its unit is " + dimsText(found);
  report(inst, at, std::move(message));
}

// --- units ----------------------------------------------------------------------

UnitValue AimLowerer::unit(const Instance &u) {
  if (!u)
    return {1, {}, "no unit"};
  if (auto it = units_.find(u.index()); it != units_.end())
    return it->second;
  units_[u.index()] = {1, {}, "a unit defined in terms of itself"};  // cycle guard
  UnitValue v;
  if (u.isA("si_unit")) {
    static const std::pair<std::string_view, double> kPrefixes[] = {
        {"exa", 1e18}, {"peta", 1e15}, {"tera", 1e12}, {"giga", 1e9},  {"mega", 1e6},   {"kilo", 1e3},
        {"hecto", 1e2}, {"deca", 1e1}, {"deci", 1e-1}, {"centi", 1e-2}, {"milli", 1e-3}, {"micro", 1e-6},
        {"nano", 1e-9}, {"pico", 1e-12}, {"femto", 1e-15}, {"atto", 1e-18}};
    double prefix = 1;
    if (auto p = u.enumeration("prefix"))
      for (const auto &[name, factor] : kPrefixes)
        if (*p == name)
          prefix = factor;
    const std::string name = u.enumeration("name").value_or("");
    if (name == "metre")
      v = {1000 * prefix, kLength, {}};
    else if (name == "second")
      v = {prefix, kTime, {}};
    else if (name == "radian")
      v = {prefix * 180 / std::numbers::pi, kAngle, {}};
    else if (name == "steradian")
      v = {prefix, {}, {}};
    else
      v.error = "the SI unit ." + express::upper(name) + ". is not one stepnc reads (metre, second, radian)";
  } else if (u.isA("conversion_based_unit")) {
    const Instance factor = u.ref("conversion_factor");
    UnitValue base = unit(factor.ref("unit_component"));
    const std::optional<double> value = factor.real("value_component");
    if (!base.error.empty() || !value)
      v.error = "its conversion factor " + (factor ? hashId(factor.id()) : std::string("(none)")) + " has no usable " +
                (value ? "unit: " + base.error : std::string("value"));
    else
      v = {*value * base.factor, base.dims, {}};
  } else if (u.isA("context_dependent_unit")) {
    const std::string name = normalName(u.string("name").value_or(""));
    if (name == "revolution" || name == "revolutions" || name == "rev")
      v = {1, kRevolution, {}};
    else if (name == "count" || name == "number" || name == "parameter unit" || name.empty())
      v = {1, {}, {}};
    else
      v.error = "the context-dependent unit '" + name + "' is not one stepnc reads (revolution)";
  } else if (u.isA("derived_unit")) {
    for (const Instance &element : u.refs("elements")) {
      UnitValue part = unit(element.ref("unit"));
      const double exponent = element.real("exponent").value_or(1);
      if (!part.error.empty()) {
        v.error = "its element " + hashId(element.id()) + ": " + part.error;
        break;
      }
      const int e = static_cast<int>(std::lround(exponent));
      v.factor *= std::pow(part.factor, exponent);
      v.dims.length += part.dims.length * e;
      v.dims.time += part.dims.time * e;
      v.dims.angle += part.dims.angle * e;
      v.dims.revolution += part.dims.revolution * e;
    }
  } else {
    v.error = "a " + std::string(u.entityName()) + " is not a unit stepnc reads";
  }
  units_[u.index()] = v;
  return v;
}

std::optional<Measure> AimLowerer::measure(const Instance &item) {
  const std::optional<double> value = item.real("value_component");
  if (!value) {
    base_.missing(item, "value_component", "is not a number");
    return std::nullopt;
  }
  Measure m;
  m.name = normalName(item.string("name").value_or(""));
  const Instance u = item.ref("unit_component");
  UnitValue v = unit(u);
  if (!v.error.empty()) {
    report(item, item.attrLoc("unit_component"),
           "'" + m.name + "': its unit " +
               (u ? hashId(u.id()) + " cannot be read: " + v.error : std::string("is not given")));
    return std::nullopt;
  }
  m.value = *value * v.factor;
  m.written = *value;
  m.factor = v.factor;
  m.dims = v.dims;
  return m;
}

std::optional<double> AimLowerer::contextFactor(const Instance &representation, const Dims &dims) {
  const Instance context = representation.ref("context_of_items");
  if (context.isA("global_unit_assigned_context"))
    for (const Instance &u : context.refs("units"))
      if (UnitValue v = unit(u); v.error.empty() && v.dims == dims)
        return v.factor;
  return std::nullopt;
}

double AimLowerer::lengthFactor(const Instance &representation) {
  if (std::optional<double> f = contextFactor(representation, kLength))
    return *f;
  const Instance context = representation.ref("context_of_items");
  if (context && reported_.insert(context.index()).second)
    base_.assumed(context, "units", "give no length unit; assumed mm");
  return 1;
}

std::optional<std::string> AimLowerer::word(const Instance &of, std::string_view property) {
  for (const Instance &rep : propertyRepresentations(of, property, false))
    for (const Instance &item : rep.refs("items"))
      if (item.isA("descriptive_representation_item"))
        if (auto d = item.string("description"))
          return normalName(*d);
  return std::nullopt;
}

// --- the program ------------------------------------------------------------------

Instance AimLowerer::mainWorkplan() {
  // The workplan a product_definition_process names and that is no other
  // workplan's element.
  std::vector<Instance> tops;
  for (const Instance &p : workplanProcesses_) {
    const Instance wp = p.ref("chosen_method");
    const bool element = sequenced_.count(wp.index()) > 0;
    if (!element && std::none_of(tops.begin(), tops.end(), [&](const Instance &t) { return t.index() == wp.index(); }))
      tops.push_back(wp);
  }
  if (tops.size() == 1)
    return tops.front();
  diags_.error(bound_.file().loc(0),
               tops.empty() ? std::string("no machining_workplan is the chosen method of a product_definition_process: "
                                          "the file has no main workplan to lower")
                            : std::to_string(tops.size()) +
                                  " machining_workplans are chosen methods of product_definition_processes and "
                                  "elements of none: which is the main workplan is not said");
  return {};
}

void AimLowerer::workpiece() {
  // The project's workpiece: the product definition its
  // machining_project_workpiece_relationship relates (the first, when several).
  Node wp(ir::Kind::Workpiece);
  Instance definition;
  if (!projectWorkpieces_.empty())
    definition = projectWorkpieces_.front().ref("related_product_definition");
  std::optional<std::string> name;
  if (definition) {
    base_.stamp(wp, definition, "");
    const Instance product = definition.ref("formation").ref("of_product");
    name = product.string("name");
    if (!name || name->empty())
      name = product.string("id");
    if (product)
      wp.origin = {product.id(), product.loc()};
  }
  if (name && !name->empty())
    wp.label = *name;
  wp.symbol = base_.symbolFor('%', wp.label.empty() ? std::nullopt : std::optional(wp.label), "workpiece");
  workpieceSymbol_ = wp.symbol;
  module_->root.add(std::move(wp));
}

std::unique_ptr<ir::Module> AimLowerer::run() {
  index();
  module_ = std::make_unique<ir::Module>();
  module_->sourceName = std::string(bound_.file().source().name());
  module_->aimSchema = bound_.schema().name;
  if (!projects_.empty()) {
    const Instance &p = projects_.front();
    std::optional<std::string> name = p.string("name");
    if (!name || name->empty())
      name = p.string("id");
    module_->root.label = name.value_or("");
    base_.stamp(module_->root, p, "");
  }
  const Instance main = mainWorkplan();
  if (!main)
    return nullptr;
  workpiece();
  reached_.insert(main.index());
  if (auto wp = workplan(main))
    module_->root.add(std::move(*wp));
  reportUnreached();
  // Steps whose file gives no security plane: the highest point of the
  // file's toolpaths is where its own rapids travel, so stepnc's links
  // between steps travel there too.
  const double z = highestZ_.value_or(0);
  bool assumed = false;
  auto secplanes = [&](Node &n, auto &self) -> void {
    if ((n.kind == ir::Kind::Workingstep || n.kind == ir::Kind::RapidMovement) && !n.has("secplane")) {
      n.set("secplane", Value::length(z));
      assumed = true;
    }
    for (Node &c : n.children)
      self(c, self);
  };
  secplanes(module_->root, secplanes);
  if (assumed) {
    diags_.assumption(main.loc(), "its workingsteps give no security plane; assumed z=" + formatTrimmed(z, 4) +
                                   " mm, the highest point of the file's toolpaths")
        .entity(main.id(), entityUpper(main));
  }
  return std::move(module_);
}

void AimLowerer::executable(const Instance &exe, Node &parent) {
  reached_.insert(exe.index());
  std::optional<Node> n;
  if (exe.isA("machining_workingstep"))
    n = workingstep(exe);
  else if (exe.isA("machining_workplan"))
    n = workplan(exe);
  else if (exe.isA("machining_rapid_movement"))
    n = rapidMovement(exe);
  else
    base_.unsupported(exe, "executable");
  if (n)
    parent.add(std::move(*n));
}

std::optional<Node> AimLowerer::workplan(const Instance &wp) {
  if (!workplansOnStack_.insert(wp.index()).second) {
    base_.missing(wp, "elements", "make a cycle: the workplan is an element of itself");
    return std::nullopt;
  }
  Node n(ir::Kind::Workplan);
  base_.stamp(n, wp, "name");
  n.symbol = base_.symbolFor('@', wp.string("name"), "workplan");
  for (const Instance &exe : related(wp, "machining_process_sequence_relationship"))
    executable(exe, n);
  workplansOnStack_.erase(wp.index());
  return n;
}

std::optional<std::string> AimLowerer::stepFeature(const Instance &ws, bool followsToolpaths) {
  Instance feature;
  for (const Instance &process : related(ws, "machining_feature_relationship"))
    if (auto it = featureOfProcess_.find(process.index()); it != featureOfProcess_.end())
      feature = at(it->second);
  // A toolpath-only feature is an instanced_feature described 'toolpath'
  // (its first description, the characterized_object's).
  const bool toolpathOnly =
      !feature || (feature.isA("instanced_feature") &&
                   normalName(feature.string("description").value_or("")) == "toolpath");
  if (!toolpathOnly && isLoweredFeature(feature))
    return machiningFeature(feature);
  if (!followsToolpaths) {
    if (!feature)
      base_.missing(ws, "feature",
                    "is not given: no machining_feature_relationship and process_property_association give the "
                    "workingstep a feature, and its operation has no toolpaths to follow");
    else if (reported_.insert(feature.index()).second)
      report(feature, feature.loc(),
             "the feature '" + feature.string("description").value_or("") +
                 "' is not one stepnc lowers yet (round holes, closed rectangular pockets, straight slots of square U "
                 "section; docs/ap238.md), and "
                 "the operation of workingstep " + hashId(ws.id()) + " has no toolpaths to follow");
    return std::nullopt;
  }
  if (!toolpathOnly)
    diags_.assumption(feature.loc(), "the feature '" + feature.string("description").value_or("") +
                                         "' is not lowered yet (AP238 machining features: docs/ap238.md); the "
                                         "step's toolpaths are followed as the file gives them, without its shape")
        .entity(feature.id(), entityUpper(feature));
  return toolpathFeature(ws, feature);
}

std::string AimLowerer::toolpathFeature(const Instance &ws, const Instance &feature) {
  const size_t key = feature ? feature.index() : ws.index();
  if (auto it = lowered_.find(key); it != lowered_.end())
    return it->second;
  Node f(ir::Kind::ToolpathFeature);
  base_.stamp(f, feature ? feature : ws, "");
  std::optional<std::string> label = feature ? feature.string("name") : std::nullopt;
  if (label && !label->empty())
    f.label = *label;
  else
    label = "toolpath " + ws.string("name").value_or("");
  f.symbol = base_.symbolFor('%', label, "toolpath_feature");
  f.set("at", Value::point(Vec3::Zero()));
  f.set("axis", Value::direction(Vec3::UnitZ()));
  f.set("ref", Value::direction(Vec3::UnitX()));
  lowered_[key] = f.symbol;
  for (Node &c : module_->root.children)
    if (c.symbol == workpieceSymbol_)
      c.add(std::move(f));
  return lowered_[key];
}

std::optional<Node> AimLowerer::workingstep(const Instance &ws) {
  Node n(ir::Kind::Workingstep);
  base_.stamp(n, ws, "name");
  n.symbol = base_.symbolFor('@', ws.string("name"), "ws");
  const std::vector<Instance> ops = related(ws, "machining_operation_relationship");
  if (ops.size() != 1) {
    base_.missing(ws, "operation",
                  ops.empty() ? std::string("is not given: no machining_operation_relationship relates the "
                                            "workingstep to an operation")
                              : "is not one: " + std::to_string(ops.size()) +
                                  " machining_operation_relationships relate the workingstep to operations");
    return std::nullopt;
  }
  std::optional<Node> op = operation(ops.front());
  if (!op)
    return std::nullopt;
  const std::optional<std::string> feature = stepFeature(ws, op->child(ir::Kind::Toolpath) != nullptr);
  if (!feature)
    return std::nullopt;
  n.set("feature", Value::ref(*feature));
  if (auto z = securityPlane(ws))
    n.set("secplane", Value::length(*z));
  n.add(std::move(*op));
  return n;
}

std::optional<double> AimLowerer::securityPlane(const Instance &ws) {
  for (const Instance &rep : propertyRepresentations(ws, "security plane", false))
    for (const Instance &item : rep.refs("items")) {
      if (!item.isA("plane")) {
        base_.unsupported(item, "a security plane that is not a plane");
        continue;
      }
      const Instance position = item.ref("position");
      const std::optional<Placement> p = base_.placement(position);
      if (!p) {
        base_.missing(item, "position");
        continue;
      }
      if (std::abs(p->axis.z()) < 1 - 1e-9) {
        base_.unsupported(item, "a security plane not normal to z");
        continue;
      }
      return p->at.z() * lengthFactor(rep);
    }
  return std::nullopt;
}

std::optional<Node> AimLowerer::rapidMovement(const Instance &rm) {
  Node n(ir::Kind::RapidMovement);
  base_.stamp(n, rm, "name");
  n.symbol = base_.symbolFor('@', rm.string("name"), "rapid");
  toolpaths(rm, n);
  return n;
}

std::optional<Node> AimLowerer::operation(const Instance &op) {
  reached_.insert(op.index());
  if (!op.isA("milling_type_operation") && !op.isA("drilling_type_operation") && !op.isA("turning_type_operation")) {
    base_.unsupported(op, "operation");
    return std::nullopt;
  }
  // An operation with toolpaths (what CAM systems write) is lowered as the
  // freeform operation of ISO 14649-11, which follows them exactly; one
  // without is the ARM operation its entity and description name, whose
  // path stepnc's strategies make.
  const bool followsToolpaths = !related(op, "machining_toolpath_sequence_relationship").empty();
  Node n(ir::Kind::FreeformOperation);
  if (op.isA("turning_type_operation")) {
    // A lathe operation is the ISO 14649-12 operation its entity and
    // description name, its toolpaths or not (docs/turning.md).
    if (std::optional<ir::Kind> kind = turningOperationKind(op))
      n.kind = *kind;
    else
      return std::nullopt;
  } else if (!followsToolpaths) {
    if (std::optional<ir::Kind> kind = strategyOperationKind(op))
      n.kind = *kind;
    else
      return std::nullopt;
  }
  base_.stamp(n, op, "name");
  auto t = toolOf_.find(op.index());
  if (t == toolOf_.end()) {
    base_.missing(op, "tool", "is not given: no machining_tool names the operation in its usage");
    return std::nullopt;
  }
  if (auto symbol = tool(at(t->second)))
    n.set("tool", Value::ref(*symbol));
  else
    return std::nullopt;
  const std::vector<Instance> techs = related(op, "machining_technology_relationship");
  if (techs.empty()) {
    base_.missing(op, "technology",
                  "is not given: no machining_technology_relationship gives the operation its feed and speed");
    return std::nullopt;
  }
  n.add(technology(techs.front()));
  if (const std::vector<Instance> functions = related(op, "machining_functions_relationship"); !functions.empty())
    n.add(machineFunctions(functions.front()));
  operationParameters(op, n);
  if (followsToolpaths) {
    toolpaths(op, n);
    if (!n.child(ir::Kind::Toolpath))
      return std::nullopt;  // each toolpath said why it was not lowered
  } else {
    strategies(op, n);
  }
  return n;
}

std::optional<std::string> AimLowerer::tool(const Instance &t) {
  if (auto it = lowered_.find(t.index()); it != lowered_.end())
    return it->second;
  Node n(ir::Kind::Tool);
  base_.stamp(n, t, "name");
  n.symbol = base_.symbolFor('%', t.string("name"), "tool");
  // The kind: the tool body representation's name ('endmill', 'twist
  // drill'), else the action_resource_type's ('milling cutting tool').
  std::string kind;
  for (const Instance &body : propertyRepresentations(t, "tool body", true))
    if (auto name = body.string("name"); name && !name->empty())
      kind = normalName(*name);
  if (kind.empty())
    kind = normalName(t.ref("kind").string("name").value_or(""));
  static const std::pair<std::string_view, std::string_view> kKinds[] = {
      {"groov", "grooving_tool"},      {"knurl", "knurling_tool"},    {"turning", "turning_tool"},
      {"ball", "ball_endmill"},        {"bull", "bullnose_endmill"},  {"face", "facemill"},
      {"center", "center_drill"},      {"centre", "center_drill"},    {"spot", "spot_drill"},
      {"twist", "twist_drill"},        {"drill", "twist_drill"},      {"ream", "reamer"},
      {"tap", "tap"},                  {"bor", "boring_tool"},        {"countersink", "countersink"},
      {"counterbore", "counterbore"},  {"side mill", "side_mill"},    {"t slot", "t_slot_mill"},
      {"end", "endmill"},              {"mill", "endmill"},           {"thread", "threading_tool"}};
  std::string_view type;
  for (const auto &[word, irType] : kKinds)
    if (type.empty() && kind.find(word) != std::string::npos)
      type = irType;
  if (type.empty()) {
    type = "cutting_tool";
    base_.assumed(t, "kind", "is '" + kind + "', no kind of tool stepnc knows; read as a cutting tool of the "
                                            "diameter the file gives");
  }
  n.set("type", Value::word(std::string(type)));
  // Dimensions: measure items of any of its representations and of those
  // related to them (a tool body's dimension representation).
  std::vector<Instance> reps;
  std::vector<std::pair<std::string, Instance>> props = properties(t, true);
  if (auto it = componentsOf_.find(t.index()); it != componentsOf_.end())
    for (size_t component : it->second)
      for (auto &p : properties(at(component), true))
        props.push_back(p);
  for (auto &[property, rep] : props)
    for (const Instance &r : withRelated(rep))
      if (std::none_of(reps.begin(), reps.end(), [&](const Instance &o) { return o.index() == r.index(); }))
        reps.push_back(r);
  for (const Instance &rep : reps)
    for (const Instance &item : rep.refs("items")) {
      if (item.isA("descriptive_representation_item") &&
          normalName(item.string("name").value_or("")) == "hand of cut") {
        // 'right', 'left' or 'neutral' (ISO 14649-111 hand_of_cut, -121 hand_of_tool).
        const std::string hand = normalName(item.string("description").value_or(""));
        if (hand == "right" || hand == "left" || hand == "neutral")
          n.set("hand", Value::word(hand));
        else
          report(item, item.loc(), "'hand of cut' is '" + hand + "': right, left or neutral");
        continue;
      }
      if (!item.isA("measure_representation_item"))
        continue;
      const std::optional<Measure> m = measure(item);
      if (!m)
        continue;
      struct Row {
        std::string_view names;
        const char *attribute;
        Dims dims;
      };
      static const Row kRows[] = {
          {"|diameter|cutting diameter|tool diameter|", "diameter", kLength},
          {"|corner radius|edge radius|nose radius|", "corner_radius", kLength},
          {"|overall assembly length|overall length|functional length|tool length|", "overall_length", kLength},
          {"|offset length|", "offset_length", kLength},
          {"|cutting edge length|flute length|", "cutting_edge_length", kLength},
          {"|tool tip half angle|", "tip_half_angle", kAngle},
          {"|taper angle|", "taper_angle", kAngle},
          {"|number of teeth|number of effective teeth|number of flutes|", "flutes", Dims{}},
      };
      bool used = false;
      for (const Row &r : kRows) {
        if (r.names.find("|" + m->name + "|") == std::string_view::npos)
          continue;
        used = true;
        if (!(m->dims == r.dims)) {
          wrongUnit(item, item.loc(), m->name, r.dims, m->dims);
          continue;
        }
        if (std::string_view(r.attribute) == "flutes")
          n.set("flutes", Value::integer(std::llround(m->value)));
        else if (r.dims == kAngle)
          n.set(r.attribute, Value::angle(m->value));
        else
          n.set(r.attribute, Value::length(m->value));
      }
      if (!used && reported_.insert(item.index()).second)
        diags_.remark(item.loc(), "tool property '" + m->name + "' is not read by stepnc")
            .entity(item.id(), entityUpper(item));
    }
  // A lathe insert has no diameter; every milling and hole-making tool has.
  const bool lathe = type == "turning_tool" || type == "grooving_tool" || type == "threading_tool" ||
                     type == "knurling_tool";
  if (!lathe && !n.has("diameter")) {
    base_.missing(t, "diameter", "is not given: no resource property of the tool has a 'diameter' measure");
    return std::nullopt;
  }
  if (n.has("overall_length") && !n.has("offset_length"))
    n.set("offset_length", Value::length(*n.number("overall_length")));
  const std::string symbol = n.symbol;
  lowered_[t.index()] = symbol;
  // After the workpiece; the workplan that uses the tool is added after it.
  module_->root.add(std::move(n));
  return symbol;
}

Node AimLowerer::technology(const Instance &tech) {
  Node n(ir::Kind::Technology);
  base_.stamp(n, tech, "");
  for (auto &[property, rep] : properties(tech, false)) {
    for (const Instance &item : rep.refs("items")) {
      if (item.isA("descriptive_representation_item")) {
        if (property == "feedrate reference") {
          const std::string d = normalName(item.string("description").value_or(""));
          n.set("feed_reference", Value::word(d.find("contact") != std::string::npos ? "ccp" : "tcp"));
        }
        continue;
      }
      if (!item.isA("measure_representation_item"))
        continue;
      const std::optional<Measure> m = measure(item);
      if (!m)
        continue;
      auto wrong = [&](std::string_view expected) {
        report(item, item.loc(),
               "'" + m->name + "' of property '" + property + "': expected " + std::string(expected) +
                   ", its unit is " + dimsText(m->dims));
      };
      if (property == "feedrate" || property == "feed") {
        // Edition 1 gives a feed per revolution or per tooth as a length
        // item of that name (its WHERE rules ask for a length unit).
        const std::string kind = m->name.empty() ? normalName(rep.string("name").value_or("")) : m->name;
        if (m->dims == kLength && kind == "feed per revolution")
          n.set("feed_per_rev", Value::feedPerRev(m->value));
        else if (m->dims == kLength && kind == "feed per tooth")
          n.set("feed_per_tooth", Value::length(m->value));
        else if (m->dims == kFeed)
          n.set("feed", Value::feed(m->scaled(60)));
        else if (m->dims == kFeedPerRev)
          n.set("feed_per_rev", Value::feedPerRev(m->value));
        else
          wrong("a feed (length per minute or per revolution)");
      } else if (property == "spindle") {
        const bool maximum = m->name.find("maximum") != std::string::npos;
        if (m->dims == kRotation)
          n.set(maximum ? "spindle_max" : "spindle", Value::spindle(maximum ? std::abs(m->scaled(60)) : m->scaled(60)));
        else if (m->dims == kFeed)
          n.set("cutting_speed", Value::feed(m->scaled(60)));
        else
          wrong("a rotational speed (revolutions per minute) or a surface speed");
      } else if (reported_.insert(item.index()).second) {
        diags_.remark(item.loc(), "technology property '" + property + "' is not read by stepnc")
            .entity(item.id(), entityUpper(item));
      }
    }
  }
  if (!n.has("feed_reference"))
    n.set("feed_reference", Value::word("tcp"));
  return n;
}

Node AimLowerer::machineFunctions(const Instance &mf) {
  Node n(ir::Kind::MachineFunctions);
  base_.stamp(n, mf, "");
  if (auto coolant = word(mf, "coolant")) {
    const bool off = coolant->find("off") != std::string::npos;
    n.set("coolant", Value::boolean(!off));
    if (!off && coolant->find("mist") != std::string::npos)
      n.set("mist", Value::boolean(true));
  }
  if (auto through = word(mf, "through spindle coolant"))
    n.set("through_spindle_coolant", Value::boolean(through->find("off") == std::string::npos));
  if (auto chips = word(mf, "chip removal"))
    n.set("chip_removal", Value::boolean(chips->find("off") == std::string::npos));
  return n;
}

void AimLowerer::toolpaths(const Instance &owner, Node &parent) {
  for (const Instance &tp : related(owner, "machining_toolpath_sequence_relationship"))
    if (auto n = toolpath(tp))
      parent.add(std::move(*n));
}

std::optional<Node> AimLowerer::toolpath(const Instance &tp) {
  reached_.insert(tp.index());
  if (!tp.isA("machining_toolpath")) {
    base_.unsupported(tp, "toolpath");
    return std::nullopt;
  }
  Node n(ir::Kind::Toolpath);
  base_.stamp(n, tp, "");
  static const std::pair<std::string_view, std::string_view> kRoles[] = {
      {"approach", "approach"}, {"lift", "lift"}, {"connect", "connect"}, {"non contact", "non_contact"},
      {"contact", "contact"},   {"trajectory path", "trajectory_path"}};
  std::string role = "trajectory_path";
  if (auto type = word(tp, "trajectory type")) {
    bool known = false;
    for (const auto &[name, irRole] : kRoles)
      if (*type == name) {
        role = irRole;
        known = true;
      }
    if (!known)
      diags_.assumption(tp.loc(), "its trajectory type '" + *type +
                                      "' is not one of ISO 14649's; read as a trajectory path")
          .entity(tp.id(), entityUpper(tp));
  }
  n.set("role", Value::word(role));
  n.set("required", Value::boolean(word(tp, "priority").value_or("required") != "suggested"));
  for (const Instance &rep : propertyRepresentations(tp, "speed profile", false))
    for (const Instance &item : rep.refs("items"))
      if (item.isA("descriptive_representation_item") && normalName(item.string("description").value_or("")) == "rapid")
        n.set("rapid", Value::boolean(true));
  if (auto direction = word(tp, "direction"); direction && direction->find("end to beginning") != std::string::npos)
    n.set("reversed", Value::boolean(true));
  if (const std::vector<Instance> techs = related(tp, "machining_technology_relationship"); !techs.empty())
    n.add(technology(techs.front()));
  if (const std::vector<Instance> functions = related(tp, "machining_functions_relationship"); !functions.empty())
    n.add(machineFunctions(functions.front()));
  if (normalName(tp.string("description").value_or("")) == "feedstop") {
    // A dwell: the time of its 'dwell' property.
    for (const Instance &rep : propertyRepresentations(tp, "dwell", false))
      for (const Instance &item : rep.refs("items"))
        if (item.isA("measure_representation_item"))
          if (std::optional<Measure> m = measure(item); m && m->dims == kTime && m->value >= 0)
            n.set("dwell", Value::time(m->value));
    if (!n.has("dwell")) {
      base_.missing(tp, "dwell", "is not given: a feedstop toolpath needs a 'dwell' property with a time");
      return std::nullopt;
    }
    return n;
  }
  std::vector<Instance> toolAxes;
  for (auto &[property, rep] : properties(tp, false)) {
    if (property == "tool axis")
      toolAxes.push_back(rep);
    else if (property == "surface normal" || property == "cross section area" || property == "contact point")
      base_.unsupported(rep, property + " curves of a toolpath (cutting-contact data)");
  }
  std::optional<Node> c = basicCurve(tp);
  if (!c)
    return std::nullopt;
  // The tool axis curve (ISO 14649-11's its_toolaxis as AP238 maps it: an
  // action property 'tool axis' whose representation holds the curve), read
  // as the ARM's is.
  if (toolAxes.size() > 1) {
    base_.missing(tp, "tool axis", "is not one: the toolpath has several 'tool axis' properties");
    return std::nullopt;
  }
  if (!toolAxes.empty()) {
    const std::vector<Instance> items = toolAxes.front().refs("items");
    if (items.size() != 1) {
      base_.missing(toolAxes.front(), "items", "must be one curve (the representation of a toolpath's tool axis)");
      return std::nullopt;
    }
    base_.toolAxes(tp, items.front(), *c, "tool axis");
  }
  n.add(std::move(*c));
  return n;
}

void AimLowerer::scaleLengths(Node &n, double factor) {
  for (ir::Attr &a : n.attrs) {
    if (a.value.type == ir::ValueType::Length)
      a.value.number *= factor;
    else if (a.value.type == ir::ValueType::Point)
      a.value.vec *= factor;
  }
  for (Node &c : n.children)
    scaleLengths(c, factor);
}

void AimLowerer::trimByPoints(Node &n, double angleToRad) {
  // A circle trimmed by parameters (0 and 2 pi: a whole turn) is trimmed by
  // the points those angles give: the IR follows trims by point.
  for (Node &c : n.children)
    trimByPoints(c, angleToRad);
  if (n.kind != ir::Kind::TrimmedCurve || n.children.empty() || n.children.front().kind != ir::Kind::Circle)
    return;
  const Node &circle = n.children.front();
  const Vec3 at = *circle.vec("at"), axis = *circle.vec("axis"), ref = *circle.vec("ref");
  const double r = *circle.number("radius");
  const Vec3 y = axis.cross(ref);
  for (std::string_view side : {"from", "to"}) {
    const std::string param = std::string(side) + "_param", point = std::string(side) + "_point";
    if (n.has(point) || !n.has(param))
      continue;
    const double t = *n.number(param) * angleToRad;
    n.set(point, Value::point(at + r * (std::cos(t) * ref + std::sin(t) * y)));
  }
}

void AimLowerer::highest(const Node &curve) {
  // Points the tool passes: polyline points and trimming points; not the
  // origins (`at`) of circles, lines and helices.
  for (const ir::Attr &a : curve.attrs)
    if (a.value.type == ir::ValueType::Point && (a.name != "at" || curve.kind == ir::Kind::Point))
      highestZ_ = std::max(highestZ_.value_or(a.value.vec.z()), a.value.vec.z());
  for (const Node &c : curve.children)
    highest(c);
}

std::optional<Node> AimLowerer::basicCurve(const Instance &tp) {
  const std::vector<Instance> reps = propertyRepresentations(tp, "basic curve", false);
  if (reps.size() != 1) {
    base_.missing(tp, "basic curve",
                  reps.empty() ? "is not given: no action_property 'basic curve' gives the toolpath's curve"
                               : "is not one: the toolpath has several 'basic curve' properties");
    return std::nullopt;
  }
  const Instance &rep = reps.front();
  const std::vector<Instance> items = rep.refs("items");
  if (items.size() != 1) {
    base_.missing(rep, "items", "must be one curve (the representation of a toolpath's basic curve)");
    return std::nullopt;
  }
  std::optional<Node> c = base_.curve(items.front());
  if (!c)
    return std::nullopt;
  // Angles in the context's unit; ISO 10303-41's default is the radian.
  trimByPoints(*c, contextFactor(rep, kAngle).value_or(180 / std::numbers::pi) * std::numbers::pi / 180);
  if (const double f = lengthFactor(rep); f != 1)
    scaleLengths(*c, f);
  highest(*c);
  return c;
}

std::unique_ptr<ir::Module> lowerAimToFeatureIR(const binding::BoundFile &bound, DiagnosticEngine &diags,
                                                const LowerOptions &options) {
  AimLowerer lowerer(bound, diags, options);
  return lowerer.run();
}

} // namespace stepnc::lowering
