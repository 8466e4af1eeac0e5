// Error-per-step control of the Birkhoffian members for forced, dissipative and stiff scenes
// (docs/birkhoffian.md §12, eqs. (B.46)–(B.49)). The member's own local error estimate ê (the
// collocation defect, eq. (B.37); a composition's sum of its sub-steps') decides each step:
//
//   accept when ê ≤ A·τ·|h|    (error per unit step)                                           (B.46)
//   h_new = h · min(α_max, max(α_min, 0.9·(τ|h|/ê)^{1/(q−1)}))   (ê ∝ h^q)                     (B.47)
//
// with τ [1/s] the error per second the estimate is aimed at, in ê's units (error_estimate.h, (A.1)):
// the adapter derives it from the position tolerance by the member's tolerance proportionality (eq. (B.53)); for the Gauss members ê includes the step's
// weighted linearised error (B.55), which sees a stiff mode a step would jump over. The growth reads the larger of the last two
// ratios ê/(τh); the accepted retry after a rejection does not grow, and while ê reads zero after a
// rejection the steps grow by at most ceiling_growth a step (birkhoffian.md §12.1). A step that is
// rejected — by the estimate, or because its stage solve did not converge, met a non-finite value
// or a singular matrix, or converged to a root whose estimate is not finite — is retried from the same point with a smaller step (a failed solve: h/4); it never
// reaches the caller. The stage solve stops at κ·τ·|h| (CollocationMemory::stage_change_limit,
// eq. (B.49)), not at round-off. A step never passes the limit it is given: the run's end, a
// landing instant, a kink of the loads (the caller passes them); it is stretched by up to 10 % to
// land on it rather than leave a sliver.
//
// The control steers ê towards 0.9^{q−1}·τ|h|. With A = 1 (the default) every accepted step meets
// τ|h|, and the estimates add up to at most τ·T; a caller whose τ is an aim rather than a bound (the
// cart's adapter, A = 2: birkhoffian.md §12.1) keeps an attempt just above it rather than take it
// again where ê swings with the motion's phase by more than the safety factor's margin.
//
// It knows no system beyond the concept (birkhoffian_system.h) and its optional traits
// (system_traits.h): the system's begin_step(t) before each attempt, its angles carried reduced in
// the grid (carried_point.h); a caller may add a plausibility check of its own for each attempt.
//
// This control is not reversible (h depends on the state at the step's start only): it is for
// scenes that are not reversible anyway. Free, reversible runs use reversible_step_control.h.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/carried_point.h"
#include "birkhoff_cart/core/integrators/compensated_summation.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

/// Settings of the error-per-step control.
struct AdaptiveStepSettings {
  double error_per_unit_step = 1e-9;  ///< τ: allowed ê per second of scene time [1/s] (eq. (B.46))
  double acceptance_ratio = 1.0;       ///< A: an attempt is kept while ê ≤ A·τ·|h| (eq. (B.46)) [-]
  double stage_change_fraction = 0.01;  ///< κ: the stage solve stops at κ·τ·|h| (eq. (B.49)) [-]
  double safety = 0.9;                 ///< factor on the predicted step [-]
  double max_growth = 4.0;             ///< α_max: largest growth of h from one step to the next [-]
  double start_growth = 100.0;         ///< α_max while the steps after a start still grow unhindered [-]
  double start_exponent_margin = 1.0;  ///< added to q − 1 in (B.47) while they do [-]
  double keep_ratio = 1.2;             ///< a step that would grow by less is kept (its Newton matrix reused) [-]
  double max_shrink = 0.2;             ///< α_min: smallest factor after a rejection [-]
  double ceiling_growth = 1.02;        ///< growth a step after a rejection while ê reads 0 [-]
  std::uint64_t max_steps_per_advance = 1000000;  ///< work limit between two limits [-]
};

/// The default plausibility check of an attempt: none.
struct AlwaysPlausible {
  template <class Point>
  bool operator()(const Point&, const Point&, double, double) const {
    return true;
  }
};

