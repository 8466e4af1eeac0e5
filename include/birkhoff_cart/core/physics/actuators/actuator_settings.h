// The actuator sections a scene may enable (docs/scenes.md "steering_actuator", "drive_actuator",
// "steering_end_stops"; docs/actuators.md). Absent sections: commands reach the cart unchanged and χ
// has no stops, at no cost.
#pragma once

#include <optional>

#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"
#include "birkhoff_cart/core/physics/actuators/torque_actuator.h"

namespace birkhoff_cart {

struct ActuatorSettings {
  std::optional<TorqueActuatorSettings> steering;        ///< between steering_torque's input and the hinge
  std::optional<TorqueActuatorSettings> drive;           ///< between drive_torque's input and the rear axle
  std::optional<SteeringEndStopSettings> end_stops;      ///< |χ| ≤ angle
  bool any() const { return steering || drive || end_stops; }
};

}  // namespace birkhoff_cart
