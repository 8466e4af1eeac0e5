// The local error estimate of Gauss–Legendre collocation (docs/birkhoffian.md §10.5, eqs.
// (B.36)–(B.37)): e = w⁺ − ŵ, ŵ = w + h (b̂₀ F(w, tₖ) + Σᵢ b̂ᵢ Fᵢ + b̂_{s+1} F(w⁺, tₖ₊₁)) an embedded
// solution of order s + 1 on the nodes {0, c₁ … c_s, 1}; e = −hβ(δ(0) + (−1)^{s+1} δ(1)), the
// collocation polynomial's defect at the step's ends. s = 1: Simpson against the midpoint rule, the
// classical O(h³) estimate of its own error (within a factor 3 of the true local error on the paper
// case); s ≥ 2: O(h^{s+2}), a conservative bound of the O(h^{2s+1}) error. The same on g for the
// passive coordinates. Cost: one rhs evaluation F(w⁺) and one passive evaluation g(z⁺, y⁺) a step
// (first same as last: they are the next step's F(w) and g(z, y)), from one evaluation of what they
// share where the system offers it (darboux_and_passive_rates, system_traits.h). It vanishes identically on linear
// autonomous ẇ = Lw (the defect is then a multiple of the node polynomial, whose end values cancel):
// under the adaptive control (memory.linear_mode_error) the step's linearised error, weighted, is
// added to it, so that a stiff mode a step would jump over is seen (linear_mode_error.h, (B.54)–(B.55)).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/collocation_memory.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/linear_mode_error.h"
#include "birkhoff_cart/core/integrators/newton.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

/// The error vectors e = x⁺ − x̂ of one or more steps (compositions add their sub-steps').
template <class System, class S>
struct LocalErrorVectors {
  StateVector<System, S> z = StateVector<System, S>::Constant(S(0.0));
  PassiveVector<System, S> y = PassiveVector<System, S>::Constant(S(0.0));
};