/// The error-per-step control of `Stepper` on `System` (file comment): a grid of accepted steps,
/// carried in `Carried` (a CarriedPoint, carried_point.h), with the point before the last step kept
/// for side steps. Rejected attempts count in StepStatistics::rejected_steps.
template <class Stepper, class System, class Carried>
class AdaptiveStepControl {
 public:
  AdaptiveStepControl(const Stepper& stepper, const AdaptiveStepSettings& settings)
      : stepper_(stepper), settings_(settings) {
    if (!(settings.error_per_unit_step > 0.0) || !std::isfinite(settings.error_per_unit_step)) {
      throw std::invalid_argument("adaptive step control: the error per unit step must be finite and > 0 1/s");
    }
    if (!(settings.acceptance_ratio >= 1.0) || !std::isfinite(settings.acceptance_ratio)) {
      throw std::invalid_argument("adaptive step control: the acceptance ratio must be finite and >= 1");
    }
    if (!(settings.start_exponent_margin >= 0.0) || !std::isfinite(settings.start_exponent_margin)) {
      throw std::invalid_argument("adaptive step control: the start's exponent margin must be finite and >= 0");
    }
    if (!(settings.stage_change_fraction >= 0.0) || !std::isfinite(settings.stage_change_fraction)) {
      throw std::invalid_argument("adaptive step control: the stage change fraction must be finite and >= 0");
    }
  }

  const AdaptiveStepSettings& settings() const { return settings_; }
  double time() const { return time_.value(); }  ///< grid time tₙ [s]
  /// The step the next attempt will try [s].
  double proposed_step() const { return proposed_step_; }
  Carried& grid() { return grid_; }
  const Carried& grid() const { return grid_; }
  const Stepper& stepper() const { return stepper_; }
  /// The grid point before the last accepted step, and its time [s].
  const CompensatedPoint<System>& previous() const { return previous_; }
  double previous_time() const { return previous_time_; }
  /// The turns of its angles [-] (carried_point.h).
  const AngleTurns<System>& previous_turns() const { return previous_turns_; }

  /// Starts the grid at the carried point of `from` (its point and turns; not its stage history) at
  /// time t [s], with the first step `first_step` [s] (> 0).
  void start(const Carried& from, double t, double first_step) {
    grid_.point = from.point;
    grid_.turns = from.turns;
    grid_.periodic_angles = from.periodic_angles;
    grid_.valid = from.valid;
    grid_.memory.clear();
    time_.set(t);
    previous_ = grid_.point;
    previous_time_ = t;
    previous_turns_ = grid_.turns;
    proposed_step_ = first_step;
    last_error_ratio_ = 0.0;
    last_step_ = 0.0;
    ramping_ = true;
    ceiling_ = std::numeric_limits<double>::infinity();
    after_rejection_ = false;
  }

  /// After a kink of the loads at the grid's time: the stage derivatives before it do not extrapolate.
  void forget_stage_history() { grid_.memory.forget_stage_history(); }

