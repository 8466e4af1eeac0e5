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
// Tolerance → ε (§11.3, eq. (B.45)): before the first step, a trial grid from the start state takes
// kTrialSteps steps at ε₀ = 0.25 rad and measures r = maxₙ eₙ/(τ hₙ), with τ = position_tolerance /
// horizon the allowed error per second (as for the adaptive control, eq. (B.48)) and eₙ the true
// local error: the member's own estimate êₙ (every step), divided by its overestimate ê/e measured
// by step doubling at every fourth step (the median; ê is of order s + 2, the error of order 2s + 1).
// Then ε = ε₀ (½/r)^{1/p} (e/h ∝ ε^p), with a second trial from there when ε moved by more than 4×.
// ε then stays fixed for the run: the map stays reversible and the run deterministic. The trials'
// work counts in the run's statistics.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/deterministic_math.h"
#include "birkhoff_cart/core/effects.h"
#include "birkhoff_cart/core/integrator_settings.h"
#include "birkhoff_cart/core/integrators/carried_state.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/integrators/reversible_step_control.h"
#include "birkhoff_cart/core/integrators/time_transformed_system.h"
#include "grid_dense_output.h"
#include "output_instants.h"
#include "step_checks.h"

namespace birkhoff_cart {

/// What the trial grids found (summaries, tests).
struct ReversibleCalibration {
  double fictive_step = 0.0;        ///< ε chosen [rad]
  double trial_fictive_step = 0.0;  ///< ε₀ of the last trial [rad]
  double trial_error_ratio = 0.0;   ///< r of the last trial [-]
  double trial_span = 0.0;          ///< the scene time the last trial covered [s]
  int trials = 0;                   ///< trial grids run [-]
  double overestimate = 1.0;        ///< f = ê/e the trials measured (eq. (B.45)) [-]
  int reductions = 0;               ///< times the run found a stretch harder than the trial and cut ε [-]
};

template <class Stepper, class System>
class ReversibleCartStepperAdapter final : public CartStepper {
  using Transformed = TimeTransformedSystem<System>;
  using Grid = CarriedCartState<System, typename Stepper::template Memory<Transformed>, Transformed>;
  using Control = ReversibleStepControl<Stepper, System, Grid>;
  using Output = CarriedCartState<System, NoStepMemory>;
  using SideMemory = typename Stepper::template Memory<System>;
  /// Hermite points: m + 1, m = max(2, p/2), so that the interpolant one point shorter, of the
  /// member's own order 2m, estimates its error (grid_dense_output.h).
  static constexpr int kDensePoints = (Stepper::kOrder / 2 > 2 ? Stepper::kOrder / 2 : 2) + 1;

 public:
  static constexpr double kFirstTrialStep = 0.25;  ///< ε₀ of the first trial [rad]
  static constexpr double kMaxFictiveStep = 0.6;   ///< ε_max [rad]: at most 0.6 rad of turning a step
  static constexpr double kMinFictiveStep = 1e-6;  ///< ε_min [rad]: a tolerance below reach
  static constexpr int kTrialSteps = 16;           ///< grid steps of a trial [-]
  static constexpr int kDoublingEvery = 4;         ///< a step-doubling check every this many trial steps [-]
  static constexpr int kMaxTrials = 3;
  /// A grid step whose error per unit step exceeds the calibrated one by this much cuts ε [-].
  static constexpr double kRecalibrationRatio = 2.0;
  static constexpr double kTwoPi = 6.283185307179586476925286766559;

  ReversibleCartStepperAdapter(const Stepper& stepper, const IntegratorSettings& settings, const CartModel& model,
                               const EffectSet& effects)
      : stepper_(stepper), system_(model, effects), transformed_(system_, 0.0, stiff_density_squared(model, effects)),
        settings_(settings), error_per_unit_step_(stepper_checks::error_per_unit_step(settings, "reversible")),
        name_(Stepper::name()), instants_(effects) {
    if (effects.depends_on_time()) {
      throw std::invalid_argument(
          "step_control 'reversible' needs loads that do not vary in time (its time transformation reads them at "
          "one time): this scene's torque profile or actuator does; use step_control 'adaptive'");
    }
  }

  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  bool symmetric() const override { return true; }
  void land_on(double time) override { instants_.land_on(time); }
  void observe_grid(GridObserver observer) override { observer_ = std::move(observer); }
  const std::optional<ReversibleCalibration>& calibration() const { return calibration_; }
  /// τ = position_tolerance / horizon [1/s] (eq. (B.48)).
  double error_per_unit_step() const { return error_per_unit_step_; }

