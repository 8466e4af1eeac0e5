#include "birkhoff_cart/core/physics/singular_steering.h"

#include <cmath>
#include <sstream>

#include "birkhoff_cart/core/integrators/step_error.h"

namespace birkhoff_cart {
namespace {

/// k such that χ ∈ [kπ, (k+1)π).
double pole_interval(double steering_angle) { return std::floor(steering_angle / M_PI); }

[[noreturn]] void throw_singular(const CartState& state, double step_size, double singular_angle) {
  const double rate = state.steering_rate;  // ω2 [rad/s]
  // t* ≈ t + (kπ − χ)/ω2: the linear estimate of when χ reaches kπ (exact in the paper's case, χ = t)
  const double singular_time =
      rate != 0.0 ? state.time + (singular_angle - state.steering_angle) / rate : state.time;
  std::ostringstream message;
  message.precision(17);
  message << "step from t = " << state.time << " s (h = " << step_size << " s, steering_angle = "
          << state.steering_angle << " rad) would reach the singular steering angle chi = "
          << std::round(singular_angle / M_PI) << " pi = " << singular_angle  // a double: no lround overflow
          << " rad, where det M(chi) = -sin^2(chi) = 0 (paper special case, eq. (3.9)) and omega1, pi1 diverge;";
  message.precision(10);
  message << " singular time t* = " << singular_time << " s; stopped at the last state before it";
  throw StepError(message.str());
}

}  // namespace

bool has_singular_steering_angles(const CartModel& model) {
  return model.inertia_model() == InertiaModel::kPaperSpecialCase;
}

void check_singular_steering(const CartModel& model, const CartState& state, double step_size,
                             const CartState* next) {
  if (!has_singular_steering_angles(model)) return;
  const double chi = state.steering_angle;                        // χ [rad]
  const double k = pole_interval(chi);                            // χ ∈ [kπ, (k+1)π)
  if (chi == k * M_PI) throw_singular(state, step_size, chi);     // already on the pole
  const double predicted = chi + step_size * state.steering_rate; // χ + h ω2 [rad]
  const double stepped = next ? next->steering_angle : chi;       // χ⁽ᵏ⁺¹⁾ [rad]
  for (const double candidate : {predicted, stepped}) {
    if (!std::isfinite(candidate)) continue;  // the stepper reports non-finite values itself
    if (candidate >= (k + 1.0) * M_PI) throw_singular(state, step_size, (k + 1.0) * M_PI);
    if (candidate <= k * M_PI) throw_singular(state, step_size, k * M_PI);
  }
}

}  // namespace birkhoff_cart
