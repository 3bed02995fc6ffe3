#include "backends/Target.h"

#include <algorithm>
#include <charconv>

namespace stepnc::backends {

namespace {

bool parseInt(const std::string &text, long lo, long hi, long &out) {
  const char *end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && p == end && out >= lo && out <= hi;
}

} // namespace

const char *cycleKindName(CycleKind kind) {
  switch (kind) {
  case CycleKind::Drill: return "drill";
  case CycleKind::Peck: return "peck";
  case CycleKind::Bore: return "bore";
  case CycleKind::Tap: return "tap";
  }
  return "?";
}

std::string overrideHelp() {
  return "decimals=N (coordinates, 0..6), line-numbers=none|every, number-step=N, "
         "max-line-length=N (0: none), arcs=ijk|radius, cycles=on|off, splines=on|off, "
         "nose-compensation=path|controller, swivel-data=NAME";
}

std::string applyOverrides(TargetDescriptor &d, const std::vector<std::string> &overrides) {
  for (const std::string &o : overrides) {
    const size_t eq = o.find('=');
    if (eq == std::string::npos)
      return "--target-opt '" + o + "' is not key=value (" + overrideHelp() + ")";
    const std::string key = o.substr(0, eq), value = o.substr(eq + 1);
    long n = 0;
    if (key == "decimals" && parseInt(value, 0, 6, n)) {
      d.coordDecimals = static_cast<int>(n);
    } else if (key == "line-numbers" && (value == "none" || value == "every")) {
      if (d.numbering == Numbering::FromZero)
        return "--target-opt line-numbers: " + d.name + " numbers every block from 0; it cannot be changed";
      d.numbering = value == "none" ? Numbering::None : Numbering::Every;
    } else if (key == "number-step" && parseInt(value, 1, 1000, n)) {
      d.numberStep = static_cast<int>(n);
    } else if (key == "max-line-length" && parseInt(value, 0, 100000, n)) {
      d.maxLineLength = static_cast<size_t>(n);
    } else if (key == "arcs" && (value == "ijk" || value == "radius")) {
      if (d.arcs == ArcForm::ModalCentre)
        return "--target-opt arcs: " + d.name + " writes arcs with a centre block (CC); it cannot be changed";
      d.arcs = value == "ijk" ? ArcForm::IncrementalCentre : ArcForm::Radius;
    } else if (key == "cycles" && (value == "on" || value == "off")) {
      if (value == "off")
        d.cycles.clear();
    } else if (key == "splines" && (value == "on" || value == "off")) {
      if (value == "on" && d.splines == SplineForm::None)
        return "--target-opt splines: " + d.name + " has no spline blocks stepnc writes; smooth runs stay lines";
      if (value == "off")
        d.splines = SplineForm::None;
    } else if (key == "swivel-data") {
      // A name the cycle call carries in double quotes; "0" deselects.
      const bool plain = !value.empty() && value != "0" && std::all_of(value.begin(), value.end(), [](char c) {
        return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
      });
      if (d.swivelDataSet.empty())
        return "--target-opt swivel-data: " + d.name + " names no swivel data set";
      if (!plain)
        return "--target-opt swivel-data: '" + value + "' is not a name of letters, digits and _ (\"0\" deselects)";
      d.swivelDataSet = value;
    } else if (key == "nose-compensation" && (value == "path" || value == "controller")) {
      if (value == "controller" && !d.latheCompensation)
        return "--target-opt nose-compensation: " + d.name +
               " does not write the controller's nose radius compensation (G41/G42) in lathe programs yet (rs274 "
               "does)";
      d.controllerNoseCompensation = value == "controller";
    } else {
      return "--target-opt '" + o + "' is not understood (" + overrideHelp() + ")";
    }
  }
  return "";
}

} // namespace stepnc::backends
