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
// How the stage equations are solved (after IRKGL16, Antoñana, Makazaga, Murua 2017, and GNI §VIII.6):
//  - the unknowns are the stage increments Zᵢ = Wᵢ − w (full relative precision), and the update is
//    w⁺ = w + Σ dᵢZᵢ, d = bᵀA⁻¹, so no evaluation at the converged stages is needed (eq. (B.33));
//  - starting values from the stage derivatives of the steps before (memory): the polynomial through
//    the last recorded (time, F) points, evaluated at the new stage times (eq. (B.32)); without memory
//    from one explicit evaluation Zᵢ = cᵢh F(w, tₖ);
//  - simplified Newton with one Jacobian J = ∂ẇ/∂w (System::darboux_jacobian in closed form, else
//    AD) kept across iterations and across steps while the iteration contracts by ≥ 200× (one stage: 20×) per
//    iteration; the inverse of I − hA ⊗ J in factored form through its Kronecker structure
//    (kronecker_newton.h, eqs. (B.38)–(B.39)), so that renewing it costs about one iteration; plain
//    fixed-point iteration contracts only by ~h‖A‖‖J‖, which near the jackknife took 7–9 iterations;
//  - the s stage rates of an iteration in one call where the system has darboux_rates_stages (the
//    cart: one vector sin/cos for all stages, vector_math.h);
//  - stop per component when its largest stage change is predicted to fall below half an ulp, or no
//    component's change reaches a new minimum twice in a row (IRKGL16's round-off rule): componentwise,
//    scale-free, unbiased; coordinates the rates never read (System::kCyclicMask, the cart's arc
//    length π1) do not vote;
//  - the passive coordinates by quadrature after the solve: System::kPassiveCouplingDepth = d says g
//    reads y only through coordinates whose own rates depend on z alone (d = 1 for the cart: ẋ reads θ,
//    θ̇ reads z), so d + 1 sweeps are exact; without it, sweeps until settled;
//  - compensated summation (Kahan, TwoSum) of w⁺ = w + Σ hbⱼFⱼ and y⁺, when the caller carries the
//    remainders (advance_compensated; needs a chart linear in z, System::kDarbouxChartIsLinear).
//
// Local error estimate (CollocationSettings::estimate_local_error; docs/birkhoffian.md §10.5, eqs.
// (B.36)–(B.37)): e = w⁺ − ŵ, ŵ = w + h (b̂₀ F(w, tₖ) + Σᵢ b̂ᵢ Fᵢ + b̂_{s+1} F(w⁺, tₖ₊₁)) an embedded
// solution of order s + 1 on the nodes {0, c₁ … c_s, 1}; e = −hβ(δ(0) + (−1)^{s+1} δ(1)), the
// collocation polynomial's defect at the step's ends. s = 1: Simpson against the midpoint rule, the
// classical O(h³) estimate of its own error (within a factor 3 of the true local error on the paper
// case); s ≥ 2: O(h^{s+2}), a conservative bound of the O(h^{2s+1}) error. The same on g for the
// passive coordinates. Cost: one rhs evaluation F(w⁺) and one passive evaluation g(z⁺, y⁺) a step
// (first same as last: they are the next step's F(w) and g(z, y)). It vanishes identically on linear autonomous ẇ = Lw
// (the defect is then a multiple of the node polynomial, whose end values cancel).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

#include "birkhoff_cart/core/autodiff.h"
#include "birkhoff_cart/core/birkhoffian_system.h"
#include "birkhoff_cart/core/diagnostics.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/kronecker_newton.h"
#include "birkhoff_cart/core/integrators/newton.h"

