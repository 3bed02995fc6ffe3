// Moves written as ISO 14649 toolpaths, and the file description: what both
// STEP-NC writers share (the machine-optimised file patched into an ARM
// input, OptimisedFile.h, and the ARM file written from the IR of an AP238
// AIM input, ArmFromIr.h).
//
// A workingstep's moves become a TOOLPATH_LIST of CUTTER_LOCATION_TRAJECTORY
// and FEEDSTOP instances in the frame of its feature: one polyline per run of
// straight moves of one kind, role and feed; each arc a trimmed circle, or a
// trimmed helix when it changes height, about its own axis (x, y or z); each
// dwell a feedstop. Feeds are milling technologies of their own. Values are
// written so that lowering the file gives them back bit for bit: points as
// the local coordinates whose mapping gives the workpiece coordinates
// exactly, speeds as the measures whose unit conversion gives them exactly.
#pragma once

#include "frontend/part21/Part21File.h"
#include "ir/Node.h"
#include "ir/geom/FeatureShape.h"
#include "support/Diagnostics.h"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

namespace stepnc::backends {

/// FILE_DESCRIPTION with `lines` first, `holds` (what the file holds) after
/// the first of them, then the input's own description.
/// Quotes in `lines` become double quotes: Open CASCADE 7.6's STEP reader
/// fails on a doubled quote followed by ',' or ')' inside a string.
std::string fileDescription(const p21::Part21File &input, const std::vector<std::string> &lines,
                            std::string_view holds);

/// `p` (workpiece coordinates) in the frame `f`: the local point that
/// expand-strategies maps back to exactly `p` where one is found.
ir::Vec3 localPoint(const ir::PlaneFrame &f, const ir::Vec3 &p);

/// New instances, numbered from a first id, as canonical Part 21 lines.
/// Points and directions of equal coordinates are written once.
class Instances {
public:
  explicit Instances(p21::InstanceId first) : next_(first) {}

  p21::InstanceId add(std::string_view entity, std::string_view params);
  p21::InstanceId point(const ir::Vec3 &p);
  p21::InstanceId direction(const ir::Vec3 &d);
  /// An axis2_placement_3d at `at` with local z `axis` and local x `ref`.
  p21::InstanceId placement(const ir::Vec3 &at, const ir::Vec3 &axis = ir::Vec3::UnitZ(),
                            const ir::Vec3 &ref = ir::Vec3::UnitX());

  static std::string ref(p21::InstanceId id) { return '#' + std::to_string(id); }
  /// A real as the canonical writer writes it (shortest round trip).
  static std::string real(double v);
  static std::string reals(const ir::Vec3 &v);

  p21::InstanceId firstFree() const { return next_; }
  const std::string &text() const { return text_; }

private:
  using Key = std::array<double, 3>;
  p21::InstanceId shared(std::map<Key, p21::InstanceId> &pool, const ir::Vec3 &v, std::string_view entity);

  p21::InstanceId next_;
  std::string text_;
  std::map<Key, p21::InstanceId> points_, directions_;
};

/// Writes the moves of workingsteps as toolpath lists.
class ToolpathWriter {
public:
  /// Feeds and spindle speeds are written in `units` (the file's own).
  ToolpathWriter(Instances &out, const ir::SourceUnits &units, DiagnosticEngine &diags)
      : out_(out), units_(units), diags_(diags) {}

  /// The TOOLPATH_LIST of `ws`'s `moves`, in the frame of its feature; none
  /// (after an error) when a move cannot be written, or (silently) when the
  /// moves are a single positioning. `start`: where the tool stands before
  /// the step, when the step starts there and not from the security plane.
  std::optional<p21::InstanceId> write(const ir::Node &ws, const ir::Node &moves, const ir::PlaneFrame &frame,
                                       const std::string &feedReference, std::optional<ir::Vec3> start);

  bool failed() const { return failed_; }

private:
  /// A run of straight moves of one kind, type and feed: one polyline.
  struct Run {
    bool rapid = false;
    std::string type;
    double feed = 0;
    std::vector<ir::Vec3> points;  ///< workpiece coordinates, from the run's start
  };

  void fail(const ir::Node &move, const std::string &why);
  void flush();
  bool arc(const ir::Vec3 &from, const ir::Node &m, std::string_view type, double feed);
  void trajectory(std::string_view type, bool rapid, double feed, p21::InstanceId curve);
  p21::InstanceId technology(double feed);

  Instances &out_;
  const ir::SourceUnits &units_;
  DiagnosticEngine &diags_;
  const ir::Node *ws_ = nullptr;
  const ir::PlaneFrame *frame_ = nullptr;
  double spindle_ = 0;
  std::string feedReference_;
  Run run_;
  std::vector<p21::InstanceId> trajectories_;
  std::map<std::tuple<double, double, std::string>, p21::InstanceId> technologies_;
  bool failed_ = false;
};

} // namespace stepnc::backends
