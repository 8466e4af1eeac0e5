// Birkhoffian systems on z ∈ R^{2n} (docs/birkhoffian.md, sign convention eq. (B.1)):
//
//   K(z,t) ż = ∇B(z,t) + ∂R/∂t(z,t) + Λ(z,t),      K_ij = ∂R_j/∂z_i − ∂R_i/∂z_j,
//
// with Birkhoff functions R, Birkhoffian B, structure matrix K and an explicit non-Birkhoffian
// generalized force Λ (nonholonomic terms, applied loads). Passive coordinates y (reconstructed
// coordinates, accumulated work) follow ẏ = g(z, y, t) and never feed back into z.
//
// A system type `System` models this concept (static polymorphism, as Boost.Odeint's systems); every
// member of the integrator registry integrates any model through its generic step(system, z, y, t,
// h, statistics) (integrators/integrator_members.h). How to bring your own, shown on the Chaplygin
// sleigh (examples/chaplygin_sleigh.h): docs/integrators.md, "Bring your own system".
//
// Units. t is in s. z has the system's own units, coordinate by coordinate ([z_i]; for a mechanical
// system z = (q, p): m or rad, then kg·m/s or kg·m²/s); R_i has units of J·s / [z_i] (R·dz is an
// action), B is in J, K_ij in J·s / ([z_i][z_j]), ∇B_i, (∂R/∂t)_i and Λ_i in J / [z_i]; the Darboux
// chart's w = (Q, P) has Q·P in J·s; y has its own units ([y_k]), g in [y_k]/s.
//
// Required, with Vector<S> = Eigen::Matrix<S, kDimension, 1>, Matrix<S> its square, PassiveVector<S>
// = Eigen::Matrix<S, kPassiveDimension, 1>, and S any scalar: double or an AD jet (autodiff.h; the
// K-symplecticity tests differentiate whole steps):
//
//   static constexpr int kDimension;          // 2n, the size of z
//   static constexpr int kPassiveDimension;   // the size of y (may be 0)
//   bool non_birkhoffian_force_enabled() const;  // false: Λ = 0 (the Birkhoffian part alone)
//   template <class S> Vector<S> birkhoff_functions(const Vector<S>& z, const S& t) const;    // R(z, t)
//   template <class S> S         birkhoffian(const Vector<S>& z, const S& t) const;           // B(z, t) [J]
//   template <class S> Matrix<S> structure_matrix(const Vector<S>& z, const S& t) const;      // K(z, t), analytic
//   template <class S> Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& t) const;  // ∇B = ∂B/∂z, analytic
//   template <class S> Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const;  // ∂R/∂t
//   template <class S> Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& t) const; // Λ (zero when
//                                                                      // non_birkhoffian_force_enabled() is false)
//   // A Darboux chart w = D(z, t) = (Q, P) with D_zᵀ K₀ D_z = K(z, t), K₀ = [[0, −I], [I, 0]], in
//   // which the Birkhoffian part is Hamiltonian; the Birkhoffian members (Gauss collocation and its
//   // compositions) step in it, which makes them K(z,t)-symplectic where Λ = 0.
//   template <class S> Vector<S> to_darboux(const Vector<S>& z, const S& t) const;            // w = D(z, t)
//   template <class S> Vector<S> from_darboux(const Vector<S>& w, const S& t) const;          // z = D⁻¹(w, t)
//   template <class S> Vector<S> darboux_rates(const Vector<S>& w, const S& t) const;         // ẇ = D_z ż + ∂_t D,
//                                                                      // analytic, Λ included when enabled
//   template <class S> PassiveVector<S> passive_rates(const Vector<S>& z, const S& t) const;  // g(z, t)
//   // or, when the passive rates read passive coordinates themselves (the cart: ẋ = ω1 cos(θ + χ)
//   // needs the heading θ, a passive coordinate), instead
//   template <class S> PassiveVector<S> passive_rates(const Vector<S>& z, const PassiveVector<S>& y,
//                                                     const S& t) const;                     // g(z, y, t)
//   // Integrators call the free function passive_coordinate_rates(system, z, y, t), which picks the
//   // member that exists. y never feeds back into z.
//
// Optional, detected by the members when present (each changes the cost or the round-off, never
// the method; a wrong one changes the trajectory, so test it: chaplygin_sleigh_test compares a
// system with its hooks against the same system without them):
//
//   template <class S> Matrix<S> structure_matrix_inverse(const Vector<S>& z, const S& t) const;
//       K⁻¹(z, t) in closed form, for the solved rates ż = K⁻¹(∇B + ∂R/∂t + Λ) (birkhoffian_rates:
//       the explicit peers, the midpoint rule); without it K is LU-factored at every call.
//   static constexpr unsigned kCyclicMask;
//       Bit i set: no component of ẇ reads w_i (the cart's arc length π1; the sleigh's π1 and θ), so
//       column i of J = ∂ẇ/∂w is zero. The stage solve takes those coordinates out of its Newton
//       block (kronecker_newton.h; it checks the column and keeps them in when it is not zero) and
//       their changes do not vote in its stop rule. Default 0 (none).
//   static constexpr int kPassiveCouplingDepth;
//       d ≥ 0: g reads y only through passive coordinates whose own rates depend on z alone, nested
//       d deep (d = 0: g does not read y at all; d = 1 for the cart: ẋ reads θ, and θ̇ reads z), so
//       d + 1 sweeps of the passive quadrature are exact. Default: sweeps until the stages settle
//       (at most 50, then StepError).
//   static constexpr bool kDarbouxChartIsLinear;
//       true: D(z, t) is linear in z (at each t), so the compensated-summation remainders map through
//       the chart; compensated summation (IntegratorSettings::compensated_summation) needs it.
//       Default false: no compensation.
//   Matrix<double> darboux_jacobian(const Vector<double>& w, double t) const;
//       J = ∂ẇ/∂w at (w, t) in closed form [1/s in the chart's units], for the simplified-Newton
//       matrices of the stage solve; default: forward-mode AD of darboux_rates (one jet evaluation).
//   template <std::size_t s> void darboux_rates_stages(const std::array<Vector<double>, s>& w,
//       const std::array<double, s>& t, std::array<Vector<double>, s>& rates) const;
//       ẇ at the s stages of a collocation step at once (the cart: one vector sin/cos for all stages,
//       vector_math.h); must equal darboux_rates point by point to round-off. Used from two stages on.
//   template <class S> PassiveVector<S> passive_coupling_rates(const Vector<S>& z, const S& t) const;
//       With kPassiveCouplingDepth = d ≥ 1: the rates of just the passive coordinates g reads, each a
//       function of z alone (the cart: θ̇), other entries zero, equal to passive_rates' entries bit
//       for bit; the first d passive sweeps evaluate only these.
//
// Optional, read by the step controls (adaptive_step_control.h, reversible_step_control.h; the table
// of system_traits.h, docs/birkhoffian.md §10.7):
//
//   static constexpr std::array<AngleCoordinate, N> kAngleCoordinates;  bool angle_is_periodic(std::size_t k) const;
//       The coordinates that are angles [rad], carried reduced to (−π, π] with their whole turns apart
//       while the rates are 2π-periodic in them (the cart: χ and θ; the sleigh: θ). Default: none.
//   template <class S> S step_density(const Vector<S>& z) const;
//       σ(z) [1/s], a function of z alone: the reversible control's steps are h ≈ ε/σ. Default 1 s⁻¹.
//   void begin_step(double t);
//       Called with the start time t [s] of each step the adaptive control attempts. Default: nothing.
//
// The analytic members (K, ∇B, ∂R/∂t, ẇ) are what the integrators use; tests check each against
// automatic differentiation of R and B (test/unit/structure_checks.h, used by
// birkhoffian_system_test for the test systems and the cart and by chaplygin_sleigh_test).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <type_traits>
#include <utility>

