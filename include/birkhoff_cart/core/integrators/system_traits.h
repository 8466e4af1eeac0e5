// What the integrators and the step controls read off a Birkhoffian system type beyond the required
// members of the system concept (birkhoffian_system.h): optional hooks, each detected at compile
// time, each with a default that is always correct and only slower or coarser. docs/birkhoffian.md
// §10.2–§10.7.
//
//   hook                                          default            used by
//   static constexpr unsigned kCyclicMask         0 (none cyclic)    the stop rule (cyclic coordinates do not
//                                                                    vote), the Newton matrix (their J columns
//                                                                    are zero: kronecker_newton.h)
//   static constexpr int kPassiveCouplingDepth    −1 (unknown)       the passive quadrature: d + 1 sweeps exact
//   static constexpr bool kDarbouxChartIsLinear   false              compensated summation through the chart
//   static constexpr bool kDarbouxChartIsIdentity false              a step's F(w⁺) as ż at its end (dense output);
//                                                                    the time transformation needs it
//   darboux_jacobian(w, t)                        forward-mode AD    the simplified-Newton matrix J = ∂ẇ/∂w
//   darboux_rates_stages(w[s], t[s], F[s])        s calls of ẇ       one call for an iteration's s stages
//   passive_coupling_rates(z, t)                  the full g         the first d passive sweeps
//   darboux_and_passive_rates(w, y, t, F, G)      ẇ and g apart      the estimate's F(w⁺) and g(z⁺, y⁺) (identity
//                                                                    chart): sin χ, ω and the loads once
//   passive_rates_stages(z[s], y[s], t[s], G[s])  s calls of g and   the passive quadrature's sweeps over the s
//   passive_coupling_rates_stages(z[s], t[s],     of the coupling    stages in one call each (the same bits)
//     G[s])                                       rates
//   static constexpr std::array<AngleCoordinate,  none               the carried point (carried_point.h): each
//     N> kAngleCoordinates                                           angle [rad] kept in (−π, π] with its whole
//                                                                    turns apart, so its ulp does not grow
//   bool angle_is_periodic(std::size_t k) const   true               whether the rates are 2π-periodic in angle k
//                                                                    now (false: it is carried unreduced)
//   template <class S> S step_density(z) const    1 [1/s]            the reversible control's σ(z) [1/s], eq.
//                                                                    (B.41): hₙ ≈ ε/σ(zₙ); a function of z alone
//   void begin_step(double t)                     nothing            called with the start time t [s] of every
//                                                                    step attempt of the adaptive control and of
//                                                                    its side steps (the cart's paper form moves
//                                                                    its structure epoch there)
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

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

template <class System, class = void>
struct HasAngleCoordinates : std::false_type {};
template <class System>
struct HasAngleCoordinates<System, std::void_t<decltype(System::kAngleCoordinates)>> : std::true_type {};

template <class System, class = void>
struct HasAnglePeriodicity : std::false_type {};
template <class System>
struct HasAnglePeriodicity<System, std::void_t<decltype(std::declval<const System&>().angle_is_periodic(
                                       std::declval<std::size_t>()))>> : std::true_type {};

template <class System, class = void>
struct HasStepDensity : std::false_type {};
template <class System>
struct HasStepDensity<System, std::void_t<decltype(std::declval<const System&>().step_density(
                                  std::declval<const StateVector<System, double>&>()))>> : std::true_type {};

template <class System, class = void>
struct HasBeginStep : std::false_type {};
template <class System>
struct HasBeginStep<System, std::void_t<decltype(std::declval<System&>().begin_step(0.0))>> : std::true_type {};

template <class System>
constexpr auto angle_coordinates() {
  if constexpr (HasAngleCoordinates<System>::value) {
    return System::kAngleCoordinates;
  } else {
    return std::array<AngleCoordinate, 0>{};
  }
}

template <class System, int Stages, class = void>
struct HasStageRates : std::false_type {};
template <class System, int Stages>
struct HasStageRates<System, Stages,
                     std::void_t<decltype(std::declval<const System&>().darboux_rates_stages(
                         std::declval<const std::array<StateVector<System, double>, Stages>&>(),
                         std::declval<const std::array<double, Stages>&>(),
                         std::declval<std::array<StateVector<System, double>, Stages>&>()))>> : std::true_type {};

