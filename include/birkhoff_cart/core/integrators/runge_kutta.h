// Explicit Runge–Kutta peers of the generalized symplectic schemes. They integrate the same
// Birkhoffian variables z (and the passive coordinates y) as birkhoff2/birkhoff4, through the
// solved form of Birkhoff's equations (docs/birkhoffian.md eq. (B.1)):
//
//   ż = K(z,t)⁻¹ (∇B + ∂R/∂t + Λ) =: f(z, t),     ẏ = g(z, y, t)   (passive_coordinate_rates).
//
// Each stage carries z and y together (the cart's g reads the heading θ, a passive coordinate).
//
// They are generic in the scalar S (double or an AD jet) so that the step map can be
// differentiated (the K-symplecticity test compares them with the Birkhoffian schemes). Neither
// is symmetric nor K(z,t)-symplectic: over long runs their energy error drifts.
//
// Statistics: each stage adds one right-hand-side evaluation; steps are counted by the caller
// (the CartStepper registry), not by the generic steppers. Each step records a local error
// estimate (error_estimate.h) from an embedded lower-order solution built from the same stages,
// at no extra right-hand-side evaluation; it estimates the embedded solution's error, so it is an
// upper estimate of the method's own local error (pessimistic by O(h^{p − p̂}), docs/accuracy.md).
#pragma once

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/integrator_kind.h"

namespace birkhoff_cart {

namespace runge_kutta_detail {

/// The joint right-hand side (ż, ẏ) = (f(z, t), g(z, y, t)) at a scalar time t [s].
template <class System, class S>
void joint_rates(const System& system, const StateVector<System, S>& z, const PassiveVector<System, S>& y,
                 double t, StateVector<System, S>& z_rate, PassiveVector<System, S>& y_rate,
                 StepStatistics& statistics) {
  const S time(t);
  z_rate = birkhoffian_rates(system, z, time);
  y_rate = passive_coordinate_rates(system, z, y, time);
  ++statistics.rhs_evaluations;
}

}  // namespace runge_kutta_detail

/// Heun's method ("rk2"): the explicit trapezoidal rule, 2nd order, 2 stages. Butcher tableau
///
///     0 |
///     1 | 1
///   ----+----------
///       | 1/2  1/2
///
/// The paper (its §4) compares its scheme with "2nd-order Runge–Kutta" without naming the
/// variant. We take Heun's method because it is what Chinese numerical-analysis textbooks call
/// 二阶龙格–库塔 / 改进欧拉法 (the improved Euler method), the paper's likely meaning; both common
/// 2-stage variants (Heun, explicit midpoint) have the same order and the same non-symmetric,
/// non-symplectic character, which is all the comparison relies on.
///
/// Error estimate: the embedded explicit Euler solution b̂ = (1, 0) (the Heun–Euler 2(1) pair),
///   x⁽ᵏ⁺¹⁾ − x̂⁽ᵏ⁺¹⁾ = h/2 (k₂ − k₁)   (local error of order h², the method's is h³).
struct HeunRungeKutta2 {
  static constexpr int kOrder = 2;
  static constexpr bool kSymmetric = false;
  static constexpr IntegratorKind kKind = IntegratorKind::kExplicitRungeKutta;
  static const char* name() { return "rk2"; }

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    using runge_kutta_detail::joint_rates;
    StateVector<System, S> k1_z, k2_z;
    PassiveVector<System, S> k1_y, k2_y;
    joint_rates(system, z, y, t, k1_z, k1_y, statistics);            // k₁ = f(z⁽ᵏ⁾, tₖ)
    const StateVector<System, S> z_euler = z + h * k1_z;             // z̃ = z⁽ᵏ⁾ + h k₁
    const PassiveVector<System, S> y_euler = y + h * k1_y;           // ỹ = y⁽ᵏ⁾ + h g₁
    joint_rates(system, z_euler, y_euler, t + h, k2_z, k2_y, statistics);  // k₂ = f(z̃, tₖ + h)
    // ê ← ‖h/2 (k₂ − k₁)‖ (Heun minus the embedded Euler solution)
    record_local_error_estimate(statistics,
                                local_error_norm<System, S>(z, y, StateVector<System, S>((0.5 * h) * (k2_z - k1_z)),
                                                            PassiveVector<System, S>((0.5 * h) * (k2_y - k1_y))));
    z += (0.5 * h) * (k1_z + k2_z);                                  // z⁽ᵏ⁺¹⁾ ← z⁽ᵏ⁾ + h/2 (k₁ + k₂)
    y += (0.5 * h) * (k1_y + k2_y);                                  // y⁽ᵏ⁺¹⁾ ← y⁽ᵏ⁾ + h/2 (g₁ + g₂)
  }
};

