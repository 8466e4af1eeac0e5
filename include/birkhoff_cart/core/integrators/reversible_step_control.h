// Reversible adaptive step size for the symmetric Birkhoffian members (docs/birkhoffian.md §11,
// eqs. (B.41)–(B.44)): Hairer & Söderlind's explicit, time-reversible step-size control (SIAM J. Sci.
// Comput. 26 (2005) 1838–1851; GNI §VIII.3.2). With a step density σ(z, t) > 0 [1/s] (how fast the
// motion turns; the system's monitor, at least σ₀), the step is h = ε/ρ where the control variable
// ρ follows σ along the solution:
//
//   ρₙ₊½ = ρₙ + (ε/2) G(zₙ, tₙ)                                                          (B.41)
//   hₙ = ε/ρₙ₊½,   (zₙ₊₁, yₙ₊₁) = Φ_{hₙ}(zₙ, yₙ),   tₙ₊₁ = tₙ + hₙ                         (B.42)
//   ρₙ₊₁ = ρₙ₊½ + (ε/2) G(zₙ₊₁, tₙ₊₁),    G = σ̇/σ = (∂σ/∂w · ẇ + ∂σ/∂t) / σ              (B.43)
//
// In the fictive time τ (dt/dτ = 1/ρ), dρ/dτ = G makes d(ρ/σ)/dt = 0: ρ keeps its ratio to σ (the
// two half-updates are a trapezoidal rule in τ). A first version updated log ρ by εσ̇/σ² so that ρ
// could not turn negative; that makes ρ/σ unstable (d log(ρ/σ)/dt = (σ̇/σ)(ρ/σ − 1)) and on the
// stiff_hinge scene the steps shrank without end. Here ρ ≤ 0 is a StepError that names it (a smaller
// ε, i.e. a tighter tolerance, keeps ρ > 0). Φ is one step of a symmetric member (Gauss collocation
// or a symmetric composition), so the map (ρₙ, zₙ, yₙ, tₙ) ↦ (ρₙ₊₁, zₙ₊₁, yₙ₊₁, tₙ₊₁) is symmetric:
// the same map with −ε undoes it (each half-update of ρ uses the state at its own end, and h
// depends on ρₙ₊½ alone). ε [rad] is the fictive-time step: the angle the motion turns in one step.
// Reversibility holds for any σ; σ only decides where the steps go.
//
// G needs the derivative of σ along the flow: one evaluation of ẇ and one of σ on dual numbers
// (forward-mode AD along ẇ), once per step (the G at the end of a step is the next step's first).
//
// Steps land on output instants without disturbing the grid: advance_to(t) takes the grid steps
// that end at or before t, then the state at t itself comes from one extra step of Φ from the last
// grid point (a side step, with a copy of the stage history): the grid, and with it the long-time
// behaviour, does not depend on when the caller asks.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>

#include "birkhoff_cart/core/autodiff.h"
#include "birkhoff_cart/core/diagnostics.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"

namespace birkhoff_cart {

/// Settings of the reversible controller.
struct ReversibleStepSettings {
  double fictive_step = 0.05;   ///< ε [rad]: the angle the motion turns per step (σ·h ≈ ε)
  double density_floor = 1.0;   ///< σ₀ [1/s]: the slowest rate resolved (σ ≥ σ₀, so h ≤ ε/σ₀)
  std::uint64_t max_steps_per_advance = 1000000;  ///< work limit of advance_grid_to [-]
};

/// The grid of a reversible adaptive run: the carried point, its stage history, ρ, and t as hi + lo.
/// `Carried` is CarriedCartState<System, Memory> or any type with `point`, `memory` and
/// reduce_angles().
template <class Stepper, class System, class Carried>
class ReversibleStepControl {
 public:
  ReversibleStepControl(const Stepper& stepper, const ReversibleStepSettings& settings)
      : stepper_(stepper), settings_(settings) {
    if (!(settings.fictive_step > 0.0) || !std::isfinite(settings.fictive_step)) {
      throw std::invalid_argument("reversible step control: fictive step ε must be finite and > 0 rad");
    }
    if (settings.max_steps_per_advance < 1) throw std::invalid_argument("reversible step control: the work limit must be >= 1");
    if (!(settings.density_floor > 0.0) || !std::isfinite(settings.density_floor)) {
      throw std::invalid_argument("reversible step control: the step density floor must be finite and > 0 1/s");
    }
  }