namespace birkhoff_cart {

namespace collocation_detail {

template <class System, class = void>
struct CyclicMask : std::integral_constant<unsigned, 0u> {};
template <class System>
struct CyclicMask<System, std::void_t<decltype(System::kCyclicMask)>>
    : std::integral_constant<unsigned, System::kCyclicMask> {};

template <class System, class = void>
struct PassiveCouplingDepth : std::integral_constant<int, -1> {};
template <class System>
struct PassiveCouplingDepth<System, std::void_t<decltype(System::kPassiveCouplingDepth)>>
    : std::integral_constant<int, System::kPassiveCouplingDepth> {};

/// Does the system give the rates of the passive coordinates g reads, alone
/// (System::passive_coupling_rates(z, t))? Then the coupling sweeps evaluate only those.
template <class System, class = void>
struct HasPassiveCouplingRates : std::false_type {};
template <class System>
struct HasPassiveCouplingRates<System,
                               std::void_t<decltype(std::declval<const System&>().passive_coupling_rates(
                                   std::declval<const StateVector<System, double>&>(), std::declval<const double&>()))>>
    : std::true_type {};

/// Does the system give J = ∂ẇ/∂w in closed form (System::darboux_jacobian(w, t))? Else AD.
template <class System, class = void>
struct HasDarbouxJacobian : std::false_type {};
template <class System>
struct HasDarbouxJacobian<System, std::void_t<decltype(std::declval<const System&>().darboux_jacobian(
                                      std::declval<const StateVector<System, double>&>(), 0.0))>> : std::true_type {};

/// J = ∂ẇ/∂w at (w, t): the system's closed form when it has one, else forward-mode AD of ẇ.
template <class System>
Eigen::Matrix<double, System::kDimension, System::kDimension> darboux_jacobian(const System& system,
                                                                             const StateVector<System, double>& w,
                                                                             double t) {
  constexpr int n = System::kDimension;
  if constexpr (HasDarbouxJacobian<System>::value) {
    return system.darboux_jacobian(w, t);
  } else {
    using JetN = newton_detail::JacobianJet<n>;
    Eigen::Matrix<JetN, n, 1> w_jet;
    for (int k = 0; k < n; ++k) {
      w_jet(k).value() = w(k);
      w_jet(k).derivatives() = Eigen::Matrix<double, n, 1, Eigen::DontAlign>::Unit(k);
    }
    const Eigen::Matrix<JetN, n, 1> rate = system.darboux_rates(w_jet, JetN(t));
    Eigen::Matrix<double, n, n> jacobian;
    for (int k = 0; k < n; ++k) jacobian.row(k) = rate(k).derivatives().transpose();
    return jacobian;
  }
}

/// Does the system evaluate ẇ at all stages of a step at once (System::darboux_rates_stages; the
/// vector path of vector_math.h)?
template <class System, int Stages, class = void>
struct HasStageRates : std::false_type {};
template <class System, int Stages>
struct HasStageRates<System, Stages,
                     std::void_t<decltype(std::declval<const System&>().darboux_rates_stages(
                         std::declval<const std::array<StateVector<System, double>, Stages>&>(),
                         std::declval<const std::array<double, Stages>&>(),
                         std::declval<std::array<StateVector<System, double>, Stages>&>()))>> : std::true_type {};

template <class System, class = void>
struct LinearChart : std::false_type {};
template <class System>
struct LinearChart<System, std::void_t<decltype(System::kDarbouxChartIsLinear)>>
    : std::integral_constant<bool, System::kDarbouxChartIsLinear> {};

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

/// s + err = a + b exactly (Knuth's TwoSum; no ordering of |a|, |b| needed).
inline void two_sum(double a, double b, double& sum, double& error) {
  sum = a + b;
  const double b_virtual = sum - a;
  error = (a - (sum - b_virtual)) + (b - b_virtual);
}

}  // namespace collocation_detail

/// What one step leaves for the next (double only): the stage derivatives, for starting values, and
/// the simplified-Newton Jacobian J = ∂ẇ/∂w with the inverses of I − h A ⊗ J for the step sizes in use.
template <class System, int Stages>
struct CollocationMemory {
  static constexpr int kDimension = System::kDimension;
  static constexpr int kUnknowns = System::kDimension * Stages;
  static constexpr int kCachedStepSizes = 9;  ///< distinct sub-step sizes (birkhoff8_kahan_li has 9)
  using StageMatrix = Eigen::Matrix<double, kUnknowns, kUnknowns>;

  int count = 0;                                             ///< stage points held [-]
  std::array<double, kMaxGaussStages> times{};               ///< stage times tⱼ [s]
  std::array<StateVector<System, double>, kMaxGaussStages> rates{};  ///< Fⱼ = ẇ(Wⱼ, tⱼ)

  bool jacobian_valid = false;
  Eigen::Matrix<double, kDimension, kDimension> jacobian = Eigen::Matrix<double, kDimension, kDimension>::Zero();
  int cached = 0;                                            ///< entries of the two arrays below in use
  int next_slot = 0;                                         ///< round-robin replacement
  std::array<double, kCachedStepSizes> cached_step{};        ///< h [s] of each cached inverse
  std::array<KroneckerNewtonInverse<kDimension, Stages>, kCachedStepSizes> cached_inverse;  ///< (I − h A ⊗ J)⁻¹

