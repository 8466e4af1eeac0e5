// The integrator registry (integrator_registry.h): the table of the members, and the two factories
// that turn a member's generic stepper into a CartStepper, at fixed steps or under the reversible
// step control, in the Birkhoffian form the settings name.
#include "birkhoff_cart/core/integrators/integrator_registry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/cart_birkhoffian.h"
#include "birkhoff_cart/core/closest_name.h"
#include "birkhoff_cart/core/integrators/birkhoff_symplectic.h"
#include "birkhoff_cart/core/integrators/dopri5.h"
#include "birkhoff_cart/core/integrators/implicit_midpoint.h"
#include "birkhoff_cart/core/integrators/runge_kutta.h"
#include "cart_stepper_adapter.h"
#include "adaptive_cart_stepper.h"
#include "dopri5_cart_stepper.h"
#include "reversible_cart_stepper.h"

namespace birkhoff_cart {
namespace {

/// A stepper with its own local error tolerance (dopri5) reads the settings' `tolerance`.
template <class Stepper, class = void>
struct HasTolerance : std::false_type {};
template <class Stepper>
struct HasTolerance<Stepper, std::void_t<decltype(std::declval<const Stepper&>().tolerance())>> : std::true_type {};

/// A member's generic stepper, built from the settings it reads: the Birkhoffian members their
/// stage solve's (collocation) settings, the midpoint rule its Newton settings, an adaptive pair
/// its tolerance, an explicit method nothing.
template <class Stepper>
Stepper configured(const IntegratorSettings& settings) {
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
  } else if constexpr (HasTolerance<Stepper>::value) {
    return Stepper(settings.tolerance);
  } else {
    return Stepper();
  }
}

/// The factory of a member at fixed steps of h; dopri5 runs once over the whole run with its own
/// steps (dopri5_cart_stepper.h; an explicit method takes the same steps in either form).
template <class Stepper>
std::unique_ptr<CartStepper> fixed_step(const IntegratorSettings& settings, const CartModel& model,
                                        const EffectSet& effects) {
  if constexpr (std::is_same_v<Stepper, DormandPrince5>) {
    return std::make_unique<Dopri5RunCartStepper>(settings.tolerance, model, effects);
  }
  const Stepper stepper = configured<Stepper>(settings);
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    return make_fixed_step_adapter<Stepper, CartPaperBirkhoffian>(stepper, model, effects);
  }
  return make_fixed_step_adapter<Stepper, CartAutonomousBirkhoffian>(stepper, model, effects);
}

/// The factory of a symmetric Birkhoffian member under the reversible step control
/// (reversible_cart_stepper.h): the controller's reversibility needs a symmetric step map, its time
/// transformation the autonomous form, its calibration the member's local error estimate.
template <class Stepper>
std::unique_ptr<CartStepper> reversible_step(const IntegratorSettings& settings, const CartModel& model,
                                             const EffectSet& effects) {
  static_assert(Stepper::kSymmetric, "the reversible step control needs a symmetric member");
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    throw std::invalid_argument(
        "step_control 'reversible' needs birkhoffian_form 'autonomous': the time transformation steps in the "
        "autonomous chart, and the paper form's chart moves with time");
  }
  IntegratorSettings estimating = settings;
  estimating.local_error_estimate = true;
  const Stepper stepper = configured<Stepper>(estimating);
  return std::make_unique<ReversibleCartStepperAdapter<Stepper, CartAutonomousBirkhoffian>>(stepper, settings, model,
                                                                                           effects);
}

/// The factory of a Birkhoffian member under the error-per-step control (adaptive_cart_stepper.h):
/// the control reads the member's own local error estimate, which is therefore always on.
template <class Stepper>
std::unique_ptr<CartStepper> adaptive_step(const IntegratorSettings& settings, const CartModel& model,
                                           const EffectSet& effects) {
  IntegratorSettings estimating = settings;
  estimating.local_error_estimate = true;
  const Stepper stepper = configured<Stepper>(estimating);
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    return std::make_unique<AdaptiveCartStepperAdapter<Stepper, CartPaperBirkhoffian>>(stepper, settings, model,
                                                                                      effects);
  }
  return std::make_unique<AdaptiveCartStepperAdapter<Stepper, CartAutonomousBirkhoffian>>(stepper, settings, model,
                                                                                         effects);
}