  const ReversibleStepSettings& settings() const { return settings_; }
  double time() const { return time_ + time_low_; }  ///< grid time tₙ [s]
  double control() const { return rho_; }  ///< ρₙ [1/s]
  Carried& grid() { return grid_; }
  const Carried& grid() const { return grid_; }

  /// Starts the grid at the carried point of `grid` (already set up by the caller; its stage
  /// history is not taken) at time t [s]: ρ₀ = σ(z₀, t₀).
  void start(System& system, const Carried& grid, double t, StepStatistics& statistics) {
    grid_.point = grid.point;
    grid_.steering_turns = grid.steering_turns;
    grid_.heading_turns = grid.heading_turns;
    grid_.periodic_in_steering_angle = grid.periodic_in_steering_angle;
    grid_.valid = grid.valid;
    grid_.memory.clear();
    time_ = t;
    time_low_ = 0.0;
    system.begin_step(t);
    double derivative = 0.0;
    const double sigma = step_density(system, t, derivative, statistics);
    rho_ = sigma;
    log_rate_ = derivative / sigma;
  }

  /// The step the grid would take next with fictive step `epsilon` (±ε) [s].
  double next_step(double epsilon) const { return step_for(epsilon, rho_ + 0.5 * epsilon * log_rate_); }

  /// One grid step (B.41)–(B.43) with fictive step ±ε (−ε undoes +ε). Returns h [s]. Throws StepError.
  double grid_step(System& system, double epsilon, StepStatistics& statistics) {
    const double rho_half = rho_ + 0.5 * epsilon * log_rate_;
    if (!(rho_half > 0.0) || !std::isfinite(rho_half)) fail("the step-size control variable ρ left (0, ∞)", rho_half);
    const double h = step_for(epsilon, rho_half);
    const double t = time();
    system.begin_step(t);
    stepper_.advance_compensated(system, grid_.point, grid_.memory, t, h, statistics);
    grid_.reduce_angles();
    collocation_detail::two_sum(time_, h, time_, time_low_add_);
    time_low_ += time_low_add_;
    renormalize_time();
    double derivative = 0.0;
    const double sigma = step_density(system, time(), derivative, statistics);
    log_rate_ = derivative / sigma;
    rho_ = rho_half + 0.5 * epsilon * log_rate_;
    ++statistics.internal_steps;
    const double size = std::abs(h);
    statistics.internal_step_min = std::min(statistics.internal_step_min, size);
    statistics.internal_step_max = std::max(statistics.internal_step_max, size);
    return h;
  }

  /// Grid steps while the next one ends at or before `t` [s] (forward) — the grid never passes t.
  /// Throws StepError beyond settings().max_steps_per_advance steps (a tolerance too tight for
  /// how fast this scene turns).
  void advance_grid_to(System& system, double t, StepStatistics& statistics) {
    const double epsilon = settings_.fictive_step;
    std::uint64_t steps = 0;
    while (time() + next_step(epsilon) <= t) {
      if (++steps > settings_.max_steps_per_advance) {
        std::ostringstream message;
        message.precision(17);
        message << "reversible step control needs more than " << settings_.max_steps_per_advance
                << " internal steps (eps = " << epsilon << " rad) to go from t = " << time() << " s to t = " << t
                << " s: a looser tolerance, or a scene that turns less fast";
        throw StepError(message.str());
      }
      grid_step(system, epsilon, statistics);
    }
  }

  /// The carried point at `t` ≥ time() [s] in `out`: the grid point itself when t is on it, else one
  /// side step of Φ from the grid point with a copy of the stage history (the grid is untouched).
  void side_step_to(System& system, double t, Carried& out, StepStatistics& statistics) const {
    out.point = grid_.point;
    out.steering_turns = grid_.steering_turns;
    out.heading_turns = grid_.heading_turns;
    out.periodic_in_steering_angle = grid_.periodic_in_steering_angle;
    out.valid = grid_.valid;
    const double delta = (t - time_) - time_low_;  // t − tₙ [s]
    if (delta == 0.0) return;
    out.memory.copy_history_from(grid_.memory);
    system.begin_step(time());
    stepper_.advance_compensated(system, out.point, out.memory, time(), delta, statistics);
    out.reduce_angles();
  }

