// The CartStepper of a member at fixed steps: a generic stepper (runge_kutta.h, dopri5.h,
// implicit_midpoint.h, gauss_collocation.h, birkhoff_symplectic.h) on one of the cart's Birkhoffian
// systems (cart_birkhoffian.h), type-erased for the simulation. Private to the core library (the
// registry, integrator_registry.cpp, makes them).
#pragma once

#include <array>
#include <memory>
#include <sstream>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "step_checks.h"

namespace birkhoff_cart {
namespace cart_stepper_adapter {

using namespace stepper_checks;

/// The command torques (steering, drive) [N·m] the effects read now; 0 for a source that is absent.
inline std::array<double, 2> command_torques(const EffectSet& effects) {
  return {effects.steering_command() ? effects.steering_command()->value : 0.0,
          effects.drive_command() ? effects.drive_command()->value : 0.0};
}

/// A fixed step that fails (a stage solve that does not converge or lands on a spurious root, a
/// non-finite result) is retried from the same state in 2, 4, … 2^kMaxSubstepHalvings substeps
/// before the failure reaches the caller.
inline constexpr int kMaxSubstepHalvings = 6;

/// The work of `trial` (right-hand sides, passive rates, solver iterations) added to `into`: a
/// failed attempt's work counts, its estimates do not.
inline void add_attempt_work(StepStatistics& into, const StepStatistics& trial, const StepStatistics& before) {
  into.rhs_evaluations += trial.rhs_evaluations - before.rhs_evaluations;
  into.passive_evaluations += trial.passive_evaluations - before.passive_evaluations;
  into.newton_iterations_total += trial.newton_iterations_total - before.newton_iterations_total;
}

/// The state a step of h [s] from `state` reaches by `take(from, length, statistics)` (one step of
/// `length` from `from`; throws StepError): the whole step, or where it fails, 2, 4, … substeps of
/// h/2, h/4, … (StepStatistics::rejected_steps counts the steps that needed them). Throws the
/// last failure, naming the substeps tried, when even h/2^kMaxSubstepHalvings fails.
template <class TakeStep>
CartState step_or_substeps(const CartState& state, double step_size, StepStatistics& statistics, TakeStep take) {
  StepStatistics trial = statistics;
  try {
    CartState next = take(state, step_size, trial);
    statistics = trial;
    return next;
  } catch (const StepError& whole) {
    add_attempt_work(statistics, trial, statistics);
    std::string last = whole.what();
    for (int halvings = 1; halvings <= kMaxSubstepHalvings; ++halvings) {
      const int pieces = 1 << halvings;
      trial = statistics;
      try {
        CartState current = state;
        for (int k = 1; k <= pieces; ++k) {
          const double end = k == pieces ? state.time + step_size
                                         : state.time + step_size * static_cast<double>(k) / pieces;  // [s]
          current = take(current, end - current.time, trial);
          current.time = end;
        }
        ++trial.rejected_steps;
        statistics = trial;
        return current;
      } catch (const StepError& error) {
        add_attempt_work(statistics, trial, statistics);
        last = error.what();
      }
    }
    std::ostringstream message;
    message.precision(17);
    message << "the step of h = " << step_size << " s from t = " << state.time << " s failed whole and in 2 to "
            << (1 << kMaxSubstepHalvings) << " substeps; the last: " << last;
    throw StepError(message.str());
  }
}

/// What a fixed-step adapter reports of its stepper: its name, order and symmetry.
template <class Stepper>
class FixedStepCartStepper : public CartStepper {
 public:
  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  bool symmetric() const override { return Stepper::kSymmetric; }

 protected:
  const std::string name_ = Stepper::name();
};

/// Generic stepper + cart system → CartStepper. Transactional: the state, the statistics and the
/// stepper's own memory (dopri5's step-size guess) change only when the whole step succeeded.
template <class Stepper, class System>
class CartStepperAdapter final : public FixedStepCartStepper<Stepper> {
  using FixedStepCartStepper<Stepper>::name_;

