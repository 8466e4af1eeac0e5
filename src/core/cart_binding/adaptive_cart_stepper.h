// The CartStepper of a Birkhoffian member under the error-per-step control (adaptive_step_control.h;
// docs/birkhoffian.md §12): the caller's step h is the output step; the member's own grid is chosen
// by the control for `position_tolerance`; the state at an output instant between grid points comes
// from the grid's Hermite dense output (hermite_dense_output.h). Private to the core library
// (integrator_registry.cpp makes it).
//
// Tolerance → the estimate's aim (eqs. (B.48), (B.53)): τ = position_tolerance / horizon is the error
// per second the run may gather; the control accepts ê ≤ τ_a·h with τ_a = c·τ^α, the member's
// tolerance proportionality (tolerance_proportionality.h), so that the delivered error lands at the
// tolerance rather than orders below it. The stage solve still stops at κ·τ·h (B.49).
//
// With global_error_estimate a Richardson shadow run on doubled steps (richardson_shadow.h,
// docs/accuracy.md §4.5, eq. (A.6)) follows the grid and estimates the position error of B the run
// has gathered: reported, not steering (the steps are the same with and without it). Its work counts
// in the run's.
//
// Where the grid must land exactly rather than interpolate: the instants given to land_on() (the
// run's end: Simulation passes it), the loads' kinks (Effect::next_kink_after: a step across a
// kink loses the member's order; after one the stage history restarts), and, in a scene whose
// effects take commands (the node's torque topics), every output instant: a new command may start
// there, and the grid restarts from the landed state when it does.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <Eigen/Eigenvalues>
#include <sstream>
#include <string>

#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/integrators/adaptive_step_control.h"
#include "controlled_cart_stepper.h"
#include "step_checks.h"
#include "birkhoff_cart/core/integrators/tolerance_proportionality.h"
#include "birkhoff_cart/core/integrators/richardson_shadow.h"

