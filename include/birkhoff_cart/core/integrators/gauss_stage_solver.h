// The stage solve of s-stage Gauss–Legendre collocation in the Darboux chart (docs/birkhoffian.md
// §10.2, §10.6): simplified Newton on the stage increments with one Jacobian kept across iterations
// and steps, its stop rule, and the policy that renews the Jacobian or falls back to Newton proper.
//
//   G(Z)ᵢ = Zᵢ − r − h Σⱼ aᵢⱼ F(w + Zⱼ, tⱼ),   Z ← Z − (I − h A ⊗ J)⁻¹ G(Z)
//
//  - J = ∂ẇ/∂w (System::darboux_jacobian in closed form, else AD) at the mean of the starting stage
//    values, kept across iterations and across steps while the iteration contracts by ≥ 200× (one
//    stage: 20×) per iteration; the inverse of I − hA ⊗ J in factored form through its Kronecker
//    structure (kronecker_newton.h, eqs. (B.38)–(B.39)), one per distinct step size, so that
//    renewing it costs about one iteration; plain fixed-point iteration contracts only by
//    ~h‖A‖‖J‖, which near the jackknife took 7–9 iterations;
//  - the s stage rates of an iteration in one call where the system has darboux_rates_stages (the
//    cart: one vector sin/cos for all stages, vector_math.h), from two stages on;
//  - stop per component when its largest stage change is predicted to fall below a hundredth of an
//    ulp, or no component's change reaches a new minimum twice in a row (IRKGL16's round-off rule):
//    componentwise, scale-free, unbiased; coordinates the rates never read (System::kCyclicMask, the
//    cart's arc length π1) do not vote; under a step control, once the change is below the accuracy
//    its tolerance needs (CollocationMemory::stage_change_limit);
//  - a stale Jacobian (diverging, or 6 iterations without converging) is renewed at the current
//    stage mean; a second time, Newton's method proper with each stage's own Jacobian.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/collocation_memory.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/kronecker_newton.h"
#include "birkhoff_cart/core/integrators/newton.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

namespace stage_solver_detail {
/// |a − b| over the value and, for AD jets, every derivative part (so that the iteration also
/// converges the derivatives when the whole step is being differentiated).
inline double change_magnitude(double a, double b) { return std::abs(a - b); }
template <class Derivatives>
double change_magnitude(const Eigen::AutoDiffScalar<Derivatives>& a, const Eigen::AutoDiffScalar<Derivatives>& b) {
  double change = std::abs(a.value() - b.value());
  if (a.derivatives().size() == b.derivatives().size() && a.derivatives().size() > 0) {
    change = std::max(change, (a.derivatives() - b.derivatives()).cwiseAbs().maxCoeff());
  }
  return change;
}
}  // namespace stage_solver_detail

/// The stage solve of the s-stage Gauss–Legendre member (gauss_collocation.h).
template <int Stages>
class GaussStageSolver {
 public:
  /// The s stage rates of an iteration in one call (System::darboux_rates_stages: the vector path
  /// of vector_math.h) from two stages on; one stage gains nothing from a 4-lane call.
  static constexpr bool kEvaluatesStagesTogether = Stages >= 2;
  template <class System, class S>
  using StageVectors = std::array<StateVector<System, S>, Stages>;

  /// `max_iterations`: simplified-Newton iterations per step before StepError [-].
  explicit GaussStageSolver(int max_iterations = 30) : max_iterations_(max_iterations) {}

