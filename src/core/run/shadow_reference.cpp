// The shadow-run reference (see shadow_reference.h).
#include "birkhoff_cart/core/run/shadow_reference.h"

#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/odeint_step_adjuster.h"
#include "../cart_binding/cart_joint_rates.h"

namespace birkhoff_cart {
namespace {

namespace odeint = boost::numeric::odeint;

/// One continuing dopri5 run with dense output (see shadow_reference.h).
class DenseShadowReference : public ReferenceSolution {
 public:
  DenseShadowReference(const IntegratorSettings& settings, const CartState& initial, const CartModel& model,
                       const EffectSet& effects)
      : settings_(settings), initial_(initial), model_(&model), system_(model, effects),
        stepper_(deterministic_controlled(settings.tolerance, settings.tolerance, odeint::runge_kutta_dopri5<Joint>())) {
    restart(initial_, settings_.step_size);
  }

  // Advances only when the simulation passes the end of the current dopri5 step: most simulator
  // steps cost one comparison.
  void step(double next_time) override {
    std::uint64_t taken = 0;
    while (stepper_.current_time() < next_time) {
      if (++taken > kMaxShadowStepsPerStep) {
        std::ostringstream message;
        message << "shadow reference (dopri5, tolerance " << settings_.tolerance << "): more than "
                << kMaxShadowStepsPerStep << " steps to reach t = " << next_time << " s from t = "
                << stepper_.current_time() << " s (work limit per simulator step)";
        throw StepError(message.str());
      }
      try {
        stepper_.do_step(JointRates{&system_, model_});  // one accepted step (odeint retries rejected ones)
      } catch (const odeint::odeint_error& error) {  // Boost ≥ 1.60: step_adjustment_error et al.
        throw StepError("shadow reference (dopri5) failed at t = " + std::to_string(stepper_.current_time()) +
                        " s: " + error.what());
      } catch (const std::overflow_error& error) {  // older Boost: too many rejected steps
        throw StepError("shadow reference (dopri5) failed at t = " + std::to_string(stepper_.current_time()) +
                        " s: " + error.what());
      }
      const Joint& state = stepper_.current_state();
      for (const double value : state) {
        if (!std::isfinite(value)) {
          throw StepError("shadow reference (dopri5) produced a non-finite state at t = " +
                          std::to_string(stepper_.current_time()) + " s");
        }
      }
    }
  }

  void reset() override { restart(initial_, settings_.step_size); }

  void command_changes(double time) override {
    // The run so far held the old command; it continues from `time` with the new one.
    const double step_size_guess = stepper_.current_time_step();
    restart(state_at(time), step_size_guess);
  }

  void restart_at(const CartState& state) override { restart(state, stepper_.current_time_step()); }

  void compare(const CartState& state, Diagnostics& diagnostics) const override {
    compare_states(state, state_at(state.time), diagnostics);
  }

 private:
  void restart(const CartState& state, double step_size_guess) {
    stepper_.initialize(joint_of(system_.to_birkhoffian(state)), state.time, step_size_guess);
  }

  /// The shadow state at `time` [s]: the current step's end, or the dense-output interpolant inside
  /// it (the simulation never asks before the current step's start).
  CartState state_at(double time) const {
    Joint x;
    if (time == stepper_.current_time()) {
      x = stepper_.current_state();
    } else {
      stepper_.calc_state(time, x);
    }
    return cart_state_of(system_, x, time);
  }

  IntegratorSettings settings_;
  CartState initial_;
  const CartModel* model_;
  CartAutonomousBirkhoffian system_;
  // calc_state() is const in meaning but not in odeint's signature.
  mutable odeint::dense_output_runge_kutta<DeterministicControlled<odeint::runge_kutta_dopri5<Joint>>> stepper_;
};

/// n fixed sub-steps of the shadow integrator per simulator step; the last lands on its time.
class SubstepShadowReference : public ReferenceSolution {
 public:
  SubstepShadowReference(const IntegratorSettings& settings, const CartState& initial, const CartModel& model,
                         const EffectSet& effects)
      : settings_(settings), initial_(initial), model_(model), effects_(effects),
        stepper_(make_cart_stepper(settings, model, effects)), state_(initial) {}

  void step(double next_time) override {
    const double h = next_time - state_.time;  // [s]
    const double ratio = h / settings_.step_size;
    // Range-checked at load for h; a shorter final step (step_to) only needs fewer.
    const long substeps = ratio > 1.0 ? std::lround(std::min(ratio, kMaxShadowSubsteps)) : 1;
    const double substep = h / static_cast<double>(substeps);  // [s]
    CartState next = state_;
    StepStatistics statistics = statistics_;
    for (long k = 1; k <= substeps; ++k) {
      stepper_->step(next, substep, statistics);
      next.time = k == substeps ? next_time : state_.time + static_cast<double>(k) * substep;
    }
    state_ = next;
    statistics_ = statistics;
  }

  void restart_at(const CartState& state) override { state_ = state; }

  void reset() override {
    stepper_ = make_cart_stepper(settings_, model_, effects_);  // forgets adaptive step-size guesses
    state_ = initial_;
    statistics_ = StepStatistics{};
  }

  void compare(const CartState& state, Diagnostics& diagnostics) const override {
    compare_states(state, state_, diagnostics);
  }

 private:
  IntegratorSettings settings_;
  CartState initial_;
  const CartModel& model_;
  const EffectSet& effects_;
  std::unique_ptr<CartStepper> stepper_;
  CartState state_;
  StepStatistics statistics_;
};

}  // namespace

std::unique_ptr<ReferenceSolution> make_shadow_reference(const IntegratorSettings& shadow, double simulation_step,
                                                         const CartState& initial, const CartModel& model,
                                                         const EffectSet& effects) {
  if (!(shadow.step_size > 0.0) || !std::isfinite(shadow.step_size)) {
    std::ostringstream message;
    message << "reference.integrator.step_size must be finite and > 0 s, got " << shadow.step_size;
    throw std::invalid_argument(message.str());
  }
  if (shadow.name == "dopri5") {
    if (!(shadow.tolerance >= kShadowToleranceFloor) || !std::isfinite(shadow.tolerance)) {
      std::ostringstream message;
      message << "reference.integrator.tolerance " << shadow.tolerance << " is below the floor "
              << kShadowToleranceFloor << " (100 machine epsilons): dopri5 cannot meet it in double precision";
      throw std::invalid_argument(message.str());
    }
    if (shadow.birkhoffian_form == BirkhoffianForm::kAutonomous) {
      return std::make_unique<DenseShadowReference>(shadow, initial, model, effects);
    }
  }
  const double substeps = simulation_step / shadow.step_size;
  if (!(substeps <= kMaxShadowSubsteps)) {
    std::ostringstream message;
    message << "reference.integrator.step_size " << shadow.step_size << " s needs " << substeps
            << " sub-steps per simulator step of " << simulation_step << " s; at most " << kMaxShadowSubsteps
            << " are allowed (work limit)";
    throw std::invalid_argument(message.str());
  }
  return std::make_unique<SubstepShadowReference>(shadow, initial, model, effects);
}

}  // namespace birkhoff_cart
