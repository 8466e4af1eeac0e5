// Quadratic air drag on the rear body at A, along its heading   (docs/derivation.md eq. (4.4)):
//   v_A = ω1 cos χ,  F = −k |v_A| v_A,  Q = (F ∂v_A/∂ω1, 0) = (−k |ω1 cos χ| ω1 cos² χ, 0).
#pragma once

#include <string>

#include "birkhoff_cart/core/physics/effects.h"

namespace birkhoff_cart {

class AirDrag : public Effect {
 public:
  /// coefficient k [N·s²/m² = kg/m] ≥ 0.
  explicit AirDrag(double coefficient);
  const std::string& name() const override;
  /// With u = ω1 cos χ:  ∂Q1/∂ω1 = −2k |u| cos² χ,  ∂Q1/∂χ = 3k sin χ |u| u.
  void add_to(const EffectInput& input, GeneralizedForce& total) const override;

 private:
  double coefficient_;  ///< k [kg/m]
};

}  // namespace birkhoff_cart
