// The reversible adaptive step of the symmetric Birkhoffian members (docs/birkhoffian.md §11): the
// member steps the time-transformed system (time_transformed_system.h, eq. (B.41)) with a constant
// fictive step ε [rad] (the angle the motion turns per step). The grid map
//
//   (zₙ, yₙ, tₙ) ↦ (zₙ₊₁, yₙ₊₁, tₙ₊₁) = Φ_ε(zₙ, yₙ, tₙ),   hₙ = tₙ₊₁ − tₙ = ε Σⱼ bⱼ/σ(Zⱼ) ≈ ε/σ(zₙ)   (B.42)
//
// is one collocation step of an autonomous system in τ, hence symmetric: Φ_{−ε} undoes Φ_ε, for any
// step density σ (reversible_step_control_test: forward then backward returns to round-off). The
// physical steps follow the motion's own time scale — long on the slow arcs, short at the jackknife
// — and, being implicit in the stages, stay stable for fictive steps of a radian (an explicit
// controller of h, Hairer & Söderlind's, turned its control variable negative above 0.1 rad on the
// whirl). Gauss collocation is A-stable, so a stiff hinge does not bound ε.
//
// The stage solve stops at κ·τ·(ε/σ(zₙ)) (eq. (B.49): τ the allowed error per second, κ = 0.01), not
// at round-off. The grid never depends on the caller's output instants: outputs come from the dense
// output between grid points or, where a state is to be exact (landings), from a side step of the
// untransformed member from the grid point before them (the caller's; the cart's adapter:
// reversible_cart_stepper.h).
//
// ReversibleStepControl takes grid steps at a given ε; ReversibleToleranceControl chooses ε for a
// tolerance (trial grids, eq. (B.45)) and cuts it mid-run where a stretch is harder than the trials
// saw. Both know no system beyond the concept and its optional traits (system_traits.h): the step
// density σ(z) (default 1 s⁻¹) and the angles carried reduced in the grid (carried_point.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/carried_point.h"
#include "birkhoff_cart/core/integrators/compensated_summation.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/time_transformed_system.h"

namespace birkhoff_cart {

/// Settings of the reversible control.
struct ReversibleStepSettings {
  double fictive_step = 0.25;          ///< ε [rad]: the angle the motion turns per step
  double error_per_unit_step = 0.0;    ///< τ [1/s] the stage solve stops at (eq. (B.49)); 0: round-off
  double stage_change_fraction = 0.01;  ///< κ [-]
  std::uint64_t max_steps_per_advance = 1000000;  ///< work limit between two outputs [-]
};

/// The grid of a reversible run: the carried point of the time-transformed system (t the last
/// passive coordinate, compensated), its stage memory and turns (`Grid`: a CarriedPoint of System
/// over TimeTransformedSystem<System>, carried_point.h), and the grid point before the last step
/// (for side steps).
template <class Stepper, class System, class Grid>
class ReversibleStepControl {
 public:
  using Transformed = TimeTransformedSystem<System>;
  static constexpr int kTimeIndex = Transformed::kTimeIndex;

  ReversibleStepControl(const Stepper& stepper, const ReversibleStepSettings& settings)
      : stepper_(stepper), settings_(settings) {
    if (!(settings.fictive_step > 0.0) || !std::isfinite(settings.fictive_step)) {
      throw std::invalid_argument("reversible step control: the fictive step eps must be finite and > 0 rad");
    }
    if (!(settings.error_per_unit_step >= 0.0) || !std::isfinite(settings.error_per_unit_step)) {
      throw std::invalid_argument("reversible step control: the error per unit step must be finite and >= 0 1/s");
    }
    if (settings.max_steps_per_advance < 1) throw std::invalid_argument("reversible step control: the work limit must be >= 1");
  }

