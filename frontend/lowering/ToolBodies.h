// ISO 14649-111 tool bodies and the IR tool types they are: one table that
// lowering reads one way (an ARM file's body entity to the IR's type) and the
// ARM writer the other (backends/step-nc/ArmFromIr.cpp).
#pragma once

#include <string_view>
#include <utility>

namespace stepnc::lowering {

/// ARM tool body entity -> IR tool type; the most specific entity first, so
/// that the first whose entity an instance is names its type.
inline constexpr std::pair<std::string_view, std::string_view> kToolBodies[] = {
    {"ball_endmill", "ball_endmill"},     {"bullnose_endmill", "bullnose_endmill"},
    {"tapered_endmill", "tapered_endmill"}, {"endmill", "endmill"},
    {"facemill", "facemill"},             {"side_mill", "side_mill"},
    {"t_slot_mill", "t_slot_mill"},       {"tapered_drill", "tapered_drill"},
    {"twist_drill", "twist_drill"},       {"spot_drill", "spot_drill"},
    {"centerdrill", "center_drill"},      {"tapered_reamer", "tapered_reamer"},
    {"reamer", "reamer"},                 {"tap", "tap"},
    {"boring_tool", "boring_tool"},       {"countersink", "countersink"},
    {"counterbore", "counterbore"}};

/// The body entity (lower case) of an IR tool type; empty for a type no ARM
/// body names.
constexpr std::string_view toolBodyEntity(std::string_view type) {
  for (const auto &[entity, word] : kToolBodies)
    if (word == type)
      return entity;
  return {};
}

} // namespace stepnc::lowering
