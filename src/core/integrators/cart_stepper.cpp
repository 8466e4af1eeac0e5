// The integrator registry: wraps a generic stepper (runge_kutta.h, dopri5.h, implicit_midpoint.h,
// birkhoff_symplectic.h) and one of the cart's Birkhoffian systems (cart_birkhoffian.h) into the
// type-erased CartStepper the simulation uses.
#include "birkhoff_cart/core/integrators/cart_stepper.h"

#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/cart_birkhoffian.h"
#include "birkhoff_cart/core/closest_name.h"
#include "birkhoff_cart/core/integrators/birkhoff_symplectic.h"
#include "birkhoff_cart/core/integrators/carried_state.h"
#include "birkhoff_cart/core/integrators/dopri5.h"
#include "birkhoff_cart/core/integrators/implicit_midpoint.h"
#include "birkhoff_cart/core/integrators/runge_kutta.h"
#include "reversible_cart_stepper.h"
#include "step_checks.h"

namespace birkhoff_cart {
namespace {

using namespace stepper_checks;

/// The command torques (steering, drive) [N·m] the effects read now; 0 for a source that is absent.
std::array<double, 2> command_torques(const EffectSet& effects) {
  return {effects.steering_command() ? effects.steering_command()->value : 0.0,
          effects.drive_command() ? effects.drive_command()->value : 0.0};
}

/// Generic stepper + cart system → CartStepper. Transactional: the state, the statistics and the
/// stepper's own memory (dopri5's step-size guess) change only when the whole step succeeded.
template <class Stepper, class System>
class CartStepperAdapter final : public CartStepper {
 public:
  CartStepperAdapter(const Stepper& stepper, const CartModel& model, const EffectSet& effects)
      : stepper_(stepper), system_(model, effects), name_(Stepper::name()) {}

  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  bool symmetric() const override { return Stepper::kSymmetric; }

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    require_valid_step_size(step_size);
    const double time = state.time;  // tₖ [s]
    system_.begin_step(time);        // rep (a): structure epoch tₑ = tₖ; rep (b): nothing
    CartBirkhoffianPoint point = system_.to_birkhoffian(state);
    Stepper trial = stepper_;
    StepStatistics counted = statistics;
    try {
      trial.step(system_, point.z, point.y, time, step_size, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + ": " + error.what());
    }
    require_finite_result(name_, time, step_size, point.z, point.y);
    const CartState next = system_.to_cart_state(point.z, point.y, time + step_size);
    require_finite_speeds(name_, time, step_size, next);
    ++counted.steps;
    state = next;
    statistics = counted;
    stepper_ = trial;
  }

 private:
  Stepper stepper_;
  System system_;
  std::string name_;
};

/// The Birkhoffian collocation members and compositions: the adapter carries the integrator's own
/// state between steps (carried_state.h) — z and y with their compensated-summation remainders, χ
/// and θ reduced modulo 2π with their turns apart, the stage-derivative memory — and uses it
/// whenever the state handed in is the one it handed out; any other state (a reset, a state set by
/// the caller) starts afresh from p = M(χ) ω. A failed step leaves the caller's state and statistics
/// untouched and drops the carried state.
template <class Stepper, class System>
class CarriedCartStepperAdapter final : public CartStepper {
 public:
  CarriedCartStepperAdapter(const Stepper& stepper, const CartModel& model, const EffectSet& effects)
      : stepper_(stepper), system_(model, effects), effects_(effects), name_(Stepper::name()) {}

  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  bool symmetric() const override { return Stepper::kSymmetric; }

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    require_valid_step_size(step_size);
    const double time = state.time;  // tₖ [s]
    system_.begin_step(time);
    if (!carried_.continues(state)) carried_.start_from(system_, state);
    // A new command changes ẇ at the same (w, t): the last step's F(w⁺) is not this step's F(w).
    const std::array<double, 2> commands = command_torques(effects_);
    if (commands != commands_) carried_.memory.forget_end_rate();
    commands_ = commands;
    StepStatistics counted = statistics;
    counted.newton_iterations_last_step = 0;
    // On any failure the carried state is dropped (the next step starts afresh from the caller's
    // unchanged state): cheaper than copying the Newton matrices every step, and as deterministic.
    carried_.valid = false;
    try {
      stepper_.advance_compensated(system_, carried_.point, carried_.memory, time, step_size, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + ": " + error.what());
    }
    const auto& point = carried_.point;
    require_finite_result(name_, time, step_size, point.z, point.y);
    carried_.reduce_angles();
    const CartState next = carried_.output(system_, time + step_size);
    require_finite_speeds(name_, time, step_size, next);
    carried_.valid = true;
    ++counted.steps;
    state = next;
    statistics = counted;
  }

 private:
  Stepper stepper_;
  System system_;
  const EffectSet& effects_;
  std::array<double, 2> commands_{};  ///< command torques at the last step [N·m]
  std::string name_;
  CarriedCartState<System, typename Stepper::template Memory<System>> carried_;
};

template <class Stepper, class System>
std::unique_ptr<CartStepper> make_adapter(const Stepper& stepper, const CartModel& model, const EffectSet& effects) {
  if constexpr (kCarriesState<Stepper, System>) {
    return std::make_unique<CarriedCartStepperAdapter<Stepper, System>>(stepper, model, effects);
  } else {
    return std::make_unique<CartStepperAdapter<Stepper, System>>(stepper, model, effects);
  }
}

template <class Stepper>
std::unique_ptr<CartStepper> wrap(const Stepper& stepper, const IntegratorSettings& settings, const CartModel& model,
                                  const EffectSet& effects) {
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    return make_adapter<Stepper, CartPaperBirkhoffian>(stepper, model, effects);
  }
  return make_adapter<Stepper, CartAutonomousBirkhoffian>(stepper, model, effects);
}

