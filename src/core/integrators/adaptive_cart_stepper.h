// The CartStepper of a Birkhoffian member under the error-per-step control (adaptive_step_control.h;
// docs/birkhoffian.md §12): the caller's step h is the output step; the member's own grid is chosen
// by the control for `position_tolerance`; the state at an output instant between grid points comes
// from the grid's Hermite dense output (hermite_dense_output.h). Private to the core library
// (integrator_registry.cpp makes it).
//
// Tolerance → τ (eq. (B.48)): the allowed error per unit step is τ = position_tolerance / horizon,
// so that the estimated local errors of a run add up to at most the tolerance by its horizon.
//
// Where the grid must land exactly rather than interpolate: the instants given to land_on() (the
// run's end: Simulation passes it), the loads' kinks (Effect::next_kink_after: a step across a
// kink loses the member's order; after one the stage history restarts), and, in a scene whose
// effects take commands (the node's torque topics), every output instant: a new command may start
// there, and the grid restarts from the landed state when it does.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include "birkhoff_cart/core/effects.h"
#include "birkhoff_cart/core/integrator_settings.h"
#include "birkhoff_cart/core/integrators/adaptive_step_control.h"
#include "birkhoff_cart/core/integrators/carried_state.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "grid_dense_output.h"
#include "output_instants.h"
#include "step_checks.h"

namespace birkhoff_cart {

template <class Stepper, class System>
class AdaptiveCartStepperAdapter final : public CartStepper {
  using Memory = typename Stepper::template Memory<System>;
  using Carried = CarriedCartState<System, Memory>;
  using Control = AdaptiveStepControl<Stepper, System, Carried>;
  using Output = CarriedCartState<System, NoStepMemory>;  ///< what was handed out (no stage memory)
  /// Hermite points: m + 1, m = max(2, p/2), so that the interpolant one point shorter, of the
  /// member's own order 2m, estimates its error (grid_dense_output.h).
  static constexpr int kDensePoints = (Stepper::kOrder / 2 > 2 ? Stepper::kOrder / 2 : 2) + 1;
  /// The work limit: internal steps between two output instants (as dopri5's, DOPRI5's NMAX).
  static constexpr std::uint64_t kMaxInternalStepsPerOutput = 100000;
  /// A failed side step is retried in up to 2^kMaxSideStepHalvings substeps.
  static constexpr int kMaxSideStepHalvings = 6;

 public:
  AdaptiveCartStepperAdapter(const Stepper& stepper, const IntegratorSettings& settings, const CartModel& model,
                             const EffectSet& effects)
      : system_(model, effects), effects_(&effects), name_(Stepper::name()),
        control_(stepper, control_settings(settings)), position_tolerance_(settings.position_tolerance),
        instants_(effects) {}

  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  bool symmetric() const override { return Stepper::kSymmetric; }
  void land_on(double time) override { instants_.land_on(time); }
  void observe_grid(GridObserver observer) override { observer_ = std::move(observer); }

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    stepper_checks::require_valid_step_size(step_size);
    const double time = state.time;  // [s]
    const double target = instants_.target(time, step_size);
    StepStatistics counted = statistics;
    counted.newton_iterations_last_step = 0;
    const bool continues = valid_ && output_.continues(state) && !instants_.commands_changed();
    valid_ = false;  // on failure: the next step starts afresh from the caller's unchanged state
    try {
      if (!continues) start(state, counted);
      advance(target, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + " (adaptive step control): " + error.what());
    }
    const auto& point = output_.point;
    stepper_checks::require_finite_result(name_, time, step_size, point.z, point.y);
    const CartState next = output_.output(system_, target);
    stepper_checks::require_finite_speeds(name_, time, step_size, next, point.z);
    instants_.remember_commands();
    valid_ = true;
    ++counted.steps;
    state = next;
    statistics = counted;
  }

 private:
  static AdaptiveStepSettings control_settings(const IntegratorSettings& settings) {
    AdaptiveStepSettings control;
    control.error_per_unit_step = stepper_checks::error_per_unit_step(settings, "adaptive");
    control.max_steps_per_advance = kMaxInternalStepsPerOutput;
    return control;
  }

  /// A grid from `state`: the carried point with χ, θ reduced, the first step from the rates there.
  void start(const CartState& state, StepStatistics& statistics) {
    Carried seed;
    system_.begin_step(state.time);
    seed.start_from(system_, state);
    control_.start(seed, state.time, first_step(seed, state.time, statistics));
    dense_.clear();
    dense_.push(control_.grid(), control_.time());
  }

  /// h₀ = 0.01·max(‖x‖, 10⁻³)/‖(ż, ẏ)‖ in ê's weights (after Hairer–Nørsett–Wanner's first guess,
  /// §II.4): deliberately small; the steps after a start grow by up to 100× each until the control
  /// first holds them back (adaptive_step_control.h).
  double first_step(const Carried& seed, double t, StepStatistics& statistics) {
    const StateVector<System, double> z = seed.point.z;
    const PassiveVector<System, double> y = seed.point.y;
    const StateVector<System, double> z_rate = birkhoffian_rates(system_, z, t);
    const PassiveVector<System, double> y_rate = passive_coordinate_rates(system_, z, y, t);
    ++statistics.rhs_evaluations;
    ++statistics.passive_evaluations;
    const double size = local_error_norm<System, double>(z, y, z, y);            // ‖x‖ [-]
    const double rate = local_error_norm<System, double>(z, y, z_rate, y_rate);  // ‖ẋ‖ [1/s]
    return 0.01 * std::max(size, 1e-3) / std::max(rate, 1e-6);
  }

