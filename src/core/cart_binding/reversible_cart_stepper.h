// The CartStepper of a symmetric Birkhoffian member under the reversible step control
// (reversible_step_control.h; docs/birkhoffian.md §11): the caller's step h is the output step; the
// member's own grid steps the time-transformed cart with a constant fictive step ε; outputs come
// from the grid's Hermite dense output (grid_dense_output.h), and where a state must be exact —
// the run's end, land_on() instants, and every output of a scene whose effects take commands — from
// a side step of the untransformed member from the grid point before the instant. The grid never
// depends on the output instants. Private to the core library (integrator_registry.cpp makes it).
//
// For loads that do not depend on time (the free cart; drag, resistance, springs and dampers; held
// commands): the time transformation reads the loads at one time. A scene whose loads vary in time
// is refused by name (the adaptive control serves it), as is the paper's eᵗ form (its chart moves
// with time).
//
// Tolerance → ε (§11.3, eq. (B.45)): τ = position_tolerance / horizon is the allowed error per
// second (as for the adaptive control, eq. (B.48)); the generic control (ReversibleToleranceControl,
// reversible_step_control.h) chooses ε for it by trial grids from the start state before the first
// step, and cuts ε mid-run where a stretch is harder than the trials saw. This adapter translates:
// CartState to and from the carried point, outputs, landings, commands, and the checks of each step.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/integrators/reversible_step_control.h"
#include "birkhoff_cart/core/integrators/time_transformed_system.h"
#include "controlled_cart_stepper.h"
#include "step_checks.h"

