// The integrator registry's members as types: one line each, the member's generic stepper and a
// one-line description. This list is the one place a member is added (docs/developing.md, "Adding
// an integrator"); everything else a row of the registry says is read from the stepper type by the
// row builder (src/core/cart_binding/integrator_registry.cpp): its name(), kOrder, kSymmetric, its
// kind (member_kind), the step controls it takes and whether it evaluates its stages together.
//
// The typed tests instantiate from IntegratorMemberTypes (integrator_contract_test and
// k_symplectic_test, on the test systems, the cart and the example system of
// examples/chaplygin_sleigh.h), and integrator_contract_test checks that its members are the
// registry's, in the registry's order.
//
// A stepper type S of a member provides (the generic stepper interface, docs/integrators.md):
//   static const char* name();             the member's name (integrator.name, --integrator)
//   static constexpr int kOrder;           order of accuracy p [-]
//   static constexpr bool kSymmetric;      a time-symmetric (self-adjoint) step map
//   static constexpr IntegratorKind kKind; the family of its scheme (integrator_kind.h)
//   template <class System, class Scalar>
//   void step(const System&, StateVector<System, Scalar>& z, PassiveVector<System, Scalar>& y,
//             double t, double h, StepStatistics&) const;      one step of h [s] from t [s]
// and is built from what its constructor takes (configured_stepper below). A Birkhoffian member
// also has `template <class System> using Memory` and advance_compensated (carried_state.h), which
// give it the reversible step control when it is symmetric.
#pragma once

#include <tuple>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/integrators/birkhoff_symplectic.h"
#include "birkhoff_cart/core/integrators/dopri5.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "birkhoff_cart/core/integrators/implicit_midpoint.h"
#include "birkhoff_cart/core/integrators/integrator_kind.h"
#include "birkhoff_cart/core/integrators/runge_kutta.h"

