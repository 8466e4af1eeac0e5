// The CartStepper of a symmetric Birkhoffian member under reversible step control
// (reversible_step_control.h; docs/birkhoffian.md §11): the caller's step h is the output step, the
// member's own grid is chosen by the controller, and the state at each output instant comes from a
// side step off the grid. Private to the core library (integrator_registry.cpp makes it).
//
// Tolerance → ε (§11.3, eq. (B.45)). The global position error of a run with fixed ε behaves like
// C·ε^p·(t − t₀) (symmetric member of order p; the error of a whirl grows like its phase error,
// linearly). Before the first step the adapter measures C on a pilot window [t₀, t₀ + W],
// W = min(horizon, 60 s): three pilot runs from the start state with ε_a, ε_a/2, ε_a/4 land at
// t₀ + W; their position differences d₁, d₂ give the observed order q and the error of the finest,
// e = d₂ / (2^q − 1). ε_a starts at 2 ε_max and is halved while a pilot fails, and (twice at most)
// until d₁/d₂ is within a factor 2 of 2^p (q = p); otherwise q = log₂(d₁/d₂) in [1, p] (a load with
// a kink lowers the order). Then ε = min(ε_a/4 · (0.5·tol·W / (e·horizon))^{1/q}, ε_a, ε_max). The
// run itself starts again from the start state: the pilots only choose ε, which is then fixed for
// the whole run (the map stays reversible and the run deterministic).
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "birkhoff_cart/core/effects.h"
#include "birkhoff_cart/core/integrators/carried_state.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/integrators/reversible_step_control.h"
#include "birkhoff_cart/core/integrator_settings.h"
#include "step_checks.h"

namespace birkhoff_cart {

/// What the pilot runs found (summaries, tests).
struct ReversibleCalibration {
  double fictive_step = 0.0;      ///< ε chosen [rad]
  double pilot_window = 0.0;      ///< W [s]
  double pilot_error = 0.0;       ///< e of the finest pilot at t₀ + W [m]
  double pilot_fictive_step = 0.0;  ///< ε of the finest pilot [rad]
  double observed_ratio = 0.0;    ///< d₁/d₂ (2^p in the asymptotic regime) [-]
  double observed_order = 0.0;    ///< the order ε was extrapolated with [-]
  bool at_round_off = false;      ///< the pilots agreed to round-off: ε is the largest allowed
  double largest_safe_step = 0.0;  ///< ε_a of the pilots that ran through [rad]
};

template <class Stepper, class System>
class ReversibleCartStepperAdapter final : public CartStepper {
  using Memory = typename Stepper::template Memory<System>;
  using Carried = CarriedCartState<System, Memory>;
  using Control = ReversibleStepControl<Stepper, System, Carried>;

 public:
  static constexpr double kMaxFictiveStep = 0.025;  ///< ε_max [rad]: above it the whirl's energy error wanders (7× at 0.05 over 1e4 s)
  static constexpr double kMinFictiveStep = 1e-6;   ///< ε_min [rad]: a tolerance below reach
  static constexpr double kPilotWindow = 60.0;      ///< longest pilot window [s]
  static constexpr int kMaxPilotAttempts = 4;       ///< halvings of ε_a after failed steps before giving up (each doubles the cost)
  static constexpr int kPilotAttemptsForOrder = 2;  ///< halvings of ε_a waiting for the order p

  ReversibleCartStepperAdapter(const Stepper& stepper, const IntegratorSettings& settings, const CartModel& model,
                               const EffectSet& effects)
      : stepper_(stepper), system_(model, effects), effects_(&effects), settings_(settings), name_(Stepper::name()) {
    if (!(settings.position_tolerance > 0.0) || !std::isfinite(settings.position_tolerance)) {
      throw std::invalid_argument("step_control 'reversible' needs a finite position_tolerance > 0 m, got " +
                                  std::to_string(settings.position_tolerance));
    }
    if (!(settings.tolerance_horizon > 0.0) || !std::isfinite(settings.tolerance_horizon)) {
      throw std::invalid_argument("integrator.tolerance_horizon must be finite and > 0 s");
    }
  }

