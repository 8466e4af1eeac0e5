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
// untransformed member from the grid point before them (reversible_cart_stepper.h).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/compensated_summation.h"
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
/// passive coordinate, compensated), its stage memory and turns (`Grid`: a CarriedCartState over
/// TimeTransformedSystem<System>), and the grid point before the last step (for side steps).
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
    double steering_turns = 0.0;  ///< [-]
    double heading_turns = 0.0;   ///< [-]
  };
  /// The grid point before the last step, and its time [s] (the start of the step that covers any
  /// instant between them).
  const GridPoint& previous() const { return previous_; }
  double previous_time() const { return previous_.point.y(kTimeIndex) + previous_.point.y_remainder(kTimeIndex); }

  /// Starts the grid at `from` (a carried point of the untransformed system, with its turns) at
  /// time t [s]: no stage history.
  template <class Carried>
  void start(const Carried& from, double t) {
    grid_.point.z = from.point.z;
    grid_.point.z_remainder = from.point.z_remainder;
    grid_.point.y.template head<System::kPassiveDimension>() = from.point.y;
    grid_.point.y_remainder.template head<System::kPassiveDimension>() = from.point.y_remainder;
    grid_.point.y(kTimeIndex) = t;
    grid_.point.y_remainder(kTimeIndex) = 0.0;
    grid_.steering_turns = from.steering_turns;
    grid_.heading_turns = from.heading_turns;
    grid_.periodic_in_steering_angle = from.periodic_in_steering_angle;
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
    previous_.steering_turns = grid_.steering_turns;
    previous_.heading_turns = grid_.heading_turns;
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

}  // namespace birkhoff_cart
