// The implicit midpoint rule ("midpoint") on the Birkhoffian variables z, a symmetric peer of
// birkhoff2. Scheme (one stage Gauss–Legendre; Butcher tableau 1/2 | 1/2 ; 1):
//
//   z⁽ᵏ⁺¹⁾ = z⁽ᵏ⁾ + h f(z̄, tₖ + h/2),   z̄ = (z⁽ᵏ⁾ + z⁽ᵏ⁺¹⁾)/2,   f(z, t) = K(z,t)⁻¹ (∇B + ∂R/∂t + Λ),
//   y⁽ᵏ⁺¹⁾ = y⁽ᵏ⁾ + h g(z̄, ȳ, tₖ + h/2), ȳ = (y⁽ᵏ⁾ + y⁽ᵏ⁺¹⁾)/2   (passive coordinates at the midpoint,
//            by fixed-point sweeps: passive_midpoint_sweeps below),
//
// solved for z⁽ᵏ⁺¹⁾ by Newton's method with the AD Jacobian I − (h/2) ∂f/∂z(z̄) (newton.h), from the
// explicit Euler predictor. Order 2, symmetric (self-adjoint).
//
// Relation to birkhoff2: birkhoff2 is the same midpoint rule applied in the Darboux chart
// w = D(z, t). On the cart's autonomous representation (b) the chart is the identity and K = K₀,
// so the two coincide in exact arithmetic (the contract test checks they agree to round-off). On
// the paper representation (a) and on the damped oscillator (K = e^{γt} K₀) the chart is not the
// identity and the two differ: the midpoint rule in z preserves K₀-type quadratic structure only,
// not K(z,t), so "midpoint" is symmetric but not K(z,t)-symplectic there.
//
// Error estimate (error_estimate.h): the explicit Euler predictor is the embedded 1st-order
// solution, already computed, so ê = ‖z⁽ᵏ⁺¹⁾ − (z⁽ᵏ⁾ + h f(z⁽ᵏ⁾, tₖ))‖ = ‖h (f(z̄) − f(z⁽ᵏ⁾))‖ costs
// nothing extra. It is O(h²) while the midpoint rule's local error is O(h³): an upper estimate.
// It covers z only (the passive coordinates have no Euler predictor here).
#pragma once

#include <Eigen/Core>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/integrator_kind.h"
#include "birkhoff_cart/core/integrators/newton.h"

namespace birkhoff_cart {

/// Midpoint rule for the passive coordinates, y⁺ = y + h g(z̄, ½(y + y⁺), t̄), by fixed-point
/// sweeps. For the cart, g is triangular in y (θ̇ depends on z only, the rest on z and θ), so
/// the second sweep is exact and the third confirms it; a system whose g does not read y
/// converges in one sweep (plus the confirming one). Throws StepError if 50 sweeps do not settle.
template <class System, class S>
PassiveVector<System, S> passive_midpoint_sweeps(const System& system, const StateVector<System, S>& z_mid,
                                                 const PassiveVector<System, S>& y, double t_mid, double h,
                                                 StepStatistics& statistics) {
  using YVector = PassiveVector<System, S>;
  if constexpr (System::kPassiveDimension == 0) return y;
  YVector y_next = y;
  constexpr int kMaxSweeps = 50;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    const YVector y_mid = S(0.5) * (y + y_next);
    // y⁺ ← y + h g(z̄, ½(y + y⁺), t̄)
    const YVector updated = y + S(h) * passive_coordinate_rates(system, z_mid, y_mid, S(t_mid));
    ++statistics.passive_evaluations;
    const bool settled = (values_of(updated) - values_of(y_next)).cwiseAbs().maxCoeff() <=
                         4.0 * std::numeric_limits<double>::epsilon() *
                             std::max(1.0, values_of(updated).cwiseAbs().maxCoeff());
    y_next = updated;
    if (sweep > 0 && settled) return y_next;  // ≥ 2 sweeps: derivative parts settled too
  }
  throw StepError("midpoint: the passive coordinates' sweeps did not settle at t = " + std::to_string(t_mid) + " s");
}

class ImplicitMidpoint {
 public:
  static constexpr int kOrder = 2;
  static constexpr bool kSymmetric = true;
  static constexpr IntegratorKind kKind = IntegratorKind::kImplicitMidpoint;
  static const char* name() { return "midpoint"; }

  ImplicitMidpoint() = default;
  explicit ImplicitMidpoint(const NewtonSettings& newton) : newton_(newton) {}

  const NewtonSettings& newton_settings() const { return newton_; }

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    constexpr int n = System::kDimension;
    const double mid_time = t + 0.5 * h;  // tₖ + h/2 [s]
    const StateVector<System, S> z_start = z;
    statistics.newton_iterations_last_step = 0;

    // F(z⁽ᵏ⁺¹⁾) = z⁽ᵏ⁺¹⁾ − z⁽ᵏ⁾ − h f((z⁽ᵏ⁾ + z⁽ᵏ⁺¹⁾)/2, tₖ + h/2)
    auto make_residual = [&system, &z_start, mid_time, h](auto cast) {
      return [&system, &z_start, mid_time, h, cast](const auto& z_next) {
        using T = typename std::decay_t<decltype(z_next)>::Scalar;
        const StateVector<System, T> z_old = cast.template apply<T>(z_start);
        const StateVector<System, T> z_mid = T(0.5) * (z_old + z_next);
        const StateVector<System, T> rate = birkhoffian_rates(system, z_mid, T(mid_time));
        return StateVector<System, T>(z_next - z_old - h * rate);
      };
    };

    // z⁽ᵏ⁺¹⁾ ← z⁽ᵏ⁾ + h f(z⁽ᵏ⁾, tₖ)   (explicit Euler predictor)
    const StateVector<System, S> z_euler = z_start + h * birkhoffian_rates(system, z_start, S(t));
    ++statistics.rhs_evaluations;
    z = z_euler;
    // z⁽ᵏ⁺¹⁾ ← root of F by Newton
    solve_newton<n>(make_residual, z, newton_, t, statistics);
    // ê ← ‖z⁽ᵏ⁺¹⁾ − z_Euler‖ (z only; the passive part of the error vector is left at 0)
    record_local_error_estimate(statistics, local_error_norm<System, S>(z_start, y, StateVector<System, S>(z - z_euler),
                                                                        PassiveVector<System, S>::Zero()));
    // z̄ ← (z⁽ᵏ⁾ + z⁽ᵏ⁺¹⁾)/2;  y⁽ᵏ⁺¹⁾ ← y⁽ᵏ⁾ + h g(z̄, ȳ, tₖ + h/2)
    const StateVector<System, S> z_mid = S(0.5) * (z_start + z);
    y = passive_midpoint_sweeps(system, z_mid, y, mid_time, h, statistics);
  }

 private:
  NewtonSettings newton_;
};

}  // namespace birkhoff_cart
