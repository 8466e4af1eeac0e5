// Rolling resistance of the four wheels   (docs/derivation.md eq. (4.3)):
//   τ_i = −c_rr N_i r_i tanh(r_i φ̇_i / v_eps),  r_i φ̇_i = d1_i ω1 + d2_i ω2   (eq. (2.4)),
//   N = ((M1/2 + m1) g, (M1/2 + m1) g, (M2/2 + m3) g, (M2/2 + m3) g),
//   Q_σ = Σ_i τ_i d_σi / r_i = −c_rr Σ_i N_i tanh(v_i / v_eps) d_σi.
// tanh regularises the sign of the rim speed over a band of width v_eps around rest.
#pragma once

#include <array>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"

namespace birkhoff_cart {

class RollingResistance : public Effect {
 public:
  /// coefficient c_rr [-] ≥ 0, speed_epsilon v_eps [m/s] > 0. Copies the model.
  RollingResistance(const CartModel& model, double coefficient, double speed_epsilon);
  const std::string& name() const override;
  void add_to(const EffectInput& input, GeneralizedForce& total) const override;
  /// N_i [N] of wheel i (0-based).
  double normal_load(int wheel) const { return normal_load_[wheel]; }

 private:
  CartModel model_;
  double coefficient_;                 ///< c_rr [-]
  double speed_epsilon_;               ///< v_eps [m/s]
  std::array<double, 4> normal_load_;  ///< N_i [N]
};

}  // namespace birkhoff_cart
