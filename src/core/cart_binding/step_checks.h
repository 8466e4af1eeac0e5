// The checks every CartStepper adapter makes (cart_stepper_adapter.h, reversible_cart_stepper.h): a
// valid step size in, finite coordinates and quasi-velocities out, with errors that name the
// coordinate. Private to the core library.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {
namespace stepper_checks {

inline const char* const kBirkhoffianNames[kBirkhoffianSize] = {"arc_length pi1", "steering_angle chi",
                                                        "forward momentum p1", "steering momentum p2"};
inline const char* const kPassiveNames[kPassiveSize] = {"x",
                                                 "y",
                                                 "heading theta",
                                                 "wheel_spin_angle phi1",
                                                 "wheel_spin_angle phi2",
                                                 "wheel_spin_angle phi3",
                                                 "wheel_spin_angle phi4",
                                                 "applied_work W",
                                                 "steering_impulse I2"};

inline void require_valid_step_size(double step_size) {
  if (!(step_size > 0.0) || !std::isfinite(step_size)) {
    std::ostringstream message;
    message << "step size must be finite and > 0 s, got " << step_size;
    throw std::invalid_argument(message.str());
  }
}

using ::birkhoff_cart::error_per_unit_step;  // the settings' own check (integrator_settings.h)

[[noreturn]] inline void throw_non_finite(const std::string& integrator, double time, double step_size,
                                   const std::string& quantity, double value) {
  std::ostringstream message;
  message.precision(17);
  message << integrator << " step from t = " << time << " s (h = " << step_size << " s) produced a non-finite "
          << quantity << " (" << value << ")";
  throw StepError(message.str());
}

/// Throws StepError naming the first non-finite coordinate of (z, y) or quasi-velocity of `next`:
/// what every adapter checks before it hands a step's result out.
inline void require_finite_result(const std::string& integrator, double time, double step_size,
                           const Eigen::Matrix<double, kBirkhoffianSize, 1>& z,
                           const Eigen::Matrix<double, kPassiveSize, 1>& y) {
  for (int i = 0; i < kBirkhoffianSize; ++i) {
    if (!std::isfinite(z(i))) throw_non_finite(integrator, time, step_size, kBirkhoffianNames[i], z(i));
  }
  for (int i = 0; i < kPassiveSize; ++i) {
    if (!std::isfinite(y(i))) throw_non_finite(integrator, time, step_size, kPassiveNames[i], y(i));
  }
}
/// The same for the quasi-velocities of `next`, and for its kinetic energy T* = ½ (p1 ω1 + p2 ω2)
/// with the momenta p of `z`: a step that blew up (an implicit solve that settled on a spurious root
/// far from the motion) can leave every coordinate finite and T* beyond the largest double.
inline void require_finite_speeds(const std::string& integrator, double time, double step_size, const CartState& next,
                                  const Eigen::Matrix<double, kBirkhoffianSize, 1>& z) {
  if (!std::isfinite(next.forward_speed)) {
    throw_non_finite(integrator, time, step_size, "forward_speed omega1 (singular mass matrix?)", next.forward_speed);
  }
  if (!std::isfinite(next.steering_rate)) {
    throw_non_finite(integrator, time, step_size, "steering_rate omega2 (singular mass matrix?)", next.steering_rate);
  }
  const double kinetic_energy =
      0.5 * (z(kForwardMomentumIndex) * next.forward_speed + z(kSteeringMomentumIndex) * next.steering_rate);
  if (!std::isfinite(kinetic_energy)) {
    throw_non_finite(integrator, time, step_size, "kinetic energy T* (the step blew up)", kinetic_energy);
  }
}

/// Does a step from `start` to `next` keep its kinetic energy within what it had and what the loads
/// supplied (eq. (3.7))? A step that gains more than 9× (T*₀ + |ΔW|) beyond the work ΔW is no
/// discretization error but a step that settled on a spurious root of its implicit equations far
/// from the motion (birkhoff6_kahan_li at h = 0.2 s on hard_cases_test's step torques: T* grew
/// 1e13-fold in one step and stayed finite). Coarse on purpose: a low-order method's honest energy
/// error where the cart comes to rest is far below it.
inline bool energy_balance_holds(const CartModel& model, const CartState& start, const CartState& next) {
  const double energy_start = model.energy(start);  // T*₀ [J]
  const double work = next.applied_work - start.applied_work;  // ΔW [J]
  const double gained = model.energy(next) - energy_start - work;  // [J]
  constexpr double kEnergyFloor = 1e-6;  // [J]: a cart at rest
  return !(gained > 9.0 * (energy_start + std::abs(work)) + kEnergyFloor);
}

/// Throws StepError naming the broken energy balance of a step (energy_balance_holds).
inline void require_energy_balance(const std::string& integrator, const CartModel& model, const CartState& start,
                                   const CartState& next, double step_size) {
  if (energy_balance_holds(model, start, next)) return;
  std::ostringstream message;
  message.precision(17);
  message << integrator << " step from t = " << start.time << " s (h = " << step_size
          << " s) broke the energy balance: T* went from " << model.energy(start) << " J to " << model.energy(next)
          << " J with " << next.applied_work - start.applied_work
          << " J of applied work (an implicit solve that settled on a spurious root)";
  throw StepError(message.str());
}

}  // namespace stepper_checks
}  // namespace birkhoff_cart
