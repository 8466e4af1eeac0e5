// The CartStepper of dopri5 (dopri5.h): ONE continuing controlled Dormand–
// Prince 5(4) run of Boost.Odeint with its own dense output over the whole run, instead of a new run
// per output step (which made the error follow the output step, not the tolerance). The caller's
// step h is the output step: the run advances only past it, and the state at an output instant
// comes from dopri5's dense output (its 4th-order continuous extension); where a state must be
// exact — the run's end, land_on() instants, every output of a scene whose effects take commands —
// from a side step of the controlled stepper from the accepted step's start. A new command restarts
// the run at that instant. An explicit method takes the same steps in the autonomous and the paper
// form (its map does not use the chart), so both run the autonomous rates. Private to the core
// library (integrator_registry.cpp makes it).
//
// The tolerance: `tolerance` (absolute and relative, per step) as given, or under step_control
// adaptive the position tolerance per second of the horizon, position_tolerance / horizon.
// Its local error estimate ê is the pair's own of each accepted step (dopri5.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/integrators/dopri5.h"
#include "birkhoff_cart/core/integrators/odeint_step_adjuster.h"
#include "cart_joint_rates.h"
#include "output_instants.h"
#include "step_checks.h"

namespace birkhoff_cart {

class Dopri5RunCartStepper final : public CartStepper {
  using Dopri5 = boost::numeric::odeint::runge_kutta_dopri5<Joint>;
  using Checker =
      dopri5_detail::NotingErrorChecker<double, typename Dopri5::algebra_type, typename Dopri5::operations_type>;
  using Controlled = DeterministicControlled<Dopri5, Checker>;
  using Dense = boost::numeric::odeint::dense_output_runge_kutta<Controlled>;

 public:
  /// `tolerance`: absolute and relative tolerance per step [-] (≥ DormandPrince5::kMinTolerance);
  /// `passive_absolute`: the passive coordinates (the positions) are held to it absolutely
  /// (NotingErrorChecker; the adaptive control's position tolerance).
  Dopri5RunCartStepper(double tolerance, const CartModel& model, const EffectSet& effects,
                       bool passive_absolute = false)
      : tolerance_(DormandPrince5(tolerance).tolerance()), passive_absolute_(passive_absolute), model_(&model),
        system_(model, effects), dense_(Controlled(checker(&trial_estimate_))), instants_(effects) {}

  const std::string& name() const override { return name_; }
  int order() const override { return DormandPrince5::kOrder; }
  bool symmetric() const override { return false; }
  void land_on(double time) override { instants_.land_on(time); }
  void observe_grid(GridObserver observer) override { observer_ = std::move(observer); }
  /// odeint's dense output on the newest accepted step (its continuous extension), the run unmoved.
  bool newest_step_state(double time, CartState& out, StepStatistics& /*work*/) override {  // no evaluation
    if (!stepped_ || !(time >= dense_.previous_time() && time <= dense_.current_time())) return false;
    Joint x;
    if (time == dense_.current_time()) {
      x = dense_.current_state();  // the step's end itself, as the run hands it out
    } else {
      dense_.calc_state(time, x);
    }
    out = cart_state_of(system_, x, time);
    return true;
  }

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    stepper_checks::require_valid_step_size(step_size);
    const double time = state.time;  // [s]
    const double target = instants_.target(time, step_size);
    StepStatistics counted = statistics;
    const bool continues = valid_ && same_state(state, last_output_) && !instants_.commands_changed();
    valid_ = false;  // on failure: the next step starts afresh from the caller's unchanged state
    if (!continues) {
      dense_.initialize(joint_of(system_.to_birkhoffian(state)), time, guess_ > 0.0 ? guess_ : step_size);
      stepped_ = false;
    }
    Joint x;
    std::uint64_t evaluations = 0;
    const JointRates rates{&system_, model_, &evaluations};
    try {
      std::uint64_t taken = 0;
      while (dense_.current_time() < target) {
        if (++taken > DormandPrince5::kMaxInternalSteps) fail(time, target, "more than 100000 internal steps");
        dense_.do_step(rates);  // one accepted step (odeint retries rejected ones)
        stepped_ = true;
        record_local_error_estimate(counted, trial_estimate_);
        ++counted.internal_steps;
        const double h = dense_.current_time() - dense_.previous_time();
        counted.internal_step_min = std::min(counted.internal_step_min, h);
        counted.internal_step_max = std::max(counted.internal_step_max, h);
        require_finite(dense_.current_state(), time, target);
        if (observer_) observer_(cart_state_of(system_, dense_.current_state(), dense_.current_time()));
      }
      if (dense_.current_time() == target) {
        x = dense_.current_state();
      } else if (instants_.exact_at(target)) {
        side_step(target, rates, x);
      } else {
        dense_.calc_state(target, x);
      }
    } catch (const boost::numeric::odeint::odeint_error& error) {
      counted.rhs_evaluations += evaluations;
      fail(time, target, std::string("odeint: ") + error.what());
    }
    counted.rhs_evaluations += evaluations;
    require_finite(x, time, target);
    const CartState next = cart_state_of(system_, x, target);
    stepper_checks::require_finite_speeds(name_, time, step_size, next, joint_z(x));
    stepper_checks::require_energy_balance(name_, system_.model(), state, next, step_size);
    guess_ = dense_.current_time_step();
    instants_.remember_commands();
    last_output_ = next;
    valid_ = true;
    ++counted.steps;
    state = next;
    statistics = counted;
  }

