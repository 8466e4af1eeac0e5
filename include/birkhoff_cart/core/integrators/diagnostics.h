// Numerical-error diagnostics as plain structs kept next to the state.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace birkhoff_cart {

/// Counters of the integrator's work.
struct StepStatistics {
  std::uint64_t steps = 0;                    ///< steps taken since start/reset
  std::uint64_t rhs_evaluations = 0;          ///< right-hand-side evaluations (incl. inside Newton)
  std::uint64_t passive_evaluations = 0;      ///< separate evaluations of the passive rates g (collocation members)
  std::uint64_t newton_iterations_total = 0;  ///< implicit-solve iterations (Newton or fixed point); 0 for explicit methods
  std::uint64_t newton_iterations_last_step = 0;
  // A step-size controller's own steps inside the caller's steps (reversible_step_control.h).
  std::uint64_t internal_steps = 0;                                          ///< grid steps taken
  double internal_step_min = std::numeric_limits<double>::infinity();        ///< smallest |h| [s]
  double internal_step_max = 0.0;                                            ///< largest |h| [s]
  std::uint64_t rejected_steps = 0;  ///< attempts the adaptive control rejected (adaptive_step_control.h); the reversible control's restarts with a smaller ε; at fixed steps, the steps whose whole step failed and that were taken in substeps of h/2, h/4, … (cart_stepper_adapter.h)
  double control_fictive_step = std::numeric_limits<double>::quiet_NaN();    ///< the reversible control's ε [rad]
  /// Under the adaptive control with global_error_estimate (docs/accuracy.md §4.5): the position
  /// error of B that the Richardson shadow estimates at the last time it met the grid [m] (NaN
  /// before), that time [s], the shadow's steps over a pair of grid steps and its failed steps, and
  /// the largest h·ρ(J) of its steps (ρ the Jacobian's spectral radius: above 3 the estimate can
  /// under-state, docs/accuracy.md §4.5).
  double global_error_estimate = std::numeric_limits<double>::quiet_NaN();
  double global_error_estimate_time = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t global_error_paired_steps = 0;
  std::uint64_t global_error_failed_steps = 0;
  double global_error_stiffness = 0.0;  ///< the largest h·ρ(J) of the shadow's steps [-]

  // The local error estimate (docs/accuracy.md): per step, the weighted max-norm
  //   ê = max( maxᵢ |ẑᵢ − zᵢ| / max(1, |zᵢ(tₖ)|),  maxⱼ |ŷⱼ − yⱼ| )   (docs/accuracy.md (A.1))
  // over the Birkhoffian variables z = (π1, χ, p1, p2) (absolute below 1 SI unit, relative above) and
  // the passive coordinates y = (x, y, θ, φ1..φ4, W, I2) (absolute) in SI units, where x̂ − x is
  // the method's own error estimate for the step (the difference to an embedded solution from the
  // same stages, see each integrator's header). Methods without an estimate leave these NaN/0.
  // Filled through record_local_error_estimate(), never written directly.
  double local_error_estimate_last_step = std::numeric_limits<double>::quiet_NaN();  ///< ê of the last step [-]
  double local_error_estimate_max = 0.0;  ///< largest ê since start/reset [-]
  double local_error_estimate_sum = 0.0;  ///< Σ ê since start/reset: a global-error proxy without propagation [-]
  std::uint64_t steps_with_error_estimate = 0;  ///< steps that recorded an estimate
};

/// Whether the method has recorded a local error estimate since start/reset.
inline bool has_local_error_estimate(const StepStatistics& statistics) {
  return statistics.steps_with_error_estimate > 0;
}

/// The one way an integrator reports its step's local error estimate ê [-] (see StepStatistics).
/// Call once per successful step, inside step(), on the statistics it was given (the CartStepper
/// adapter commits them only if the whole step succeeds). A non-finite ê is recorded as given: the
/// accuracy guard treats it as an error.
inline void record_local_error_estimate(StepStatistics& statistics, double estimate) {
  statistics.local_error_estimate_last_step = estimate;
  const double largest = statistics.local_error_estimate_max;
  statistics.local_error_estimate_max = (std::isnan(estimate) || std::isnan(largest)) ? std::nan("")
                                        : (estimate > largest ? estimate : largest);
  statistics.local_error_estimate_sum += estimate;
  ++statistics.steps_with_error_estimate;
}

/// Invariants and errors of one state (see msg/IntegrationError.msg for the published form).
struct Diagnostics {
  double energy = 0.0;                    ///< T* [J]
  double energy_balance_residual = 0.0;   ///< T* − T*₀ − ∫ω·Q dt [J]
  double p2_balance_residual = 0.0;       ///< p2 − p2₀ − ∫Q2 dt [N·m·s]
  double max_constraint_residual = 0.0;   ///< max |eq. (15) residual| [m/s]
  bool has_reference = false;
  double reference_position_error = std::numeric_limits<double>::quiet_NaN();             ///< [m]
  double reference_heading_error = std::numeric_limits<double>::quiet_NaN();              ///< [rad]
  double reference_arc_length_relative_error = std::numeric_limits<double>::quiet_NaN();  ///< [-]
};

}  // namespace birkhoff_cart