namespace birkhoff_cart {

template <class Stepper, class System>
class AdaptiveCartStepperAdapter final
    : public ControlledCartStepper<AdaptiveCartStepperAdapter<Stepper, System>, Stepper, System> {
  using Base = ControlledCartStepper<AdaptiveCartStepperAdapter<Stepper, System>, Stepper, System>;
  friend Base;
  using Memory = typename Stepper::template Memory<System>;
  using Carried = CarriedCartState<System, Memory>;
  using Control = AdaptiveStepControl<Stepper, System, Carried>;
  using Output = typename Base::Output;
  using Base::dense_;
  using Base::instants_;
  using Base::output_;
  using Base::position_tolerance_;
  using Base::system_;
  /// The work limit: internal steps between two output instants (as the reversible control's). A
  /// legitimate run can take more than DOPRI5's NMAX of 100 000: birkhoff_gauss4 on very_stiff_hinge
  /// at 1e-5 m with one output row over its 20 s takes 146 863 steps, at 1e-7 m 553 049.
  static constexpr std::uint64_t kMaxInternalStepsPerOutput = 1000000;
  /// A of (B.46) [-]: an attempt is kept while ê ≤ A·τ_a·|h|.
  static constexpr double kAcceptanceRatio = 2.0;
  /// A failed side step is retried in up to 2^kMaxSideStepHalvings substeps.
  static constexpr int kMaxSideStepHalvings = 6;
  /// κ of (B.49) and (B.49') [-]: the grid's is rescaled to the asked τ in control_settings().
  static constexpr double kStageChangeFraction = AdaptiveStepSettings{}.stage_change_fraction;

 public:
  /// `estimate_free_stepper`: the member without its ê, as the global error estimate's shadow and the
  /// side steps to output instants step it.
  AdaptiveCartStepperAdapter(const Stepper& stepper, const Stepper& estimate_free_stepper, const IntegratorSettings& settings,
                             const CartModel& model, const EffectSet& effects)
      : Base(model, effects, "adaptive", settings.position_tolerance), effects_(&effects), control_(stepper, control_settings(settings)),
        estimate_free_stepper_(estimate_free_stepper),
        global_error_estimate_(settings.global_error_estimate),
        stage_change_per_unit_step_(control_.settings().stage_change_fraction * control_.settings().error_per_unit_step),
        side_stage_change_per_unit_step_(kStageChangeFraction * control_.settings().error_per_unit_step) {}

  bool symmetric() const override { return Stepper::kSymmetric; }

 private:
  static AdaptiveStepSettings control_settings(const IntegratorSettings& settings) {
    AdaptiveStepSettings control;
    const double asked = stepper_checks::error_per_unit_step(settings, "adaptive");  // τ [1/s] (B.48)
    control.error_per_unit_step = aimed_error_per_unit_step<AdaptiveToleranceProportionality<Stepper>>(asked);
    // The stage solve stops at κ·τ·h of the asked τ (B.49), not of the aim.
    control.stage_change_fraction *= asked / control.error_per_unit_step;
    control.max_steps_per_advance = kMaxInternalStepsPerOutput;
    // τ_a is an aim calibrated against the delivered position error, not a bound on each step: an
    // attempt is kept up to twice it (B.46), where ê's swings with the motion's phase would
    // otherwise reject one step in 6–20 on the short scenes (birkhoffian.md §12.1).
    control.acceptance_ratio = kAcceptanceRatio;
    return control;
  }

  /// A grid from `state`: the carried point with χ, θ reduced, the first step from the rates there.
  void start(const CartState& state, StepStatistics& statistics) {
    Carried seed;
    system_traits::begin_step(system_, state.time);
    seed.start_from(system_, state);
    control_.start(seed, state.time, first_step(seed, state.time, statistics));
    dense_.clear();
    dense_.push(control_.grid(), control_.time());
    side_jacobian_at_ = std::numeric_limits<double>::quiet_NaN();  // a new grid: no side step's J carries over
    if (global_error_estimate_) {
      // A new grid (the run's start, a command, a failed step, a new state): the shadow starts again
      // at its point; the error read so far is kept.
      keep_read_error();
      shadow_.start(control_.grid(), control_.time());
    }
  }

  /// Before the shadow restarts at the grid's point: the error it has read stays in the estimate.
  void keep_read_error() {
    carried_error_ += met_error_;
    met_error_.setZero();
  }

  /// The shadow follows the grid's accepted step that ended at the grid's time (`closes`: on a point
  /// the grid had to land on; `after_kink`: a kink of the loads there); where it meets the grid, the
  /// estimate (A.6) is read into `statistics`.
  void follow_with_shadow(bool closes, bool after_kink, StepStatistics& statistics) {
    StepStatistics shadow_work;  // its work counts in the run's; its ê (none) is not the run's
    const auto met = shadow_.follow(
        system_, estimate_free_stepper_, control_.grid(), control_.time(), closes, after_kink, stage_change_per_unit_step_,
        [this](const auto& before, const auto& after, double t, double h) {
          return stepper_checks::energy_balance_holds(system_.model(), cart_state(before, t), cart_state(after, t + h));
        },
        shadow_work);
    statistics.rhs_evaluations += shadow_work.rhs_evaluations;
    statistics.passive_evaluations += shadow_work.passive_evaluations;
    statistics.newton_iterations_total += shadow_work.newton_iterations_total;
    statistics.global_error_paired_steps = shadow_.paired_steps();
    statistics.global_error_failed_steps = shadow_.failed_steps();
    using Follow = typename RichardsonShadow<Stepper, System, Carried>::Follow;
    if (met == Follow::kResynchronised) keep_read_error();
    if (met != Follow::kMet) return;
    const double t = control_.time();  // [s]
    // h·ρ(J) of the shadow's step (J the grid's last Jacobian): beyond kLargestAsymptoticStiffness a
    // mode is stepped over, outside (A.6)'s asymptotic range.
    const auto& memory = control_.grid().memory;
    if (memory.jacobian_valid) {
      const Eigen::EigenSolver<std::decay_t<decltype(memory.jacobian)>> modes(memory.jacobian, false);
      const double stiffness = shadow_.last_step() * modes.eigenvalues().cwiseAbs().maxCoeff();  // [-]
      if (std::isfinite(stiffness)) {
        statistics.global_error_stiffness = std::max(statistics.global_error_stiffness, stiffness);
      }
    }
    const CartState grid = cart_state(control_.grid().point, t);
    const CartState shadow = cart_state(shadow_.shadow().point, t);
    met_error_ = Eigen::Vector2d(grid.x - shadow.x, grid.y - shadow.y) / richardson_divisor<Stepper>();  // (A.6) [m]
    statistics.global_error_estimate = (carried_error_ + met_error_).norm();
    statistics.global_error_estimate_time = t;
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
      const bool after_kink = at_kink && control_.time() == kink;
      if (after_kink) {
        control_.forget_stage_history();
        dense_.clear();
      }
      if (global_error_estimate_) follow_with_shadow(control_.time() == limit, after_kink, statistics);
      dense_.push(control_.grid(), control_.time());
      this->notify_grid(control_.grid(), control_.time());
    }
    const Carried& grid = control_.grid();
    output_.periodic_angles = grid.periodic_angles;
    output_.valid = true;
    if (control_.time() == target) {
      output_.point = grid.point;
      output_.turns = grid.turns;
    } else {
      this->between_grid_points(target, output_, statistics);
    }
  }