namespace birkhoff_cart {

/// An angle among a system's coordinates [rad]: z(index), or y(index) when `passive` (the optional
/// kAngleCoordinates of a system: system_traits.h).
struct AngleCoordinate {
  bool passive = false;
  int index = 0;
};

template <class System, class S>
using StateVector = Eigen::Matrix<S, System::kDimension, 1>;
template <class System, class S>
using StructureMatrix = Eigen::Matrix<S, System::kDimension, System::kDimension>;
template <class System, class S>
using PassiveVector = Eigen::Matrix<S, System::kPassiveDimension, 1>;

/// K₀ = [[0, −I], [I, 0]]: the structure matrix of R = (p, 0), i.e. of canonical coordinates
/// z = (q, p) in our sign convention (docs eq. (B.2)).
template <int Dimension>
Eigen::Matrix<double, Dimension, Dimension> canonical_structure() {
  constexpr int n = Dimension / 2;
  Eigen::Matrix<double, Dimension, Dimension> k = Eigen::Matrix<double, Dimension, Dimension>::Zero();
  k.template block<n, n>(0, n) = -Eigen::Matrix<double, n, n>::Identity();
  k.template block<n, n>(n, 0) = Eigen::Matrix<double, n, n>::Identity();
  return k;
}

namespace birkhoffian_system_detail {
template <class System, class S, class = void>
struct HasStructureMatrixInverse : std::false_type {};
template <class System, class S>
struct HasStructureMatrixInverse<System, S,
                                 std::void_t<decltype(std::declval<const System&>().structure_matrix_inverse(
                                     std::declval<const StateVector<System, S>&>(), std::declval<const S&>()))>>
    : std::true_type {};
}  // namespace birkhoffian_system_detail

/// ż = K(z,t)⁻¹ (∇B + ∂R/∂t + Λ): Birkhoff's equations solved for the rates (docs eq. (B.1)).
/// A system may provide an analytic `structure_matrix_inverse(z, t)` (e.g. K₀⁻¹ = −K₀ for the
/// cart); otherwise K is LU-factored at every call.
template <class System, class S>
StateVector<System, S> birkhoffian_rates(const System& system, const StateVector<System, S>& z, const S& t) {
  const StateVector<System, S> right_hand_side = system.birkhoffian_gradient(z, t) +
                                                 system.birkhoff_functions_time_derivative(z, t) +
                                                 system.non_birkhoffian_force(z, t);
  if constexpr (birkhoffian_system_detail::HasStructureMatrixInverse<System, S>::value) {
    return system.structure_matrix_inverse(z, t) * right_hand_side;
  } else {
    const StructureMatrix<System, S> k = system.structure_matrix(z, t);
    return k.partialPivLu().solve(right_hand_side);
  }
}

namespace birkhoffian_system_detail {
template <class System, class S, class = void>
struct HasPassiveRatesWithY : std::false_type {};
template <class System, class S>
struct HasPassiveRatesWithY<System, S,
                            std::void_t<decltype(std::declval<const System&>().passive_rates(
                                std::declval<const StateVector<System, S>&>(),
                                std::declval<const PassiveVector<System, S>&>(), std::declval<const S&>()))>>
    : std::true_type {};
}  // namespace birkhoffian_system_detail

/// ẏ = g(z, y, t): the system's passive_rates(z, y, t) if it has one, else passive_rates(z, t).
template <class System, class S>
PassiveVector<System, S> passive_coordinate_rates(const System& system, const StateVector<System, S>& z,
                                                  const PassiveVector<System, S>& y, const S& t) {
  if constexpr (birkhoffian_system_detail::HasPassiveRatesWithY<System, S>::value) {
    return system.passive_rates(z, y, t);
  } else {
    static_cast<void>(y);
    return system.passive_rates(z, t);
  }
}

}  // namespace birkhoff_cart