  /// Solves Zᵢ = r + h Σⱼ aᵢⱼ F(w + Zⱼ, tⱼ) for the stage increments in place by simplified Newton,
  /// Z ← Z − (I − h A ⊗ J)⁻¹ G(Z), G(Z) = Z − r − h (A ⊗ I) F(w + Z), with J from the memory (kept
  /// across steps while the iteration contracts fast; refreshed when it does not). Leaves in
  /// `stage_rates` the F of the last evaluation and in `last_stage_change` the largest |ΔZ| of the
  /// final update. Returns the iterations taken.
  ///
  /// Stop (per component k of w, cyclic ones excluded; Dₖ the largest stage change of the iteration):
  /// all Dₖ = 0; or (doubles) each Dₖ shrinking with a predicted next change Dₖ²/Dₖ_prev below 1 % of
  /// an ulp of the stage values, so the increments are converged beyond round-off; or two iterations
  /// in a row in which no Dₖ reached a new minimum (round-off floor). None biases a component. Under
  /// a step control (memory.stage_change_limit = λ > 0) a component also stops once Dₖ ≤ λ·max(1, |Wₖ|):
  /// the iteration stops at the accuracy the tolerance needs (eq. (B.49)).
  template <class System, class S>
  int solve(const System& system, const GaussLegendreTableau& tableau, const StateVector<System, S>& w,
                   const StateVector<System, S>& w_remainder, const std::array<double, Stages>& stage_times,
                   double t, double h, StageVectors<System, S>& increments, StageVectors<System, S>& stage_rates,
                   CollocationMemory<System, Stages>& memory, StepStatistics& statistics,
                   double& last_stage_change) const {
    constexpr int n = System::kDimension;
    constexpr unsigned kCyclic = system_traits::kCyclicMask<System>;
    // A stop with the predicted next change just under half an ulp leaves an error of one sign every
    // step (the stale-Jacobian iteration approaches from one side): on the 1000 s whirl, birkhoff_gauss8
    // at h = 0.01 s drifted 1.2e-10 J. At 1 % of an ulp the leftover is far below the final rounding
    // and the drift fell to 7e-13 J, for 0.5 more iterations a step.
    constexpr double kPredictedChangeLimit = 0.01 * std::numeric_limits<double>::epsilon();
    using W = StateVector<System, S>;

    const double stage_change_limit = memory.stage_change_limit;  // 0: to round-off
    double rate_scale = -1.0;  // h·maxⱼ‖Fⱼ⁽⁰⁾‖ at the starting stages, for the wander check below [-]
    const double t_jacobian = t + 0.5 * h;
    // J at the mean of the starting stage values: with good starting values this is within their
    // error of where the stages end, so the iteration contracts like Newton's.
    W stage_mean = w;
    for (int i = 0; i < Stages; ++i) stage_mean += increments[i] / S(Stages);
    // M⁻¹: the factored simplified-Newton inverse, or (after two slow refreshes) Newton's own.
    const auto* inverse = &newton_inverse(system, tableau, values_of(stage_mean), t_jacobian, h, memory, statistics);
    const typename CollocationMemory<System, Stages>::StageMatrix* exact = nullptr;
    int since_refresh = 0;   // iterations since the Jacobian was last recomputed inside this step
    int refreshes = 0;       // recomputations inside this step
    typename CollocationMemory<System, Stages>::StageMatrix exact_inverse;  // Newton proper, when needed

    std::array<double, n> smallest_change;
    smallest_change.fill(std::numeric_limits<double>::infinity());
    std::array<double, n> previous_change;
    previous_change.fill(std::numeric_limits<double>::infinity());
    double previous_total = std::numeric_limits<double>::infinity();
    double worst_contraction = 0.0;
    int growths = 0;
    int stalls = 0;
    int iterations = 0;
    std::array<std::array<double, Stages>, Stages> step_coefficients;  // h aᵢⱼ [s]
    for (int i = 0; i < Stages; ++i) {
      for (int j = 0; j < Stages; ++j) step_coefficients[i][j] = h * tableau.coefficients[i][j];
    }
    while (true) {
      if constexpr (std::is_same<S, double>::value && kEvaluatesStagesTogether &&
                    system_traits::kHasStageRates<System, Stages>) {
        StageVectors<System, double> stage_points;
        for (int j = 0; j < Stages; ++j) stage_points[j] = w + increments[j];
        system.darboux_rates_stages(stage_points, stage_times, stage_rates);
        statistics.rhs_evaluations += Stages;
      } else {
        for (int j = 0; j < Stages; ++j) {
          stage_rates[j] = system.darboux_rates(W(w + increments[j]), S(stage_times[j]));
          ++statistics.rhs_evaluations;
        }
      }
      if (rate_scale < 0.0) {  // the first evaluation: the rates at the starting stages
        rate_scale = 0.0;
        for (int k = 0; k < n; ++k) {
          if (kCyclic & (1u << k)) continue;
          const double weight = std::abs(h) / std::max(1.0, std::abs(value_of(w(k))));
          for (int j = 0; j < Stages; ++j) rate_scale = std::max(rate_scale, std::abs(value_of(stage_rates[j](k))) * weight);
        }
      }
      std::array<S, n * Stages> residual;
      stage_residual<n>(increments, w_remainder, stage_rates, step_coefficients, residual);
      ++iterations;
      // M⁻¹ G(Z), column by column (the inverse is column-major).
      std::array<S, n * Stages> correction;
      correction.fill(S(0.0) * residual[0]);
      if (exact == nullptr) {
        inverse->apply(residual, correction);
      } else {
        for (int c = 0; c < n * Stages; ++c) {  // column by column (column-major)
          const S& residual_c = residual[c];
          const double* column = exact->data() + static_cast<std::ptrdiff_t>(c) * n * Stages;
          for (int r = 0; r < n * Stages; ++r) correction[r] += column[r] * residual_c;
        }
      }
      // Z ← Z − M⁻¹ G(Z), and the stop rule's measures.
      bool improved = false;
      bool any_change = false;
      bool predicted_converged = std::is_same<S, double>::value;
      double total = 0.0;  // max over voting components of Dₖ / max(|wₖ|, 1) (divergence watch)
      std::array<double, n> change;
      change.fill(0.0);
      for (int i = 0; i < Stages; ++i) {
        for (int k = 0; k < n; ++k) {
          const S updated = increments[i](k) - correction[i * n + k];
          change[k] = std::max(change[k], stage_solver_detail::change_magnitude(updated, increments[i](k)));
          increments[i](k) = updated;
        }
      }
      last_stage_change = *std::max_element(change.begin(), change.end());
      for (int k = 0; k < n; ++k) {
        if (kCyclic & (1u << k)) continue;
        if (!std::isfinite(change[k])) fail_collocation_step("met a non-finite stage value", t, iterations);
        double scale = 0.0;  // largest stage value of component k
        for (int i = 0; i < Stages; ++i) scale = std::max(scale, std::abs(value_of(w(k) + increments[i](k))));
        total = std::max(total, change[k] / std::max(scale, 1.0));
        if (change[k] > 0.0) {
          any_change = true;
          if (change[k] < smallest_change[k]) {
            smallest_change[k] = change[k];
            improved = true;
          }
          const bool shrinking = std::isfinite(previous_change[k]) && change[k] < previous_change[k];
          // Enough for the step control's tolerance: the change itself is below the limit, and what
          // is left after it is smaller still (the iteration contracts). (Stopping on the predicted
          // next change Dₖ²/Dₖ_prev instead saved a fifth of the iterations on drive_rr_drag with
          // birkhoff_gauss8, but the unconverged stages spoiled the error estimate: the error at a
          // given cost grew about tenfold.)
          const bool within_limit = change[k] <= stage_change_limit * std::max(scale, 1.0);
          if (!within_limit && (!shrinking || change[k] * change[k] / previous_change[k] > kPredictedChangeLimit * scale)) {
            predicted_converged = false;
          }
        }
        previous_change[k] = change[k];
      }
      if (std::isfinite(previous_total) && previous_total > 1e-12) {  // ratios of round-off say nothing
        worst_contraction = std::max(worst_contraction, total / previous_total);
      }
      if (!any_change || predicted_converged) break;
      if (improved) {
        stalls = 0;
      } else if (++stalls >= 2) {
        break;  // round-off floor: two iterations without any component getting closer
      }
      growths = (total > previous_total && total > 1e-12) ? growths + 1 : 0;
      previous_total = total;
      ++since_refresh;
      const bool slow = growths >= 2 || since_refresh >= 6;
      if (slow) {
        // Stale Jacobian (diverging, or 6 iterations without converging). First: recompute the one J
        // at the current stage mean (kept for later steps). Again: Newton's method proper, with each
        // stage's own Jacobian, (I − h A ⊗ J)ᵢⱼ = δᵢⱼ I − h aᵢⱼ Jⱼ (large h, fast dynamics).
        memory.forget_jacobian();
        if (++refreshes == 1) {
          stage_mean = w;
          for (int i = 0; i < Stages; ++i) stage_mean += increments[i] / S(Stages);
          inverse = &newton_inverse(system, tableau, values_of(stage_mean), t_jacobian, h, memory, statistics);
          exact = nullptr;
        } else {
          exact_inverse = stage_newton_inverse(system, tableau, values_of(w), increments, stage_times, h, t, statistics);
          exact = &exact_inverse;
        }
        since_refresh = 0;
        growths = 0;
        previous_total = std::numeric_limits<double>::infinity();
        continue;
      }
      if (iterations >= max_iterations_) fail_collocation_step("did not converge (Newton)", t, iterations);
    }
    if (refreshes >= 2) memory.forget_jacobian();  // the per-stage matrix is this step's only
    // A root whose stage increments exceed a hundredfold what the rates at the starting stages move
    // in a step is a spurious one of the stage equations (they have many for large h‖J‖):
    // birkhoff6_kahan_li at h = 0.2 s on hard_cases_test's step torques jumped χ by 1e5 rad and T*
    // by 1e13×, every value finite. A failed step, not a state. (Against the starting increments
    // themselves it also refused honest steps after a new command, which the starting values
    // extrapolated from before it cannot know.)
    double reach = 0.0;  // maxᵢ ‖Zᵢ‖ in ê's weights [-]
    for (int k = 0; k < n; ++k) {
      if (kCyclic & (1u << k)) continue;
      const double weight = 1.0 / std::max(1.0, std::abs(value_of(w(k))));
      for (int i = 0; i < Stages; ++i) reach = std::max(reach, std::abs(value_of(increments[i](k))) * weight);
    }
    if (reach > kWanderLimit * rate_scale + kWanderFloor) fail_collocation_step("wandered to a spurious root", t, iterations);
    // Keep J for the next step only while it contracts fast enough. A new J costs one closed-form
    // evaluation and the Kronecker factors (kronecker_newton.h), about one iteration's work; a stale
    // one costs iterations. On the 1000 s whirl (CPU, min of 3 runs), keeping J up to a contraction
    // of 0.05, 0.005, 0.001 or 0 (a new J every step) took 5.7, 4.6, 4.0, 3.5 iterations a step
    // with gauss8 at h = 0.025 s and 66.7, 62.9, 64.3, 73.1 ms; gauss4 at 0.01 s: 124, 120, 117,
    // 125 ms; gauss8 at 0.1 s: 28.2, 27.5, 26.9, 26.9 ms. One stage (birkhoff2 and the compositions
    // built on it) keeps 0.05: with a J renewed more often, birkhoff4's backward sub-step of −0.34 s
    // at h = 0.2 s settled on a spurious root and blew up (hard_cases_test, LargeSteps).
    constexpr double kKeptJacobianContraction = Stages == 1 ? 0.05 : 0.005;
    if (worst_contraction > kKeptJacobianContraction) memory.forget_jacobian();
    return iterations;
  }

