// Gauss–Legendre collocation in the Darboux chart: the K(z,t)-symplectic members birkhoff2 (s = 1,
// order 2: the midpoint rule, i.e. Su's scheme with the first term of the generating-function series),
// birkhoff_gauss4/6/8 (s = 2, 3, 4; orders 4, 6, 8). docs/birkhoffian.md §10, eqs. (B.30)–(B.35).
//
//   w = D(z, tₖ),  Wᵢ = w + h Σⱼ aᵢⱼ Fⱼ,  Fⱼ = ẇ(Wⱼ, tₖ + cⱼh),  w⁺ = w + h Σⱼ bⱼ Fⱼ,  z⁺ = D⁻¹(w⁺, tₖ₊₁)
//   Yᵢ = y + h Σⱼ aᵢⱼ Gⱼ,  Gⱼ = g(D⁻¹(Wⱼ, tⱼ), Yⱼ, tⱼ),  y⁺ = y + h Σⱼ bⱼ Gⱼ         (passive quadrature)
//
// In the chart the structure is K₀ (constant), where every Gauss method is symplectic (GNI Thm VI.4.2),
// so z ↦ z⁺ is K(z,t)-symplectic where Λ = 0; it is symmetric (self-adjoint), so a step with −h from
// tₖ₊₁ undoes a step with h (test/unit/gauss_collocation_test.cpp, k_symplectic_test.cpp).
//
// One step, as this file writes it (after IRKGL16, Antoñana, Makazaga, Murua 2017, and GNI §VIII.6):
//  1. the unknowns are the stage increments Zᵢ = Wᵢ − w (full relative precision); starting values
//     from the stage derivatives of the steps before (the step memory, collocation_memory.h): the
//     polynomial through the last recorded (time, F) points at the new stage times (eq. (B.32));
//     without memory one explicit evaluation, Zᵢ = cᵢh F(w, tₖ);
//  2. the stage solve (gauss_stage_solver.h): simplified Newton with its stop rule and Jacobian policy;
//  3. the update w⁺ = w + Σ dᵢZᵢ, d = bᵀA⁻¹, with no evaluation at the converged stages (eq. (B.33)),
//     compensated (Kahan, TwoSum: compensated_summation.h) when the caller carries the remainders
//     (advance_compensated; needs a chart linear in z, System::kDarbouxChartIsLinear);
//  4. the passive coordinates by quadrature on the converged stages (passive_quadrature.h, eq. (B.35));
//  5. the local error estimate (collocation_error_estimate.h, eqs. (B.36)–(B.37)), when
//     CollocationSettings::estimate_local_error: it only observes (the trajectory is the same bit for
//     bit either way).
// The optional system hooks each part reads are listed in system_traits.h.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/collocation_error_estimate.h"
#include "birkhoff_cart/core/integrators/collocation_memory.h"
#include "birkhoff_cart/core/integrators/compensated_summation.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/gauss_stage_solver.h"
#include "birkhoff_cart/core/integrators/newton.h"
#include "birkhoff_cart/core/integrators/passive_quadrature.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

/// Settings of the implicit stage solve.
struct CollocationSettings {
  int max_iterations = 30;  ///< simplified-Newton iterations per step before StepError [-]
  bool compensated = true;  ///< Kahan/TwoSum summation of the update (advance_compensated)
  /// Record the local error estimate ê (eq. (B.37)): one more rhs evaluation and one passive one a
  /// step; observes only (the trajectory is the same bit for bit either way).
  bool estimate_local_error = true;
};

/// s-stage Gauss–Legendre collocation in the Darboux chart (order 2s, symmetric, K(z,t)-symplectic).
template <int Stages>
class GaussCollocation {
  static_assert(Stages >= 1 && Stages <= kMaxGaussStages, "1 to 4 stages");

 public:
  static constexpr int kStages = Stages;
  static constexpr int kOrder = 2 * Stages;
  static constexpr bool kSymmetric = true;
  /// ê ∝ h^q of the local error estimate (eq. (B.37)): q = 3 for s = 1 (Simpson against the midpoint
  /// rule), s + 2 for s ≥ 2; the error-per-step control's exponent (adaptive_step_control.h).
  static constexpr int kErrorEstimateOrder = Stages == 1 ? 3 : Stages + 2;
  /// The s stage rates of an iteration in one call (gauss_stage_solver.h).
  static constexpr bool kEvaluatesStagesTogether = GaussStageSolver<Stages>::kEvaluatesStagesTogether;
  template <class System>
  using Memory = CollocationMemory<System, Stages>;
  static const char* name() {
    static const std::string kName = Stages == 1 ? "birkhoff2" : "birkhoff_gauss" + std::to_string(2 * Stages);
    return kName.c_str();
  }

  GaussCollocation() = default;
  explicit GaussCollocation(const CollocationSettings& settings)
      : settings_(settings), solver_(settings.max_iterations) {}
  const CollocationSettings& settings() const { return settings_; }

  /// Builds the stage solve's settings from the registry's Newton settings.
  explicit GaussCollocation(const NewtonSettings& newton) : solver_(newton.max_iterations) {
    settings_.max_iterations = newton.max_iterations;
  }

