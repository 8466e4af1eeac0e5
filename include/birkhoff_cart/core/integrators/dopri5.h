// Adaptive Dormand–Prince 5(4) ("dopri5") from Boost.Odeint, used as a tolerance-controlled
// reference peer. Scheme: the embedded explicit Runge–Kutta pair of Dormand & Prince (1980),
// 7 stages, FSAL, 5th-order solution with a 4th-order error estimate (Hairer–Nørsett–Wanner I,
// Table II.5.2); step-size control by odeint's controlled_runge_kutta with the error checker
//
//   err = max_i |x̂_i − x_i| / (ε_abs + ε_rel (|x_i| + h |ẋ_i|)),   accept if err ≤ 1,
//
// with ε_abs = ε_rel = IntegratorSettings::tolerance. It integrates the joint system
// (ż, ẏ) = (K(z,t)⁻¹(∇B + ∂R/∂t + Λ), g(z, y, t)) over each simulator step [t, t + h] with
// odeint's integrate_adaptive (the last internal step is shortened to land on t + h exactly).
//
// Determinism: the internal step-size guess is carried from one simulator step to the next (the
// last internal step the controller chose freely, i.e. not shortened to land on t + h); a fresh
// odeint stepper is made for every simulator step, so its first-same-as-last cache never holds a
// rate from before a command change or a reset. Same inputs ⇒ bit-identical outputs.
// Double precision only (odeint's controller is not meant to be differentiated).
//
// Error estimate (error_estimate.h): the pair's own x̂ − x (5th minus embedded 4th order) of each
// accepted internal step, in the weighted norm ê of StepStatistics; a simulator step records the
// sum over its internal steps (propagation ignored). It estimates the 4th-order solution's error
// while the 5th-order one is propagated (local extrapolation), so it is an upper estimate.
//
// Work limits (a tolerance or a time where the controller cannot make progress must end in a named
// error, not in a run that never ends):
//   - tolerance ≥ kMinTolerance = 10 ε (ε = 2.2e-16, machine epsilon), the floor of Hairer's DOPRI5
//     ("RTOL > 10·UROUND"): below it the error estimate is round-off and the controller shrinks the
//     step without end (10 ms of scene time took 10.7 s at 1e-24, > 30 s at 1e-25). Refused by the
//     constructor (std::invalid_argument), i.e. when the Simulation is built.
//   - at most max_internal_steps accepted internal steps per simulator step (default
//     kMaxInternalSteps = 100000, DOPRI5's NMAX): more ends the step with a StepError naming the
//     limit. This also bounds the case where the internal step falls below the spacing of doubles
//     at t (t + dt = t: odeint would loop for ever).
//   - odeint gives up after 500 rejected trial steps in a row with boost::numeric::odeint::
//     step_adjustment_error (a std::runtime_error; no_progress_error likewise): caught and
//     rethrown as a StepError that names it.
#pragma once

#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/odeint_step_adjuster.h"

namespace birkhoff_cart {

namespace dopri5_detail {

/// odeint's default error checker that first notes ê of the raw error vector x̂ − x (before the
/// default checker overwrites it with the tolerance-scaled one) in *trial_estimate, in the norm of
/// every integrator (error_estimate.h, (A.1)): the components from `passive_from` on are passive
/// coordinates, measured absolutely.
///
/// `passive_absolute`: the step is also accepted on that norm's split — the passive components by
/// |x̂ᵢ − xᵢ| ≤ ε_abs, the others by odeint's ε_abs + ε_rel (|xᵢ| + |h ẋᵢ|) — instead of odeint's
/// relative measure of every component (the adaptive control's position tolerance is absolute:
/// docs/accuracy.md §4.4).
template <class Value, class Algebra, class Operations>
class NotingErrorChecker {
 public:
  using value_type = Value;
  using algebra_type = Algebra;
  using operations_type = Operations;
  using Default = boost::numeric::odeint::default_error_checker<Value, Algebra, Operations>;

  NotingErrorChecker(Value eps_abs, Value eps_rel, double* trial_estimate, std::size_t passive_from,
                     bool passive_absolute = false)
      : default_(eps_abs, eps_rel), eps_abs_(eps_abs), eps_rel_(eps_rel), trial_estimate_(trial_estimate),
        passive_from_(passive_from), passive_absolute_(passive_absolute) {}