 private:
  /// (I − h A ⊗ J)⁻¹ for this h from the memory's cache (kronecker_newton.h), computing J = ∂ẇ/∂w
  /// (closed form or AD, at `w`, time `t_jacobian`) and the factors when missing.
  template <class System>
  const KroneckerNewtonInverse<System::kDimension, Stages>& newton_inverse(
      const System& system, const GaussLegendreTableau& tableau, const StateVector<System, double>& w,
      double t_jacobian, double h, CollocationMemory<System, Stages>& memory, StepStatistics& statistics) const {
    if (!memory.jacobian_valid) {
      memory.jacobian = system_traits::darboux_jacobian(system, w, t_jacobian);
      ++statistics.rhs_evaluations;  // one evaluation of J (closed form, or AD: value and Jacobian)
      if (!memory.jacobian.allFinite()) fail_collocation_step("met a non-finite Jacobian", t_jacobian - 0.5 * h, 0);
      memory.jacobian_valid = true;
      memory.cached = 0;
      memory.next_slot = 0;
    }
    for (int slot = 0; slot < memory.cached; ++slot) {
      if (memory.cached_step[slot] == h) return memory.cached_inverse[slot];
    }
    const int slot = memory.next_slot;
    memory.next_slot = (slot + 1) % CollocationMemory<System, Stages>::kCachedStepSizes;
    memory.cached = std::max(memory.cached, slot + 1);
    memory.cached_step[slot] = h;
    if (!memory.cached_inverse[slot].build(memory.jacobian, tableau.coefficients, h,
                                           system_traits::kCyclicMask<System>)) {
      memory.cached = 0;
      fail_collocation_step("met a singular Newton matrix", t_jacobian - 0.5 * h, 0);
    }
    return memory.cached_inverse[slot];
  }

