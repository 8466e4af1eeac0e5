// Generalized K(z,t)-symplectic difference schemes for Birkhoffian systems (Su's scheme, paper
// eqs. (12)–(14); docs/birkhoffian.md §4, eqs. (B.12)–(B.17)).
//
// birkhoff2 — the α mapping is the Darboux chart w = D(z, t) (D_zᵀ K₀ D_z = K) composed with the
// Euler-centred (Cayley/Poincaré) generating-function map
//     α(z̃, z) = ( K₀-type difference D(z̃, t⁺) − D(z, t),  mean ½[D(z̃, t⁺) + D(z, t)] ),
// which satisfies α_*ᵀ J₄ₙ α_* = diag(K(z̃, t⁺), −K(z, t)) (eq. (B.13), checked in
// k_symplectic_test.cpp). With the series (13) truncated after its first term ψ = τ H_w(w̄, t̄) the
// scheme is the midpoint rule in the chart:
//
//     w⁽ᵏ⁾   = D(z⁽ᵏ⁾, tₖ)
//     w⁽ᵏ⁺¹⁾ = w⁽ᵏ⁾ + h ẇ(w̄, t̄),   w̄ = ½(w⁽ᵏ⁾ + w⁽ᵏ⁺¹⁾), t̄ = tₖ + h/2     (solved by Newton)
//     z⁽ᵏ⁺¹⁾ = D⁻¹(w⁽ᵏ⁺¹⁾, tₖ₊₁)
//     y⁽ᵏ⁺¹⁾ = y⁽ᵏ⁾ + h g(D⁻¹(w̄, t̄), t̄)                                       (passive coordinates)
//
// For Λ = 0 the map z⁽ᵏ⁾ ↦ z⁽ᵏ⁺¹⁾ is K(z,t)-symplectic, Mᵀ K(z⁽ᵏ⁺¹⁾, tₖ₊₁) M = K(z⁽ᵏ⁾, tₖ) with
// M = ∂z⁽ᵏ⁺¹⁾/∂z⁽ᵏ⁾, explicitly so by construction; it is symmetric (the adjoint of the step with
// −h from tₖ₊₁ is itself), hence of order 2 with one term of the series.
//
// birkhoff4 — the symmetric triple jump (Yoshida 1990, Suzuki 1990) of birkhoff2 with
// γ₁ = γ₃ = 1/(2 − 2^{1/3}), γ₂ = 1 − 2γ₁: a composition of K(z,t)-symplectic maps between
// consecutive times is K(z,t)-symplectic, and a symmetric composition of a symmetric order-2 map
// with these weights has order 4 (eq. (B.17)).
//
// The generic steppers never call system.begin_step(t) (the test systems have none): the caller
// (the CartStepper registry) does, before every step; see docs/birkhoffian.md §6.
// Statistics: each evaluation of ẇ counts one right-hand-side evaluation, Newton iterations are
// counted per step; steps are counted by the caller.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "birkhoff_cart/core/birkhoffian_system.h"
#include "birkhoff_cart/core/diagnostics.h"
#include "birkhoff_cart/core/integrators/newton.h"

namespace birkhoff_cart {

/// birkhoff2: generalized K(z,t)-symplectic scheme of order 2 (Darboux chart + midpoint).
class BirkhoffSymplectic2 {
 public:
  static constexpr int kOrder = 2;
  static constexpr bool kSymmetric = true;
  static const char* name() { return "birkhoff2"; }

  BirkhoffSymplectic2() = default;
  explicit BirkhoffSymplectic2(const NewtonSettings& newton) : newton_(newton) {}
  const NewtonSettings& newton_settings() const { return newton_; }

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    statistics.newton_iterations_last_step = 0;
    advance(system, z, y, t, h, statistics);
  }

