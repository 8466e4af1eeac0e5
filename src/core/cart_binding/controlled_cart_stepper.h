// What the CartSteppers of the adaptive and the reversible step controls share
// (adaptive_cart_stepper.h, reversible_cart_stepper.h): the caller's step h is the output step, the
// member's own grid is the control's; a step continues the carried grid when the state handed in is
// the one handed out and no command changed, else starts a new grid there; its result is checked
// (finite, speeds) before it is handed out, and a failed step leaves the caller's state and
// statistics untouched. Private to the core library.
//
// `Derived` supplies start(state, statistics) (a new grid at the state), advance(target, statistics)
// (the carried point at `target` in output_) and, optionally, before_start(state, statistics) and
// check(before, after, h) (more checks of a step's result).
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "grid_dense_output.h"
#include "output_instants.h"
#include "step_checks.h"

namespace birkhoff_cart {

template <class Derived, class Stepper, class System>
class ControlledCartStepper : public CartStepper {
 public:
  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  void land_on(double time) override { instants_.land_on(time); }
  void observe_grid(GridObserver observer) override { observer_ = std::move(observer); }
  /// The state the run would output at `time` inside the grid's newest step — the grid's Hermite
  /// interpolant (grid_dense_output.h), or a side step where its estimate exceeds the tolerance —
  /// on a copy of the handed-out point: the run and its output stay as they were (the work, counted
  /// in `work`: the held points' rates, which the next output then takes as known, and the side step).
  bool newest_step_state(double time, CartState& out, StepStatistics& work) override {
    if (dense_.size() < 2 || !(time >= dense_.time(1) && time <= dense_.time(0))) return false;
    Output probe = output_;
    probe.periodic_angles = system_traits::periodic_angles(system_);
    try {
      between_grid_points(time, probe, work);
    } catch (const StepError& error) {
      throw StepError(name_ + " (" + control_name_ + " step control): " + error.what());
    }
    out = probe.output(system_, time);
    return true;
  }

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    stepper_checks::require_valid_step_size(step_size);
    const double time = state.time;  // [s]
    const double target = instants_.target(time, step_size);
    StepStatistics counted = statistics;
    counted.newton_iterations_last_step = 0;
    const bool continues = valid_ && output_.continues(state) && !instants_.commands_changed();
    valid_ = false;  // on failure: the next step starts afresh from the caller's unchanged state
    try {
      derived().before_start(state, counted);
      if (!continues) derived().start(state, counted);
      derived().advance(target, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + " (" + control_name_ + " step control): " + error.what());
    }
    const auto& point = output_.point;
    stepper_checks::require_finite_result(name_, time, step_size, point.z, point.y);
    const CartState next = output_.output(system_, target);
    stepper_checks::require_finite_speeds(name_, time, step_size, next, point.z);
    derived().check(state, next, step_size);
    instants_.remember_commands();
    valid_ = true;
    ++counted.steps;
    state = next;
    statistics = counted;
  }

 protected:
  using Output = CarriedCartState<System, NoStepMemory>;  ///< what was handed out (no stage memory)
  /// Hermite points: m + 1, m = max(2, p/2), so that the interpolant one point shorter, of the
  /// member's own order 2m, estimates its error (grid_dense_output.h).
  static constexpr int kDensePoints = (Stepper::kOrder / 2 > 2 ? Stepper::kOrder / 2 : 2) + 1;

  /// `control`: "adaptive" or "reversible", for messages; `position_tolerance` [m] judges the rows
  /// between grid points.
  ControlledCartStepper(const CartModel& model, const EffectSet& effects, const char* control,
                        double position_tolerance)
      : system_(model, effects), name_(Stepper::name()), control_name_(control), instants_(effects),
        position_tolerance_(position_tolerance) {}

  /// The carried point at `target` inside the grid's newest step in `out`: the dense output, or the
  /// derived control's side_step(target, out, statistics) where the dense output's own estimate
  /// exceeds the tolerance. Depends on the grid and `target` only (the rows asked before do not
  /// change it), so a read by newest_step_state is the row the run would output there.
  void between_grid_points(double target, Output& out, StepStatistics& statistics) {
    if (!(dense_.at(system_, target, out, statistics) <= position_tolerance_)) {
      derived().side_step(target, out, statistics);
    }
  }

  /// Defaults of the optional hooks: nothing more to do or check.
  void before_start(const CartState& /*state*/, StepStatistics& /*statistics*/) {}
  void check(const CartState& /*before*/, const CartState& /*after*/, double /*step_size*/) const {}

  /// The grid point of `carried` at time t [s] as a CartState, for the grid observer.
  template <class Carried>
  void notify_grid(const Carried& carried, double t) {
    if (!observer_) return;
    Output grid;
    grid.take_point(carried);
    observer_(grid.output(system_, t));
  }

  System system_;
  std::string name_;
  const char* control_name_;  ///< "adaptive" or "reversible"
  GridDenseOutput<System, kDensePoints> dense_;
  Output output_;
  GridObserver observer_;
  bool valid_ = false;
  OutputInstants instants_;
  double position_tolerance_;  ///< [m]

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }
};

}  // namespace birkhoff_cart