  /// (δᵢⱼ I − h aᵢⱼ Jⱼ)⁻¹ with Jⱼ = ∂ẇ/∂w at each stage (AD): the Jacobian of the stage equations
  /// themselves, for Newton's method where one J for all stages does not converge.
  template <class System, class S>
  static typename CollocationMemory<System, Stages>::StageMatrix stage_newton_inverse(
      const System& system, const GaussLegendreTableau& tableau, const StateVector<System, double>& w,
      const StageVectors<System, S>& increments, const std::array<double, Stages>& stage_times, double h, double t,
      StepStatistics& statistics) {
    constexpr int n = System::kDimension;
    using Matrix = typename CollocationMemory<System, Stages>::StageMatrix;
    Matrix matrix = Matrix::Identity();
    for (int j = 0; j < Stages; ++j) {
      const StateVector<System, double> stage = w + values_of(increments[j]);
      const Eigen::Matrix<double, n, n> jacobian = system_traits::darboux_jacobian(system, stage, stage_times[j]);
      ++statistics.rhs_evaluations;
      if (!jacobian.allFinite()) fail_collocation_step("met a non-finite Jacobian", t, 0);
      for (int i = 0; i < Stages; ++i) {
        matrix.template block<n, n>(i * n, j * n) -= (h * tableau.coefficients[i][j]) * jacobian;
      }
    }
    const Matrix inverse = matrix.partialPivLu().inverse();
    if (!inverse.allFinite()) fail_collocation_step("met a singular Newton matrix", t, 0);
    return inverse;
  }

