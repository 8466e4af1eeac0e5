// The integrator a scene or a caller chooses, with its settings: plain data read by the registry
// (integrators/cart_stepper.h). Defaults match docs/scenes.md, "integrator".
#pragma once

#include <string>

namespace birkhoff_cart {

/// Integrator choice and its settings.
struct IntegratorSettings {
  std::string name = "birkhoff_gauss4";           ///< a name from integrator_names(); the default scene's
  double step_size = 0.01;                        ///< h [s], the default scene's
  double tolerance = 1e-10;                       ///< dopri5 absolute and relative local tolerance [-] (dopri5 only)
  std::string birkhoffian_form = "autonomous";    ///< "autonomous" (z = (π1, χ, p1, p2), K = K₀) or "paper" (K = eᵗ J)
  int max_newton_iterations = 30;                 ///< per implicit step
  double newton_tolerance = 1e-14;                ///< on the scaled Newton update [-]
  bool compensated_summation = true;              ///< Birkhoffian members: Kahan/TwoSum state update
  bool local_error_estimate = true;               ///< Birkhoffian members: compute ê (one more rhs evaluation a step)
  /// "fixed": steps of step_size. "reversible" (symmetric Birkhoffian members): internal steps
  /// chosen by the reversible controller (docs/birkhoffian.md §11) for `position_tolerance`, the
  /// position error [m] the run may reach by `tolerance_horizon`; step_size is then only the output step.
  std::string step_control = "fixed";
  double position_tolerance = 0.0;  ///< reversible: the position error allowed at the horizon [m]; 0: not given
  double tolerance_horizon = 0.0;   ///< reversible: the time position_tolerance is for [s]; 0: the scene's duration
};

}  // namespace birkhoff_cart
