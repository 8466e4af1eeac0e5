// What the collocation members read off a Birkhoffian system type beyond the required members of the
// system concept (birkhoffian_system.h): optional hooks, each detected at compile time, each with a
// default that is always correct and only slower. docs/birkhoffian.md §10.2–§10.6.
//
//   hook                                          default            used by
//   static constexpr unsigned kCyclicMask         0 (none cyclic)    the stop rule (cyclic coordinates do not
//                                                                    vote), the Newton matrix (their J columns
//                                                                    are zero: kronecker_newton.h)
//   static constexpr int kPassiveCouplingDepth    −1 (unknown)       the passive quadrature: d + 1 sweeps exact
//   static constexpr bool kDarbouxChartIsLinear   false              compensated summation through the chart
//   static constexpr bool kDarbouxChartIsIdentity false              a step's F(w⁺) as ż at its end (dense output)
//   darboux_jacobian(w, t)                        forward-mode AD    the simplified-Newton matrix J = ∂ẇ/∂w
//   darboux_rates_stages(w[s], t[s], F[s])        s calls of ẇ       one call for an iteration's s stages
//   passive_coupling_rates(z, t)                  the full g         the first d passive sweeps
#pragma once

#include <Eigen/Core>
#include <array>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/autodiff.h"
#include "birkhoff_cart/core/birkhoffian_system.h"

namespace birkhoff_cart {
namespace system_traits {

namespace detail {
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

template <class System, class = void>
struct IdentityChart : std::false_type {};
template <class System>
struct IdentityChart<System, std::void_t<decltype(System::kDarbouxChartIsIdentity)>>
    : std::integral_constant<bool, System::kDarbouxChartIsIdentity> {};

template <class System, class = void>
struct HasPassiveCouplingRates : std::false_type {};
template <class System>
struct HasPassiveCouplingRates<System,
                               std::void_t<decltype(std::declval<const System&>().passive_coupling_rates(
                                   std::declval<const StateVector<System, double>&>(), std::declval<const double&>()))>>
    : std::true_type {};

template <class System, class = void>
struct HasDarbouxJacobian : std::false_type {};
template <class System>
struct HasDarbouxJacobian<System, std::void_t<decltype(std::declval<const System&>().darboux_jacobian(
                                      std::declval<const StateVector<System, double>&>(), 0.0))>> : std::true_type {};

template <class System, int Stages, class = void>
struct HasStageRates : std::false_type {};
template <class System, int Stages>
struct HasStageRates<System, Stages,
                     std::void_t<decltype(std::declval<const System&>().darboux_rates_stages(
                         std::declval<const std::array<StateVector<System, double>, Stages>&>(),
                         std::declval<const std::array<double, Stages>&>(),
                         std::declval<std::array<StateVector<System, double>, Stages>&>()))>> : std::true_type {};
}  // namespace detail

/// The coordinates no rate reads (bit k: coordinate k of z), e.g. the cart's arc length π1.
template <class System>
constexpr unsigned kCyclicMask = detail::CyclicMask<System>::value;

/// d ≥ 0: g reads y only through coordinates whose own rates depend on z alone, d levels deep, so
/// d + 1 sweeps of the passive quadrature are exact; −1: unknown (sweeps until settled).
template <class System>
constexpr int kPassiveCouplingDepth = detail::PassiveCouplingDepth<System>::value;

/// w = D(z, t) is linear in z (remainders of compensated summation map through it).
template <class System>
constexpr bool kDarbouxChartIsLinear = detail::LinearChart<System>::value;

/// w = D(z, t) = z: ẇ is ż.
template <class System>
constexpr bool kDarbouxChartIsIdentity = detail::IdentityChart<System>::value;

/// The system gives the rates of the passive coordinates g reads, alone (passive_coupling_rates).
template <class System>
constexpr bool kHasPassiveCouplingRates = detail::HasPassiveCouplingRates<System>::value;

/// The system gives J = ∂ẇ/∂w in closed form (darboux_jacobian(w, t)).
template <class System>
constexpr bool kHasDarbouxJacobian = detail::HasDarbouxJacobian<System>::value;

/// The system evaluates ẇ at all s stages of an iteration at once (darboux_rates_stages).
template <class System, int Stages>
constexpr bool kHasStageRates = detail::HasStageRates<System, Stages>::value;

/// J = ∂ẇ/∂w at (w, t): the system's closed form when it has one, else forward-mode AD of ẇ.
template <class System>
Eigen::Matrix<double, System::kDimension, System::kDimension> darboux_jacobian(const System& system,
                                                                             const StateVector<System, double>& w,
                                                                             double t) {
  constexpr int n = System::kDimension;
  if constexpr (kHasDarbouxJacobian<System>) {
    return system.darboux_jacobian(w, t);
  } else {
    using JetN = Eigen::AutoDiffScalar<Eigen::Matrix<double, n, 1, Eigen::DontAlign>>;
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

}  // namespace system_traits
}  // namespace birkhoff_cart