/// The classical 4th-order Runge–Kutta method ("rk4"), 4 stages. Butcher tableau
///
///     0   |
///     1/2 | 1/2
///     1/2 | 0    1/2
///     1   | 0    0    1
///   ------+--------------------
///         | 1/6  1/3  1/3  1/6
///
/// Error estimate: no 3rd-order solution exists from these four stages (the order-3 conditions
/// force b̂ = b), so the embedded solution is the 2nd-order b̂ = (1/6, 2/3, 0, 1/6) (Simpson's rule
/// with k₂ at the midpoint; it also meets Σ b̂ᵢcᵢ² = 1/3, the closest 2nd-order member):
///   x⁽ᵏ⁺¹⁾ − x̂⁽ᵏ⁺¹⁾ = h/3 (k₃ − k₂)   (order h³ while the method's local error is h⁵: an upper
///   estimate, pessimistic by a factor ~ 10/(hλ)² on ẋ = λx).
struct ClassicalRungeKutta4 {
  static constexpr int kOrder = 4;
  static constexpr bool kSymmetric = false;
  static constexpr IntegratorKind kKind = IntegratorKind::kExplicitRungeKutta;
  static const char* name() { return "rk4"; }

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    using runge_kutta_detail::joint_rates;
    StateVector<System, S> k1_z, k2_z, k3_z, k4_z;
    PassiveVector<System, S> k1_y, k2_y, k3_y, k4_y;
    const double half = 0.5 * h;
    using Z = StateVector<System, S>;
    using Y = PassiveVector<System, S>;
    joint_rates(system, z, y, t, k1_z, k1_y, statistics);                   // k₁ = f(z⁽ᵏ⁾, tₖ)
    joint_rates(system, Z(z + half * k1_z), Y(y + half * k1_y), t + half, k2_z, k2_y,
                statistics);                                                // k₂ = f(z⁽ᵏ⁾ + h/2 k₁, tₖ + h/2)
    joint_rates(system, Z(z + half * k2_z), Y(y + half * k2_y), t + half, k3_z, k3_y,
                statistics);                                                // k₃ = f(z⁽ᵏ⁾ + h/2 k₂, tₖ + h/2)
    joint_rates(system, Z(z + h * k3_z), Y(y + h * k3_y), t + h, k4_z, k4_y,
                statistics);                                                // k₄ = f(z⁽ᵏ⁾ + h k₃, tₖ + h)
    // ê ← ‖h/3 (k₃ − k₂)‖ (rk4 minus the embedded b̂ = (1/6, 2/3, 0, 1/6))
    record_local_error_estimate(statistics,
                                local_error_norm<System, S>(z, y, Z((h / 3.0) * (k3_z - k2_z)), Y((h / 3.0) * (k3_y - k2_y))));
    z += (h / 6.0) * (k1_z + 2.0 * k2_z + 2.0 * k3_z + k4_z);  // z⁽ᵏ⁺¹⁾ ← z⁽ᵏ⁾ + h/6 (k₁ + 2k₂ + 2k₃ + k₄)
    y += (h / 6.0) * (k1_y + 2.0 * k2_y + 2.0 * k3_y + k4_y);  // y⁽ᵏ⁺¹⁾ ← y⁽ᵏ⁾ + h/6 (g₁ + 2g₂ + 2g₃ + g₄)
  }
};

}  // namespace birkhoff_cart