/// dopri5 under step_control adaptive: its run with the tolerance per step from the position
/// tolerance per second of the horizon (dopri5_cart_stepper.h).
std::unique_ptr<CartStepper> adaptive_dopri5(const IntegratorSettings& settings, const CartModel& model,
                                             const EffectSet& effects) {
  if (!(settings.position_tolerance > 0.0) || !std::isfinite(settings.position_tolerance)) {
    throw std::invalid_argument("step_control 'adaptive' needs a finite position_tolerance > 0 m, got " +
                                std::to_string(settings.position_tolerance));
  }
  if (!(settings.tolerance_horizon > 0.0) || !std::isfinite(settings.tolerance_horizon)) {
    throw std::invalid_argument("integrator.tolerance_horizon must be finite and > 0 s");
  }
  // A tenth of the position tolerance per second of the horizon: measured on the shipped scenes, the
  // delivered error then stays within 10× of the tolerance (the default scene's 60 s came closest).
  const double per_step = 0.1 * settings.position_tolerance / settings.tolerance_horizon;  // [-]
  return std::make_unique<Dopri5RunCartStepper>(std::max(per_step, DormandPrince5::kMinTolerance), model, effects);
}

/// Does the member evaluate its stages together (GaussCollocation::kEvaluatesStagesTogether)?
template <class Stepper, class = void>
struct StagesTogether : std::false_type {};
template <class Stepper>
struct StagesTogether<Stepper, std::void_t<decltype(Stepper::kEvaluatesStagesTogether)>>
    : std::integral_constant<bool, Stepper::kEvaluatesStagesTogether> {};
template <class Stepper>
constexpr bool vector_stages = StagesTogether<Stepper>::value;

using Kind = IntegratorKind;

}  // namespace