  /// G(Z)ᵢ = Zᵢ − r − h Σⱼ aᵢⱼ Fⱼ, stage i in residual[i·n …]. (Plain loops: Eigen's expressions on
  /// these 4-vectors were not inlined in solve(), and cost more than their arithmetic.) For doubles of
  /// an even dimension two components per SSE2 instruction (baseline x86-64), each entry with the
  /// operations of the scalar loop in its order: the same bits on every x86-64 CPU.
  template <int n, class W, class S>
  static void stage_residual(const std::array<W, Stages>& increments, const W& w_remainder,
                             const std::array<W, Stages>& stage_rates,
                             const std::array<std::array<double, Stages>, Stages>& step_coefficients,
                             std::array<S, n * Stages>& residual) {
#if defined(__SSE2__)
    if constexpr (std::is_same<S, double>::value && n % 2 == 0) {
      for (int i = 0; i < Stages; ++i) {
        for (int k = 0; k < n; k += 2) {
          __m128d g = _mm_sub_pd(_mm_loadu_pd(increments[i].data() + k), _mm_loadu_pd(w_remainder.data() + k));
          for (int j = 0; j < Stages; ++j) {
            g = _mm_sub_pd(g, _mm_mul_pd(_mm_set1_pd(step_coefficients[i][j]), _mm_loadu_pd(stage_rates[j].data() + k)));
          }
          _mm_storeu_pd(residual.data() + i * n + k, g);
        }
      }
      return;
    }
#endif
    for (int i = 0; i < Stages; ++i) {
      for (int k = 0; k < n; ++k) {
        S g = increments[i](k) - w_remainder(k);
        for (int j = 0; j < Stages; ++j) g -= S(step_coefficients[i][j]) * stage_rates[j](k);
        residual[i * n + k] = g;
      }
    }
  }

  /// ‖Z‖ beyond kWanderLimit·h‖F⁽⁰⁾‖ + kWanderFloor is a spurious root [-].
  static constexpr double kWanderLimit = 100.0;
  static constexpr double kWanderFloor = 1e-9;

  int max_iterations_;
};

}  // namespace birkhoff_cart
