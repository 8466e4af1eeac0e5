// Steering hinge torsion spring, docs/derivation.md eq. (4.6).
#include "birkhoff_cart/core/physics/effects/steering_stiffness.h"

#include <cmath>

namespace birkhoff_cart {

SteeringStiffness::SteeringStiffness(double coefficient) : coefficient_(coefficient) {}

const std::string& SteeringStiffness::name() const {
  static const std::string kName = "steering_stiffness";
  return kName;
}

void SteeringStiffness::add_to(const EffectInput& input, GeneralizedForce& total) const {
  total.force(1) += -coefficient_ * input.steering_angle;  // Q2 += −k_s χ   (eq. (4.6))
  total.jacobian(1, 0) += -coefficient_;                   // ∂Q2/∂χ
}

}  // namespace birkhoff_cart
