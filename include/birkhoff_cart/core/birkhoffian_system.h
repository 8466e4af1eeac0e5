// Birkhoffian systems on z ∈ R^{2n} (docs/birkhoffian.md, sign convention eq. (B.1)):
//
//   K(z,t) ż = ∇B(z,t) + ∂R/∂t(z,t) + Λ(z,t),      K_ij = ∂R_j/∂z_i − ∂R_i/∂z_j,
//
// with Birkhoff functions R, Birkhoffian B, structure matrix K and an explicit non-Birkhoffian
// generalized force Λ (nonholonomic terms, applied loads). Passive coordinates y (reconstructed
// coordinates, accumulated work) follow ẏ = g(z, t) and never feed back.
//
// A system type `System` models this concept (static polymorphism, as Boost.Odeint's systems) by
// providing, with Vector<S> = Eigen::Matrix<S, kDimension, 1>:
//
//   static constexpr int kDimension;          // 2n
//   static constexpr int kPassiveDimension;   // dim y (may be 0)
//   template <class S> Vector<S>  birkhoff_functions(const Vector<S>& z, const S& t) const;   // R
//   template <class S> S          birkhoffian(const Vector<S>& z, const S& t) const;          // B
//   template <class S> Matrix<S>  structure_matrix(const Vector<S>& z, const S& t) const;     // K, analytic
//   (optional) template <class S> Matrix<S> structure_matrix_inverse(z, t) const;            // K⁻¹, analytic
//   template <class S> Vector<S>  birkhoffian_gradient(const Vector<S>& z, const S& t) const; // ∇B, analytic
//   template <class S> Vector<S>  birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const; // ∂R/∂t
//   template <class S> Vector<S>  non_birkhoffian_force(const Vector<S>& z, const S& t) const; // Λ (zero
//                                                                   // when non_birkhoffian_force_enabled() is false)
//   bool non_birkhoffian_force_enabled() const;
//   // A Darboux chart w = D(z, t) = (Q, P) with D_zᵀ K₀ D_z = K(z, t), K₀ = [[0, −I], [I, 0]], in
//   // which the Birkhoffian part is Hamiltonian; the generalized symplectic schemes work in it.
//   template <class S> Vector<S>  to_darboux(const Vector<S>& z, const S& t) const;
//   template <class S> Vector<S>  from_darboux(const Vector<S>& w, const S& t) const;
//   template <class S> Vector<S>  darboux_rates(const Vector<S>& w, const S& t) const;        // ẇ, analytic
//   template <class S> PassiveVector<S> passive_rates(const Vector<S>& z, const S& t) const;  // g(z, t)
//   // or, when the passive rates read passive coordinates themselves (the cart: ẋ = ω1 cos(θ + χ)
//   // needs the heading θ, a passive coordinate), instead
//   template <class S> PassiveVector<S> passive_rates(const Vector<S>& z, const PassiveVector<S>& y,
//                                                     const S& t) const;                     // g(z, y, t)
//   // Integrators call the free function passive_coordinate_rates(system, z, y, t), which picks the
//   // member that exists. y never feeds back into z.
//
// The analytic members (K, ∇B, ∂R/∂t, ẇ) are what the integrators use; tests check each against
// automatic differentiation of R and B (test/unit/birkhoffian_system_test.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <type_traits>
#include <utility>

namespace birkhoff_cart {

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
