// Steering torque, docs/derivation.md eq. (4.1).
#include "birkhoff_cart/core/physics/effects/steering_torque.h"

namespace birkhoff_cart {

const std::string& SteeringTorque::name() const {
  static const std::string kName = "steering_torque";
  return kName;
}

void SteeringTorque::add_to(const EffectInput& input, GeneralizedForce& total) const {
  // Q2 += τ(t)   (eq. (4.1)); τ depends on t only, so ∂Q/∂(χ, ω) = 0.
  total.force(1) += source_.at(input.time);
}

}  // namespace birkhoff_cart