 public:
  CartStepperAdapter(const Stepper& stepper, const CartModel& model, const EffectSet& effects)
      : stepper_(stepper), system_(model, effects) {}

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    require_valid_step_size(step_size);
    Stepper trial = stepper_;
    StepStatistics counted = statistics;
    const auto take = [&](const CartState& from, double length, StepStatistics& work) {
      const double time = from.time;  // tₖ [s]
      system_.begin_step(time);       // rep (a): structure epoch tₑ = tₖ; rep (b): nothing
      CartBirkhoffianPoint point = system_.to_birkhoffian(from);
      Stepper attempt = trial;
      try {
        attempt.step(system_, point.z, point.y, time, length, work);
      } catch (const StepError& error) {
        throw StepError(name_ + ": " + error.what());
      }
      require_finite_result(name_, time, length, point.z, point.y);
      const CartState next = system_.to_cart_state(point.z, point.y, time + length);
      require_finite_speeds(name_, time, length, next, point.z);
      require_energy_balance(name_, system_.model(), from, next, length);
      trial = attempt;
      return next;
    };
    const CartState next = step_or_substeps(state, step_size, counted, take);
    ++counted.steps;
    state = next;
    statistics = counted;
    stepper_ = trial;
  }

 private:
  Stepper stepper_;
  System system_;
};

/// The Birkhoffian collocation members and compositions: the adapter carries the integrator's own
/// state between steps (carried_state.h) — z and y with their compensated-summation remainders, χ
/// and θ reduced modulo 2π with their turns apart, the stage-derivative memory — and uses it
/// whenever the state handed in is the one it handed out; any other state (a reset, a state set by
/// the caller) starts afresh from p = M(χ) ω. A failed step leaves the caller's state and statistics
/// untouched and drops the carried state.
template <class Stepper, class System>
class CarriedCartStepperAdapter final : public FixedStepCartStepper<Stepper> {
  using FixedStepCartStepper<Stepper>::name_;

 public:
  CarriedCartStepperAdapter(const Stepper& stepper, const CartModel& model, const EffectSet& effects)
      : stepper_(stepper), system_(model, effects), effects_(effects) {}

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    require_valid_step_size(step_size);
    StepStatistics counted = statistics;
    counted.newton_iterations_last_step = 0;
    const CartState next = step_or_substeps(state, step_size, counted, [this](const CartState& from, double length,
                                                                              StepStatistics& work) {
      return take(from, length, work);
    });
    ++counted.steps;
    state = next;
    statistics = counted;
  }

 private:
  /// One step of `length` [s] from `from`, continuing the carried state when `from` is what it
  /// handed out. On any failure the carried state is dropped (the next attempt starts afresh from
  /// `from`): cheaper than copying the Newton matrices every step, and as deterministic.
  CartState take(const CartState& from, double length, StepStatistics& counted) {
    const double time = from.time;  // tₖ [s]
    system_.begin_step(time);
    if (!carried_.continues(from)) carried_.start_from(system_, from);
    // A new command changes ẇ at the same (w, t): the last step's F(w⁺) is not this step's F(w).
    const std::array<double, 2> commands = command_torques(effects_);
    if (commands != commands_) carried_.memory.forget_end_rate();
    commands_ = commands;
    carried_.valid = false;
    try {
      stepper_.advance_compensated(system_, carried_.point, carried_.memory, time, length, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + ": " + error.what());
    }
    const auto& point = carried_.point;
    require_finite_result(name_, time, length, point.z, point.y);
    carried_.reduce_angles();
    const CartState next = carried_.output(system_, time + length);
    require_finite_speeds(name_, time, length, next, point.z);
    require_energy_balance(name_, system_.model(), from, next, length);
    carried_.valid = true;
    return next;
  }

  Stepper stepper_;
  System system_;
  const EffectSet& effects_;
  std::array<double, 2> commands_{};  ///< command torques at the last step [N·m]
  CarriedCartState<System, typename Stepper::template Memory<System>> carried_;
};

}  // namespace cart_stepper_adapter

/// `stepper` on `System` at fixed steps: the adapter that carries the integrator's own state
/// between steps where the stepper has one (the Birkhoffian members), the plain one otherwise.
template <class Stepper, class System>
std::unique_ptr<CartStepper> make_fixed_step_adapter(const Stepper& stepper, const CartModel& model,
                                                     const EffectSet& effects) {
  if constexpr (kCarriesState<Stepper, System>) {
    return std::make_unique<cart_stepper_adapter::CarriedCartStepperAdapter<Stepper, System>>(stepper, model, effects);
  } else {
    return std::make_unique<cart_stepper_adapter::CartStepperAdapter<Stepper, System>>(stepper, model, effects);
  }
}

}  // namespace birkhoff_cart