  const ReversibleStepSettings& settings() const { return settings_; }
  /// Grid time tₙ [s].
  double time() const { return grid_.point.y(kTimeIndex) + grid_.point.y_remainder(kTimeIndex); }
  Grid& grid() { return grid_; }
  const Grid& grid() const { return grid_; }
  /// A grid point without its stage memory.
  struct GridPoint {
    CompensatedPoint<Transformed> point;
    AngleTurns<System> turns{};  ///< [-]
  };
  /// The grid point before the last step, and its time [s] (the start of the step that covers any
  /// instant between them).
  const GridPoint& previous() const { return previous_; }
  double previous_time() const { return previous_.point.y(kTimeIndex) + previous_.point.y_remainder(kTimeIndex); }

  /// Starts the grid at `from` (a carried point of the untransformed system, with its turns) at
  /// time t [s]: no stage history.
  template <class Carried>
  void start(const Carried& from, double t) {
    grid_.take_point(from);
    grid_.periodic_angles = from.periodic_angles;
    grid_.point.y(kTimeIndex) = t;
    grid_.point.y_remainder(kTimeIndex) = 0.0;
    grid_.valid = true;
    grid_.memory.clear();
    fictive_time_ = 0.0;
    remember_previous();
  }

  /// One grid step (B.42) with fictive step ±ε (−ε undoes +ε) of the transformed `system`.
  /// Returns hₙ [s]. Throws StepError (the grid is then unusable: restart it).
  double grid_step(const Transformed& system, double epsilon, StepStatistics& statistics) {
    const double t = time();
    remember_previous();
    // The stage solve's stop at κ·τ·h with h ≈ ε/σ(zₙ) (B.49).
    const double density = system.step_density(StateVector<System, double>(grid_.point.z));
    grid_.memory.stage_change_limit =
        settings_.stage_change_fraction * settings_.error_per_unit_step * std::abs(epsilon) / density;
    stepper_.advance_compensated(system, grid_.point, grid_.memory, fictive_time_, epsilon, statistics);
    fictive_time_ += epsilon;
    grid_.reduce_angles();
    const double h = time() - t;
    if (!(std::abs(h) > 0.0) || !std::isfinite(h)) fail("a step of zero or non-finite length", h);
    ++statistics.internal_steps;
    statistics.internal_step_min = std::min(statistics.internal_step_min, std::abs(h));
    statistics.internal_step_max = std::max(statistics.internal_step_max, std::abs(h));
    return h;
  }

  /// Grid steps with +ε until the grid reaches or passes `t` [s], calling after_step() after each
  /// (false: stop there, the caller restarts the grid). Throws StepError beyond
  /// settings().max_steps_per_advance steps (a tolerance too tight for how fast this scene turns).
  template <class AfterStep>
  void advance_past(const Transformed& system, double t, StepStatistics& statistics, AfterStep after_step) {
    std::uint64_t steps = 0;
    while (time() < t) {
      if (++steps > settings_.max_steps_per_advance) {
        std::ostringstream message;
        message.precision(17);
        message << "reversible step control needs more than " << settings_.max_steps_per_advance
                << " internal steps (eps = " << settings_.fictive_step << " rad) to go from t = " << time()
                << " s to t = " << t << " s: a looser tolerance, or a scene that turns less fast";
        throw StepError(message.str());
      }
      grid_step(system, settings_.fictive_step, statistics);
      if (!after_step()) return;
    }
  }

 private:
  void remember_previous() {
    previous_.point = grid_.point;
    previous_.turns = grid_.turns;
  }
  [[noreturn]] void fail(const char* what, double value) const {
    std::ostringstream message;
    message.precision(17);
    message << "reversible step control: " << what << " (" << value << " s) at t = " << time() << " s";
    throw StepError(message.str());
  }

  Stepper stepper_;
  ReversibleStepSettings settings_;
  Grid grid_;
  GridPoint previous_;
  double fictive_time_ = 0.0;  ///< τ [rad]
};


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

/// A tolerance the reversible control cannot reach: the trials ask for ε below kMinFictiveStep.
class FictiveStepOutOfReach : public StepError {
 public:
  explicit FictiveStepOutOfReach(double fictive_step)
      : StepError("the tolerance would need eps = " + std::to_string(fictive_step) + " rad"),
        fictive_step_(fictive_step) {}
  double fictive_step() const { return fictive_step_; }  ///< the ε the trials asked for [rad]

