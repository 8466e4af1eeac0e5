// Quadratic air drag at the rear-axle midpoint A, docs/derivation.md eq. (4.4).
#include "birkhoff_cart/core/physics/effects/air_drag.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <cmath>

namespace birkhoff_cart {

AirDrag::AirDrag(double coefficient) : coefficient_(coefficient) {}

const std::string& AirDrag::name() const {
  static const std::string kName = "air_drag";
  return kName;
}

void AirDrag::add_to(const EffectInput& input, GeneralizedForce& total) const {
  const double s = input.sin_steering_angle();
  const double c = input.cos_steering_angle();
  const double speed_a = input.forward_speed * c;  // v_A = ω1 cos χ [m/s]   (eq. (2.3))
  const double k = coefficient_;
  // Q1 += −k |v_A| v_A cos χ   (eq. (4.4))
  total.force(0) += -k * std::abs(speed_a) * speed_a * c;
  total.jacobian(0, 0) += 3.0 * k * s * std::abs(speed_a) * speed_a;  // ∂Q1/∂χ
  total.jacobian(0, 1) += -2.0 * k * std::abs(speed_a) * c * c;       // ∂Q1/∂ω1
}

}  // namespace birkhoff_cart
