// A global error estimate for a step control's grid by Richardson extrapolation on doubled steps
// (docs/accuracy.md §4.5, eq. (A.6)). A shadow run of the same member takes each pair of the grid's
// accepted steps [tₖ, tₖ₊₂] as one step of h₁ + h₂, from its own state. Where both runs are in the
// member's asymptotic range the shadow's global error is 2^p times the grid's (p the member's order),
// so at every time the two runs meet
//
//   e(t) ≈ (x_grid(t) − x_shadow(t)) / (2^q − 1),   q = min(p, the estimate's order)          (A.6)
//
// q ≤ p keeps the estimate from under-stating where the member's order drops (the stiff hinges:
// order reduction): on smooth motion it over-states by (2^p − 1)/(2^q − 1) (1, 2.0, 4.0 for gauss4,
// gauss6, gauss8). Unlike the local estimate ê it carries every step's error to the time it is read:
// the jackknife's amplification, a coast's drift, a damper's decay, in the coordinates asked for.
//
// A pair never straddles a point the grid had to land on (a kink of the loads, where the member's
// order is lost across it; a landing where a command may change): a step that ends there closes the
// pair, alone if it is the pair's first (a lone step, the grid's own step map from the shadow's
// state, adds no new information). A shadow step that fails (its stage solve, a non-finite state, or
// the caller's plausibility check) restarts the shadow at the grid's point: the caller keeps the estimate it had (`resynchronised`).
//
// Its range (measured on the shipped scenes: docs/accuracy.md §4.5): the estimate follows the error
// where every shadow step stays within its asymptotic range, h·ρ(J) ≤ 3 (ρ the spectral radius of
// the Jacobian J = ∂ẇ/∂w), over at least 8 pairs. Where a step goes beyond — a stiff hinge stepped
// over (h·ρ up to 10³), the loosest tolerances' few long steps — (A.6)'s premise fails and the
// estimate can under-state the error (by up to 70× measured); global_error_estimate_in_range() says which.
//
// Cost: about half the grid's steps again, each of twice the size (more stage iterations); counted
// in the statistics the caller gives. It knows no system beyond the concept and its traits.
#pragma once

#include <cstdint>

#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

/// The largest h·ρ(J) of a shadow step and the fewest pairs with which (A.6) is within its range.
constexpr double kLargestAsymptoticStiffness = 3.0;  // [-]
constexpr std::uint64_t kFewestEstimatePairs = 8;    // [-]

/// Whether an estimate read over `paired_steps` pairs whose largest h·ρ(J) was `stiffness` [-] is
/// within (A.6)'s range (file comment).
inline bool global_error_estimate_in_range(std::uint64_t paired_steps, double stiffness) {
  return paired_steps >= kFewestEstimatePairs && stiffness <= kLargestAsymptoticStiffness;
}

/// 2^q − 1 of (A.6) for `Stepper` [-].
template <class Stepper>
constexpr double richardson_divisor() {
  constexpr int q = Stepper::kOrder < Stepper::kErrorEstimateOrder ? Stepper::kOrder : Stepper::kErrorEstimateOrder;
  return static_cast<double>((1ULL << q) - 1ULL);
}

/// The shadow run of `Stepper` on `System`, carried in `Carried` (a CarriedPoint, carried_point.h).
template <class Stepper, class System, class Carried>
class RichardsonShadow {
 public:
  /// What follow() did.
  enum class Follow {
    kPending,         ///< the grid's step opened a pair: the shadow waits at the pair's start
    kMet,             ///< the shadow stepped to the grid's time: (A.6) may be read
    kResynchronised,  ///< the shadow's step failed: it starts again at the grid's point
  };

  /// The shadow at the grid's point `grid` at time t [s]; no pair open.
  void start(const Carried& grid, double t) {
    shadow_ = grid;
    shadow_.memory.clear();
    time_ = t;
    pending_ = false;
  }

  /// After the grid's accepted step that ended at time `t_end` [s] on the point `grid`: opens a pair,
  /// or steps the shadow from its time to t_end (the pair, or a lone step when `closes` — the grid
  /// landed where a pair must end — and no pair is open). `after_kink`: the loads have a kink at
  /// t_end (the shadow's stage history restarts there, as the grid's).
  template <class SystemRef, class Plausible>
  Follow follow(SystemRef& system, const Stepper& stepper, const Carried& grid, double t_end, bool closes,
                bool after_kink, double stage_change_per_unit_step, Plausible plausible, StepStatistics& statistics) {
    if (!pending_ && !closes) {
      pending_ = true;
      return Follow::kPending;
    }
    const bool pair = pending_;  // else a lone step
    pending_ = false;
    const double h = t_end - time_;  // h₁ + h₂, or the lone step [s]
    bool solved = true;
    const auto before = shadow_.point;
    // Starting values from the grid's last step, inside the shadow's (not extrapolated over 2h).
    shadow_.memory.take_stage_points(grid.memory);
    shadow_.memory.stage_change_limit = stage_change_per_unit_step * h;
    try {
      system_traits::begin_step(system, time_);
      stepper.advance_compensated(system, shadow_.point, shadow_.memory, time_, h, statistics);
    } catch (const StepError&) {
      solved = false;
    }
    if (!solved || !shadow_.point.z.allFinite() || !shadow_.point.y.allFinite() ||
        !plausible(before, shadow_.point, time_, h)) {
      ++failed_steps_;
      start(grid, t_end);
      return Follow::kResynchronised;
    }
    shadow_.reduce_angles();
    last_step_ = h;
    time_ = t_end;
    if (after_kink) shadow_.memory.forget_stage_history();
    if (pair) ++paired_steps_;
    return Follow::kMet;
  }

  const Carried& shadow() const { return shadow_; }
  double time() const { return time_; }  ///< [s]
  double last_step() const { return last_step_; }  ///< the shadow's last step [s]
  std::uint64_t paired_steps() const { return paired_steps_; }
  std::uint64_t failed_steps() const { return failed_steps_; }

 private:
  Carried shadow_;
  double time_ = 0.0;  ///< the shadow's time [s]
  double last_step_ = 0.0;  ///< [s]
  bool pending_ = false;
  std::uint64_t paired_steps_ = 0;
  std::uint64_t failed_steps_ = 0;
};

}  // namespace birkhoff_cart