 private:
  double fictive_step_;
};

/// The reversible control for an error per unit step τ [1/s] (eq. (B.48)), for any system of the
/// concept with an identity chart (docs/birkhoffian.md §11.3, eq. (B.45)).
///
/// Tolerance → ε: before the first step, trial grids from the start point. A trial takes up to
/// kTrialSteps grid steps at ε (no more than a tenth of the horizon after the fourth) and measures
/// r = maxₙ eₙ/(τ hₙ), eₙ the true local error: the member's own estimate êₙ (every step) divided by
/// its overestimate f = ê/e, measured by step doubling at every kDoublingEvery-th step and taken at
/// its smallest (ê is of order s + 2, the error of order 2s + 1). Then ε = ε_trial (½/r)^{1/p}
/// (e/h ∝ ε^p), capped at kMaxFictiveStep; from ε₀ = kFirstTrialStep, at most kMaxTrials trials,
/// repeated while ε moves by more than 1.5×; a trial whose stage solve fails is repeated at ε/4.
///
/// During the run, each grid step's ê/f (f carried to the run's ε as ε^{q−p−1}) is checked against
/// τh: a step more than kRecalibrationRatio (2×) over it — a stretch harder than the trials saw —
/// is taken back, and the grid restarts from the point before it with ε (½/r)^{1/p}: reversible again
/// from there on, ε cut for the rest of the run. The trials' and the restarts' work counts in the
/// run's statistics.
template <class Stepper, class System>
class ReversibleToleranceControl {
 public:
  using Transformed = TimeTransformedSystem<System>;
  using Grid = CarriedPoint<System, typename Stepper::template Memory<Transformed>, Transformed>;
  using Control = ReversibleStepControl<Stepper, System, Grid>;
  using GridPoint = typename Control::GridPoint;
  static constexpr int kTimeIndex = Transformed::kTimeIndex;

  static constexpr double kFirstTrialStep = 0.25;  ///< ε₀ of the first trial [rad]
  static constexpr double kMaxFictiveStep = 0.6;   ///< ε_max [rad]: at most 0.6 rad of turning a step
  static constexpr double kMinFictiveStep = 1e-6;  ///< ε_min [rad]: a tolerance below reach
  static constexpr int kTrialSteps = 16;           ///< grid steps of a trial [-]
  static constexpr int kDoublingEvery = 4;         ///< a step-doubling check every this many trial steps [-]
  static constexpr int kMaxTrials = 3;
  /// A grid step whose error per unit step exceeds the calibrated one by this much cuts ε [-].
  static constexpr double kRecalibrationRatio = 2.0;

  /// `system` (the time-transformed system) must outlive the control; τ [1/s] ≥ 0 the allowed error
  /// per second, `horizon` [s] > 0 the run's horizon (it bounds the trials' span).
  ReversibleToleranceControl(const Stepper& stepper, const Transformed& system, double error_per_unit_step,
                             double horizon)
      : stepper_(stepper), system_(&system), error_per_unit_step_(error_per_unit_step), horizon_(horizon) {
    if (!(error_per_unit_step >= 0.0) || !std::isfinite(error_per_unit_step)) {
      throw std::invalid_argument("reversible step control: the error per unit step must be finite and >= 0 1/s");
    }
    if (!(horizon > 0.0) || !std::isfinite(horizon)) {
      throw std::invalid_argument("reversible step control: the horizon must be finite and > 0 s");
    }
  }

  double error_per_unit_step() const { return error_per_unit_step_; }  ///< τ [1/s]
  const std::optional<ReversibleCalibration>& calibration() const { return calibration_; }

