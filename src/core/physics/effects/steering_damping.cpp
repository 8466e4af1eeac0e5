// Viscous steering damping, docs/derivation.md eq. (4.5).
#include "birkhoff_cart/core/physics/effects/steering_damping.h"

#include <cmath>

namespace birkhoff_cart {

SteeringDamping::SteeringDamping(double coefficient) : coefficient_(coefficient) {}

const std::string& SteeringDamping::name() const {
  static const std::string kName = "steering_damping";
  return kName;
}

void SteeringDamping::add_to(const EffectInput& input, GeneralizedForce& total) const {
  total.force(1) += -coefficient_ * input.steering_rate;  // Q2 += −b ω2   (eq. (4.5))
  total.jacobian(1, 2) += -coefficient_;                  // ∂Q2/∂ω2
}

}  // namespace birkhoff_cart