/// The error vectors e = (e_z, e_y) of one collocation step from (z, y) at t [s] over h [s] (eq.
/// (B.37)): e_w from the stage rates and F(w⁺, tₖ₊₁), mapped to z through the chart, and e_y from
/// the passive rates at the step's ends and stages. Stores F(w⁺) and g(z⁺, y⁺) in `memory` (first
/// same as last: the next step's start rates) and counts the evaluations in `statistics`.
///
/// The stage rates are those of the solve's last evaluation, one update before the final Zᵢ: they
/// are off by about J ΔZ, which moves e by ≲ 4 Σ|ηᵢ| |ΔZ| (h‖J‖ ≲ 4 where the iteration
/// contracts). Used when that is below a tenth of |e| (or e is at round-off), else re-evaluated at
/// the converged stages.
template <int Stages, class System, class S>
LocalErrorVectors<System, S> collocation_error_vectors(const System& system, const GaussLegendreTableau& tableau, const StateVector<System, S>& w,
                          const StateVector<System, S>& start_rate, const StateVector<System, S>& w_next,
                          const std::array<StateVector<System, S>, Stages>& increments, const std::array<StateVector<System, S>, Stages>& stage_rates,
                          double last_stage_change, const std::array<double, Stages>& stage_times,
                          const StateVector<System, S>& z_start, const PassiveVector<System, S>& y_start,
                          const StateVector<System, S>& z_next, const PassiveVector<System, S>& y_next,
                          const std::array<PassiveVector<System, S>, Stages>& passive_rates,
                          bool continues_last_step, double t, double h,
                          CollocationMemory<System, Stages>& memory, StepStatistics& statistics) {
  using W = StateVector<System, S>;
  using Y = PassiveVector<System, S>;
  const std::array<double, kMaxGaussStages + 2>& eta = tableau.estimate_weights;
  const double t_next = t + h;
  // F(w⁺, tₖ₊₁), and g(z⁺, y⁺, tₖ₊₁) with it where the system shares their work (w = z: the identity
  // chart; system_traits.h), bit for bit the two calls.
  constexpr bool kEndRatesTogether = std::is_same_v<S, double> && System::kPassiveDimension > 0 &&
                                     system_traits::kDarbouxChartIsIdentity<System> &&
                                     system_traits::kHasDarbouxAndPassiveRates<System>;
  W end_rate;
  Y end_passive_rate_together;
  if constexpr (kEndRatesTogether) {
    system.darboux_and_passive_rates(w_next, y_next, t_next, end_rate, end_passive_rate_together);
  } else {
    end_rate = system.darboux_rates(w_next, S(t_next));
  }
  ++statistics.rhs_evaluations;
  memory.end_rate_valid = true;
  memory.end_time = t_next;
  memory.end_point = values_of(w_next);
  memory.end_rate = values_of(end_rate);

  // e_w = h (η₀ F(w) + Σ ηᵢ Fᵢ + η_{s+1} F(w⁺))
  auto darboux_error = [&](const std::array<StateVector<System, S>, Stages>& rates) {
    W error = S(h * eta[0]) * start_rate + S(h * eta[Stages + 1]) * end_rate;
    for (int i = 0; i < Stages; ++i) error += S(h * eta[i + 1]) * rates[i];
    return error;
  };
  W e_w = darboux_error(stage_rates);
  double eta_sum = 0.0;
  for (int i = 0; i < Stages; ++i) eta_sum += std::abs(eta[i + 1]);
  const double stale_bound = 4.0 * eta_sum * last_stage_change;
  const double size = values_of(e_w).cwiseAbs().maxCoeff();
  const double round_off = 64.0 * std::numeric_limits<double>::epsilon() *
                           std::max(1.0, values_of(w).cwiseAbs().maxCoeff());
  if (!(stale_bound <= std::max(0.1 * size, round_off))) {
    // A copy: the memory keeps the solve's own rates, so that the next step's starting values (and
    // with them the trajectory, bit for bit) do not depend on whether the estimate is on.
    std::array<StateVector<System, S>, Stages> converged_rates;
    for (int i = 0; i < Stages; ++i) {
      converged_rates[i] = system.darboux_rates(W(w + increments[i]), S(stage_times[i]));
      ++statistics.rhs_evaluations;
    }
    e_w = darboux_error(converged_rates);
  }
  // Under the adaptive control, the linearised error the defect cannot see, weighted (B.54)–(B.55):
  // ê = ‖e + w_L e_L‖, computed where w_L e_L's leading term could reach a hundredth of e.
  if constexpr (std::is_same_v<S, double>) {
    if (memory.linear_mode_error) {
      const double defect = std::max(e_w.cwiseAbs().maxCoeff(), round_off);
      e_w += kLinearModeWeight *
             linear_mode_error<Stages>(memory.jacobian, start_rate, h, 0.01 * defect / kLinearModeWeight);
    }
  }

  // e_z: through the chart (linear: directly; else z⁺ − D⁻¹(w⁺ − e_w)).
  W e_z;
  if constexpr (system_traits::kDarbouxChartIsLinear<System>) {
    e_z = system.from_darboux(e_w, S(t_next));
  } else {
    e_z = z_next - system.from_darboux(W(w_next - e_w), S(t_next));
  }
  Y e_y = Y::Constant(S(0.0));
  if constexpr (System::kPassiveDimension > 0) {
    Y start_passive_rate;  // g(z, y, tₖ): first same as last too, while y is the last step's y⁺
    if (continues_last_step && memory.end_passive_rate_belongs_to(values_of(y_start))) {
      start_passive_rate = memory.end_passive_rate.template cast<S>();
    } else {
      start_passive_rate = passive_coordinate_rates(system, z_start, y_start, S(t));
      ++statistics.passive_evaluations;
    }
    Y end_passive_rate;
    if constexpr (kEndRatesTogether) {
      end_passive_rate = end_passive_rate_together;
    } else {
      end_passive_rate = passive_coordinate_rates(system, z_next, y_next, S(t_next));
    }
    ++statistics.passive_evaluations;
    memory.end_passive_point = values_of(y_next);
    memory.end_passive_rate = values_of(end_passive_rate);
    e_y = S(h * eta[0]) * start_passive_rate + S(h * eta[Stages + 1]) * end_passive_rate;
    for (int i = 0; i < Stages; ++i) e_y += S(h * eta[i + 1]) * passive_rates[i];
  }
  LocalErrorVectors<System, S> error;
  error.z = e_z;
  error.y = e_y;
  return error;
}

}  // namespace birkhoff_cart