  const std::string& name() const override { return name_; }
  int order() const override { return Stepper::kOrder; }
  bool symmetric() const override { return true; }
  const std::optional<ReversibleCalibration>& calibration() const { return calibration_; }

  /// The pilot runs (ε for the tolerance) from `start`; a tolerance out of reach is a settings
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
    counted.control_observed_order = calibration_->observed_order;
    statistics = counted;
  }

  void step(CartState& state, double step_size, StepStatistics& statistics) override {
    stepper_checks::require_valid_step_size(step_size);
    const double time = state.time;  // tₖ [s]
    const double target = time + step_size;
    StepStatistics counted = statistics;
    counted.newton_iterations_last_step = 0;
    const bool continues = valid_ && output_.continues(state) && !commands_changed();
    valid_ = false;  // on failure: the next step starts afresh from the caller's unchanged state
    try {
      if (!calibration_) calibrate(state, counted);
      counted.control_fictive_step = calibration_->fictive_step;
      counted.control_observed_order = calibration_->observed_order;
      if (!continues) start(state, counted);
      advance(*control_, target, output_, counted);
    } catch (const StepError& error) {
      throw StepError(name_ + " (reversible step control): " + error.what());
    }
    const auto& point = output_.point;
    stepper_checks::require_finite_result(name_, time, step_size, point.z, point.y);
    const CartState next = output_.output(system_, target);
    stepper_checks::require_finite_speeds(name_, time, step_size, next, point.z);
    remember_commands();
    valid_ = true;
    ++counted.steps;
    state = next;
    statistics = counted;
  }

 private:
  /// A grid from `state`: the carried point with χ, θ reduced, ρ₀ = σ(z₀).
  void start(const CartState& state, StepStatistics& statistics) {
    Carried seed;
    system_.begin_step(state.time);
    seed.start_from(system_, state);
    ReversibleStepSettings control_settings;
    control_settings.fictive_step = calibration_->fictive_step;
    control_ = std::make_unique<Control>(stepper_, control_settings);
    control_->start(system_, seed, state.time, statistics);
  }

  /// The position (x, y) [m] at t₀ + window of a run from `state` with fictive step ε. Its work
  /// counts in `statistics` (rhs, passive evaluations, iterations); its steps do not.
  Eigen::Vector2d pilot(const CartState& state, double epsilon, double window, StepStatistics& counted) {
    StepStatistics statistics;
    struct AddWork {
      StepStatistics& into;
      const StepStatistics& from;
      ~AddWork() {
        into.rhs_evaluations += from.rhs_evaluations;
        into.passive_evaluations += from.passive_evaluations;
        into.newton_iterations_total += from.newton_iterations_total;
      }
    } add_work{counted, statistics};
    Carried seed;
    system_.begin_step(state.time);
    seed.start_from(system_, state);
    ReversibleStepSettings control_settings;
    control_settings.fictive_step = epsilon;
    Control control(stepper_, control_settings);
    control.start(system_, seed, state.time, statistics);
    const double end = state.time + window;
    Carried landed;
    advance(control, end, landed, statistics);
    return Eigen::Vector2d(landed.point.y(kXIndex) + landed.point.y_remainder(kXIndex),
                           landed.point.y(kYIndex) + landed.point.y_remainder(kYIndex));
  }

  /// The carried point at `target` [s] in `out`: grid steps, and at every kink of the loads in time
  /// before `target` (a ramp's corners) a side step onto it and a new grid from there — a step
  /// across a kink loses the member's order (on the default scene a 1e-7 m/s jump in ω1 at the
  /// ramp's start, at h = 0.011 s); then a side step onto `target`.
  void advance(Control& control, double target, Carried& out, StepStatistics& statistics) {
    if (system_.non_birkhoffian_force_enabled()) {
      for (double kink = effects_->next_kink_after(control.time()); kink < target;
           kink = effects_->next_kink_after(kink)) {
        control.advance_grid_to(system_, kink, statistics);
        control.side_step_to(system_, kink, out, statistics);
        control.start(system_, out, kink, statistics);
      }
    }
    control.advance_grid_to(system_, target, statistics);
    control.side_step_to(system_, target, out, statistics);
  }