  // First same as last (the local error estimate, eq. (B.37)): F(w⁺, tₖ₊₁) of the last step stands
  // in for the next step's F(w, tₖ) while that step starts from the same point and time.
  bool end_rate_valid = false;
  double end_time = 0.0;                                                     ///< tₖ₊₁ [s]
  StateVector<System, double> end_point = StateVector<System, double>::Zero();  ///< w⁺
  StateVector<System, double> end_rate = StateVector<System, double>::Zero();   ///< F(w⁺, tₖ₊₁)
  PassiveVector<System, double> end_passive_point = PassiveVector<System, double>::Zero();  ///< y⁺
  PassiveVector<System, double> end_passive_rate = PassiveVector<System, double>::Zero();   ///< g(z⁺, y⁺, tₖ₊₁)

  void clear() {
    count = 0;
    forget_jacobian();
    forget_end_rate();
  }
  /// After anything that changes ẇ at a given (w, t) between steps (a new command torque).
  void forget_end_rate() { end_rate_valid = false; }
  /// Does the remembered F(w⁺, tₖ₊₁) belong to the step starting at (w, t)? Equal to round-off: the
  /// chart's round trip and t₀ + n·h against tₖ + h differ by an ulp or two; a new chart epoch
  /// (rep (a)) or a reduced angle (whole turns) differ by far more.
  bool end_rate_belongs_to(const StateVector<System, double>& w, double t) const {
    constexpr double kRoundOff = 8.0 * std::numeric_limits<double>::epsilon();
    if (!end_rate_valid || !(std::abs(t - end_time) <= kRoundOff * std::max(1.0, std::abs(t)))) return false;
    for (int k = 0; k < kDimension; ++k) {
      if (!(std::abs(w(k) - end_point(k)) <= kRoundOff * std::abs(end_point(k)))) return false;
    }
    return true;
  }
  /// The same for the passive rate g(z⁺, y⁺, tₖ₊₁), given that the Birkhoffian part belongs.
  bool end_passive_rate_belongs_to(const PassiveVector<System, double>& y) const {
    constexpr double kRoundOff = 8.0 * std::numeric_limits<double>::epsilon();
    for (int k = 0; k < y.size(); ++k) {
      if (!(std::abs(y(k) - end_passive_point(k)) <= kRoundOff * std::abs(end_passive_point(k)))) return false;
    }
    return true;
  }
  void forget_jacobian() {
    jacobian_valid = false;
    cached = 0;
    next_slot = 0;
  }
  /// The stage history and J of `other`, without its cached inverses (a side step's copy: the
  /// inverses are h-specific and large).
  void copy_history_from(const CollocationMemory& other) {
    count = other.count;
    times = other.times;
    for (int m = 0; m < other.count; ++m) rates[m] = other.rates[m];
    jacobian_valid = other.jacobian_valid;
    jacobian = other.jacobian;
    cached = 0;
    next_slot = 0;
    end_rate_valid = other.end_rate_valid;
    end_time = other.end_time;
    end_point = other.end_point;
    end_rate = other.end_rate;
    end_passive_point = other.end_passive_point;
    end_passive_rate = other.end_passive_rate;
  }
};

/// A point (z, y) with the round-off remainders that compensated summation carries between steps.
template <class System>
struct CompensatedPoint {
  StateVector<System, double> z = StateVector<System, double>::Zero();
  StateVector<System, double> z_remainder = StateVector<System, double>::Zero();
  PassiveVector<System, double> y = PassiveVector<System, double>::Zero();
  PassiveVector<System, double> y_remainder = PassiveVector<System, double>::Zero();
};

/// Settings of the implicit stage solve.
struct CollocationSettings {
  int max_iterations = 30;  ///< simplified-Newton iterations per step before StepError [-]
  bool compensated = true;  ///< Kahan/TwoSum summation of the update (advance_compensated)
  /// Record the local error estimate ê (eq. (B.37)): one more rhs evaluation and one passive one a
  /// step; observes only (the trajectory is the same bit for bit either way).
  bool estimate_local_error = true;
};

/// The error vectors e = x⁺ − x̂ of one or more steps (compositions add their sub-steps').
template <class System, class S>
struct LocalErrorVectors {
  StateVector<System, S> z = StateVector<System, S>::Constant(S(0.0));
  PassiveVector<System, S> y = PassiveVector<System, S>::Constant(S(0.0));
};

/// s-stage Gauss–Legendre collocation in the Darboux chart (order 2s, symmetric, K(z,t)-symplectic).
template <int Stages>
class GaussCollocation {
  static_assert(Stages >= 1 && Stages <= kMaxGaussStages, "1 to 4 stages");

