// Lowering of ISO 14649-17 additive features and operations with stepnc's
// extension for directed energy deposition (schemas/stepnc_additive.exp,
// docs/additive.md): the deposition head, its technology and strategy, the
// added features' shapes and the channels left empty in them.
#include "frontend/lowering/Lowerer.h"

#include "support/Format.h"

#include <cmath>

namespace stepnc::lowering {

namespace {

/// A value of the deposition technology, or another attribute, outside
/// physical sense: an error at the attribute (nothing is written from it).
bool inRange(Lowerer &l, const Instance &inst, std::string_view attribute, double value, double low, double high,
             std::string_view unit) {
  if (value >= low && value <= high)
    return true;
  l.missing(inst, attribute,
            "is " + formatShortest(value) + " " + std::string(unit) + ", outside " + formatShortest(low) + ".." +
                formatShortest(high) + " " + std::string(unit) + ", what a deposition head does");
  return false;
}

} // namespace

bool Lowerer::additiveFeature(const Instance &f, Node &n) {
  n.kind = ir::Kind::AmSimpleFeature;
  const bool extruded = f.isA("am_extruded_feature"), revolved = f.isA("am_revolved_feature");
  if (!extruded && !revolved && !f.isA("am_faceted_feature")) {
    unsupported(f, f.isA("am_simple_feature")
                       ? "feature (an am_simple_feature without a shape: stepnc builds the extruded, revolved and "
                         "faceted added features of its extension schema, docs/additive.md)"
                       : "feature");
    return false;
  }
  bool ok = true;
  if (auto p = placement(f.ref("feature_placement")))
    setPlacement(n, *p);
  else {
    missing(f, "feature_placement");
    ok = false;
  }
  copyReal(n, "skin_thickness", f, "skin_thickness", Value::length);
  // Skin and core: solid, or infill (the core's pattern, direction and
  // share are what the strategy's infill follows).
  for (auto [attribute, irName] : {std::pair{"skin_construction", "skin"}, {"core_construction", "core"}}) {
    Instance c = f.ref(attribute);
    if (!c)
      continue;
    if (c.isA("am_solid")) {
      n.set(irName, Value::word("solid"));
      continue;
    }
    if (!c.isA("am_infill")) {
      unsupported(c, "construction");
      continue;
    }
    n.set(irName, Value::word("infill"));
    if (std::string_view(irName) == "skin") {
      assumed(f, attribute,
              "is an infill; the skin is built of contour beads side by side, solid (docs/additive.md)");
      continue;
    }
    if (auto pct = c.real("infill_percentage")) {
      if (inRange(*this, c, "infill_percentage", *pct, 5, 100, "%"))
        n.set("infill_percentage", Value::ratio(*pct));
      else
        ok = false;
    }
    if (Instance d = c.ref("its_direction"))
      if (auto v = direction(d))
        n.set("infill_dir", Value::direction(*v));
    if (auto pattern = c.string("its_pattern"))
      n.set("infill_pattern", Value::string(*pattern));
  }
  if (extruded) {
    n.set("shape", Value::word("extruded"));
    if (auto h = f.real("height"))
      n.set("height", Value::length(*h));
    else {
      missing(f, "height");
      ok = false;
    }
    copyAngle(n, "draft", f, "draft_angle");
    if (auto p = profile(f.ref("its_profile")))
      n.add(std::move(*p));
    else {
      missing(f, "its_profile");
      ok = false;
    }
  } else if (revolved) {
    n.set("shape", Value::word("revolved"));
    if (auto p = profile(f.ref("its_profile")))
      n.add(std::move(*p));
    else {
      missing(f, "its_profile");
      ok = false;
    }
  } else {
    n.set("shape", Value::word("faceted"));
    for (const Instance &plane : f.refs("bounding_planes")) {
      std::optional<Placement> p = plane.isA("plane") ? placement(plane.ref("position")) : std::nullopt;
      if (!p) {
        missing(f, "bounding_planes", "each is a plane with a position (its axis out of the solid)");
        ok = false;
        continue;
      }
      Node b(ir::Kind::BoundingPlane);
      b.set("at", Value::point(p->at));
      b.set("normal", Value::direction(p->axis));
      n.add(std::move(b));
    }
  }
  for (const Instance &v : f.refs("voids")) {
    Node node(ir::Kind::AmVoid);
    stamp(node, v);
    if (auto d = toleranced(v, "diameter"); d && *d > 0)
      node.set("diameter", Value::length(*d));
    else {
      missing(v, "diameter");
      ok = false;
    }
    if (auto c = curve(v.ref("guide")))
      node.add(std::move(*c));
    else {
      missing(v, "guide");
      ok = false;
    }
    n.add(std::move(node));
  }
  return ok;
}

std::optional<std::string> Lowerer::depositionHead(const Instance &t) {
  Node n(ir::Kind::Tool);
  stamp(n, t);
  n.symbol = symbolFor('%', t.string("its_id"), "head");
  n.set("type", Value::word("deposition_head"));
  for (auto [attribute, irName] : {std::pair{"nozzle_diameter", "diameter"}, {"standoff", "standoff"},
                                   {"head_diameter", "holder_diameter"}, {"spot_diameter", "spot_diameter"}})
    if (auto v = toleranced(t, attribute)) {
      if (!inRange(*this, t, attribute, *v, 0.1, 500, "mm"))
        return std::nullopt;
      n.set(irName, Value::length(*v));
    }
  if (!n.has("standoff")) {
    missing(t, "standoff");
    return std::nullopt;
  }
  copyAngle(n, "taper_angle", t, "nozzle_angle");
  if (auto a = n.number("taper_angle"); a && !(*a >= 0 && *a < 90)) {
    missing(t, "nozzle_angle", "is " + formatShortest(*a) + " deg, no cone's half angle (0 to 90 deg)");
    return std::nullopt;
  }
  if (auto source = t.string("energy_source"))
    n.set("energy_source", Value::string(*source));
  const std::string symbol = n.symbol;
  lowered_[t.index()] = symbol;
  module_->root.add(std::move(n));
  return symbol;
}

std::optional<Node> Lowerer::additiveOperation(const Instance &op) {
  if (op.isA("am_oned_operation") || !op.isA("am_twod_operation")) {
    unsupported(op, "operation (stepnc deposits layers: an am_twod_operation as a deposition_operation)");
    return std::nullopt;
  }
  if (!op.isA("deposition_operation")) {
    diags_
        .error(op.loc(), "an ISO 14649-17 am_twod_operation names no deposition head nor technology: stepnc "
                         "deposits a deposition_operation of its extension schema (docs/additive.md)")
        .entity(op.id(), std::string(op.entityName()));
    return std::nullopt;
  }
  Node n(ir::Kind::AmTwodOperation);
  stamp(n, op);
  bool ok = true;
  if (Instance head = op.ref("its_tool"); head && head.isA("deposition_head")) {
    if (auto sym = lowered_.count(head.index()) ? std::optional(lowered_[head.index()]) : depositionHead(head))
      n.set("tool", Value::ref(*sym));
    else
      ok = false;
  } else {
    missing(op, "its_tool", "a deposition_head");
    ok = false;
  }
  // The technology.
  Instance tech = op.ref("its_technology");
  Node t(ir::Kind::DepositionTechnology);
  if (!tech) {
    missing(op, "its_technology");
    return std::nullopt;
  }
  stamp(t, tech, "");
  if (auto f = tech.real("feedrate")) {
    const double mmPerMin = feedMmPerMin(*f);
    ok = inRange(*this, tech, "feedrate", mmPerMin, 1, 60000, "mm/min") && ok;
    t.set("feed", Value::feed(mmPerMin));
  } else {
    missing(tech, "feedrate", "the travel speed along a bead");
    ok = false;
  }
  if (auto p = tech.real("power")) {
    ok = inRange(*this, tech, "power", *p, 1, 50000, "W") && ok;
    t.set("power", Value::power(*p));
  } else {
    missing(tech, "power");
    ok = false;
  }
  if (Instance feed = tech.ref("material_feed"); feed.isA("powder_feed")) {
    if (auto m = feed.real("mass_flow")) {
      ok = inRange(*this, feed, "mass_flow", *m, 0.01, 1000, "g/min") && ok;
      t.set("powder_feed", Value::massFlow(*m));
    } else {
      missing(feed, "mass_flow");
      ok = false;
    }
    if (auto gas = feed.string("carrier_gas"))
      t.set("carrier_gas", Value::string(*gas));
    copyReal(t, "carrier_gas_flow", feed, "carrier_gas_flow", Value::real);
  } else if (feed.isA("wire_feed")) {
    if (auto s = feed.real("feed_speed")) {
      const double mmPerMin = feedMmPerMin(*s);
      ok = inRange(*this, feed, "feed_speed", mmPerMin, 1, 60000, "mm/min") && ok;
      t.set("wire_feed", Value::feed(mmPerMin));
    } else {
      missing(feed, "feed_speed");
      ok = false;
    }
    copyReal(t, "wire_diameter", feed, "wire_diameter", Value::length);
  } else {
    missing(tech, "material_feed", "a powder_feed or a wire_feed");
    ok = false;
  }
  for (auto [attribute, low, high] : {std::tuple{"bead_width", 0.05, 50.0}, {"bead_height", 0.01, 20.0}}) {
    if (auto v = toleranced(tech, attribute)) {
      ok = inRange(*this, tech, attribute, *v, low, high, "mm") && ok;
      t.set(attribute, Value::length(*v));
    } else {
      missing(tech, attribute);
      ok = false;
    }
  }
  if (auto o = tech.real("overlap")) {
    ok = inRange(*this, tech, "overlap", *o, 0, 0.9, "(share of the bead width)") && ok;
    t.set("overlap", Value::ratio(*o));
  } else {
    missing(tech, "overlap");
    ok = false;
  }
  copyWord(t, "bead_profile", tech, "bead_profile");
  if (tech.enumeration("bead_profile").value_or("rectangle") != "rectangle")
    assumed(tech, "bead_profile",
            "is " + *tech.enumeration("bead_profile") + ": stepnc lays and checks beads as rectangles of the bead's "
            "width and height (docs/additive.md)");
  if (auto gas = tech.string("shielding_gas"))
    t.set("gas", Value::string(*gas));
  copyReal(t, "gas_flow", tech, "shielding_gas_flow", Value::real);
  if (auto d = tech.real("layer_dwell")) {
    ok = inRange(*this, tech, "layer_dwell", *d, 0, 3600, "s") && ok;
    t.set("layer_dwell", Value::time(*d));
  }
  if (Instance m = tech.ref("deposited_material"))
    t.set("material", Value::string(m.string("material_identifier").value_or("")));
  if (auto rho = tech.real("material_density")) {
    ok = inRange(*this, tech, "material_density", *rho, 0.5, 25, "g/cm3") && ok;
    t.set("density", Value::real(*rho));
  }
  // The operation's own attributes.
  if (auto h = toleranced(op, "layer_thickness")) {
    ok = inRange(*this, op, "layer_thickness", *h, 0.01, 20, "mm") && ok;
    n.set("layer_thickness", Value::length(*h));
    if (auto bead = t.number("bead_height"); bead && std::abs(*bead - *h) > 0.05 * *bead)
      diags_
          .warning(op.attrLoc("layer_thickness"),
                   "its layer thickness " + formatShortest(*h) + " mm is not the bead height " +
                       formatShortest(*bead) + " mm its technology deposits: the head's stand-off changes by " +
                       formatFixed(std::abs(*bead - *h), 3) + " mm every layer")
          .entity(op.id(), std::string(op.entityName()));
  } else if (auto bead = t.number("bead_height")) {
    n.set("layer_thickness", Value::length(*bead));
    assumed(op, "layer_thickness", "absent; assumed " + formatShortest(*bead) + " mm, the bead height of its technology");
  }
  if (Instance d = op.ref("normal_direction"))
    if (auto v = direction(d))
      n.set("normal", Value::direction(*v));
  if (op.ref("base_layer"))
    assumed(op, "base_layer", "is not read: layers start on the feature's placement (its base surface)");
  if (auto a = toleranced(op, "allowance")) {
    ok = inRange(*this, op, "allowance", *a, 0, 20, "mm") && ok;
    n.set("allowance", Value::length(*a));
  }
  n.add(std::move(t));
  if (Instance s = op.ref("its_strategy")) {
    Node st(ir::Kind::DepositionStrategy);
    stamp(st, s, "");
    if (auto p = s.enumeration("pattern"))
      st.set("pattern", Value::word(*p));
    else {
      missing(s, "pattern");
      ok = false;
    }
    if (auto c = s.integer("contours")) {
      if (*c < 0 || *c > 1000) {
        missing(s, "contours", "is " + std::to_string(*c) + ", not a number of contour beads (0 to 1000)");
        ok = false;
      } else {
        st.set("contours", Value::integer(*c));
      }
    }
    copyWord(st, "infill", s, "infill");
    copyAngle(st, "infill_angle", s, "infill_angle");
    copyAngle(st, "layer_rotation", s, "layer_rotation");
    copyAngle(st, "seam_shift", s, "seam_shift");
    for (std::string_view lead : {"lead_in", "lead_out"})
      if (auto v = s.real(lead)) {
        ok = inRange(*this, s, lead, *v, 0, 100, "mm") && ok;
        st.set(std::string(lead), Value::length(*v));
      }
    n.add(std::move(st));
  }
  if (!ok)
    return std::nullopt;
  return n;
}

} // namespace stepnc::lowering