  /// The trial grids (ε for the tolerance) from `start`; a tolerance out of reach is a settings
  /// error (std::invalid_argument), not a failed step.
  void prepare(const CartState& start, StepStatistics& statistics) override {
    if (calibration_) return;
    StepStatistics counted = statistics;
    try {
      calibrate(start, counted);
    } catch (const StepError& error) {
      throw std::invalid_argument(name_ + " (reversible step control): " + error.what());
    }
    counted.control_fictive_step = calibration_->fictive_step;
    statistics = counted;
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
      if (!calibration_) calibrate(state, counted);
      counted.control_fictive_step = calibration_->fictive_step;
      if (!continues) start(state);
      advance(target, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + " (reversible step control): " + error.what());
    }
    const auto& point = output_.point;
    stepper_checks::require_finite_result(name_, time, step_size, point.z, point.y);
    const CartState next = output_.output(system_, target);
    stepper_checks::require_finite_speeds(name_, time, step_size, next, point.z);
    stepper_checks::require_energy_balance(name_, system_.model(), state, next, step_size);
    instants_.remember_commands();
    valid_ = true;
    ++counted.steps;
    state = next;
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

  ReversibleStepSettings control_settings(double epsilon) const {
    ReversibleStepSettings settings;
    settings.fictive_step = epsilon;
    settings.error_per_unit_step = error_per_unit_step();
    return settings;
  }

  /// A grid from `state`: the carried point with χ, θ reduced.
  void start(const CartState& state) {
    Output seed;
    seed.start_from(system_, state);
    control_ = std::make_unique<Control>(stepper_, control_settings(calibration_->fictive_step));
    control_->start(seed, state.time);
    dense_.clear();
    push_dense();
  }

  /// The carried point at `target` in output_: grid steps until the grid reaches or passes it,
  /// then the grid point itself, a side step (landings) or the dense output.
  void advance(double target, StepStatistics& statistics) {
    while (control_->time() < target) {
      bool violated = false;
      control_->advance_past(transformed_, target, statistics, [&] {
        if (beyond_calibration(statistics)) {
          violated = true;
          return false;
        }
        push_dense();
        if (observer_) observer_(grid_state());
        return true;
      });
      if (violated) restart_finer(statistics);
    }
    output_.periodic_in_steering_angle = control_->grid().periodic_in_steering_angle;
    output_.valid = true;
    const bool land = instants_.exact_at(target);
    if (control_->time() == target) {
      copy_grid_point(control_->grid().point, control_->grid().steering_turns, control_->grid().heading_turns);
    } else if (land || !(dense_.at(system_, target, output_, statistics) <= settings_.position_tolerance)) {
      side_step(target, statistics);  // exact, or where the dense output's own estimate exceeds the tolerance
    }
  }

  /// Did the grid step just taken exceed the error per unit step the trial calibrated ε for, by
  /// more than 4× (eq. (B.45): a stretch of the run harder than its start, e.g. nearer a singular
  /// steering angle)? The estimate ê of the step over its overestimate f from the trial.
  bool beyond_calibration(const StepStatistics& statistics) const {
    return error_ratio(statistics) > kRecalibrationRatio;
  }

  /// r = e/(τh) of the grid step just taken, e = ê/f with the overestimate f the trial measured at
  /// ε_trial carried to this ε: f ∝ ε^{q−p−1} (ê of order q, e of order p + 1).
  double error_ratio(const StepStatistics& statistics) const {
    constexpr int kOverestimateOrder = Stepper::kErrorEstimateOrder - Stepper::kOrder - 1;
    const double h = control_->time() - control_->previous_time();
    const double overestimate =
        calibration_->overestimate *
        deterministic::pow(calibration_->fictive_step / calibration_->trial_fictive_step, kOverestimateOrder);
    return statistics.local_error_estimate_last_step / std::max(overestimate, 1.0) / (h * error_per_unit_step());
  }