 public:
  static constexpr int kStages = Stages;
  static constexpr int kOrder = 2 * Stages;
  static constexpr bool kSymmetric = true;
  /// The s stage rates of an iteration in one call (System::darboux_rates_stages: the vector path
  /// of vector_math.h) from two stages on; one stage gains nothing from a 4-lane call.
  static constexpr bool kEvaluatesStagesTogether = Stages >= 2;
  template <class System>
  using Memory = CollocationMemory<System, Stages>;
  static const char* name() {
    static const std::string kName = Stages == 1 ? "birkhoff2" : "birkhoff_gauss" + std::to_string(2 * Stages);
    return kName.c_str();
  }

  GaussCollocation() = default;
  explicit GaussCollocation(const CollocationSettings& settings) : settings_(settings) {}
  const CollocationSettings& settings() const { return settings_; }

  /// Builds the stage solve's settings from the registry's Newton settings.
  explicit GaussCollocation(const NewtonSettings& newton) { settings_.max_iterations = newton.max_iterations; }

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
    const bool compensate = settings_.compensated && collocation_detail::LinearChart<System>::value;
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
    if constexpr (collocation_detail::LinearChart<System>::value) w_remainder = system.to_darboux(z_remainder, S(t));

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
    const int iterations = solve_stages(system, tableau, w, w_remainder, stage_times, t, h, increments, stage_rates,
                                        memory, statistics, last_stage_change);
    statistics.newton_iterations_last_step += static_cast<std::uint64_t>(iterations);
    statistics.newton_iterations_total += static_cast<std::uint64_t>(iterations);

    // w⁺ = w + (r + Σ dᵢZᵢ), compensated (eqs. (B.33)–(B.34)).
    W increment = w_remainder;
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
    passive_quadrature(system, tableau, stage_points, stage_times, h, y, y_remainder, passive_rates, statistics);

    z = system.from_darboux(w_next, S(t + h));
    if (estimate) {
      if (!have_start_rate) {
        start_rate = system.darboux_rates(w, S(t));
        ++statistics.rhs_evaluations;
      }
      estimate_local_error(system, tableau, w, start_rate, w_next, increments, stage_rates, last_stage_change,
                           stage_times, z_start, y_start, z, y, passive_rates, continues_last_step, t, h, memory,
                           statistics, error_sum);
    } else {
      memory.forget_end_rate();
    }
    if constexpr (collocation_detail::LinearChart<System>::value) {
      z_remainder = system.from_darboux(w_next_remainder, S(t + h));
    } else {
      z_remainder = W::Constant(S(0.0));
    }
    remember(memory, stage_times, stage_rates);
  }