  template <class State, class Deriv, class Err, class Time>
  Value error(Algebra& algebra, const State& x_old, const Deriv& dxdt_old, Err& x_err, Time dt) const {
    double estimate = 0.0;  // ê = max(maxᵢ |x̂ᵢ − xᵢ| / max(1, |xᵢ(tₖ)|) over z, maxⱼ |x̂ⱼ − xⱼ| over y)
    for (std::size_t i = 0; i < x_err.size(); ++i) {
      const double weight = i < passive_from_ ? std::max(1.0, std::abs(x_old[i])) : 1.0;
      const double component = std::abs(x_err[i]) / weight;
      estimate = std::isnan(component) ? component : std::max(estimate, component);
      if (std::isnan(estimate)) break;
    }
    *trial_estimate_ = estimate;
    if (!passive_absolute_) return default_.error(algebra, x_old, dxdt_old, x_err, dt);
    Value error = 0;
    for (std::size_t i = 0; i < x_err.size(); ++i) {
      const Value scale = i < passive_from_ ? std::abs(x_old[i]) + std::abs(dt * dxdt_old[i]) : Value(0);
      const Value component = std::abs(x_err[i]) / (eps_abs_ + eps_rel_ * scale);
      error = std::isnan(component) ? component : std::max(error, component);
      if (std::isnan(error)) break;
    }
    return error;
  }
  template <class State, class Deriv, class Err, class Time>
  Value error(const State& x_old, const Deriv& dxdt_old, Err& x_err, Time dt) const {
    Algebra algebra;
    return error(algebra, x_old, dxdt_old, x_err, dt);
  }

 private:
  Default default_;
  Value eps_abs_;
  Value eps_rel_;
  double* trial_estimate_;
  std::size_t passive_from_;  ///< the first passive component
  bool passive_absolute_;
};

}  // namespace dopri5_detail

class DormandPrince5 {
 public:
  static constexpr int kOrder = 5;
  static constexpr bool kSymmetric = false;
  static const char* name() { return "dopri5"; }
  /// Most accepted internal steps over one simulator step [t, t + h]. Near a singularity (the
  /// paper's case at χ → kπ) the controller's steps shrink without end and the run would hang;
  /// past this count the step fails with a StepError instead (found by the randomized hard cases).
  static constexpr std::uint64_t kMaxInternalSteps = 100000;  // (DOPRI5's NMAX)
  /// The smallest tolerance accepted: 10 machine epsilons (≈ 2.2e-15) [-].
  static constexpr double kMinTolerance = 10.0 * std::numeric_limits<double>::epsilon();

  /// `tolerance`: absolute and relative error tolerance per internal step [-], finite, ≥ kMinTolerance.
  /// `max_internal_steps`: accepted internal steps allowed per simulator step [-], ≥ 1.
  explicit DormandPrince5(double tolerance = 1e-10, std::uint64_t max_internal_steps = kMaxInternalSteps)
      : tolerance_(tolerance), max_internal_steps_(max_internal_steps) {
    if (!(tolerance >= kMinTolerance) || !std::isfinite(tolerance)) {
      std::ostringstream message;
      message << "dopri5 tolerance must be finite and >= " << kMinTolerance
              << " (10 machine epsilons: below it the error estimate is round-off and the step size "
                 "shrinks without end), got "
              << tolerance;
      throw std::invalid_argument(message.str());
    }
    if (max_internal_steps < 1) throw std::invalid_argument("dopri5 max_internal_steps must be >= 1");
  }

  double tolerance() const { return tolerance_; }
  std::uint64_t max_internal_steps() const { return max_internal_steps_; }
  /// The magnitude of the internal step-size guess for the next simulator step [s] (0: none yet, use h).
  double step_size_guess() const { return step_size_guess_; }
  /// Forget the step-size guess (the next step starts from h, as after construction).
  void reset() { step_size_guess_ = 0.0; }

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    static_assert(std::is_same<S, double>::value, "dopri5 integrates in double precision only");
    constexpr int n = System::kDimension;
    constexpr int m = System::kPassiveDimension;
    using Joint = std::array<double, n + m>;
    namespace odeint = boost::numeric::odeint;

    Joint x;
    for (int i = 0; i < n; ++i) x[i] = z(i);
    for (int i = 0; i < m; ++i) x[n + i] = y(i);