namespace birkhoff_cart {

/// One member of the registry: its stepper type, a one-line description for help texts and, for a
/// member with a local error estimate that the adaptive step control cannot steer to the tolerance
/// asked, why it is refused there (nullptr: taken where its stepper type allows it).
template <class Stepper>
struct IntegratorMember {
  using Type = Stepper;
  const char* description;
  const char* adaptive_refusal = nullptr;
};

/// Why the compositions are refused under the adaptive step control (measured: docs/accuracy.md,
/// "Members the adaptive control refuses").
inline constexpr const char* kCompositionAdaptiveRefusal =
    "a composition's estimate (the sum of its birkhoff2 sub-steps' estimates, of order 4) does not follow "
    "its error, and the adaptive control ended up to 540x beyond the tolerance with it on the shipped scenes; "
    "run it at fixed steps, or take birkhoff_gauss4, birkhoff_gauss6 or birkhoff_gauss8 under the adaptive control";

/// Why birkhoff2 is refused under the adaptive step control (measured as above).
inline constexpr const char* kMidpointCollocationAdaptiveRefusal =
    "its estimate (the 1-stage collocation defect) under-states its error, and the adaptive control ended "
    "2.5-3.1x beyond the tolerance with it on drive_rr_drag and free_coast; run it at fixed steps, or take "
    "birkhoff_gauss4, birkhoff_gauss6 or birkhoff_gauss8 under the adaptive control";

/// The registry's members, in the registry's order (integrator_names(), `cart_simulate --help`, the
/// tests' cases). A new member is one more line here.
inline constexpr std::tuple kIntegratorMembers{
    IntegratorMember<GaussCollocation<1>>{"Su's scheme: 1-stage Gauss in the chart", kMidpointCollocationAdaptiveRefusal},
    IntegratorMember<BirkhoffComposition<TripleJumpWeights>>{"triple jump of birkhoff2", kCompositionAdaptiveRefusal},
    IntegratorMember<HeunRungeKutta2>{"Heun's method"},
    IntegratorMember<ClassicalRungeKutta4>{"classical Runge-Kutta"},
    IntegratorMember<DormandPrince5>{"Dormand-Prince 5(4) of Boost.Odeint"},
    IntegratorMember<ImplicitMidpoint>{"implicit midpoint rule on z"},
    IntegratorMember<GaussCollocation<2>>{"2-stage Gauss-Legendre in the chart"},
    IntegratorMember<GaussCollocation<3>>{"3-stage Gauss-Legendre in the chart"},
    IntegratorMember<GaussCollocation<4>>{"4-stage Gauss-Legendre in the chart"},
    IntegratorMember<BirkhoffComposition<SuzukiFiveWeights>>{"Suzuki's 5 stages of birkhoff2", kCompositionAdaptiveRefusal},
    IntegratorMember<BirkhoffComposition<KahanLiSixWeights>>{"Kahan & Li's 9 stages of birkhoff2",
                                                      kCompositionAdaptiveRefusal},
    IntegratorMember<BirkhoffComposition<KahanLiEightWeights>>{"Kahan & Li's 17 stages of birkhoff2",
                                                        kCompositionAdaptiveRefusal},
};

/// A list of stepper types (for typed tests: integrator_contract_test turns it into testing::Types).
template <class... Steppers>
struct StepperList {
  static constexpr std::size_t kSize = sizeof...(Steppers);
};

namespace integrator_members_detail {
template <class Members>
struct StepperTypes;
template <class... Steppers>
struct StepperTypes<std::tuple<IntegratorMember<Steppers>...>> {
  using type = StepperList<Steppers...>;
};

/// The kind of a stepper type that does not state kKind itself.
template <class Stepper>
struct StatedKind;
template <int Stages>
struct StatedKind<GaussCollocation<Stages>> : std::integral_constant<IntegratorKind, IntegratorKind::kBirkhoffianCollocation> {};
template <>
struct StatedKind<DormandPrince5> : std::integral_constant<IntegratorKind, IntegratorKind::kAdaptive> {};

template <class Stepper, class = void>
struct HasKind : std::false_type {};
template <class Stepper>
struct HasKind<Stepper, std::void_t<decltype(Stepper::kKind)>> : std::true_type {};

/// A stepper with its own local error tolerance (dopri5) reads the settings' `tolerance`.
template <class Stepper, class = void>
struct HasTolerance : std::false_type {};
template <class Stepper>
struct HasTolerance<Stepper, std::void_t<decltype(std::declval<const Stepper&>().tolerance())>> : std::true_type {};
}  // namespace integrator_members_detail

/// The stepper types of the members, in the registry's order.
using IntegratorMemberTypes =
    typename integrator_members_detail::StepperTypes<std::remove_cv_t<decltype(kIntegratorMembers)>>::type;

/// The family of a member's scheme: its Stepper::kKind.
template <class Stepper>
constexpr IntegratorKind member_kind() {
  if constexpr (integrator_members_detail::HasKind<Stepper>::value) {
    return Stepper::kKind;
  } else {
    return integrator_members_detail::StatedKind<Stepper>::value;
  }
}

/// A member's generic stepper, built from the settings it reads: the Birkhoffian members their
/// stage solve's (collocation) settings, the midpoint rule its Newton settings, an adaptive pair
/// its tolerance, an explicit method nothing. The registry's factories and the typed tests build
/// them with this one function.
template <class Stepper>
Stepper configured_stepper(const IntegratorSettings& settings) {
  if constexpr (std::is_constructible_v<Stepper, const CollocationSettings&>) {
    CollocationSettings collocation;
    collocation.max_iterations = settings.max_newton_iterations;
    collocation.compensated = settings.compensated_summation;
    collocation.estimate_local_error = settings.local_error_estimate;
    return Stepper(collocation);
  } else if constexpr (std::is_constructible_v<Stepper, const NewtonSettings&>) {
    NewtonSettings newton;
    newton.tolerance = settings.newton_tolerance;
    newton.max_iterations = settings.max_newton_iterations;
    return Stepper(newton);
  } else if constexpr (integrator_members_detail::HasTolerance<Stepper>::value) {
    return Stepper(settings.tolerance);
  } else {
    return Stepper();
  }
}

}  // namespace birkhoff_cart
