// All six effects on, with non-trivial time profiles and state-dependent Jacobians: the effect set of
// the tests that check the cart's rates and their derivatives with every load acting
// (cart_birkhoffian_test, cart_jacobian_test). Header-only: every test/unit/*.cpp is its own executable.
#pragma once

#include <vector>

#include "birkhoff_cart/core/effect_spec.h"

namespace birkhoff_cart_test {

inline std::vector<birkhoff_cart::EffectSpec> all_effect_specs() {
  using birkhoff_cart::TorqueProfile;
  std::vector<birkhoff_cart::EffectSpec> specs(6);
  specs[0].name = "steering_torque";
  specs[0].profile.kind = TorqueProfile::Kind::kCosine;
  specs[0].profile.amplitude = 3.0;     // [N·m]
  specs[0].profile.frequency = 0.4;     // [Hz]
  specs[1].name = "drive_torque";
  specs[1].profile.kind = TorqueProfile::Kind::kConstant;
  specs[1].profile.value = 25.0;        // [N·m]
  specs[2].name = "rolling_resistance";
  specs[2].coefficients = {{"coefficient", 0.015}, {"speed_epsilon", 0.05}};
  specs[3].name = "air_drag";
  specs[3].coefficients = {{"coefficient", 0.4}};
  specs[4].name = "steering_damping";
  specs[4].coefficients = {{"coefficient", 2.0}};
  specs[5].name = "steering_stiffness";
  specs[5].coefficients = {{"coefficient", 15.0}};
  return specs;
}

}  // namespace birkhoff_cart_test