 private:
  Checker checker(double* estimate) const {
    return Checker(tolerance_, tolerance_, estimate, kBirkhoffianSize, passive_absolute_);
  }
  /// x(target) by controlled steps from the accepted step's start (exact to the method's order,
  /// the run itself untouched).
  void side_step(double target, const JointRates& rates, Joint& x) {
    Controlled controlled(checker(&side_estimate_));
    x = dense_.previous_state();
    double t = dense_.previous_time();
    double dt = target - t;
    const double close = 1e-12 * (1.0 + std::abs(target));  // [s]
    for (int attempt = 0; target - t > close; ++attempt) {
      if (attempt > 500) throw StepError("dopri5: the landing step was rejected 500 times");
      dt = std::min(dt, target - t);
      controlled.try_step(rates, x, t, dt);  // on success x, t advance; dt becomes the next proposal
    }
  }

  static StateVector<CartAutonomousBirkhoffian, double> joint_z(const Joint& x) {
    StateVector<CartAutonomousBirkhoffian, double> z;
    for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x[i];
    return z;
  }
  void require_finite(const Joint& x, double time, double target) const {
    for (const double value : x) {
      if (!std::isfinite(value)) fail(time, target, "a non-finite state");
    }
  }
  [[noreturn]] void fail(double time, double target, const std::string& why) const {
    std::ostringstream message;
    message.precision(17);
    message << "dopri5 failed in the run from t = " << time << " s to " << target << " s (tolerance " << tolerance_
            << "): " << why;
    throw StepError(message.str());
  }
  /// Is `a` the state this run handed out as `b` (every field but the time, bit for bit)? The time
  /// is left out: callers set t = t₀ + n·h themselves (simulation.cpp), which may differ from the
  /// run's tₖ + h by an ulp; a restart there would start the run again from the dense output's
  /// state at every such output instant, and the error would follow the output rate.
  static bool same_state(const CartState& a, const CartState& b) {
    return a.x == b.x && a.y == b.y && a.heading == b.heading &&
           a.steering_angle == b.steering_angle && a.wheel_spin_angle == b.wheel_spin_angle &&
           a.arc_length == b.arc_length && a.forward_speed == b.forward_speed && a.steering_rate == b.steering_rate &&
           a.applied_work == b.applied_work && a.steering_impulse == b.steering_impulse &&
           a.steering_angle_low == b.steering_angle_low && a.heading_low == b.heading_low;
  }

  const std::string name_ = DormandPrince5::name();
  double tolerance_;  ///< [-]
  bool passive_absolute_;  ///< the passive coordinates held to the tolerance absolutely
  const CartModel* model_;
  CartAutonomousBirkhoffian system_;
  double trial_estimate_ = 0.0;  ///< ê of the latest trial step [-] (the checker writes it)
  double side_estimate_ = 0.0;   ///< the same for side steps [-]
  Dense dense_;
  double guess_ = 0.0;           ///< the run's step size when it last handed a state out [s]
  GridObserver observer_;
  bool stepped_ = false;  ///< dense_ holds an accepted step (newest_step_state)
  CartState last_output_;
  bool valid_ = false;
  OutputInstants instants_;
};

}  // namespace birkhoff_cart
