// The passive coordinates of a collocation step by quadrature on the converged stages
// (docs/birkhoffian.md §10.3, eq. (B.35)):
//
//   Yᵢ = y + r_y + h Σⱼ aᵢⱼ Gⱼ,  Gⱼ = g(D⁻¹(Wⱼ, tⱼ), Yⱼ, tⱼ),  y⁺ + r_y⁺ = y + (r_y + h Σⱼ bⱼ Gⱼ)
//
// System::kPassiveCouplingDepth = d says g reads y only through coordinates whose own rates depend on
// z alone (d = 1 for the cart: ẋ reads θ, θ̇ reads z), so d + 1 sweeps over the stages are exact;
// without it, sweeps until settled.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/compensated_summation.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/gauss_stage_solver.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

/// Yᵢ = y + r + h Σ aᵢⱼ Gⱼ by sweeps (exact after depth + 1 when the system states its coupling
/// depth), then y⁺ = y + (r + h Σ bⱼ Gⱼ) compensated. Leaves the final Gⱼ in `passive_rates`.
template <int Stages, class System, class S>
void passive_quadrature(const System& system, const GaussLegendreTableau& tableau,
                        const std::array<StateVector<System, S>, Stages>& stage_points,
                        const std::array<double, Stages>& stage_times, double h, PassiveVector<System, S>& y,
                        PassiveVector<System, S>& y_remainder, std::array<PassiveVector<System, S>, Stages>& passive_rates,
                        StepStatistics& statistics) {
  using Y = PassiveVector<System, S>;
  if constexpr (System::kPassiveDimension == 0) {
    return;
  } else {
    constexpr int kDepth = system_traits::kPassiveCouplingDepth<System>;
    constexpr int kMaxSweeps = 50;
    std::array<Y, Stages> passive_stages;
    passive_stages.fill(y);
    // With a known depth d and the coupling rates alone (System::passive_coupling_rates), sweeps
    // 0 … d − 1 only carry the coordinates g reads to their stage values; sweep d is the full one.
    constexpr bool kCouplingSweeps = kDepth >= 0 && system_traits::kHasPassiveCouplingRates<System>;
    // A system that evaluates g at the s stages at once (one vector call for their sines and
    // cosines: system_traits.h) gives the same bits in one call a sweep. Not for one stage: there the
    // scalar functions' memo (deterministic_math.h) answers the full sweep's angles the coupling
    // sweep asked for, which a vector call of one lane would compute again (birkhoff2 paid 4 % more).
    constexpr bool kStagesTogether =
        Stages >= 2 && std::is_same_v<S, double> && system_traits::kHasPassiveStageRates<System, Stages>;
    for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
      if constexpr (kStagesTogether) {
        if (kCouplingSweeps && sweep < kDepth) {
          system.passive_coupling_rates_stages(stage_points, stage_times, passive_rates);
        } else {
          system.passive_rates_stages(stage_points, passive_stages, stage_times, passive_rates);
          statistics.passive_evaluations += Stages;
        }
      } else {
        for (int j = 0; j < Stages; ++j) {
          if constexpr (kCouplingSweeps) {
            if (sweep < kDepth) {
              passive_rates[j] = system.passive_coupling_rates(stage_points[j], S(stage_times[j]));
              continue;
            }
          }
          passive_rates[j] = passive_coordinate_rates(system, stage_points[j], passive_stages[j], S(stage_times[j]));
          ++statistics.passive_evaluations;
        }
      }
      if (kDepth >= 0 && sweep == kDepth) break;  // exact: the rates just computed are final
      double change = 0.0;
      double size = 1.0;
      for (int i = 0; i < Stages; ++i) {
        Y increment = y_remainder;
        for (int j = 0; j < Stages; ++j) increment += S(h * tableau.coefficients[i][j]) * passive_rates[j];
        const Y updated = y + increment;
        for (int k = 0; k < Y::RowsAtCompileTime; ++k) {
          change = std::max(change, stage_solver_detail::change_magnitude(updated(k), passive_stages[i](k)));
          size = std::max(size, std::abs(value_of(updated(k))));
        }
        passive_stages[i] = updated;
      }
      if (kDepth < 0 && sweep > 0 && change <= 4.0 * std::numeric_limits<double>::epsilon() * size) break;
      if (sweep + 1 == kMaxSweeps) fail_collocation_step("could not settle the passive coordinates", stage_times[0], sweep + 1);
    }
    Y increment = y_remainder;
    for (int j = 0; j < Stages; ++j) increment += S(h * tableau.weights[j]) * passive_rates[j];
    Y sum;
    add_compensated(y, increment, sum, y_remainder);
    y = sum;
  }
}

}  // namespace birkhoff_cart