template <class System, int Stages, class = void>
struct HasPassiveStageRates : std::false_type {};
template <class System, int Stages>
struct HasPassiveStageRates<
    System, Stages,
    std::void_t<decltype(std::declval<const System&>().passive_rates_stages(
                    std::declval<const std::array<StateVector<System, double>, Stages>&>(),
                    std::declval<const std::array<PassiveVector<System, double>, Stages>&>(),
                    std::declval<const std::array<double, Stages>&>(),
                    std::declval<std::array<PassiveVector<System, double>, Stages>&>())),
                decltype(std::declval<const System&>().passive_coupling_rates_stages(
                    std::declval<const std::array<StateVector<System, double>, Stages>&>(),
                    std::declval<const std::array<double, Stages>&>(),
                    std::declval<std::array<PassiveVector<System, double>, Stages>&>()))>> : std::true_type {};

template <class System, class = void>
struct HasDarbouxAndPassiveRates : std::false_type {};
template <class System>
struct HasDarbouxAndPassiveRates<System, std::void_t<decltype(std::declval<const System&>().darboux_and_passive_rates(
                                             std::declval<const StateVector<System, double>&>(),
                                             std::declval<const PassiveVector<System, double>&>(), 0.0,
                                             std::declval<StateVector<System, double>&>(),
                                             std::declval<PassiveVector<System, double>&>()))>> : std::true_type {};
}  // namespace detail

/// The system gives ẇ and g at one point of its identity chart from one evaluation of what they
/// share (darboux_and_passive_rates(w, y, t, ẇ, g)), bit for bit darboux_rates and passive_rates:
/// the local error estimate's rates at a step's end.
template <class System>
constexpr bool kHasDarbouxAndPassiveRates = detail::HasDarbouxAndPassiveRates<System>::value;

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

/// The system evaluates g (passive_rates) and the coupling rates (passive_coupling_rates) at all s
/// stages at once (passive_rates_stages, passive_coupling_rates_stages), bit for bit the same as
/// stage by stage: the passive quadrature's sweeps (passive_quadrature.h).
template <class System, int Stages>
constexpr bool kHasPassiveStageRates = detail::HasPassiveStageRates<System, Stages>::value;

/// The angles the system declares (kAngleCoordinates), in its order; none by default.
template <class System>
constexpr auto kAngleCoordinates = detail::angle_coordinates<System>();

/// How many angles the system declares [-].
template <class System>
constexpr std::size_t kAngleCount = kAngleCoordinates<System>.size();

/// Bit k set: the rates are 2π-periodic in angle k of kAngleCoordinates now (the system's
/// angle_is_periodic(k); by default every declared angle is).
template <class System>
unsigned periodic_angles(const System& system) {
  unsigned mask = 0u;
  for (std::size_t k = 0; k < kAngleCount<System>; ++k) {
    bool periodic = true;
    if constexpr (detail::HasAnglePeriodicity<System>::value) periodic = system.angle_is_periodic(k);
    if (periodic) mask |= 1u << k;
  }
  return mask;
}

/// σ(z) [1/s], the step density of the reversible control (eq. (B.41)): the system's step_density(z)
/// when it has one, else 1 s⁻¹ (constant physical steps h = ε s).
template <class System, class S>
S step_density(const System& system, const Eigen::Matrix<S, System::kDimension, 1>& z) {
  if constexpr (detail::HasStepDensity<System>::value) {
    return system.step_density(z);
  } else {
    static_cast<void>(system);
    static_cast<void>(z);
    return S(1.0);
  }
}

/// Calls the system's begin_step(t) [s] before a step from t, if it has one (`System` may be const
/// when it has none).
template <class System>
void begin_step(System& system, double t) {
  if constexpr (detail::HasBeginStep<std::remove_const_t<System>>::value) {
    system.begin_step(t);
  } else {
    static_cast<void>(system);
    static_cast<void>(t);
  }
}

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