  /// One accepted step that ends at or before `limit` [s] (exactly on it when the step reaches it;
  /// +inf: no limit),
  /// after as many rejected attempts as it takes. Returns the step taken [s]. Throws StepError
  /// when the step size underflows (a singularity, or a tolerance the member cannot reach there).
  ///
  /// `plausible(before, after, t, h)` (two CompensatedPoints, and the step's start time and size [s]),
  /// a predicate the caller supplies, may reject an attempt the estimate accepted — one whose physics
  /// is broken (the cart's energy balance: a spurious root of the stage equations; the estimate
  /// vanishes on linear dynamics).
  ///
  /// `system`: a System, const when it has no begin_step (system_traits.h).
  template <class SystemRef, class Plausible = AlwaysPlausible>
  double step(SystemRef& system, double limit, StepStatistics& statistics, Plausible plausible = {}) {
    static_assert(std::is_same_v<std::remove_const_t<SystemRef>, System>, "the control's own system type");
    const double remaining = time_.until(limit);  // [s]; +inf: no limit
    if (!(remaining > 0.0)) throw std::logic_error("adaptive step control: the limit is not ahead of the grid");
    for (int attempt = 0;; ++attempt) {
      double h = proposed_step_;
      const bool lands = h >= remaining / 1.1;  // stretch by up to 10 % rather than leave a sliver
      if (lands) h = remaining;
      const double smallest = 64.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(time()));
      if (!(h > smallest)) fail("the step size fell below round-off of the time", h);
      if (attempt >= kMaxAttempts) fail("rejected every attempt", h);

      const CompensatedPoint<System> saved_point = grid_.point;
      const auto saved_history = grid_.memory.history();
      StepStatistics trial;
      grid_.memory.stage_change_limit = settings_.stage_change_fraction * settings_.error_per_unit_step * h;
      grid_.memory.linear_mode_error = true;  // ê sees a stiff mode the step would jump over (B.55)
      bool solved = true;
      try {
        system_traits::begin_step(system, time());
        stepper_.advance_compensated(system, grid_.point, grid_.memory, time(), h, trial);
      } catch (const StepError&) {
        solved = false;
      }
      const double estimate = trial.local_error_estimate_last_step;  // ê [-]
      const double allowed = settings_.error_per_unit_step * h;      // τ·h [-]
      // ê below its round-off floor says only "no error seen": at tiny steps it would otherwise
      // read as an error per unit step that grows as h shrinks, and hold the steps there.
      const double ratio = std::max(estimate - kEstimateRoundOff, 0.0) / allowed;  // ≤ A: accept (B.46)
      add_work(statistics, trial);
      if (!solved || !finite_point() || !(ratio <= settings_.acceptance_ratio) || !plausible(saved_point, grid_.point, time(), h)) {
        grid_.point = saved_point;
        grid_.memory.restore(saved_history);
        ++statistics.rejected_steps;
        ramping_ = false;
        const double factor = solved && std::isfinite(ratio) ? shrink_factor(ratio) : 0.25;
        proposed_step_ = h * factor;
        ceiling_ = proposed_step_;
        after_rejection_ = true;
        continue;
      }
      previous_ = saved_point;
      previous_turns_ = grid_.turns;
      previous_time_ = time();
      grid_.reduce_angles();
      if (lands) {
        time_.set(limit);
      } else {
        time_.add(h);
      }
      record_local_error_estimate(statistics, estimate);
      statistics.newton_iterations_last_step += trial.newton_iterations_total;
      ++statistics.internal_steps;
      statistics.internal_step_min = std::min(statistics.internal_step_min, h);
      statistics.internal_step_max = std::max(statistics.internal_step_max, h);
      // A landing step was cut to fit: the step after it is the one the controller wanted.
      // Growth from the larger of this step's and the last step's ratio: where ê swings with the phase
      // of a fast oscillation (the stiff hinge's 400 rad/s), one low reading does not invite a step
      // the next phase rejects.
      const double growth_ratio = std::max(ratio, lands ? 0.0 : last_error_ratio_);
      // Gustafsson's predictive term (as RADAU5): where ê/h grows from step to step, shrink ahead
      // of the rejection that would follow: h/h₋ · (r₋/r)^{1/k} · r^{-1/k}.
      const bool predicts = last_error_ratio_ > 0.0 && ratio > 0.0 && last_step_ > 0.0 && !lands;
      // Both powers from one call (pow_pair: the bits of two pow calls, at about the price of one).
      std::array<double, 2> powers{0.0, 0.0};
      if (growth_ratio > 0.0 || predicts) {
        powers = deterministic::pow_pair({growth_ratio > 0.0 ? growth_ratio : 1.0,
                                          predicts ? last_error_ratio_ / (ratio * ratio) : 1.0},
                                         {-1.0 / growth_exponent(), 1.0 / kExponentOrder});
      }
      double factor = growth_factor(growth_ratio, powers[0]);
      if (predicts) {
        const double predictive = settings_.safety * (h / last_step_) * powers[1];
        factor = std::min(factor, std::max(settings_.max_shrink, predictive));
      }
      // After a rejection (Hairer–Nørsett–Wanner I §II.4): the accepted retry does not grow; and while
      // the steps' estimates stay below their round-off floor (ratio 0: no error seen, no prediction)
      // they grow from the retry's size by at most ceiling_growth a step instead of max_growth (on the
      // very stiff hinge at 1e-9 m a 4× growth from "no error seen" is rejected at ê ≈ 500 τh and
      // retried 4× smaller: every other step). An estimate above its floor predicts again.
      if (after_rejection_) factor = std::min(factor, 1.0);
      if (ratio > 0.0) {
        ceiling_ = std::numeric_limits<double>::infinity();
      } else if (!lands) {
        ceiling_ *= settings_.ceiling_growth;
        factor = std::min(factor, std::max(1.0, ceiling_ / h));
      }
      after_rejection_ = false;
      // A step that would grow by less than keep_ratio stays as it is: its Newton matrix is cached
      // by h (RADAU5's rule, Hairer–Wanner II §IV.8); on the stiff hinge this saved 10–15 %.
      if (!lands && factor >= 1.0 && factor <= settings_.keep_ratio) factor = 1.0;
      const double next = h * factor;
      proposed_step_ = lands ? std::max(next, proposed_step_) : next;
      last_error_ratio_ = ratio;
      last_step_ = h;
      return h;
    }
  }

  /// Steps until the grid reaches `limit` exactly [s]. Throws StepError beyond
  /// settings().max_steps_per_advance steps.
  template <class SystemRef>
  void advance_to(SystemRef& system, double limit, StepStatistics& statistics) {
    std::uint64_t steps = 0;
    while (time() < limit) {
      if (++steps > settings_.max_steps_per_advance) {
        std::ostringstream message;
        message.precision(17);
        message << "adaptive step control needs more than " << settings_.max_steps_per_advance
                << " steps to go from t = " << time() << " s to t = " << limit << " s: a looser tolerance";
        throw StepError(message.str());
      }
      step(system, limit, statistics);
    }
  }

 private:
  static constexpr int kMaxAttempts = 60;  ///< rejections in a row before giving up (each cuts h to 0.2–0.9 of itself; a failed solve to 0.25)
  /// The round-off floor of ê, a weighted norm relative above 1 SI unit: 64 ε [-].
  static constexpr double kEstimateRoundOff = 64.0 * std::numeric_limits<double>::epsilon();
  static constexpr int kExponentOrder = Stepper::kErrorEstimateOrder - 1;  ///< ê/h ∝ h^{q−1}

  double shrink_factor(double ratio) const {
    return std::max(settings_.max_shrink, settings_.safety * deterministic::pow(ratio, -1.0 / kExponentOrder));
  }
  /// The exponent the growth reads ê/h with: q − 1, plus the margin while the start ramps [-].
  double growth_exponent() const {
    return kExponentOrder + (ramping_ ? settings_.start_exponent_margin : 0.0);
  }
  /// After a start the first guess may be far too small: the steps then grow by up to
  /// start_growth until the first rejection or the first step the control would not grow freely.
  /// While they do, the growth reads ê/h ∝ h^{q−1+m} (m = start_exponent_margin): a growth of 10–40×
  /// reaches steps where ê has left its asymptotic range and grows faster than h^{q−1} (the shipped
  /// scenes' start ramps: up to q − 1 + 1.9 between two readings), and the step after the ramp was
  /// rejected at 20–600 times its aim.
  /// `power` = ratio^{−1/growth_exponent()}, computed by the caller (with the predictive term's).
  double growth_factor(double ratio, double power) {
    const double cap = ramping_ ? settings_.start_growth : settings_.max_growth;
    const double wanted = ratio > 0.0 ? settings_.safety * power
                                      : std::numeric_limits<double>::infinity();  // ê = 0: grow at once
    if (wanted < settings_.max_growth) ramping_ = false;
    return std::min(cap, std::max(settings_.max_shrink, wanted));
  }
  bool finite_point() const { return grid_.point.z.allFinite() && grid_.point.y.allFinite(); }
  /// The work of an attempt counts whether it was accepted or not; its estimate only if accepted.
  static void add_work(StepStatistics& into, const StepStatistics& trial) {
    into.rhs_evaluations += trial.rhs_evaluations;
    into.passive_evaluations += trial.passive_evaluations;
    into.newton_iterations_total += trial.newton_iterations_total;
  }
  [[noreturn]] void fail(const char* what, double h) const {
    std::ostringstream message;
    message.precision(17);
    message << "adaptive step control: " << what << " (h = " << h << " s) at t = " << time()
            << " s (a singular point, or a tolerance out of reach there)";
    throw StepError(message.str());
  }

  Stepper stepper_;
  AdaptiveStepSettings settings_;
  Carried grid_;
  CompensatedTime time_;         ///< tₙ [s]
  CompensatedPoint<System> previous_;      ///< the point before the last accepted step
  double previous_time_ = 0.0;             ///< [s]
  AngleTurns<System> previous_turns_{};  ///< its turns [-]
  double proposed_step_ = 0.0;   ///< the next attempt's h [s]
  double last_error_ratio_ = 0.0;  ///< ê/(τh) of the last accepted step [-]
  bool ramping_ = false;           ///< the steps after a start are still growing unhindered
  double last_step_ = 0.0;         ///< h of the last accepted step [s]
  double ceiling_ = std::numeric_limits<double>::infinity();  ///< growth bound while ê reads 0 [s]
  bool after_rejection_ = false;   ///< the attempt now running follows a rejected one
};

}  // namespace birkhoff_cart
