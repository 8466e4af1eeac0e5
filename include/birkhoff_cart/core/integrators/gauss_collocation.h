// Gauss–Legendre collocation in the Darboux chart: the K(z,t)-symplectic members birkhoff2 (s = 1,
// order 2: the midpoint rule, i.e. Su's scheme with the first term of the generating-function series),
// birkhoff_gauss4/6/8 (s = 2, 3, 4; orders 4, 6, 8). docs/birkhoffian.md §7, eqs. (B.20)–(B.25).
//
//   w = D(z, tₖ),  Wᵢ = w + h Σⱼ aᵢⱼ Fⱼ,  Fⱼ = ẇ(Wⱼ, tₖ + cⱼh),  w⁺ = w + h Σⱼ bⱼ Fⱼ,  z⁺ = D⁻¹(w⁺, tₖ₊₁)
//   Yᵢ = y + h Σⱼ aᵢⱼ Gⱼ,  Gⱼ = g(D⁻¹(Wⱼ, tⱼ), Yⱼ, tⱼ),  y⁺ = y + h Σⱼ bⱼ Gⱼ         (passive quadrature)
//
// In the chart the structure is K₀ (constant), where every Gauss method is symplectic (GNI Thm VI.4.2),
// so z ↦ z⁺ is K(z,t)-symplectic where Λ = 0; it is symmetric (self-adjoint), so a step with −h from
// tₖ₊₁ undoes a step with h (test/unit/gauss_collocation_test.cpp, k_symplectic_test.cpp).
//
// How the stage equations are solved (after IRKGL16, Antoñana, Makazaga, Murua 2017, and GNI §VIII.6):
//  - starting values from the stage derivatives of the steps before (memory): the polynomial through
//    the last recorded (time, F) points, integrated from tₖ (eq. (B.22)); without memory from one
//    explicit evaluation Wᵢ = w + cᵢh F(w, tₖ);
//  - plain fixed-point iteration Wᵢ ← w + h Σ aᵢⱼ F(Wⱼ), which contracts for non-stiff h; when it does
//    not, simplified Newton with one Jacobian ∂ẇ/∂w (AD, at the step's start) for the whole solve;
//  - stop when no component's largest stage change decreases any more (twice in a row): a
//    componentwise, scale-free test that ends at round-off without biasing any component;
//    coordinates the rates never read (System::kCyclicMask, the cart's arc length π1) do not vote;
//  - the passive coordinates by quadrature after the solve: System::kPassiveCouplingDepth = d says g
//    reads y only through coordinates whose own rates depend on z alone (d = 1 for the cart: ẋ reads θ,
//    θ̇ reads z), so d + 1 sweeps are exact; without it, sweeps until settled;
//  - compensated summation (Kahan, TwoSum) of w⁺ = w + Σ hbⱼFⱼ and y⁺, when the caller carries the
//    remainders (advance_compensated; needs a chart linear in z, System::kDarbouxChartIsLinear).
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
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
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

/// Stage derivatives remembered from the steps before, for starting values (double only).
template <class System>
struct CollocationMemory {
  int count = 0;                                             ///< points held [-]
  std::array<double, kMaxGaussStages> times{};               ///< stage times tⱼ [s]
  std::array<StateVector<System, double>, kMaxGaussStages> rates{};  ///< Fⱼ = ẇ(Wⱼ, tⱼ)
  void clear() { count = 0; }
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
  int max_iterations = 30;            ///< Newton iterations after the fixed point gave up [-]
  int max_fixed_point_iterations = 25;  ///< before switching to simplified Newton [-]
  bool compensated = true;            ///< Kahan/TwoSum summation of the update (advance_compensated)
};

/// s-stage Gauss–Legendre collocation in the Darboux chart (order 2s, symmetric, K(z,t)-symplectic).
template <int Stages>
class GaussCollocation {
  static_assert(Stages >= 1 && Stages <= kMaxGaussStages, "1 to 4 stages");