    std::uint64_t evaluations = 0;
    auto rates = [&system, &evaluations](const Joint& state, Joint& state_rate, double time) {
      StateVector<System, double> z_now;
      PassiveVector<System, double> y_now;
      for (int i = 0; i < n; ++i) z_now(i) = state[i];
      for (int i = 0; i < m; ++i) y_now(i) = state[n + i];
      const StateVector<System, double> z_rate = birkhoffian_rates(system, z_now, time);               // ż = f(z, t)
      const PassiveVector<System, double> y_rate = passive_coordinate_rates(system, z_now, y_now, time);  // ẏ = g(z, y, t)
      for (int i = 0; i < n; ++i) state_rate[i] = z_rate(i);
      for (int i = 0; i < m; ++i) state_rate[n + i] = y_rate(i);
      ++evaluations;
    };

    // Internal step times, to carry the controller's last free choice to the next simulator step.
    // odeint calls the observer once per loop turn (before each internal step and at the end), so
    // counting its calls bounds the work even when t + dt = t.
    double previous_time = t;
    double last_free_step = 0.0;
    const double end_time = t + h;
    double trial_estimate = 0.0;  // ê of the latest trial internal step [-]
    double step_estimate = 0.0;   // Σ ê over the accepted internal steps of [t, t + h] [-]
    std::uint64_t internal_steps = 0;
    struct TooManySteps {};
    double last_taken = 0.0;  // [s]
    std::uint64_t observer_calls = 0;
    struct WorkLimitReached {};
    auto observer = [&](const Joint&, double time) {
      if (time != t && ++internal_steps > max_internal_steps_) throw TooManySteps{};
      const double taken = time - previous_time;
      if (time != t && time != end_time) last_free_step = taken;  // not shortened to hit t + h
      if (time != t) step_estimate += trial_estimate;  // the observer sees accepted steps only
      if (time != t) last_taken = taken;
      previous_time = time;
      if (++observer_calls > max_internal_steps_ + 1) throw WorkLimitReached{};
    };
    const auto fail = [&](const std::string& why) {
      statistics.rhs_evaluations += evaluations;
      std::ostringstream message;
      message.precision(17);
      message << "dopri5 failed in the step from t = " << t << " s to " << end_time << " s (h = " << h
              << " s, tolerance " << tolerance_ << "): " << why;
      throw StepError(message.str());
    };

    using Dopri5 = odeint::runge_kutta_dopri5<Joint>;
    using Checker = dopri5_detail::NotingErrorChecker<double, typename Dopri5::algebra_type,
                                                      typename Dopri5::operations_type>;
    DeterministicControlled<Dopri5, Checker> controlled(Checker(tolerance_, tolerance_, &trial_estimate, n));
    // First internal step: the carried guess (a magnitude), with the sign of h (h < 0 runs backwards).
    const double first_guess = step_size_guess_ > 0.0 ? std::copysign(step_size_guess_, h) : h;
    try {
      // x(t + h) ← adaptive dopri5 steps over [t, t + h]
      odeint::integrate_adaptive(controlled, rates, x, t, end_time, first_guess, observer);
    } catch (const TooManySteps&) {
      statistics.rhs_evaluations += evaluations;
      std::ostringstream message;
      message.precision(17);
      message << "dopri5 needed more than max_internal_steps = " << max_internal_steps_ << " internal steps from t = " << t
              << " s to " << end_time << " s (stalled at t = " << previous_time << " s; tolerance " << tolerance_
              << "): the solution is singular or too stiff there";
      throw StepError(message.str());
    } catch (const WorkLimitReached&) {
      std::ostringstream why;
      why.precision(17);
      why << "more than max_internal_steps = " << max_internal_steps_
          << " internal steps (work limit): reached t = " << previous_time << " s with internal steps of "
          << last_taken << " s";
      fail(why.str());
    } catch (const odeint::step_adjustment_error& error) {  // 500 rejected trial steps in a row
      fail(std::string("odeint step_adjustment_error (no acceptable step size): ") + error.what());
    } catch (const odeint::odeint_error& error) {  // e.g. no_progress_error
      fail(std::string("odeint error: ") + error.what());
    }
    statistics.rhs_evaluations += evaluations;
    record_local_error_estimate(statistics, step_estimate);

    for (int i = 0; i < n; ++i) z(i) = x[i];
    for (int i = 0; i < m; ++i) y(i) = x[n + i];
    if (last_free_step != 0.0) step_size_guess_ = std::abs(last_free_step);
    else if (step_size_guess_ <= 0.0) step_size_guess_ = std::abs(h);
  }

 private:
  double tolerance_;
  std::uint64_t max_internal_steps_;
  mutable double step_size_guess_ = 0.0;  ///< [s]; mutable: step() is const in the stepper concept
};

}  // namespace birkhoff_cart