  /// ε for the tolerance from three pilot runs (file comment; eq. (B.45)).
  void calibrate(const CartState& state, StepStatistics& statistics) {
    constexpr int p = Stepper::kOrder;
    const double ratio_expected = std::pow(2.0, p);
    const double window = std::min(settings_.tolerance_horizon, kPilotWindow);
    ReversibleCalibration found;
    found.pilot_window = window;
    double epsilon = 2.0 * kMaxFictiveStep;  // ε_a: the pilots are short; the run itself keeps ε ≤ ε_max
    for (int attempt = 0;; ++attempt) {
      Eigen::Vector2d coarse, middle, fine;
      try {
        coarse = pilot(state, epsilon, window, statistics);
        middle = pilot(state, epsilon / 2.0, window, statistics);
        fine = pilot(state, epsilon / 4.0, window, statistics);
      } catch (const StepError&) {  // too coarse for the stage solve: finer pilots
        if (attempt == kMaxPilotAttempts) throw;
        epsilon /= 2.0;
        continue;
      }
      const double d1 = (coarse - middle).norm();
      const double d2 = (middle - fine).norm();
      const double noise = 1e-13 * (1.0 + fine.norm());  // [m]
      found.pilot_fictive_step = epsilon / 4.0;
      found.largest_safe_step = epsilon;
      found.observed_ratio = d1 / d2;
      if (d1 <= noise && d2 <= noise) {  // already at round-off at the largest ε tried
        found.at_round_off = true;
        found.observed_order = p;
        found.pilot_error = d2;
        found.fictive_step = epsilon;
        break;
      }
      const bool asymptotic = d2 > noise && found.observed_ratio > 0.5 * ratio_expected &&
                              found.observed_ratio < 2.0 * ratio_expected;
      if (asymptotic || attempt >= kPilotAttemptsForOrder) {
        // A load with a kink in time (a torque ramp's corners) or in the state (|v| v drag) lowers
        // the order the run shows: extrapolate with the order observed, 1 ≤ q ≤ p, not with p.
        const double order =
            asymptotic ? p : std::clamp(std::log2(std::max(found.observed_ratio, 2.0)), 1.0, double(p));
        found.observed_order = order;
        found.pilot_error = d2 / (std::pow(2.0, order) - 1.0);
        const double allowed = 0.5 * settings_.position_tolerance * window / settings_.tolerance_horizon;  // [m] at W
        found.fictive_step = epsilon / 4.0 * std::pow(allowed / std::max(found.pilot_error, noise), 1.0 / order);
        break;
      }
      epsilon /= 2.0;
    }
    // Never above ε_max, nor above the coarsest pilot that ran through the window (a coarser ε let
    // ρ turn negative there: σ fell by more than ρ in one half-step).
    found.fictive_step = std::min({found.fictive_step, kMaxFictiveStep, found.largest_safe_step});
    if (!(found.fictive_step >= kMinFictiveStep)) {
      std::ostringstream message;
      message << "position_tolerance " << settings_.position_tolerance << " m is out of reach for " << name_ << " (it would need eps = "
              << found.fictive_step << " rad < " << kMinFictiveStep << "): use a higher-order member or a looser tolerance";
      throw StepError(message.str());
    }
    calibration_ = found;
  }

  bool commands_changed() const {
    const auto& steering = effects_->steering_command();
    const auto& drive = effects_->drive_command();
    return (steering && steering->value != steering_command_) || (drive && drive->value != drive_command_);
  }
  void remember_commands() {
    if (effects_->steering_command()) steering_command_ = effects_->steering_command()->value;
    if (effects_->drive_command()) drive_command_ = effects_->drive_command()->value;
  }

  Stepper stepper_;
  System system_;
  const EffectSet* effects_;
  IntegratorSettings settings_;
  std::string name_;
  std::optional<ReversibleCalibration> calibration_;
  std::unique_ptr<Control> control_;
  Carried output_;
  bool valid_ = false;
  double steering_command_ = 0.0;  ///< the commands the grid was started or continued with [N·m]
  double drive_command_ = 0.0;
};

}  // namespace birkhoff_cart