  /// ε for the tolerance from trial grids starting at `seed` (a carried point of System) at time t
  /// [s], their work added to `statistics`. Throws FictiveStepOutOfReach when ε would fall below
  /// kMinFictiveStep, StepError when even fine trials fail.
  template <class Seed>
  const ReversibleCalibration& calibrate(const Seed& seed, double t, StepStatistics& statistics) {
    constexpr int kExponent = Stepper::kOrder;  // e/h ∝ ε^p
    ReversibleCalibration found;
    double epsilon = kFirstTrialStep;
    for (int attempt = 0; attempt < 8 && found.trials < kMaxTrials;) {
      double span = 0.0;
      double ratio = 0.0;
      double overestimate = 1.0;
      try {
        ratio = trial(seed, t, epsilon, span, overestimate, statistics);
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
    if (!(found.fictive_step >= kMinFictiveStep)) throw FictiveStepOutOfReach(found.fictive_step);
    calibration_ = found;
    return *calibration_;
  }

  /// A grid from `seed` (a carried point of System) at time t [s] with the calibrated ε.
  template <class Seed>
  void start(const Seed& seed, double t) {
    control_ = std::make_unique<Control>(stepper_, control_settings(calibration_->fictive_step));
    control_->start(seed, t);
  }

  /// Grid steps until the grid reaches or passes t [s], calling on_grid_point() after each step it
  /// keeps; a step beyond the calibration is taken back and the grid restarts finer from the point
  /// before it (class comment). Throws StepError beyond the control's work limit or when ε would
  /// fall below kMinFictiveStep.
  template <class OnGridPoint>
  void advance_past(double t, StepStatistics& statistics, OnGridPoint on_grid_point) {
    while (control_->time() < t) {
      bool violated = false;
      control_->advance_past(*system_, t, statistics, [&] {
        if (error_ratio(statistics) > kRecalibrationRatio) {
          violated = true;
          return false;
        }
        on_grid_point();
        return true;
      });
      if (violated) restart_finer(statistics);
    }
  }

  double time() const { return control_->time(); }  ///< grid time tₙ [s]
  const Grid& grid() const { return control_->grid(); }
  /// The grid point before the last step, and its time [s].
  const GridPoint& previous() const { return control_->previous(); }
  double previous_time() const { return control_->previous_time(); }
  const Stepper& stepper() const { return stepper_; }

 private:
  ReversibleStepSettings control_settings(double epsilon) const {
    ReversibleStepSettings settings;
    settings.fictive_step = epsilon;
    settings.error_per_unit_step = error_per_unit_step_;
    return settings;
  }

  /// r = e/(τh) of the grid step just taken, e = ê/f with the overestimate f the trial measured at
  /// ε_trial carried to this ε: f ∝ ε^{q−p−1} (ê of order q, e of order p + 1).
  double error_ratio(const StepStatistics& statistics) const {
    const double h = control_->time() - control_->previous_time();
    return statistics.local_error_estimate_last_step / std::max(carried_overestimate(), 1.0) /
           (h * error_per_unit_step_);
  }
  /// f carried to the run's ε, for error_ratio(): computed again only when the calibration changed
  /// (a power at every grid step was ~3 % of a reversible run on the whirl).
  double carried_overestimate() const {
    constexpr int kOverestimateOrder = Stepper::kErrorEstimateOrder - Stepper::kOrder - 1;
    const ReversibleCalibration& now = *calibration_;
    if (now.fictive_step != carried_for_.fictive_step || now.trial_fictive_step != carried_for_.trial_fictive_step ||
        now.overestimate != carried_for_.overestimate) {
      carried_for_ = now;
      carried_overestimate_ =
          now.overestimate * deterministic::pow(now.fictive_step / now.trial_fictive_step, kOverestimateOrder);
    }
    return carried_overestimate_;
  }

  /// After a step beyond the calibration: back to the grid point before it, and on from there with
  /// the fictive step the step's own error asks for, ε (½/r)^{1/p} — a new grid.
  void restart_finer(StepStatistics& statistics) {
    calibration_->fictive_step *= deterministic::pow(0.5 / error_ratio(statistics), 1.0 / Stepper::kOrder);
    if (!(calibration_->fictive_step >= kMinFictiveStep)) {
      throw StepError("the fictive step needed past t = " + std::to_string(control_->previous_time()) +
                      " s fell below " + std::to_string(kMinFictiveStep) + " rad: a looser tolerance");
    }
    ++calibration_->reductions;
    ++statistics.rejected_steps;
    statistics.control_fictive_step = calibration_->fictive_step;
    CarriedPoint<System, NoStepMemory> seed;
    const GridPoint& previous = control_->previous();
    seed.point.z = previous.point.z;
    seed.point.z_remainder = previous.point.z_remainder;
    seed.point.y = previous.point.y.template head<System::kPassiveDimension>();
    seed.point.y_remainder = previous.point.y_remainder.template head<System::kPassiveDimension>();
    seed.turns = previous.turns;
    seed.periodic_angles = control_->grid().periodic_angles;
    const double time = control_->previous_time();
    start(seed, time);
  }

  /// The true local error of the grid step just taken from `start` (the ε step, in `grid`) by step
  /// doubling: against two ε/2 steps from the same point, e = |Φ_ε − Φ_{ε/2}²|·2^p/(2^p − 1) [-].
  double doubled_step_error(const GridPoint& start, const Grid& grid, double epsilon, StepStatistics& statistics) {
    CompensatedPoint<Transformed> halves = start.point;
    typename Stepper::template Memory<Transformed> memory;  // the halves' own (no stage history)
    stepper_.advance_compensated(*system_, halves, memory, 0.0, 0.5 * epsilon, statistics);
    stepper_.advance_compensated(*system_, halves, memory, 0.5 * epsilon, 0.5 * epsilon, statistics);
    CompensatedPoint<Transformed> whole = grid.point;
    // The grid point's angles were reduced after the step; the halves' were not.
    unreduce_angles<System>(whole, grid.turns, start.turns);
    const StateVector<Transformed, double> z_error = (whole.z + whole.z_remainder) - (halves.z + halves.z_remainder);
    const PassiveVector<Transformed, double> y_error = (whole.y + whole.y_remainder) - (halves.y + halves.y_remainder);
    const double doubling = deterministic::pow(2.0, Stepper::kOrder);
    return local_error_norm<Transformed, double>(whole.z, whole.y, z_error, y_error) * doubling / (doubling - 1.0);
  }

  /// r = maxₙ eₙ/(τ hₙ) over up to kTrialSteps grid steps from `seed` at t [s] with fictive step ε
  /// (class comment; eq. (B.45)); also the scene time the steps covered [s] and the overestimate f.
  template <class Seed>
  double trial(const Seed& seed, double t, double epsilon, double& span, double& overestimate,
               StepStatistics& counted) {
    Control control(stepper_, control_settings(epsilon));
    control.start(seed, t);
    StepStatistics statistics;
    double largest_estimate = 0.0;  // maxₙ êₙ/hₙ [1/s]
    std::vector<double> overestimates;
    // At most kTrialSteps steps, and no more than a tenth of the horizon after the first four: on a
    // short run the trial must not cost more than the run.
    const double trial_end = t + 0.1 * horizon_;  // [s]
    for (int n = 0; n < kTrialSteps; ++n) {
      const double h = control.grid_step(*system_, epsilon, statistics);
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
    span = control.time() - t;
    overestimate = 1.0;  // f: at round-off both vanish; take the estimate as it is
    if (!overestimates.empty()) {  // the smallest: the estimate's tightest moment, e = ê/f the largest
      overestimate = std::max(1.0, *std::min_element(overestimates.begin(), overestimates.end()));
    }
    return largest_estimate / overestimate / error_per_unit_step_;
  }

  Stepper stepper_;
  const Transformed* system_;
  double error_per_unit_step_;  ///< τ [1/s]
  double horizon_;              ///< [s]
  std::optional<ReversibleCalibration> calibration_;
  mutable ReversibleCalibration carried_for_;  ///< the calibration carried_overestimate_ is for
  mutable double carried_overestimate_ = 1.0;  ///< f = ê/e at its ε (carried_overestimate()) [-]
  std::unique_ptr<Control> control_;
};

}  // namespace birkhoff_cart