  /// After such a step: back to the grid point before it, and on from there with the fictive step
  /// the step's own error asks for, ε (½/r)^{1/p} — a new grid (reversible again from there on).
  void restart_finer(StepStatistics& statistics) {
    calibration_->fictive_step *= deterministic::pow(0.5 / error_ratio(statistics), 1.0 / Stepper::kOrder);
    if (!(calibration_->fictive_step >= kMinFictiveStep)) {
      throw StepError("the fictive step needed past t = " + std::to_string(control_->previous_time()) +
                      " s fell below " + std::to_string(kMinFictiveStep) + " rad: a looser tolerance");
    }
    ++calibration_->reductions;
    ++statistics.rejected_steps;
    statistics.control_fictive_step = calibration_->fictive_step;
    Output seed;
    const auto& previous = control_->previous();
    seed.point.z = previous.point.z;
    seed.point.z_remainder = previous.point.z_remainder;
    seed.point.y = previous.point.y.template head<System::kPassiveDimension>();
    seed.point.y_remainder = previous.point.y_remainder.template head<System::kPassiveDimension>();
    seed.steering_turns = previous.steering_turns;
    seed.heading_turns = previous.heading_turns;
    seed.periodic_in_steering_angle = control_->grid().periodic_in_steering_angle;
    const double time = control_->previous_time();
    control_ = std::make_unique<Control>(stepper_, control_settings(calibration_->fictive_step));
    control_->start(seed, time);
  }

  /// The state at `target` by one step of the untransformed member from the grid point before it.
  void side_step(double target, StepStatistics& statistics) {
    const auto& previous = control_->previous();
    copy_grid_point(previous.point, previous.steering_turns, previous.heading_turns);
    CompensatedPoint<System> point = output_.point;
    SideMemory memory;  // no stage history: an explicit start
    const double start = control_->previous_time();
    stepper_.advance_compensated(system_, point, memory, start, target - start, statistics);
    output_.point = point;
    output_.reduce_angles();
  }

  template <class Point>
  void copy_grid_point(const Point& point, double steering_turns, double heading_turns) {
    output_.point.z = point.z;
    output_.point.z_remainder = point.z_remainder;
    output_.point.y = point.y.template head<System::kPassiveDimension>();
    output_.point.y_remainder = point.y_remainder.template head<System::kPassiveDimension>();
    output_.steering_turns = steering_turns;
    output_.heading_turns = heading_turns;
  }

  /// The grid point into the dense output, with its rates in scene time: the step's first-same-as-
  /// last rates in τ times σ there (dw/dt = σ dw/dτ).
  void push_dense() {
    const Grid& grid = control_->grid();
    dense_.push_point(grid.point, grid.steering_turns, grid.heading_turns, control_->time());
    if (grid.memory.end_rate_valid) {
      const double density = transformed_.step_density(StateVector<System, double>(grid.point.z));
      dense_.set_newest_rate(grid.memory.end_rate * density, grid.memory.end_passive_rate * density);
    }
  }

  CartState grid_state() {
    Output grid;
    const Grid& point = control_->grid();
    grid.point.z = point.point.z;
    grid.point.z_remainder = point.point.z_remainder;
    grid.point.y = point.point.y.template head<System::kPassiveDimension>();
    grid.point.y_remainder = point.point.y_remainder.template head<System::kPassiveDimension>();
    grid.steering_turns = point.steering_turns;
    grid.heading_turns = point.heading_turns;
    return grid.output(system_, control_->time());
  }

  /// The true local error of the grid step just taken from `start` (the ε step, in `grid`) by step
  /// doubling: against two ε/2 steps from the same point, e = |Φ_ε − Φ_{ε/2}²|·2^p/(2^p − 1) [-].
  double doubled_step_error(const typename Control::GridPoint& start, const Grid& grid, double epsilon,
                            StepStatistics& statistics) {
    CompensatedPoint<Transformed> halves = start.point;
    typename Stepper::template Memory<Transformed> memory;  // the halves' own (no stage history)
    stepper_.advance_compensated(transformed_, halves, memory, 0.0, 0.5 * epsilon, statistics);
    stepper_.advance_compensated(transformed_, halves, memory, 0.5 * epsilon, 0.5 * epsilon, statistics);
    CompensatedPoint<Transformed> whole = grid.point;
    // The grid point's angles were reduced after the step; the halves' were not.
    whole.z(kSteeringAngleIndex) += kTwoPi * (grid.steering_turns - start.steering_turns);
    whole.y(kHeadingIndex) += kTwoPi * (grid.heading_turns - start.heading_turns);
    const StateVector<Transformed, double> z_error = (whole.z + whole.z_remainder) - (halves.z + halves.z_remainder);
    const PassiveVector<Transformed, double> y_error = (whole.y + whole.y_remainder) - (halves.y + halves.y_remainder);
    const double doubling = deterministic::pow(2.0, Stepper::kOrder);
    return local_error_norm<Transformed, double>(whole.z, whole.y, z_error, y_error) * doubling / (doubling - 1.0);
  }