const std::vector<IntegratorEntry>& integrator_registry() {
  // The members, in the registry's order (integrator_names(), the help, the tests' cases): name,
  // order p, symmetric, kind, description, factory at fixed steps, factory under reversible control,
  // stages evaluated together (from the stepper's type).
  // A function's static: built at the first call, whichever static initializer asks first.
  static const std::vector<IntegratorEntry> kRegistry = {
      {"birkhoff2", 2, true, Kind::kBirkhoffianCollocation, "Su's scheme: 1-stage Gauss in the chart",
       fixed_step<GaussCollocation<1>>, reversible_step<GaussCollocation<1>>, adaptive_step<GaussCollocation<1>>, vector_stages<GaussCollocation<1>>},
      {"birkhoff4", 4, true, Kind::kComposition, "triple jump of birkhoff2",
       fixed_step<BirkhoffComposition<TripleJumpWeights>>, reversible_step<BirkhoffComposition<TripleJumpWeights>>,
       adaptive_step<BirkhoffComposition<TripleJumpWeights>>, vector_stages<BirkhoffComposition<TripleJumpWeights>>},
      {"rk2", 2, false, Kind::kExplicitRungeKutta, "Heun's method", fixed_step<HeunRungeKutta2>, nullptr, nullptr,
       vector_stages<HeunRungeKutta2>},
      {"rk4", 4, false, Kind::kExplicitRungeKutta, "classical Runge-Kutta", fixed_step<ClassicalRungeKutta4>, nullptr, nullptr,
       vector_stages<ClassicalRungeKutta4>},
      {"dopri5", 5, false, Kind::kAdaptive, "Dormand-Prince 5(4) of Boost.Odeint", fixed_step<DormandPrince5>,
       nullptr, adaptive_dopri5, vector_stages<DormandPrince5>},
      {"midpoint", 2, true, Kind::kImplicitMidpoint, "implicit midpoint rule on z", fixed_step<ImplicitMidpoint>,
       nullptr, nullptr, vector_stages<ImplicitMidpoint>},
      {"birkhoff_gauss4", 4, true, Kind::kBirkhoffianCollocation, "2-stage Gauss-Legendre in the chart",
       fixed_step<GaussCollocation<2>>, reversible_step<GaussCollocation<2>>, adaptive_step<GaussCollocation<2>>, vector_stages<GaussCollocation<2>>},
      {"birkhoff_gauss6", 6, true, Kind::kBirkhoffianCollocation, "3-stage Gauss-Legendre in the chart",
       fixed_step<GaussCollocation<3>>, reversible_step<GaussCollocation<3>>, adaptive_step<GaussCollocation<3>>, vector_stages<GaussCollocation<3>>},
      {"birkhoff_gauss8", 8, true, Kind::kBirkhoffianCollocation, "4-stage Gauss-Legendre in the chart",
       fixed_step<GaussCollocation<4>>, reversible_step<GaussCollocation<4>>, adaptive_step<GaussCollocation<4>>, vector_stages<GaussCollocation<4>>},
      {"birkhoff4_suzuki", 4, true, Kind::kComposition, "Suzuki's 5 stages of birkhoff2",
       fixed_step<BirkhoffComposition<SuzukiFiveWeights>>, reversible_step<BirkhoffComposition<SuzukiFiveWeights>>,
       adaptive_step<BirkhoffComposition<SuzukiFiveWeights>>, vector_stages<BirkhoffComposition<SuzukiFiveWeights>>},
      {"birkhoff6_kahan_li", 6, true, Kind::kComposition, "Kahan & Li's 9 stages of birkhoff2",
       fixed_step<BirkhoffComposition<KahanLiSixWeights>>, reversible_step<BirkhoffComposition<KahanLiSixWeights>>,
       adaptive_step<BirkhoffComposition<KahanLiSixWeights>>, vector_stages<BirkhoffComposition<KahanLiSixWeights>>},
      {"birkhoff8_kahan_li", 8, true, Kind::kComposition, "Kahan & Li's 17 stages of birkhoff2",
       fixed_step<BirkhoffComposition<KahanLiEightWeights>>, reversible_step<BirkhoffComposition<KahanLiEightWeights>>,
       adaptive_step<BirkhoffComposition<KahanLiEightWeights>>, vector_stages<BirkhoffComposition<KahanLiEightWeights>>},
  };
  return kRegistry;
}

const char* to_string(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::kBirkhoffianCollocation: return "Birkhoffian collocation";
    case IntegratorKind::kComposition: return "composition";
    case IntegratorKind::kExplicitRungeKutta: return "explicit RK";
    case IntegratorKind::kAdaptive: return "adaptive";
    case IntegratorKind::kImplicitMidpoint: return "implicit midpoint";
  }
  throw std::invalid_argument("no text for IntegratorKind " + std::to_string(static_cast<int>(kind)));
}

const IntegratorEntry* find_integrator(const std::string& name) {
  for (const IntegratorEntry& entry : integrator_registry()) {
    if (name == entry.name) return &entry;
  }
  return nullptr;
}

const IntegratorEntry& integrator_entry(const std::string& name) {
  const IntegratorEntry* entry = find_integrator(name);
  if (entry == nullptr) throw std::invalid_argument(unknown_name_message("integrator", name, integrator_names()));
  return *entry;
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const IntegratorEntry& entry : integrator_registry()) names.emplace_back(entry.name);
  return names;
}

std::vector<std::string> reversible_integrator_names() {
  std::vector<std::string> names;
  for (const IntegratorEntry& entry : integrator_registry()) {
    if (entry.reversible()) names.emplace_back(entry.name);
  }
  return names;
}

std::vector<std::string> adaptive_integrator_names() {
  std::vector<std::string> names;
  for (const IntegratorEntry& entry : integrator_registry()) {
    if (entry.adaptive()) names.emplace_back(entry.name);
  }
  return names;
}

}  // namespace birkhoff_cart