  /// The carried point at `target` in output_: grid steps that land on kinks and landings, then the
  /// grid point itself when it is at `target`, else the dense output.
  void advance(double target, StepStatistics& statistics) {
    const bool land = instants_.exact_at(target);
    std::uint64_t taken = 0;
    while (control_.time() < target) {
      if (++taken > control_.settings().max_steps_per_advance) {
        std::ostringstream message;
        message.precision(17);
        message << "work limit: more than " << control_.settings().max_steps_per_advance
                << " internal steps from t = " << control_.time() << " s to the output instant t = " << target
                << " s (position tolerance " << position_tolerance_ << " m; a looser tolerance, or a singular point)";
        throw StepError(message.str());
      }
      double limit = land ? target : instants_.next_landing_after(control_.time());  // +inf: none
      const double kink = system_.non_birkhoffian_force_enabled() ? effects_->next_kink_after(control_.time())
                                                                  : std::numeric_limits<double>::infinity();
      const bool at_kink = kink <= limit;
      limit = std::min(limit, kink);
      control_.step(system_, limit, statistics, [this](const auto& before, const auto& after, double t, double h) {
        return stepper_checks::energy_balance_holds(system_.model(), cart_state(before, t), cart_state(after, t + h));
      });
      if (at_kink && control_.time() == kink) {
        control_.forget_stage_history();
        dense_.clear();
      }
      dense_.push(control_.grid(), control_.time());
      if (observer_) observer_(grid_state());
    }
    const Carried& grid = control_.grid();
    output_.periodic_in_steering_angle = grid.periodic_in_steering_angle;
    output_.valid = true;
    if (control_.time() == target) {
      output_.point = grid.point;
      output_.steering_turns = grid.steering_turns;
      output_.heading_turns = grid.heading_turns;
    } else if (!(dense_.at(system_, target, output_, statistics) <= position_tolerance_)) {
      side_step(target, statistics);  // where the dense output's own estimate exceeds the tolerance
    }
  }

  /// The state at `target` by one step of the member from the grid point before it: exact to the
  /// member's order where the dense output's estimate says it is not. A side step whose stage solve
  /// fails or lands on a spurious root (non-finite, or the energy balance broken) is retried in 2,
  /// 4, … 2^kMaxSideStepHalvings substeps, as the control retries a rejected attempt smaller.
  void side_step(double target, StepStatistics& statistics) {
    const double start = control_.previous_time();  // [s]
    std::string last;
    for (int halvings = 0; halvings <= kMaxSideStepHalvings; ++halvings) {
      const int pieces = 1 << halvings;
      output_.point = control_.previous();
      output_.steering_turns = control_.previous_steering_turns();
      output_.heading_turns = control_.previous_heading_turns();
      Memory memory;  // no stage history: an explicit start
      try {
        for (int k = 1; k <= pieces; ++k) {
          const double from = start + (target - start) * static_cast<double>(k - 1) / pieces;           // [s]
          const double to = k == pieces ? target : start + (target - start) * static_cast<double>(k) / pieces;  // [s]
          const CompensatedPoint<System> before = output_.point;
          system_.begin_step(from);
          control_.stepper().advance_compensated(system_, output_.point, memory, from, to - from, statistics);
          const bool finite = output_.point.z.allFinite() && output_.point.y.allFinite();
          if (!finite || !stepper_checks::energy_balance_holds(system_.model(), cart_state(before, from),
                                                               cart_state(output_.point, to))) {
            throw StepError("a non-finite state or a broken energy balance (a spurious root)");
          }
        }
        output_.reduce_angles();
        return;
      } catch (const StepError& error) {
        last = error.what();
      }
    }
    std::ostringstream message;
    message.precision(17);
    message << "the side step to the output instant t = " << target << " s failed whole and in 2 to "
            << (1 << kMaxSideStepHalvings) << " substeps; the last: " << last;
    throw StepError(message.str());
  }

  /// A grid point's CartState at time t [s] (its angles as carried: the balance does not read turns).
  CartState cart_state(const CompensatedPoint<System>& point, double t) const {
    return system_.to_cart_state(point.z + point.z_remainder, point.y + point.y_remainder, t);
  }

  /// The grid's state as a CartState (for the grid observer).
  CartState grid_state() {
    Output grid;
    grid.point = control_.grid().point;
    grid.steering_turns = control_.grid().steering_turns;
    grid.heading_turns = control_.grid().heading_turns;
    return grid.output(system_, control_.time());
  }


  System system_;
  const EffectSet* effects_;
  std::string name_;
  Control control_;
  double position_tolerance_;  ///< [m]
  GridDenseOutput<System, kDensePoints> dense_;
  Output output_;
  GridObserver observer_;
  bool valid_ = false;
  OutputInstants instants_;
};

}  // namespace birkhoff_cart
