// Viscous damping in the steering hinge: Q = (0, −b ω2)   (docs/derivation.md eq. (4.5)).
#pragma once

#include <string>

#include "birkhoff_cart/core/physics/effects.h"

namespace birkhoff_cart {

class SteeringDamping : public Effect {
 public:
  /// coefficient b [N·m·s/rad] ≥ 0.
  explicit SteeringDamping(double coefficient);
  const std::string& name() const override;
  /// Q2 += −b ω2;  ∂Q2/∂ω2 += −b.
  void add_to(const EffectInput& input, GeneralizedForce& total) const override;

 private:
  double coefficient_;  ///< b [N·m·s/rad]
};

}  // namespace birkhoff_cart
