// Rolling resistance of the four wheels, docs/derivation.md eq. (4.3).
#include "birkhoff_cart/core/physics/effects/rolling_resistance.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/integrators/vector_math.h"

#include <cmath>

namespace birkhoff_cart {

RollingResistance::RollingResistance(const CartModel& model, double coefficient, double speed_epsilon)
    : model_(model), coefficient_(coefficient), speed_epsilon_(speed_epsilon) {
  const CartParameters& p = model_.parameters();
  const double rear_load = (0.5 * p.rear_body_mass + p.rear_wheel_mass) * p.gravity;   // [N]
  const double front_load = (0.5 * p.front_axle_mass + p.front_wheel_mass) * p.gravity;  // [N]
  normal_load_ = {rear_load, rear_load, front_load, front_load};
}

const std::string& RollingResistance::name() const {
  static const std::string kName = "rolling_resistance";
  return kName;
}

void RollingResistance::add_to(const EffectInput& input, GeneralizedForce& total) const {
  const double w1 = input.forward_speed;
  const double w2 = input.steering_rate;
  const double s = input.sin_steering_angle();
  const double c = input.cos_steering_angle();
  std::array<double, 4> d1;
  std::array<double, 4> d2;
  model_.rim_speed_coefficients_at(s, c, d1, d2);  // r_i φ̇_i = d1_i ω1 + d2_i ω2   (eq. (2.4))
  // ∂d1_i/∂χ (d2 is constant).
  const CartParameters& p = model_.parameters();
  const double a_over_l = p.rear_half_track / p.wheelbase;
  const double cf_over_l = p.front_half_track / p.wheelbase;
  const std::array<double, 4> d1_chi = {-s - a_over_l * c, -s + a_over_l * c, -cf_over_l * c, cf_over_l * c};

  // tanh(v_i/v_eps) of the four wheels in one call (vector_math.h: one AVX call where the CPU has
  // it, the same bits as four scalar ones); it was a fifth of the instructions of a drive scene.
  double ratios[4];  // v_i / v_eps [-], v_i = r_i φ̇_i [m/s]
  for (int wheel = 0; wheel < 4; ++wheel) ratios[wheel] = (d1[wheel] * w1 + d2[wheel] * w2) / speed_epsilon_;
  double tanh_ratios[4];
  tanh_lanes(ratios, 4, tanh_ratios);
  for (int wheel = 0; wheel < 4; ++wheel) {
    const double tanh_ratio = tanh_ratios[wheel];
    const double sech2_ratio = 1.0 - tanh_ratio * tanh_ratio;
    const double load = coefficient_ * normal_load_[wheel];  // c_rr N_i [N]
    // Rim force F_i = τ_i / r_i = −c_rr N_i tanh(v_i/v_eps);  Q_σ += F_i d_σi   (eq. (4.3)).
    const double rim_force = -load * tanh_ratio;                       // [N]
    const double rim_force_slope = -load * sech2_ratio / speed_epsilon_;  // ∂F_i/∂v_i [N·s/m]
    const double speed_chi = d1_chi[wheel] * w1;                        // ∂v_i/∂χ [m/s/rad]
    total.force(0) += rim_force * d1[wheel];
    total.force(1) += rim_force * d2[wheel];
    // ∂Q_σ/∂χ = F_i' (∂v_i/∂χ) d_σi + F_i ∂d_σi/∂χ;  ∂Q_σ/∂ω_k = F_i' d_ki d_σi.
    total.jacobian(0, 0) += rim_force_slope * speed_chi * d1[wheel] + rim_force * d1_chi[wheel];
    total.jacobian(1, 0) += rim_force_slope * speed_chi * d2[wheel];
    total.jacobian(0, 1) += rim_force_slope * d1[wheel] * d1[wheel];
    total.jacobian(0, 2) += rim_force_slope * d2[wheel] * d1[wheel];
    total.jacobian(1, 1) += rim_force_slope * d1[wheel] * d2[wheel];
    total.jacobian(1, 2) += rim_force_slope * d2[wheel] * d2[wheel];
  }
}

}  // namespace birkhoff_cart