  /// One step from (z, y) at t [s] by h [s] (any scalar S: double or AD jets), no memory, no
  /// compensation: the generic stepper interface of the contract and K-symplecticity tests.
  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    statistics.newton_iterations_last_step = 0;
    advance(system, z, y, t, h, statistics);
  }

  /// step() without resetting the per-step iteration counter (compositions call it per sub-step).
  /// The local error estimate is recorded, or, with `error_sum`, added to it (compositions).
  template <class System, class S>
  void advance(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
               StepStatistics& statistics, LocalErrorVectors<System, S>* error_sum = nullptr) const {
    StateVector<System, S> z_remainder = StateVector<System, S>::Constant(S(0.0));
    PassiveVector<System, S> y_remainder = PassiveVector<System, S>::Constant(S(0.0));
    CollocationMemory<System, Stages> fresh;  // no history: explicit start, Jacobian at the step's start
    collocate(system, z, z_remainder, y, y_remainder, t, h, fresh, statistics, error_sum);
  }

  /// One step of the carried point (remainders kept when settings().compensated and the chart is
  /// linear), with starting values from and into `memory`. Does not reset the per-step iteration
  /// counter. The local error estimate is recorded, or, with `error_sum`, added to it.
  template <class System>
  void advance_compensated(const System& system, CompensatedPoint<System>& point, CollocationMemory<System, Stages>& memory,
                           double t, double h, StepStatistics& statistics,
                           LocalErrorVectors<System, double>* error_sum = nullptr) const {
    const bool compensate = settings_.compensated && system_traits::kDarbouxChartIsLinear<System>;
    if (!compensate) {
      point.z += point.z_remainder;
      point.y += point.y_remainder;
      point.z_remainder.setZero();
      point.y_remainder.setZero();
    }
    collocate(system, point.z, point.z_remainder, point.y, point.y_remainder, t, h, memory, statistics, error_sum);
    if (!compensate) {
      point.z_remainder.setZero();
      point.y_remainder.setZero();
    }
  }

 private:
  template <class System, class S>
  using Stages_ = std::array<StateVector<System, S>, Stages>;

  template <class System, class S>
  void collocate(const System& system, StateVector<System, S>& z, StateVector<System, S>& z_remainder,
                 PassiveVector<System, S>& y, PassiveVector<System, S>& y_remainder, double t, double h,
                 CollocationMemory<System, Stages>& memory, StepStatistics& statistics,
                 LocalErrorVectors<System, S>* error_sum) const {
    using W = StateVector<System, S>;
    using Y = PassiveVector<System, S>;
    const bool estimate = settings_.estimate_local_error;
    const GaussLegendreTableau& tableau = gauss_legendre_tableau(Stages);
    std::array<double, Stages> stage_times{};  // tⱼ = tₖ + cⱼh [s]
    for (int i = 0; i < Stages; ++i) stage_times[i] = t + tableau.nodes[i] * h;

    const W w = system.to_darboux(z, S(t));  // w = D(z, tₖ)
    // The remainder maps through the (linear) chart; for other charts it is zero here.
    W w_remainder = W::Constant(S(0.0));
    if constexpr (system_traits::kDarbouxChartIsLinear<System>) w_remainder = system.to_darboux(z_remainder, S(t));

    // Starting stage increments Zᵢ⁽⁰⁾ (eq. (B.32)).
    Stages_<System, S> increments;   // Zᵢ = Wᵢ − w
    Stages_<System, S> stage_rates;  // Fⱼ at the latest evaluated stages
    W start_rate = W::Constant(S(0.0));  // F(w, tₖ), for the estimate, when evaluated anyway
    bool have_start_rate = false;
    if (memory.count > 0 && extrapolation_is_sound(memory, t, h)) {
      // Fⱼ⁽⁰⁾ = P(tₖ + cⱼh), P through the remembered (tₘ, Fₘ); Zᵢ⁽⁰⁾ = h Σⱼ aᵢⱼ Fⱼ⁽⁰⁾ (the collocation
      // polynomial's increments, not ∫P: for s = 1 the stage sees F at the midpoint only).
      std::array<double, kMaxGaussStages> points{};  // memory times in units of h from tₖ
      for (int m = 0; m < memory.count; ++m) points[m] = (memory.times[m] - t) / h;
      // Fⱼ⁽⁰⁾ = Σₘ Lₘ(cⱼ) Fₘ, in plain loops over the components.
      for (int j = 0; j < Stages; ++j) {
        const std::array<double, kMaxGaussStages> basis = lagrange_basis_values(points, memory.count, tableau.nodes[j]);
        for (int k = 0; k < W::RowsAtCompileTime; ++k) {
          double rate = 0.0;
          for (int m = 0; m < memory.count; ++m) rate += basis[m] * memory.rates[m](k);
          stage_rates[j](k) = S(rate);
        }
      }
      for (int i = 0; i < Stages; ++i) {
        for (int k = 0; k < W::RowsAtCompileTime; ++k) {
          S increment = S(0.0);
          for (int j = 0; j < Stages; ++j) increment += S(h * tableau.coefficients[i][j]) * stage_rates[j](k);
          increments[i](k) = increment;
        }
      }
    } else {
      const W rate = system.darboux_rates(w, S(t));
      ++statistics.rhs_evaluations;
      for (int i = 0; i < Stages; ++i) increments[i] = S(tableau.nodes[i] * h) * rate;
      start_rate = rate;
      have_start_rate = true;
    }
    const bool continues_last_step = estimate && memory.end_rate_belongs_to(values_of(w), t);
    if (continues_last_step && !have_start_rate) {
      start_rate = memory.end_rate.template cast<S>();  // first same as last
      have_start_rate = true;
    }

    double last_stage_change = 0.0;  // largest |ΔZ| of the final iteration
    const int iterations = solver_.solve(system, tableau, w, w_remainder, stage_times, t, h, increments, stage_rates,
                                        memory, statistics, last_stage_change);
    statistics.newton_iterations_last_step += static_cast<std::uint64_t>(iterations);
    statistics.newton_iterations_total += static_cast<std::uint64_t>(iterations);

    // w⁺ = w + (r + Σ dᵢ(Zᵢ − r)), compensated (eqs. (B.33)–(B.34)): the increments Zᵢ = r + h Σⱼ aᵢⱼFⱼ
    // include the remainder, which Σ dᵢ would count Σ dᵢ = 1 − (−1)^s times more (2 for odd s).
    W increment = S(tableau.remainder_weight) * w_remainder;
    for (int i = 0; i < Stages; ++i) increment += S(tableau.increment_weights[i]) * increments[i];
    W w_next;
    W w_next_remainder;
    add_compensated(w, increment, w_next, w_next_remainder);

    // Passive coordinates by quadrature on the converged stages (eq. (B.35)).
    std::array<StateVector<System, S>, Stages> stage_points;  // Zⱼ = D⁻¹(w + Zⱼ, tⱼ)
    for (int j = 0; j < Stages; ++j) stage_points[j] = system.from_darboux(W(w + increments[j]), S(stage_times[j]));
    const W z_start = z;
    const Y y_start = y;
    std::array<Y, Stages> passive_rates;  // Gⱼ at the converged stages
    passive_quadrature<Stages>(system, tableau, stage_points, stage_times, h, y, y_remainder, passive_rates, statistics);

    z = system.from_darboux(w_next, S(t + h));
    if (estimate) {
      if (!have_start_rate) {
        start_rate = system.darboux_rates(w, S(t));
        ++statistics.rhs_evaluations;
      }
      const LocalErrorVectors<System, S> error = collocation_error_vectors<Stages>(
          system, tableau, w, start_rate, w_next, increments, stage_rates, last_stage_change, stage_times, z_start,
          y_start, z, y, passive_rates, continues_last_step, t, h, memory, statistics);
      if (error_sum != nullptr) {
        error_sum->z += error.z;
        error_sum->y += error.y;
      } else {
        record_local_error_estimate(statistics, local_error_norm<System, S>(z_start, y_start, error.z, error.y));
      }
    } else {
      memory.forget_end_rate();
    }
    if constexpr (system_traits::kDarbouxChartIsLinear<System>) {
      z_remainder = system.from_darboux(w_next_remainder, S(t + h));
    } else {
      z_remainder = W::Constant(S(0.0));
    }
    remember(memory, stage_times, stage_rates);
  }

  /// Extrapolating over many steps' length, or through coincident times, is worse than one explicit
  /// evaluation.
  template <class System>
  static bool extrapolation_is_sound(const CollocationMemory<System, Stages>& memory, double t, double h) {
    for (int j = 0; j < memory.count; ++j) {
      if (!(std::abs(memory.times[j] - t) <= 50.0 * std::abs(h))) return false;
      for (int m = 0; m < j; ++m) {
        if (!(std::abs(memory.times[j] - memory.times[m]) > 1e-3 * std::abs(h))) return false;
      }
    }
    return true;
  }

  /// Keeps the stage points the next step's starting values extrapolate from: s = 1 keeps the last
  /// three midpoint rates (kPoints, from three steps), s ≥ 2 the s stages of the last step.
  template <class System, class S>
  static void remember(CollocationMemory<System, Stages>& memory, const std::array<double, Stages>& stage_times,
                       const std::array<StateVector<System, S>, Stages>& stage_rates) {
    if constexpr (Stages == 1) {
      constexpr int kPoints = 3;
      for (int j = std::min(memory.count, kPoints - 1); j > 0; --j) {
        memory.times[j] = memory.times[j - 1];
        memory.rates[j] = memory.rates[j - 1];
      }
      memory.times[0] = stage_times[0];
      memory.rates[0] = values_of(stage_rates[0]);
      memory.count = std::min(memory.count + 1, kPoints);
    } else {
      for (int j = 0; j < Stages; ++j) {
        memory.times[j] = stage_times[j];
        memory.rates[j] = values_of(stage_rates[j]);
      }
      memory.count = Stages;
    }
  }


  CollocationSettings settings_;
  GaussStageSolver<Stages> solver_;
};

}  // namespace birkhoff_cart
