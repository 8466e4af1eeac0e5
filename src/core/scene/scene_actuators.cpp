// The actuator sections of a scene file (docs/scenes.md "steering_actuator", "drive_actuator",
// "steering_end_stops"; docs/actuators.md). Each is optional; present, it enables that actuator:
//
//   steering_actuator:            # every key optional (that stage off)
//     time_constant: 0.05         # [s]
//     dead_time: 0.02             # [s]
//     rate_limit: 20.0            # [N·m/s]
//     torque_limit: 2.0           # [N·m]
//     dead_band: 0.05             # [N·m]
//   drive_actuator: {time_constant: 0.2, torque_limit: 8.0}
//   steering_end_stops: {angle: 0.6, restitution: 0.0}
#include <cmath>
#include <string>

#include "scene_reader.h"

namespace birkhoff_cart {
namespace scene_detail {
namespace {

std::optional<TorqueActuatorSettings> read_torque_actuator(const SceneReader& reader, const YAML::Node& node,
                                                           const std::string& section) {
  if (!node) return std::nullopt;
  if (node.IsNull()) reader.fail(section, "is empty: give its keys, or leave the section out (actuator off)");
  reader.require_map(node, section, {"time_constant", "dead_time", "rate_limit", "torque_limit", "dead_band"});
  TorqueActuatorSettings settings;
  settings.time_constant = reader.optional_number(node, section, "time_constant", Range::kNonNegative, 0.0);
  settings.dead_time = reader.optional_number(node, section, "dead_time", Range::kNonNegative, 0.0);
  settings.rate_limit = reader.optional_number(node, section, "rate_limit", Range::kPositive, settings.rate_limit);
  settings.torque_limit = reader.optional_number(node, section, "torque_limit", Range::kPositive, settings.torque_limit);
  settings.dead_band = reader.optional_number(node, section, "dead_band", Range::kNonNegative, 0.0);
  return settings;
}

std::optional<SteeringEndStopSettings> read_end_stops(const SceneReader& reader, const YAML::Node& node) {
  const std::string section = "steering_end_stops";
  if (!node) return std::nullopt;
  if (node.IsNull()) reader.fail(section, "is empty: give its angle, or leave the section out (no stops)");
  reader.require_map(node, section, {"angle", "restitution"});
  SteeringEndStopSettings settings;
  settings.angle = reader.required_number(node, section, "angle", Range::kPositive);
  if (!(settings.angle < 0.5 * M_PI)) {
    reader.fail(section + ".angle", "must be below pi/2 rad (the stops sit at +-angle), got " +
                                        reader.required(node, section, "angle").Scalar());
  }
  settings.restitution = reader.optional_number(node, section, "restitution", Range::kNonNegative, 0.0);
  if (!(settings.restitution <= 1.0)) {
    reader.fail(section + ".restitution", "must be within [0, 1], got " + reader.required(node, section, "restitution").Scalar());
  }
  return settings;
}

}  // namespace

ActuatorSettings read_actuators(const SceneReader& reader, const YAML::Node& root) {
  ActuatorSettings actuators;
  actuators.steering = read_torque_actuator(reader, root["steering_actuator"], "steering_actuator");
  actuators.drive = read_torque_actuator(reader, root["drive_actuator"], "drive_actuator");
  actuators.end_stops = read_end_stops(reader, root["steering_end_stops"]);
  return actuators;
}

}  // namespace scene_detail
}  // namespace birkhoff_cart
