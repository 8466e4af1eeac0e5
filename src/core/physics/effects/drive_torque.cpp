// Drive torque on the rear axle, docs/derivation.md eq. (4.2).
#include "birkhoff_cart/core/physics/effects/drive_torque.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <cmath>
#include <stdexcept>

namespace birkhoff_cart {

DriveTorque::DriveTorque(TorqueSource source, double rear_wheel_radius)
    : source_(std::move(source)), rear_wheel_radius_(rear_wheel_radius) {
  if (!std::isfinite(rear_wheel_radius) || rear_wheel_radius <= 0.0) {
    throw std::invalid_argument("effect 'drive_torque': rear wheel radius must be finite and > 0");
  }
}

const std::string& DriveTorque::name() const {
  static const std::string kName = "drive_torque";
  return kName;
}

void DriveTorque::add_to(const EffectInput& input, GeneralizedForce& total) const {
  // The rear rims roll at r1 φ̇ = ω1 cos χ ∓ …; the ∓ parts cancel over the two wheels, so the
  // total torque T does power T ω1 cos χ / r1:  Q1 += T cos χ / r1   (eq. (4.2)).
  const double torque = source_.at(input.time);  // T [N·m]
  const double per_radius = torque / rear_wheel_radius_;  // [N]
  total.force(0) += per_radius * input.cos_steering_angle();
  total.jacobian(0, 0) += -per_radius * input.sin_steering_angle();  // ∂Q1/∂χ
}

}  // namespace birkhoff_cart