  /// One birkhoff2 step without resetting the per-step Newton counter (used by compositions).
  template <class System, class S>
  void advance(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
               StepStatistics& statistics) const {
    constexpr int n = System::kDimension;
    using WVector = StateVector<System, S>;
    const double t_mid = t + 0.5 * h;  // t̄ [s]
    const double t_next = t + h;       // tₖ₊₁ [s]
    const WVector w_start = system.to_darboux(z, S(t));  // w⁽ᵏ⁾ = D(z⁽ᵏ⁾, tₖ)

    // F(w⁺) = w⁺ − w⁽ᵏ⁾ − h ẇ(½(w⁽ᵏ⁾ + w⁺), t̄); Jacobian I − (h/2) ∂ẇ/∂w by AD in newton.h.
    const auto make_residual = [&system, &w_start, t_mid, h](auto cast) {
      return [&system, &w_start, t_mid, h, cast](const auto& w_next) {
        using T = typename std::decay_t<decltype(w_next)>::Scalar;
        const Eigen::Matrix<T, n, 1> w_k = cast.template apply<T>(w_start);
        const Eigen::Matrix<T, n, 1> w_mid = T(0.5) * (w_k + w_next);
        return Eigen::Matrix<T, n, 1>(w_next - w_k - T(h) * system.darboux_rates(w_mid, T(t_mid)));
      };
    };
    // Predictor: w⁺ ← w⁽ᵏ⁾ + h ẇ(w⁽ᵏ⁾, tₖ) (explicit Euler).
    WVector w_next = w_start + S(h) * system.darboux_rates(w_start, S(t));
    ++statistics.rhs_evaluations;
    solve_newton<n>(make_residual, w_next, newton_, t, statistics);  // w⁽ᵏ⁺¹⁾ ← root of F

    const WVector z_mid = system.from_darboux(WVector(S(0.5) * (w_start + w_next)), S(t_mid));  // z̄ = D⁻¹(w̄, t̄)
    y = passive_midpoint(system, z_mid, y, t_mid, h, statistics);  // y⁽ᵏ⁺¹⁾ ← y⁽ᵏ⁾ + h g(z̄, ȳ, t̄)
    z = system.from_darboux(w_next, S(t_next));                    // z⁽ᵏ⁺¹⁾ ← D⁻¹(w⁽ᵏ⁺¹⁾, tₖ₊₁)
  }

  /// Midpoint rule for the passive coordinates, y⁺ = y + h g(z̄, ½(y + y⁺), t̄), by fixed-point
  /// sweeps. For the cart, g is triangular in y (θ̇ depends on z only, the rest on z and θ), so
  /// the second sweep is exact and the third confirms it; a system whose g does not read y
  /// converges in one sweep (plus the confirming one). Throws StepError if 50 sweeps do not settle.
  template <class System, class S>
  static PassiveVector<System, S> passive_midpoint(const System& system, const StateVector<System, S>& z_mid,
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
      ++statistics.rhs_evaluations;
      const bool settled = (values_of(updated) - values_of(y_next)).cwiseAbs().maxCoeff() <=
                           4.0 * std::numeric_limits<double>::epsilon() *
                               std::max(1.0, values_of(updated).cwiseAbs().maxCoeff());
      y_next = updated;
      if (sweep > 0 && settled) return y_next;  // ≥ 2 sweeps: derivative parts settled too
    }
    throw StepError("birkhoff2: the passive coordinates' midpoint sweeps did not settle at t = " +
                    std::to_string(t_mid) + " s");
  }

 private:
  NewtonSettings newton_;
};

/// birkhoff4: symmetric triple-jump composition of birkhoff2 (order 4, K(z,t)-symplectic).
class BirkhoffSymplectic4 {
 public:
  static constexpr int kOrder = 4;
  static constexpr bool kSymmetric = true;
  static const char* name() { return "birkhoff4"; }

  BirkhoffSymplectic4() = default;
  explicit BirkhoffSymplectic4(const NewtonSettings& newton) : base_(newton) {}
  const NewtonSettings& newton_settings() const { return base_.newton_settings(); }

  /// γ₁ = γ₃ = 1/(2 − 2^{1/3}) ≈ 1.3512, γ₂ = 1 − 2γ₁ ≈ −1.7024 (eq. (B.17)).
  static double outer_weight() { return 1.0 / (2.0 - std::cbrt(2.0)); }
  static double inner_weight() { return 1.0 - 2.0 * outer_weight(); }

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    statistics.newton_iterations_last_step = 0;
    const double h1 = outer_weight() * h;  // γ₁ h [s]
    const double h2 = inner_weight() * h;  // γ₂ h [s]
    base_.advance(system, z, y, t, h1, statistics);            // z ← Φ_{γ₁h}(z) from tₖ
    base_.advance(system, z, y, t + h1, h2, statistics);       // z ← Φ_{γ₂h}(z) from tₖ + γ₁h
    base_.advance(system, z, y, t + h1 + h2, h1, statistics);  // z ← Φ_{γ₁h}(z) from tₖ + (γ₁+γ₂)h
  }

 private:
  BirkhoffSymplectic2 base_;
};

}  // namespace birkhoff_cart