  /// The local error estimate (eqs. (B.36)–(B.37)): e = w⁺ − ŵ = h Σⱼ ηⱼ F(node j) on the nodes
  /// {0, c₁ … c_s, 1}, with F(w, tₖ) (first same as last, or evaluated), the stage rates Fᵢ and one
  /// new evaluation F(w⁺, tₖ₊₁) (kept for the next step's start); the same quadrature on g for the
  /// passive coordinates, with g at (z, y, tₖ) and (z⁺, y⁺, tₖ₊₁). ê = local_error_norm(e_z, e_y) is
  /// recorded, or the vectors added to `error_sum`.
  ///
  /// The stage rates are those of the solve's last evaluation, one update before the final Zᵢ: they
  /// are off by about J ΔZ, which moves e by ≲ 4 Σ|ηᵢ| |ΔZ| (h‖J‖ ≲ 4 where the iteration
  /// contracts). Used when that is below a tenth of |e| (or e is at round-off), else re-evaluated at
  /// the converged stages.
  template <class System, class S>
  void estimate_local_error(const System& system, const GaussLegendreTableau& tableau, const StateVector<System, S>& w,
                            const StateVector<System, S>& start_rate, const StateVector<System, S>& w_next,
                            const Stages_<System, S>& increments, const Stages_<System, S>& stage_rates,
                            double last_stage_change, const std::array<double, Stages>& stage_times,
                            const StateVector<System, S>& z_start, const PassiveVector<System, S>& y_start,
                            const StateVector<System, S>& z_next, const PassiveVector<System, S>& y_next,
                            const std::array<PassiveVector<System, S>, Stages>& passive_rates,
                            bool continues_last_step, double t, double h,
                            CollocationMemory<System, Stages>& memory, StepStatistics& statistics,
                            LocalErrorVectors<System, S>* error_sum) const {
    using W = StateVector<System, S>;
    using Y = PassiveVector<System, S>;
    const std::array<double, kMaxGaussStages + 2>& eta = tableau.estimate_weights;
    const double t_next = t + h;
    const W end_rate = system.darboux_rates(w_next, S(t_next));  // F(w⁺, tₖ₊₁)
    ++statistics.rhs_evaluations;
    memory.end_rate_valid = true;
    memory.end_time = t_next;
    memory.end_point = values_of(w_next);
    memory.end_rate = values_of(end_rate);

    // e_w = h (η₀ F(w) + Σ ηᵢ Fᵢ + η_{s+1} F(w⁺))
    auto darboux_error = [&](const Stages_<System, S>& rates) {
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
      Stages_<System, S> converged_rates;
      for (int i = 0; i < Stages; ++i) {
        converged_rates[i] = system.darboux_rates(W(w + increments[i]), S(stage_times[i]));
        ++statistics.rhs_evaluations;
      }
      e_w = darboux_error(converged_rates);
    }

    // e_z: through the chart (linear: directly; else z⁺ − D⁻¹(w⁺ − e_w)).
    W e_z;
    if constexpr (collocation_detail::LinearChart<System>::value) {
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
      const Y end_passive_rate = passive_coordinate_rates(system, z_next, y_next, S(t_next));
      ++statistics.passive_evaluations;
      memory.end_passive_point = values_of(y_next);
      memory.end_passive_rate = values_of(end_passive_rate);
      e_y = S(h * eta[0]) * start_passive_rate + S(h * eta[Stages + 1]) * end_passive_rate;
      for (int i = 0; i < Stages; ++i) e_y += S(h * eta[i + 1]) * passive_rates[i];
    }
    if (error_sum != nullptr) {
      error_sum->z += e_z;
      error_sum->y += e_y;
    } else {
      record_local_error_estimate(statistics, local_error_norm<System, S>(z_start, y_start, e_z, e_y));
    }
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

  /// Keeps the last max(s, 2) stage points (s = 1 keeps two: linear extrapolation of the midpoint rate).
  template <class System, class S>
  static void remember(CollocationMemory<System, Stages>& memory, const std::array<double, Stages>& stage_times,
                       const Stages_<System, S>& stage_rates) {
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

  /// x⁺ + r⁺ = x + increment, componentwise TwoSum (the increment already holds the old remainder).
  template <class Vector>
  static void add_compensated(const Vector& x, const Vector& increment, Vector& sum, Vector& remainder) {
    sum = x + increment;
    if constexpr (std::is_same<typename Vector::Scalar, double>::value) {
      for (Eigen::Index k = 0; k < x.size(); ++k) collocation_detail::two_sum(x(k), increment(k), sum(k), remainder(k));
    } else {
      remainder = Vector::Constant(typename Vector::Scalar(0.0));
    }
  }

  /// (I − h A ⊗ J)⁻¹ for this h from the memory's cache (kronecker_newton.h), computing J = ∂ẇ/∂w
  /// (closed form or AD, at `w`, time `t_jacobian`) and the factors when missing.
  template <class System>
  const KroneckerNewtonInverse<System::kDimension, Stages>& newton_inverse(
      const System& system, const GaussLegendreTableau& tableau, const StateVector<System, double>& w,
      double t_jacobian, double h, CollocationMemory<System, Stages>& memory, StepStatistics& statistics) const {
    if (!memory.jacobian_valid) {
      memory.jacobian = collocation_detail::darboux_jacobian(system, w, t_jacobian);
      ++statistics.rhs_evaluations;  // one evaluation of J (closed form, or AD: value and Jacobian)
      if (!memory.jacobian.allFinite()) fail("met a non-finite Jacobian", t_jacobian - 0.5 * h, 0);
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
                                           collocation_detail::CyclicMask<System>::value)) {
      memory.cached = 0;
      fail("met a singular Newton matrix", t_jacobian - 0.5 * h, 0);
    }
    return memory.cached_inverse[slot];
  }

  /// (δᵢⱼ I − h aᵢⱼ Jⱼ)⁻¹ with Jⱼ = ∂ẇ/∂w at each stage (AD): the Jacobian of the stage equations
  /// themselves, for Newton's method where one J for all stages does not converge.
  template <class System, class S>
  static typename CollocationMemory<System, Stages>::StageMatrix stage_newton_inverse(
      const System& system, const GaussLegendreTableau& tableau, const StateVector<System, double>& w,
      const Stages_<System, S>& increments, const std::array<double, Stages>& stage_times, double h, double t,
      StepStatistics& statistics) {
    constexpr int n = System::kDimension;
    using Matrix = typename CollocationMemory<System, Stages>::StageMatrix;
    Matrix matrix = Matrix::Identity();
    for (int j = 0; j < Stages; ++j) {
      const StateVector<System, double> stage = w + values_of(increments[j]);
      const Eigen::Matrix<double, n, n> jacobian = collocation_detail::darboux_jacobian(system, stage, stage_times[j]);
      ++statistics.rhs_evaluations;
      if (!jacobian.allFinite()) fail("met a non-finite Jacobian", t, 0);
      for (int i = 0; i < Stages; ++i) {
        matrix.template block<n, n>(i * n, j * n) -= (h * tableau.coefficients[i][j]) * jacobian;
      }
    }
    const Matrix inverse = matrix.partialPivLu().inverse();
    if (!inverse.allFinite()) fail("met a singular Newton matrix", t, 0);
    return inverse;
  }

  /// Solves Zᵢ = r + h Σⱼ aᵢⱼ F(w + Zⱼ, tⱼ) for the stage increments in place by simplified Newton,
  /// Z ← Z − (I − h A ⊗ J)⁻¹ G(Z), G(Z) = Z − r − h (A ⊗ I) F(w + Z), with J from the memory (kept
  /// across steps while the iteration contracts fast; refreshed when it does not). Leaves in
  /// `stage_rates` the F of the last evaluation and in `last_stage_change` the largest |ΔZ| of the
  /// final update. Returns the iterations taken.
  ///
  /// Stop (per component k of w, cyclic ones excluded; Dₖ the largest stage change of the iteration):
  /// all Dₖ = 0; or (doubles) each Dₖ shrinking with a predicted next change Dₖ²/Dₖ_prev below 1 % of
  /// an ulp of the stage values, so the increments are converged beyond round-off; or two iterations
  /// in a row in which no Dₖ reached a new minimum (round-off floor). None biases a component.
  template <class System, class S>
  int solve_stages(const System& system, const GaussLegendreTableau& tableau, const StateVector<System, S>& w,
                   const StateVector<System, S>& w_remainder, const std::array<double, Stages>& stage_times,
                   double t, double h, Stages_<System, S>& increments, Stages_<System, S>& stage_rates,
                   CollocationMemory<System, Stages>& memory, StepStatistics& statistics,
                   double& last_stage_change) const {
    constexpr int n = System::kDimension;
    constexpr unsigned kCyclic = collocation_detail::CyclicMask<System>::value;
    // A stop with the predicted next change just under half an ulp leaves an error of one sign every
    // step (the stale-Jacobian iteration approaches from one side): on the 1000 s whirl, birkhoff_gauss8
    // at h = 0.01 s drifted 1.2e-10 J. At 1 % of an ulp the leftover is far below the final rounding
    // and the drift fell to 7e-13 J, for 0.5 more iterations a step.
    constexpr double kPredictedChangeLimit = 0.01 * std::numeric_limits<double>::epsilon();
    using W = StateVector<System, S>;

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
                    collocation_detail::HasStageRates<System, Stages>::value) {
        Stages_<System, double> stage_points;
        for (int j = 0; j < Stages; ++j) stage_points[j] = w + increments[j];
        system.darboux_rates_stages(stage_points, stage_times, stage_rates);
        statistics.rhs_evaluations += Stages;
      } else {
        for (int j = 0; j < Stages; ++j) {
          stage_rates[j] = system.darboux_rates(W(w + increments[j]), S(stage_times[j]));
          ++statistics.rhs_evaluations;
        }
      }
      // G(Z)ᵢ = Zᵢ − r − h Σⱼ aᵢⱼ Fⱼ. (Plain loops here and below: Eigen's expressions on these
      // 4-vectors were not inlined in this function, and cost more than their arithmetic.)
      std::array<S, n * Stages> residual;
      for (int i = 0; i < Stages; ++i) {
        for (int k = 0; k < n; ++k) {
          S g = increments[i](k) - w_remainder(k);
          for (int j = 0; j < Stages; ++j) g -= S(step_coefficients[i][j]) * stage_rates[j](k);
          residual[i * n + k] = g;
        }
      }
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
          change[k] = std::max(change[k], collocation_detail::change_magnitude(updated, increments[i](k)));
          increments[i](k) = updated;
        }
      }
      last_stage_change = *std::max_element(change.begin(), change.end());
      for (int k = 0; k < n; ++k) {
        if (kCyclic & (1u << k)) continue;
        if (!std::isfinite(change[k])) fail("met a non-finite stage value", t, iterations);
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
          if (!shrinking || change[k] * change[k] / previous_change[k] > kPredictedChangeLimit * scale) predicted_converged = false;
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
      if (iterations >= settings_.max_iterations) fail("did not converge (Newton)", t, iterations);
    }
    if (refreshes >= 2) memory.forget_jacobian();  // the per-stage matrix is this step's only
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

  [[noreturn]] static void fail(const char* what, double time, int iterations) {
    std::ostringstream message;
    message.precision(17);
    message << "Gauss collocation stage solve " << what << " in the step from t = " << time << " s after " << iterations
            << " iterations";
    throw StepError(message.str());
  }

  /// Yᵢ = y + r + h Σ aᵢⱼ Gⱼ by sweeps (exact after depth + 1 when the system states its coupling
  /// depth), then y⁺ = y + (r + h Σ bⱼ Gⱼ) compensated. Leaves the final Gⱼ in `passive_rates`.
  template <class System, class S>
  void passive_quadrature(const System& system, const GaussLegendreTableau& tableau,
                          const std::array<StateVector<System, S>, Stages>& stage_points,
                          const std::array<double, Stages>& stage_times, double h, PassiveVector<System, S>& y,
                          PassiveVector<System, S>& y_remainder, std::array<PassiveVector<System, S>, Stages>& passive_rates,
                          StepStatistics& statistics) const {
    using Y = PassiveVector<System, S>;
    if constexpr (System::kPassiveDimension == 0) {
      return;
    } else {
      constexpr int kDepth = collocation_detail::PassiveCouplingDepth<System>::value;
      constexpr int kMaxSweeps = 50;
      std::array<Y, Stages> passive_stages;
      passive_stages.fill(y);
      // With a known depth d and the coupling rates alone (System::passive_coupling_rates), sweeps
      // 0 … d − 1 only carry the coordinates g reads to their stage values; sweep d is the full one.
      constexpr bool kCouplingSweeps = kDepth >= 0 && collocation_detail::HasPassiveCouplingRates<System>::value;
      for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
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
        if (kDepth >= 0 && sweep == kDepth) break;  // exact: the rates just computed are final
        double change = 0.0;
        double size = 1.0;
        for (int i = 0; i < Stages; ++i) {
          Y increment = y_remainder;
          for (int j = 0; j < Stages; ++j) increment += S(h * tableau.coefficients[i][j]) * passive_rates[j];
          const Y updated = y + increment;
          for (int k = 0; k < Y::RowsAtCompileTime; ++k) {
            change = std::max(change, collocation_detail::change_magnitude(updated(k), passive_stages[i](k)));
            size = std::max(size, std::abs(value_of(updated(k))));
          }
          passive_stages[i] = updated;
        }
        if (kDepth < 0 && sweep > 0 && change <= 4.0 * std::numeric_limits<double>::epsilon() * size) break;
        if (sweep + 1 == kMaxSweeps) fail("could not settle the passive coordinates", stage_times[0], sweep + 1);
      }
      Y increment = y_remainder;
      for (int j = 0; j < Stages; ++j) increment += S(h * tableau.weights[j]) * passive_rates[j];
      Y sum;
      add_compensated(y, increment, sum, y_remainder);
      y = sum;
    }
  }

  CollocationSettings settings_;
};

}  // namespace birkhoff_cart