 private:
  /// hₙ = ε/ρₙ₊½: a function of ρₙ₊½ alone, so −ε retraces +ε (B.42). (A cap h_max was tried: where
  /// it binds, h stops scaling with ε and the pilots' error model breaks — runs ended 3×
  /// over their tolerance with max_step 5 ms; σ ≥ σ₀ bounds h by ε/σ₀ instead.)
  double step_for(double epsilon, double rho_half) const { return epsilon / rho_half; }

  void renormalize_time() {
    const double sum = time_ + time_low_;
    time_low_ = time_low_ - (sum - time_);
    time_ = sum;
  }

  /// σ(z, t) and dσ/dt along the flow [1/s, 1/s²] (B.43); the system gives σ² (B.44).
  double step_density(System& system, double t, double& derivative, StepStatistics& statistics) const {
    using Dual = Jet<1>;
    using W = StateVector<System, double>;
    const W z = grid_.point.z + grid_.point.z_remainder;
    const W w = system.to_darboux(z, t);
    // ẇ at the grid point: the step's own F(w⁺, tₙ₊₁) when its local error estimate left one there
    // (first same as last), else one evaluation.
    W rate;
    if (grid_.memory.end_rate_belongs_to(w, t)) {
      rate = grid_.memory.end_rate;
    } else {
      rate = system.darboux_rates(w, t);
      ++statistics.rhs_evaluations;
    }
    StateVector<System, Dual> w_dual;
    for (int k = 0; k < System::kDimension; ++k) {
      w_dual(k) = Dual(w(k), Eigen::Matrix<double, 1, 1>(rate(k)));
    }
    const Dual t_dual(t, Eigen::Matrix<double, 1, 1>(1.0));
    const Dual sigma_squared =
        system.squared_step_density(system.from_darboux(w_dual, t_dual), t_dual, settings_.density_floor);
    ++statistics.rhs_evaluations;  // the monitor on dual numbers costs about one rhs
    const double sigma = std::sqrt(sigma_squared.value());
    double squared_rate = sigma_squared.derivatives()(0);  // dσ²/dt along the flow [1/s³]
    if (system.depends_on_time()) {
      // The loads' explicit time dependence (AD does not differentiate t through an effect):
      // ∂σ²/∂t by a central difference at the same z — a function of (z, t), so still reversible.
      const StateVector<System, double> z_here = system.from_darboux(w, t);
      const double dt = 1e-6 * std::max(1.0, std::abs(t));
      squared_rate += (system.squared_step_density(z_here, t + dt, settings_.density_floor) -
                       system.squared_step_density(z_here, t - dt, settings_.density_floor)) /
                      (2.0 * dt);
      statistics.rhs_evaluations += 2;
    }
    derivative = 0.5 * squared_rate / sigma;
    if (!std::isfinite(sigma) || !std::isfinite(derivative)) fail("met a non-finite step density σ", sigma);
    return sigma;
  }
  [[noreturn]] void fail(const char* what, double value) const {
    std::ostringstream message;
    message.precision(17);
    message << "reversible step control " << what << " (" << value << ") at t = " << time()
            << " s (a tighter tolerance, i.e. a smaller eps, keeps it inside)";
    throw StepError(message.str());
  }

  Stepper stepper_;
  ReversibleStepSettings settings_;
  Carried grid_;
  double time_ = 0.0;      ///< tₙ, high part [s]
  double time_low_ = 0.0;  ///< tₙ, low part [s]
  double time_low_add_ = 0.0;
  double rho_ = 1.0;       ///< ρₙ [1/s]
  double log_rate_ = 0.0;  ///< G(zₙ, tₙ) = σ̇/σ [1/s]
};

}  // namespace birkhoff_cart