/// A symmetric Birkhoffian member under reversible step control (reversible_cart_stepper.h).
template <class Stepper>
std::unique_ptr<CartStepper> wrap_reversible(const Stepper& stepper, const IntegratorSettings& settings,
                                             const CartModel& model, const EffectSet& effects) {
  if (settings.birkhoffian_form == BirkhoffianForm::kPaper) {
    return std::make_unique<ReversibleCartStepperAdapter<Stepper, CartPaperBirkhoffian>>(stepper, settings, model,
                                                                                        effects);
  }
  return std::make_unique<ReversibleCartStepperAdapter<Stepper, CartAutonomousBirkhoffian>>(stepper, settings, model,
                                                                                           effects);
}

/// The registry's symmetric Birkhoffian members, under reversible step control.
std::unique_ptr<CartStepper> make_reversible(const IntegratorSettings& settings, const CollocationSettings& collocation,
                                             const CartModel& model, const EffectSet& effects) {
  const std::string& name = settings.name;
  if (name == "birkhoff2") return wrap_reversible(GaussCollocation<1>(collocation), settings, model, effects);
  if (name == "birkhoff4") {
    return wrap_reversible(BirkhoffComposition<TripleJumpWeights>(collocation), settings, model, effects);
  }
  if (name == "birkhoff_gauss4") return wrap_reversible(GaussCollocation<2>(collocation), settings, model, effects);
  if (name == "birkhoff_gauss6") return wrap_reversible(GaussCollocation<3>(collocation), settings, model, effects);
  if (name == "birkhoff_gauss8") return wrap_reversible(GaussCollocation<4>(collocation), settings, model, effects);
  if (name == "birkhoff4_suzuki") {
    return wrap_reversible(BirkhoffComposition<SuzukiFiveWeights>(collocation), settings, model, effects);
  }
  if (name == "birkhoff6_kahan_li") {
    return wrap_reversible(BirkhoffComposition<KahanLiSixWeights>(collocation), settings, model, effects);
  }
  if (name == "birkhoff8_kahan_li") {
    return wrap_reversible(BirkhoffComposition<KahanLiEightWeights>(collocation), settings, model, effects);
  }
  throw std::invalid_argument("step_control 'reversible' is for the symmetric Birkhoffian members (" +
                              name_list(reversible_integrator_names()) + "), not '" + name + "'");
}

}  // namespace

std::vector<std::string> integrator_names() {
  return {"birkhoff2",          "birkhoff4",          "rk2",
          "rk4",                "dopri5",             "midpoint",
          "birkhoff_gauss4",    "birkhoff_gauss6",    "birkhoff_gauss8",
          "birkhoff4_suzuki",   "birkhoff6_kahan_li", "birkhoff8_kahan_li"};
}

std::vector<std::string> reversible_integrator_names() {
  return {"birkhoff2",        "birkhoff4",          "birkhoff_gauss4",   "birkhoff_gauss6",
          "birkhoff_gauss8",  "birkhoff4_suzuki",   "birkhoff6_kahan_li", "birkhoff8_kahan_li"};
}

std::unique_ptr<CartStepper> make_cart_stepper(const IntegratorSettings& settings, const CartModel& model,
                                               const EffectSet& effects) {
  require_valid_step_size(settings.step_size);
  if (settings.max_newton_iterations < 1) {
    throw std::invalid_argument("max_newton_iterations must be >= 1, got " +
                                std::to_string(settings.max_newton_iterations));
  }
  if (!(settings.newton_tolerance > 0.0) || !std::isfinite(settings.newton_tolerance)) {
    throw std::invalid_argument("newton_tolerance must be finite and > 0");
  }
  NewtonSettings newton;
  newton.tolerance = settings.newton_tolerance;
  newton.max_iterations = settings.max_newton_iterations;
  const std::string& name = settings.name;
  CollocationSettings collocation;
  collocation.max_iterations = settings.max_newton_iterations;
  collocation.compensated = settings.compensated_summation;
  collocation.estimate_local_error = settings.local_error_estimate;
  if (settings.step_control == StepControl::kReversible) return make_reversible(settings, collocation, model, effects);
  if (name == "birkhoff2") return wrap(GaussCollocation<1>(collocation), settings, model, effects);
  if (name == "birkhoff4") return wrap(BirkhoffComposition<TripleJumpWeights>(collocation), settings, model, effects);
  if (name == "birkhoff_gauss4") return wrap(GaussCollocation<2>(collocation), settings, model, effects);
  if (name == "birkhoff_gauss6") return wrap(GaussCollocation<3>(collocation), settings, model, effects);
  if (name == "birkhoff_gauss8") return wrap(GaussCollocation<4>(collocation), settings, model, effects);
  if (name == "birkhoff4_suzuki") {
    return wrap(BirkhoffComposition<SuzukiFiveWeights>(collocation), settings, model, effects);
  }
  if (name == "birkhoff6_kahan_li") {
    return wrap(BirkhoffComposition<KahanLiSixWeights>(collocation), settings, model, effects);
  }
  if (name == "birkhoff8_kahan_li") {
    return wrap(BirkhoffComposition<KahanLiEightWeights>(collocation), settings, model, effects);
  }
  if (name == "rk2") return wrap(HeunRungeKutta2(), settings, model, effects);
  if (name == "rk4") return wrap(ClassicalRungeKutta4(), settings, model, effects);
  if (name == "dopri5") return wrap(DormandPrince5(settings.tolerance), settings, model, effects);
  if (name == "midpoint") return wrap(ImplicitMidpoint(newton), settings, model, effects);
  throw std::invalid_argument(unknown_name_message("integrator", name, integrator_names()));
}

}  // namespace birkhoff_cart
