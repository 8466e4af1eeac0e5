// The integrator registry (integrator_registry.h): one row per member of integrator_members.h, read
// from its stepper type, with the factories that turn the member's generic stepper into a
// CartStepper — at fixed steps, under the reversible or under the adaptive step control — in the
// Birkhoffian form the settings name.
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/support/closest_name.h"
#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/integrators/adaptive_refusal.h"
#include "birkhoff_cart/core/integrators/integrator_members.h"
#include "adaptive_cart_stepper.h"
#include "cart_stepper_adapter.h"
#include "dopri5_cart_stepper.h"
#include "reversible_cart_stepper.h"

namespace birkhoff_cart {
namespace {

/// The factory of a member at fixed steps of h; dopri5 runs once over the whole run with its own
/// steps (dopri5_cart_stepper.h; an explicit method takes the same steps in either form).
template <class Stepper>
std::unique_ptr<CartStepper> fixed_step(const IntegratorSettings& settings, const CartModel& model,
                                        const EffectSet& effects) {
  if constexpr (std::is_same_v<Stepper, DormandPrince5>) {
    return std::make_unique<Dopri5RunCartStepper>(settings.tolerance, model, effects);
  }
  const Stepper stepper = configured_stepper<Stepper>(settings);
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    return make_fixed_step_adapter<Stepper, CartPaperBirkhoffian>(stepper, model, effects);
  }
  return make_fixed_step_adapter<Stepper, CartAutonomousBirkhoffian>(stepper, model, effects);
}

/// The member's stepper with its local error estimate on: the step controls read it.
template <class Stepper>
Stepper estimating_stepper(const IntegratorSettings& settings) {
  IntegratorSettings estimating = settings;
  estimating.local_error_estimate = true;
  return configured_stepper<Stepper>(estimating);
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
  return std::make_unique<ReversibleCartStepperAdapter<Stepper, CartAutonomousBirkhoffian>>(
      estimating_stepper<Stepper>(settings), settings, model, effects);
}

/// The reversible step control is offered to the symmetric members that carry their own state
/// between steps (the Birkhoffian ones: carried_state.h); nullptr for the others.
template <class Stepper>
constexpr CartStepperFactory reversible_factory() {
  if constexpr (Stepper::kSymmetric && kCarriesState<Stepper, CartAutonomousBirkhoffian>) {
    return reversible_step<Stepper>;
  } else {
    return nullptr;
  }
}

/// The factory of a Birkhoffian member under the error-per-step control (adaptive_cart_stepper.h).
template <class Stepper>
std::unique_ptr<CartStepper> adaptive_step(const IntegratorSettings& settings, const CartModel& model,
                                           const EffectSet& effects) {
  const Stepper stepper = estimating_stepper<Stepper>(settings);
  IntegratorSettings shadow = settings;  // the global error estimate's shadow reads no ê
  shadow.local_error_estimate = false;
  const Stepper shadow_stepper = configured_stepper<Stepper>(shadow);
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    return std::make_unique<AdaptiveCartStepperAdapter<Stepper, CartPaperBirkhoffian>>(stepper, shadow_stepper, settings,
                                                                                      model, effects);
  }
  return std::make_unique<AdaptiveCartStepperAdapter<Stepper, CartAutonomousBirkhoffian>>(stepper, shadow_stepper,
                                                                                         settings, model, effects);
}

/// dopri5 under step_control adaptive: its run with the tolerance per step from the position
/// tolerance per second of the horizon (dopri5_cart_stepper.h).
std::unique_ptr<CartStepper> adaptive_dopri5(const IntegratorSettings& settings, const CartModel& model,
                                             const EffectSet& effects) {
  require_position_tolerance(settings, to_string(StepControl::kAdaptive));
  if (settings.global_error_estimate) {
    throw std::invalid_argument("global_error_estimate is for the Gauss members under step_control 'adaptive', "
                                "not dopri5 (a shadow on doubled steps needs the member's own grid)");
  }
  // The position tolerance per second of the horizon, per step, with the passive coordinates held to
  // it absolutely (measured relatively, the growing ones — the loads' work above all — took errors
  // that grew with them: 9–10× the tolerance on very_stiff_hinge); every shipped scene then ends
  // within 1.4× the tolerance, and 96 % of the runs at 1e-3 … 1e-7 m above a hundredth of it
  // (accuracy.md §4.3).
  const double per_step = settings.position_tolerance / settings.tolerance_horizon;  // [-]
  if (per_step < DormandPrince5::kMinTolerance) {
    throw std::invalid_argument("step_control 'adaptive': dopri5 cannot reach position_tolerance " +
                                std::to_string(settings.position_tolerance) + " m over " +
                                std::to_string(settings.tolerance_horizon) +
                                " s (its local tolerance would fall below 10 machine epsilons)");
  }
  return std::make_unique<Dopri5RunCartStepper>(per_step, model, effects, /*passive_absolute=*/true);
}

/// The adaptive step control is offered to the members with their own local error estimate: the
/// Birkhoffian ones (they carry their state between steps) and dopri5; nullptr for the others.
template <class Stepper>
constexpr CartStepperFactory adaptive_factory() {
  if constexpr (std::is_same_v<Stepper, DormandPrince5>) {
    return adaptive_dopri5;
  } else if constexpr (kCarriesState<Stepper, CartAutonomousBirkhoffian>) {
    return adaptive_step<Stepper>;
  } else {
    return nullptr;
  }
}

/// Does the member evaluate its stages together (GaussCollocation::kEvaluatesStagesTogether)?
template <class Stepper, class = void>
struct StagesTogether : std::false_type {};
template <class Stepper>
struct StagesTogether<Stepper, std::void_t<decltype(Stepper::kEvaluatesStagesTogether)>>
    : std::integral_constant<bool, Stepper::kEvaluatesStagesTogether> {};

/// The row of a member: everything but the description read from its stepper type. A new column
/// (a factory under another step control) is one more line here.
template <class Stepper>
IntegratorEntry registry_row(const IntegratorMember<Stepper>& member) {
  IntegratorEntry row;
  row.name = Stepper::name();
  row.order = Stepper::kOrder;
  row.symmetric = Stepper::kSymmetric;
  row.kind = member_kind<Stepper>();
  row.description = member.description;
  row.make_fixed = fixed_step<Stepper>;
  row.make_reversible = reversible_factory<Stepper>();
  row.make_adaptive = member.adaptive_refusal == nullptr ? adaptive_factory<Stepper>() : nullptr;
  row.vector_stages = StagesTogether<Stepper>::value;
  return row;
}

}  // namespace

const std::vector<IntegratorEntry>& integrator_registry() {
  // One row per member of integrator_members.h, in its order. A function's static: built at the
  // first call, whichever static initializer asks first.
  static const std::vector<IntegratorEntry> kRegistry = std::apply(
      [](const auto&... member) { return std::vector<IntegratorEntry>{registry_row(member)...}; },
      kIntegratorMembers);
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

const char* adaptive_refusal(const std::string& name) {
  const char* reason = nullptr;
  std::apply(
      [&](const auto&... member) {
        ((name == std::decay_t<decltype(member)>::Type::name() ? (reason = member.adaptive_refusal) : nullptr), ...);
      },
      kIntegratorMembers);
  return reason;
}

std::string adaptive_refusal_message(const std::string& name) {
  std::string message = "step_control 'adaptive' is for (" + name_list(adaptive_integrator_names()) + "), not '" + name + "'";
  if (const char* reason = adaptive_refusal(name)) message += std::string(": ") + reason;
  return message;
}

}  // namespace birkhoff_cart
