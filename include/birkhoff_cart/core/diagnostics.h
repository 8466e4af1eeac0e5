// Numerical-error diagnostics as plain structs kept next to the state.
#pragma once

#include <cstdint>
#include <limits>

namespace birkhoff_cart {

/// Counters of the integrator's work.
struct StepStatistics {
  std::uint64_t steps = 0;                    ///< steps taken since start/reset
  std::uint64_t rhs_evaluations = 0;          ///< right-hand-side evaluations (incl. inside Newton)
  std::uint64_t newton_iterations_total = 0;  ///< 0 for explicit methods
  std::uint64_t newton_iterations_last_step = 0;
};

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
