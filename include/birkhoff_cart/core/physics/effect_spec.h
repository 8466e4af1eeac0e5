// One effect as a scene enables it (name, torque profile, coefficients): plain data that the effect
// library (effect_library.h) turns into an Effect.
#pragma once

#include <map>
#include <string>

#include "birkhoff_cart/core/physics/torque_profile.h"

namespace birkhoff_cart {

/// One enabled effect as the scene names it.
struct EffectSpec {
  std::string name;                           ///< steering_torque, drive_torque, rolling_resistance, ...
  TorqueProfile profile;                      ///< for steering_torque and drive_torque
  std::map<std::string, double> coefficients; ///< for the others, e.g. {"coefficient": 0.015, "speed_epsilon": 0.05}
};

}  // namespace birkhoff_cart