  /// The state at `target` by one step of the member from the grid point before it: exact to the
  /// member's order where the dense output's estimate says it is not. The step lies inside the grid's
  /// last step, so its stage solve starts from that step's stage points (interpolated, not an explicit
  /// start) and its J — where the grid has none, J at the grid point before, computed by the first
  /// side step in the grid step and kept for the others — and stops at the accuracy the tolerance
  /// needs (κ·τ_a·h, eq. (B.49'), a hundredth of the aim: its error ends at its row, where a grid
  /// step's carries on, so it need not converge to the grid's κ·τ·h); it reads no ê (the run's ê is
  /// its grid's). A side
  /// step whose stage solve fails or
  /// lands on a spurious root (non-finite, or the energy balance broken) is retried in 2, 4, …
  /// 2^kMaxSideStepHalvings substeps, as the control retries a rejected attempt smaller.
  void side_step(double target, Output& out, StepStatistics& statistics) {
    const double start = control_.previous_time();  // [s]
    const auto& grid_memory = control_.grid().memory;
    if (!grid_memory.jacobian_valid && side_jacobian_at_ != start) {
      const CompensatedPoint<System>& before = control_.previous();
      const StateVector<System, double> z = before.z + before.z_remainder;
      side_jacobian_ = system_traits::darboux_jacobian(system_, system_.to_darboux(z, start), start);
      ++statistics.rhs_evaluations;  // one evaluation of J, as the stage solve counts it
      if (!side_jacobian_.allFinite()) throw StepError("the side step met a non-finite Jacobian");
      side_jacobian_at_ = start;
    }
    std::string last;
    for (int halvings = 0; halvings <= kMaxSideStepHalvings; ++halvings) {
      const int pieces = 1 << halvings;
      out.point = control_.previous();
      out.turns = control_.previous_turns();
      side_memory_.start_side_step_from(grid_memory, side_stage_change_per_unit_step_ * (target - start) / pieces,
                                        grid_memory.jacobian_valid ? nullptr : &side_jacobian_);
      try {
        for (int k = 1; k <= pieces; ++k) {
          const double from = start + (target - start) * static_cast<double>(k - 1) / pieces;           // [s]
          const double to = k == pieces ? target : start + (target - start) * static_cast<double>(k) / pieces;  // [s]
          const CompensatedPoint<System> before = out.point;
          system_traits::begin_step(system_, from);
          estimate_free_stepper_.advance_compensated(system_, out.point, side_memory_, from, to - from, statistics);
          const bool finite = out.point.z.allFinite() && out.point.y.allFinite();
          if (!finite || !stepper_checks::energy_balance_holds(system_.model(), cart_state(before, from),
                                                               cart_state(out.point, to))) {
            throw StepError("a non-finite state or a broken energy balance (a spurious root)");
          }
        }
        out.reduce_angles();
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

  const EffectSet* effects_;
  Control control_;
  Stepper estimate_free_stepper_;  ///< the member without its ê: the shadow's steps and the side steps
  Memory side_memory_;             ///< a side step's (kept: it is large, and set afresh for each)
  /// The side steps' J where the grid has none: at the grid point before, of time side_jacobian_at_ [s].
  Eigen::Matrix<double, System::kDimension, System::kDimension> side_jacobian_;
  double side_jacobian_at_ = std::numeric_limits<double>::quiet_NaN();
  bool global_error_estimate_;
  double stage_change_per_unit_step_;  ///< κ·τ: the stage solve stops at this·h [1/s] (B.49)
  double side_stage_change_per_unit_step_;  ///< κ·τ_a: a side step's stage solve stops at this·h [1/s] (B.49')
  RichardsonShadow<Stepper, System, Carried> shadow_;
  Eigen::Vector2d carried_error_ = Eigen::Vector2d::Zero();  ///< estimate kept over the shadow's restarts [m]
  Eigen::Vector2d met_error_ = Eigen::Vector2d::Zero();      ///< (A.6) at the last meeting since then [m]
};

}  // namespace birkhoff_cart