 public:
  static constexpr int kStages = Stages;
  static constexpr int kOrder = 2 * Stages;
  static constexpr bool kSymmetric = true;
  static const char* name() {
    constexpr const char* kNames[] = {"birkhoff2", "birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8"};
    return kNames[Stages - 1];
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
  template <class System, class S>
  void advance(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
               StepStatistics& statistics) const {
    StateVector<System, S> z_remainder = StateVector<System, S>::Constant(S(0.0));
    PassiveVector<System, S> y_remainder = PassiveVector<System, S>::Constant(S(0.0));
    collocate(system, z, z_remainder, y, y_remainder, t, h, static_cast<CollocationMemory<System>*>(nullptr),
              statistics);
  }

  /// One step of the carried point (remainders kept when settings().compensated and the chart is
  /// linear), with starting values from and into `memory`. Does not reset the per-step iteration
  /// counter.
  template <class System>
  void advance_compensated(const System& system, CompensatedPoint<System>& point, CollocationMemory<System>& memory,
                           double t, double h, StepStatistics& statistics) const {
    const bool compensate = settings_.compensated && collocation_detail::LinearChart<System>::value;
    if (!compensate) {
      point.z += point.z_remainder;
      point.y += point.y_remainder;
      point.z_remainder.setZero();
      point.y_remainder.setZero();
    }
    collocate(system, point.z, point.z_remainder, point.y, point.y_remainder, t, h, &memory, statistics);
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
                 CollocationMemory<System>* memory, StepStatistics& statistics) const {
    using W = StateVector<System, S>;
    const GaussLegendreTableau& tableau = gauss_legendre_tableau(Stages);
    std::array<double, Stages> stage_times{};  // tⱼ = tₖ + cⱼh [s]
    for (int i = 0; i < Stages; ++i) stage_times[i] = t + tableau.nodes[i] * h;

    const W w = system.to_darboux(z, S(t));  // w = D(z, tₖ)
    // The remainder maps through the (linear) chart; for other charts it is zero here.
    W w_remainder = W::Constant(S(0.0));
    if constexpr (collocation_detail::LinearChart<System>::value) w_remainder = system.to_darboux(z_remainder, S(t));

    // Starting values Wᵢ⁽⁰⁾ (eq. (B.22)).
    Stages_<System, S> stage_values;
    Stages_<System, S> stage_rates;
    const bool use_memory = memory != nullptr && memory->count > 0 && extrapolation_is_sound(*memory, t, h);
    if (use_memory) {
      std::array<double, kMaxGaussStages> points{};  // memory times in units of h from tₖ
      for (int j = 0; j < memory->count; ++j) points[j] = (memory->times[j] - t) / h;
      for (int i = 0; i < Stages; ++i) {
        const std::array<double, kMaxGaussStages> integrals =
            lagrange_basis_integrals(points, memory->count, 0.0, tableau.nodes[i]);
        W increment = W::Constant(S(0.0));
        for (int j = 0; j < memory->count; ++j) increment += (h * integrals[j]) * memory->rates[j].template cast<S>();
        stage_values[i] = w + increment;
      }
    } else {
      const W rate = system.darboux_rates(w, S(t));
      ++statistics.rhs_evaluations;
      for (int i = 0; i < Stages; ++i) stage_values[i] = w + S(tableau.nodes[i] * h) * rate;
    }

    const int iterations = solve_stages(system, tableau, w, w_remainder, stage_times, h, stage_values, stage_rates,
                                        statistics);
    statistics.newton_iterations_last_step += static_cast<std::uint64_t>(iterations);
    statistics.newton_iterations_total += static_cast<std::uint64_t>(iterations);

    // w⁺ = w + Σ hbⱼFⱼ, compensated (eq. (B.24)).
    W increment = w_remainder;
    for (int j = 0; j < Stages; ++j) increment += S(h * tableau.weights[j]) * stage_rates[j];
    W w_next;
    W w_next_remainder;
    add_compensated(w, increment, w_next, w_next_remainder);

    // Passive coordinates by quadrature on the converged stages (eq. (B.25)).
    std::array<StateVector<System, S>, Stages> stage_points;  // Zⱼ = D⁻¹(Wⱼ, tⱼ)
    for (int j = 0; j < Stages; ++j) stage_points[j] = system.from_darboux(stage_values[j], S(stage_times[j]));
    passive_quadrature(system, tableau, stage_points, stage_times, h, y, y_remainder, statistics);

    z = system.from_darboux(w_next, S(t + h));
    if constexpr (collocation_detail::LinearChart<System>::value) {
      z_remainder = system.from_darboux(w_next_remainder, S(t + h));
    } else {
      z_remainder = W::Constant(S(0.0));
    }

    if (memory != nullptr) remember(*memory, stage_times, stage_rates);
  }

  /// Extrapolating over many steps. length, or through coincident times, is worse than
  /// one explicit evaluation.
  template <class System>
  static bool extrapolation_is_sound(const CollocationMemory<System>& memory, double t, double h) {
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
  static void remember(CollocationMemory<System>& memory, const std::array<double, Stages>& stage_times,
                       const Stages_<System, S>& stage_rates) {
    if constexpr (Stages == 1) {
      if (memory.count >= 1) {
        memory.times[1] = memory.times[0];
        memory.rates[1] = memory.rates[0];
      }
      memory.times[0] = stage_times[0];
      memory.rates[0] = values_of(stage_rates[0]);
      memory.count = std::min(memory.count + 1, 2);
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

  /// Solves Wᵢ = w + r + h Σⱼ aᵢⱼ F(Wⱼ, tⱼ) for the stages in place; leaves Fⱼ = F(Wⱼ) of the final
  /// stage values in `stage_rates`. Returns the iterations taken.
  template <class System, class S>
  int solve_stages(const System& system, const GaussLegendreTableau& tableau, const StateVector<System, S>& w,
                   const StateVector<System, S>& w_remainder, const std::array<double, Stages>& stage_times, double h,
                   Stages_<System, S>& stage_values, Stages_<System, S>& stage_rates,
                   StepStatistics& statistics) const {
    constexpr int n = System::kDimension;
    constexpr int kUnknowns = n * Stages;
    constexpr unsigned kCyclic = collocation_detail::CyclicMask<System>::value;
    using W = StateVector<System, S>;
    using Big = Eigen::Matrix<double, kUnknowns, kUnknowns>;

    std::array<double, n> smallest_change;
    smallest_change.fill(std::numeric_limits<double>::infinity());
    double previous_total = std::numeric_limits<double>::infinity();
    int growths = 0;
    int stalls = 0;
    bool newton = false;
    Big newton_inverse = Big::Zero();  // (I − h A ⊗ J)⁻¹ once Newton takes over
    int iterations = 0;
    int phase_iterations = 0;
    bool changed = true;
    while (true) {
      for (int j = 0; j < Stages; ++j) {
        stage_rates[j] = system.darboux_rates(stage_values[j], S(stage_times[j]));
        ++statistics.rhs_evaluations;
      }
      for (int j = 0; j < Stages; ++j) {
        for (int k = 0; k < n; ++k) {
          if (!std::isfinite(value_of(stage_rates[j](k)))) fail("met a non-finite stage derivative", t_of(stage_times), iterations);
        }
      }
      // Fixed point: Wᵢ⁺ = w + (r + h Σ aᵢⱼ Fⱼ); Newton: Wᵢ⁺ = Wᵢ − [M⁻¹ G(W)]ᵢ with G(W) = W − that.
      Stages_<System, S> updated;
      for (int i = 0; i < Stages; ++i) {
        W increment = w_remainder;
        for (int j = 0; j < Stages; ++j) increment += S(h * tableau.coefficients[i][j]) * stage_rates[j];
        updated[i] = w + increment;
      }
      if (newton) {
        Eigen::Matrix<S, kUnknowns, 1> residual;
        for (int i = 0; i < Stages; ++i) residual.template segment<n>(i * n) = stage_values[i] - updated[i];
        for (int i = 0; i < Stages; ++i) {
          W correction = W::Constant(S(0.0));
          for (int c = 0; c < kUnknowns; ++c) {
            for (int k = 0; k < n; ++k) correction(k) += newton_inverse(i * n + k, c) * residual(c);
          }
          updated[i] = stage_values[i] - correction;
        }
      }
      ++iterations;
      ++phase_iterations;
      // Largest stage change per component, and the stop rule.
      bool improved = false;
      bool any_change = false;
      double total = 0.0;  // max over voting components of change / max(|w|, 1) (divergence watch)
      for (int k = 0; k < n; ++k) {
        if (kCyclic & (1u << k)) continue;
        double change = 0.0;
        for (int i = 0; i < Stages; ++i) {
          change = std::max(change, collocation_detail::change_magnitude(updated[i](k), stage_values[i](k)));
        }
        if (!std::isfinite(change)) fail("met a non-finite stage value", t_of(stage_times), iterations);
        total = std::max(total, change / std::max(std::abs(value_of(w(k))), 1.0));
        if (change > 0.0) {
          any_change = true;
          if (change < smallest_change[k]) {
            smallest_change[k] = change;
            improved = true;
          }
        }
      }
      stage_values = updated;
      if (!any_change) {
        changed = false;
        break;
      }
      if (improved) {
        stalls = 0;
      } else if (++stalls >= 2) {
        break;  // at round-off: two iterations without any component getting closer
      }
      growths = (total > previous_total && total > 1e-9) ? growths + 1 : 0;
      previous_total = total;
      const bool fixed_point_failing =
          !newton && (growths >= 2 || phase_iterations >= settings_.max_fixed_point_iterations);
      if (fixed_point_failing) {
        newton = true;
        phase_iterations = 0;
        growths = 0;
        stalls = 0;
        smallest_change.fill(std::numeric_limits<double>::infinity());
        newton_inverse = newton_matrix_inverse(system, tableau, values_of(w), stage_times, h);
        continue;
      }
      if (newton && phase_iterations >= settings_.max_iterations) {
        fail("did not converge (simplified Newton after the fixed-point iteration)", t_of(stage_times), iterations);
      }
    }
    if (changed) {
      for (int j = 0; j < Stages; ++j) {
        stage_rates[j] = system.darboux_rates(stage_values[j], S(stage_times[j]));
        ++statistics.rhs_evaluations;
      }
    }
    return iterations;
  }

  static double t_of(const std::array<double, Stages>& stage_times) { return stage_times[0]; }

  [[noreturn]] static void fail(const char* what, double time, int iterations) {
    std::ostringstream message;
    message.precision(17);
    message << "Gauss collocation stage solve " << what << " near t = " << time << " s after " << iterations
            << " iterations";
    throw StepError(message.str());
  }

  /// (I − h A ⊗ J)⁻¹ with J = ∂ẇ/∂w at (w, t̄) by forward-mode AD (simplified Newton).
  template <class System>
  static Eigen::Matrix<double, System::kDimension * Stages, System::kDimension * Stages> newton_matrix_inverse(
      const System& system, const GaussLegendreTableau& tableau, const StateVector<System, double>& w,
      const std::array<double, Stages>& stage_times, double h) {
    constexpr int n = System::kDimension;
    constexpr int kUnknowns = n * Stages;
    using JetN = newton_detail::JacobianJet<n>;
    Eigen::Matrix<JetN, n, 1> w_jet;
    for (int k = 0; k < n; ++k) {
      w_jet(k).value() = w(k);
      w_jet(k).derivatives() = Eigen::Matrix<double, n, 1, Eigen::DontAlign>::Unit(k);
    }
    double t_mean = 0.0;
    for (double time : stage_times) t_mean += time / Stages;
    const Eigen::Matrix<JetN, n, 1> rate = system.darboux_rates(w_jet, JetN(t_mean));
    Eigen::Matrix<double, n, n> jacobian;
    for (int k = 0; k < n; ++k) jacobian.row(k) = rate(k).derivatives().transpose();
    Eigen::Matrix<double, kUnknowns, kUnknowns> matrix = Eigen::Matrix<double, kUnknowns, kUnknowns>::Identity();
    for (int i = 0; i < Stages; ++i) {
      for (int j = 0; j < Stages; ++j) {
        matrix.template block<n, n>(i * n, j * n) -= (h * tableau.coefficients[i][j]) * jacobian;
      }
    }
    Eigen::PartialPivLU<Eigen::Matrix<double, kUnknowns, kUnknowns>> lu(matrix);
    return lu.inverse();
  }

  /// Yᵢ = y + r + h Σ aᵢⱼ Gⱼ by sweeps (exact after depth + 1 when the system states its coupling
  /// depth), then y⁺ = y + (r + h Σ bⱼ Gⱼ) compensated.
  template <class System, class S>
  void passive_quadrature(const System& system, const GaussLegendreTableau& tableau,
                          const std::array<StateVector<System, S>, Stages>& stage_points,
                          const std::array<double, Stages>& stage_times, double h, PassiveVector<System, S>& y,
                          PassiveVector<System, S>& y_remainder, StepStatistics& statistics) const {
    using Y = PassiveVector<System, S>;
    if constexpr (System::kPassiveDimension == 0) {
      return;
    } else {
      constexpr int kDepth = collocation_detail::PassiveCouplingDepth<System>::value;
      constexpr int kMaxSweeps = 50;
      std::array<Y, Stages> passive_stages;
      std::array<Y, Stages> passive_rates;
      passive_stages.fill(y);
      for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
        for (int j = 0; j < Stages; ++j) {
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