namespace birkhoff_cart {

template <class Stepper, class System>
class ReversibleCartStepperAdapter final
    : public ControlledCartStepper<ReversibleCartStepperAdapter<Stepper, System>, Stepper, System> {
  using Base = ControlledCartStepper<ReversibleCartStepperAdapter<Stepper, System>, Stepper, System>;
  friend Base;
  using Transformed = TimeTransformedSystem<System>;
  using Control = ReversibleToleranceControl<Stepper, System>;
  using Grid = typename Control::Grid;
  using Output = typename Base::Output;
  using SideMemory = typename Stepper::template Memory<System>;
  using Base::dense_;
  using Base::instants_;
  using Base::name_;
  using Base::output_;
  using Base::system_;

 public:
  static constexpr double kMinFictiveStep = Control::kMinFictiveStep;  ///< ε_min [rad]

  ReversibleCartStepperAdapter(const Stepper& stepper, const IntegratorSettings& settings, const CartModel& model,
                               const EffectSet& effects)
      : Base(model, effects, "reversible", settings.position_tolerance), transformed_(system_, 0.0, stiff_density_squared(model, effects)),
        settings_(settings),
        control_(stepper, transformed_, stepper_checks::error_per_unit_step(settings, "reversible"),
                 settings.tolerance_horizon) {
    if (effects.depends_on_time()) {
      throw std::invalid_argument(
          "step_control 'reversible' needs loads that do not vary in time (its time transformation reads them at "
          "one time): this scene's torque profile or actuator does; use step_control 'adaptive'");
    }
    // Its ε is calibrated at the run's start; the paper's case stiffens towards its pole at χ = π
    // (det M → 0), and birkhoff_gauss8 under it ended 3.4× beyond 1e-7 m and 2.6× beyond 1e-9 m
    // (accuracy.md §4.4): refused rather than missed silently.
    if (model.inertia_model() == InertiaModel::kPaperSpecialCase) {
      throw std::invalid_argument(
          "step_control 'reversible' cannot hold the paper's special case (paper_special_case: true) to its "
          "tolerance: its fictive step is calibrated at the run's start, and the case stiffens towards its pole at "
          "chi = pi (birkhoff_gauss8 under it ended 3.4x beyond 1e-7 m); use step_control 'adaptive'");
    }
  }

  bool symmetric() const override { return true; }
  const std::optional<ReversibleCalibration>& calibration() const { return control_.calibration(); }
  /// τ = position_tolerance / horizon [1/s] (eq. (B.48)).
  double error_per_unit_step() const { return control_.error_per_unit_step(); }

  /// The trial grids (ε for the tolerance) from `start`; a tolerance out of reach is a settings
  /// error (std::invalid_argument), not a failed step.
  void prepare(const CartState& start, StepStatistics& statistics) override {
    if (calibration()) return;
    StepStatistics counted = statistics;
    try {
      calibrate(start, counted);
    } catch (const StepError& error) {
      throw std::invalid_argument(name_ + " (reversible step control): " + error.what());
    }
    counted.control_fictive_step = calibration()->fictive_step;
    statistics = counted;
  }

 private:
  /// A hinge spring's natural frequency squared, k/(l ν) [1/s²] with k = −∂Q2/∂χ at χ = 0 (eq.
  /// (B.44)): the steps resolve its swing even where the cart itself turns slowly.
  static double stiff_density_squared(const CartModel& model, const EffectSet& effects) {
    if (effects.empty()) return 0.0;
    const GeneralizedForce load = effects.evaluate(EffectInput{});
    const double stiffness = std::max(0.0, -load.jacobian(1, 0));  // [N·m/rad]
    return stiffness / (model.parameters().wheelbase * model.inertia().nu);
  }

  /// ε for the tolerance from the generic control's trial grids from `state`; a tolerance out of
  /// reach names the position tolerance and the member.
  void calibrate(const CartState& state, StepStatistics& statistics) {
    Output seed;
    seed.start_from(system_, state);
    try {
      control_.calibrate(seed, state.time, statistics);
    } catch (const FictiveStepOutOfReach& error) {
      std::ostringstream message;
      message << "position_tolerance " << settings_.position_tolerance << " m is out of reach for " << name_
              << " (it would need eps = " << error.fictive_step() << " rad < " << kMinFictiveStep
              << "): use a higher-order member or a looser tolerance";
      throw StepError(message.str());
    }
  }

  /// Before a step: ε for the tolerance, once (when prepare() was not called).
  void before_start(const CartState& state, StepStatistics& statistics) {
    if (!calibration()) calibrate(state, statistics);
    statistics.control_fictive_step = calibration()->fictive_step;
  }

  /// The energy balance of the step (a spurious root of the stage equations breaks it).
  void check(const CartState& before, const CartState& after, double step_size) const {
    stepper_checks::require_energy_balance(name_, system_.model(), before, after, step_size);
  }

  /// A grid from `state`: the carried point with χ, θ reduced.
  void start(const CartState& state, StepStatistics& /*statistics*/) {
    Output seed;
    seed.start_from(system_, state);
    control_.start(seed, state.time);
    dense_.clear();
    push_dense();
  }

  /// The carried point at `target` in output_: grid steps until the grid reaches or passes it,
  /// then the grid point itself, a landing step, the dense output or a side step.
  void advance(double target, StepStatistics& statistics) {
    control_.advance_past(target, statistics, [&] {
      push_dense();
      this->notify_grid(control_.grid(), control_.time());
    });
    output_.periodic_angles = control_.grid().periodic_angles;
    output_.valid = true;
    const bool land = instants_.exact_at(target);
    if (control_.time() == target) {
      output_.take_point(control_.grid());
    } else if (land) {
      landing_step(target, output_, statistics);
    } else {
      this->between_grid_points(target, output_, statistics);
    }
  }

  /// The state at a landing instant `target` (the run's end, a land_on() instant, a command's): a
  /// step from the grid point before it with a fresh memory, converged to round-off: a new grid may
  /// start from it.
  void landing_step(double target, Output& out, StepStatistics& statistics) {
    SideMemory memory;
    step_from_previous(target, memory, out, statistics);
  }

  /// The state at an output instant `target`: a step from the grid point before it, from an explicit
  /// start (the grid's stage points are in the fictive time), stopping at the accuracy the tolerance
  /// needs (κ·τ·h, eq. (B.49)), with its own J (at its starting stages' mean): it depends on the grid
  /// and `target` only. (J at the grid point, computed once and kept for the grid step's other side
  /// steps, took 14.2 evaluations a row on the whirl at 1e-6 m and 100 Hz against 13.1: from an
  /// explicit start the contraction needs J where the stages are.)
  void side_step(double target, Output& out, StepStatistics& statistics) {
    const double start = control_.previous_time();  // [s]
    side_memory_.clear();
    side_memory_.stage_change_limit = kStageChangeFraction * error_per_unit_step() * (target - start);
    step_from_previous(target, side_memory_, out, statistics);
  }

  /// `out` at `target` by one step of the untransformed member from the grid point before it.
  void step_from_previous(double target, SideMemory& memory, Output& out, StepStatistics& statistics) {
    out.take_point(control_.previous());
    CompensatedPoint<System> point = out.point;
    const double start = control_.previous_time();  // [s]
    control_.stepper().advance_compensated(system_, point, memory, start, target - start, statistics);
    out.point = point;
    out.reduce_angles();
  }

  /// The grid point into the dense output, with its rates in scene time: the step's first-same-as-
  /// last rates in τ times σ there (dw/dt = σ dw/dτ).
  void push_dense() {
    const Grid& grid = control_.grid();
    dense_.push_point(grid.point, grid.turns, control_.time());
    if (grid.memory.end_rate_valid) {
      const double density = transformed_.step_density(StateVector<System, double>(grid.point.z));
      dense_.set_newest_rate(grid.memory.end_rate * density, grid.memory.end_passive_rate * density);
    }
  }

  /// κ of the side step's stop (eq. (B.49), as the adaptive control's) [-].
  static constexpr double kStageChangeFraction = 0.01;

  Transformed transformed_;
  IntegratorSettings settings_;
  Control control_;
  SideMemory side_memory_;  ///< a side step's (kept: it is large; cleared for each)
};

}  // namespace birkhoff_cart
