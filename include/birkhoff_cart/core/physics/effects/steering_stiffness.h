// Torsion spring centring the steering hinge: Q = (0, −k_s χ)   (docs/derivation.md eq. (4.6)).
#pragma once

#include <string>

#include "birkhoff_cart/core/physics/effects.h"

namespace birkhoff_cart {

class SteeringStiffness : public Effect {
 public:
  /// coefficient k_s [N·m/rad] ≥ 0.
  explicit SteeringStiffness(double coefficient);
  const std::string& name() const override;
  /// Q2 += −k_s χ;  ∂Q2/∂χ += −k_s.
  void add_to(const EffectInput& input, GeneralizedForce& total) const override;
  /// Q2 = −k_s χ grows with the turns: the integrators must keep χ unwrapped.
  bool periodic_in_steering_angle() const override { return false; }

 private:
  double coefficient_;  ///< k_s [N·m/rad]
};

}  // namespace birkhoff_cart