  /// r = maxₙ eₙ/(τ hₙ) over kTrialSteps grid steps from `state` with fictive step ε (eq. (B.45)):
  /// eₙ the true local error, estimated as the member's own ê (cheap, every step) divided by its
  /// overestimate f = ê/e measured by step doubling at every kDoublingEvery-th step (the median).
  /// Also the scene time the steps covered.
  double trial(const CartState& state, double epsilon, double& span, double& overestimate, StepStatistics& counted) {
    Output seed;
    seed.start_from(system_, state);
    Control control(stepper_, control_settings(epsilon));
    control.start(seed, state.time);
    StepStatistics statistics;
    double largest_estimate = 0.0;  // maxₙ êₙ/hₙ [1/s]
    std::vector<double> overestimates;
    // At most kTrialSteps steps, and no more than a tenth of the horizon after the first four: on a
    // short run the trial must not cost more than the run.
    const double trial_end = state.time + 0.1 * settings_.tolerance_horizon;  // [s]
    for (int n = 0; n < kTrialSteps; ++n) {
      const double h = control.grid_step(transformed_, epsilon, statistics);
      const double estimate = statistics.local_error_estimate_last_step;
      if (!std::isfinite(estimate)) throw StepError("the trial grid's local error estimate is not finite");
      largest_estimate = std::max(largest_estimate, estimate / h);
      const bool last = n + 1 == kTrialSteps || (n >= 3 && control.time() >= trial_end);
      if (n % kDoublingEvery == kDoublingEvery - 1 || (last && overestimates.empty())) {
        const double error = doubled_step_error(control.previous(), control.grid(), epsilon, statistics);
        if (!std::isfinite(error)) throw StepError("the trial grid's local error is not finite");
        if (error > 0.0 && estimate > 0.0) overestimates.push_back(estimate / error);
      }
      if (last) break;
    }
    counted.rhs_evaluations += statistics.rhs_evaluations;
    counted.passive_evaluations += statistics.passive_evaluations;
    counted.newton_iterations_total += statistics.newton_iterations_total;
    span = control.time() - state.time;
    overestimate = 1.0;  // f: at round-off both vanish; take the estimate as it is
    if (!overestimates.empty()) {  // the smallest: the estimate's tightest moment, e = ê/f the largest
      overestimate = std::max(1.0, *std::min_element(overestimates.begin(), overestimates.end()));
    }
    return largest_estimate / overestimate / error_per_unit_step();
  }

  /// ε for the tolerance from the trial grids (file comment; eq. (B.45)).
  void calibrate(const CartState& state, StepStatistics& statistics) {
    constexpr int kExponent = Stepper::kOrder;  // e/h ∝ ε^p
    ReversibleCalibration found;
    double epsilon = kFirstTrialStep;
    for (int attempt = 0; attempt < 8 && found.trials < kMaxTrials;) {
      double span = 0.0;
      double ratio = 0.0;
      double overestimate = 1.0;
      try {
        ratio = trial(state, epsilon, span, overestimate, statistics);
      } catch (const StepError&) {  // too coarse for the stage solve: a finer trial
        if (++attempt == 8) throw;
        epsilon /= 4.0;
        continue;
      }
      ++found.trials;
      found.trial_fictive_step = epsilon;
      found.trial_error_ratio = ratio;
      found.trial_span = span;
      found.overestimate = overestimate;
      const double wanted = ratio > 0.0 ? epsilon * deterministic::pow(0.5 / ratio, 1.0 / kExponent) : kMaxFictiveStep;
      const double next = std::min(wanted, kMaxFictiveStep);
      found.fictive_step = next;
      if (next <= 1.5 * epsilon && next >= epsilon / 1.5) break;
      epsilon = next;
    }
    if (!(found.fictive_step >= kMinFictiveStep)) {
      std::ostringstream message;
      message << "position_tolerance " << settings_.position_tolerance << " m is out of reach for " << name_
              << " (it would need eps = " << found.fictive_step << " rad < " << kMinFictiveStep
              << "): use a higher-order member or a looser tolerance";
      throw StepError(message.str());
    }
    calibration_ = found;
  }


  Stepper stepper_;
  System system_;
  Transformed transformed_;
  IntegratorSettings settings_;
  double error_per_unit_step_;  ///< τ [1/s]
  std::string name_;
  std::optional<ReversibleCalibration> calibration_;
  std::unique_ptr<Control> control_;
  GridDenseOutput<System, kDensePoints> dense_;
  Output output_;
  GridObserver observer_;
  bool valid_ = false;
  OutputInstants instants_;
};

}  // namespace birkhoff_cart
