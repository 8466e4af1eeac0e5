// The step memory of the collocation members (docs/birkhoffian.md §10.2, §10.5): what one step leaves
// for the next — the stage derivatives for the starting values (eq. (B.32)), the simplified-Newton
// Jacobian with the factored inverses of I − h A ⊗ J for the step sizes in use (eqs. (B.38)–(B.39)),
// and the end rate F(w⁺, tₖ₊₁) that the local error estimate computed (first same as last).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/kronecker_newton.h"

namespace birkhoff_cart {

/// What one step leaves for the next (double only): the stage derivatives, for starting values, and
/// the simplified-Newton Jacobian J = ∂ẇ/∂w with the inverses of I − h A ⊗ J for the step sizes in use.
template <class System, int Stages>
struct CollocationMemory {
  static constexpr int kDimension = System::kDimension;
  static constexpr int kUnknowns = System::kDimension * Stages;
  static constexpr int kCachedStepSizes = 9;  ///< distinct sub-step sizes (birkhoff8_kahan_li has 9)
  using StageMatrix = Eigen::Matrix<double, kUnknowns, kUnknowns>;

  int count = 0;                                             ///< stage points held [-]
  std::array<double, kMaxGaussStages> times{};               ///< stage times tⱼ [s]
  std::array<StateVector<System, double>, kMaxGaussStages> rates{};  ///< Fⱼ = ẇ(Wⱼ, tⱼ)

  bool jacobian_valid = false;
  Eigen::Matrix<double, kDimension, kDimension> jacobian = Eigen::Matrix<double, kDimension, kDimension>::Zero();
  int cached = 0;                                            ///< entries of the two arrays below in use
  int next_slot = 0;                                         ///< round-robin replacement
  std::array<double, kCachedStepSizes> cached_step{};        ///< h [s] of each cached inverse
  std::array<KroneckerNewtonInverse<kDimension, Stages>, kCachedStepSizes> cached_inverse;  ///< (I − h A ⊗ J)⁻¹

  // First same as last (the local error estimate, eq. (B.37)): F(w⁺, tₖ₊₁) of the last step stands
  // in for the next step's F(w, tₖ) while that step starts from the same point and time.
  bool end_rate_valid = false;
  double end_time = 0.0;                                                     ///< tₖ₊₁ [s]
  StateVector<System, double> end_point = StateVector<System, double>::Zero();  ///< w⁺
  StateVector<System, double> end_rate = StateVector<System, double>::Zero();   ///< F(w⁺, tₖ₊₁)
  PassiveVector<System, double> end_passive_point = PassiveVector<System, double>::Zero();  ///< y⁺
  PassiveVector<System, double> end_passive_rate = PassiveVector<System, double>::Zero();   ///< g(z⁺, y⁺, tₖ₊₁)

  /// The stage solve may stop once every component's stage change is below this, in the units of
  /// the Birkhoffian variables' weights of ê (absolute below 1, relative above; error_estimate.h): the accuracy a step
  /// control's tolerance needs (gauss_stage_solver.h). 0: converge to round-off.
  double stage_change_limit = 0.0;
  /// The local error estimate adds the step's weighted linearised error w_L e_L (eqs. (B.54)–(B.55),
  /// linear_mode_error.h), which the defect (B.37) cannot see: the adaptive control sets it, for the
  /// stiff modes a step may jump over. false: the estimate (B.37) alone (fixed steps, the reversible
  /// control, the diagnostics).
  bool linear_mode_error = false;

  /// The part of the memory a rejected step must give back (stage history and end rate; J and the
  /// Newton inverses stay: they are keyed by h and remain a good approximation).
  struct History {
    int count = 0;
    std::array<double, kMaxGaussStages> times{};
    std::array<StateVector<System, double>, kMaxGaussStages> rates{};
    bool end_rate_valid = false;
    double end_time = 0.0;
    StateVector<System, double> end_point;
    StateVector<System, double> end_rate;
    PassiveVector<System, double> end_passive_point;
    PassiveVector<System, double> end_passive_rate;
  };
  History history() const {
    return History{count, times, rates, end_rate_valid, end_time, end_point, end_rate, end_passive_point, end_passive_rate};
  }
  void restore(const History& saved) {
    count = saved.count;
    times = saved.times;
    rates = saved.rates;
    end_rate_valid = saved.end_rate_valid;
    end_time = saved.end_time;
    end_point = saved.end_point;
    end_rate = saved.end_rate;
    end_passive_point = saved.end_passive_point;
    end_passive_rate = saved.end_passive_rate;
  }
  /// After a kink of the loads: the stage derivatives of the steps before no longer extrapolate.
  void forget_stage_history() {
    count = 0;
    forget_end_rate();
  }

  void clear() {
    count = 0;
    forget_jacobian();
    forget_end_rate();
  }
  /// After anything that changes ẇ at a given (w, t) between steps (a new command torque).
  void forget_end_rate() { end_rate_valid = false; }
  /// Does the remembered F(w⁺, tₖ₊₁) belong to the step starting at (w, t)? Equal to round-off: the
  /// chart's round trip and t₀ + n·h against tₖ + h differ by an ulp or two; a new chart epoch
  /// (rep (a)) or a reduced angle (whole turns) differ by far more.
  bool end_rate_belongs_to(const StateVector<System, double>& w, double t) const {
    constexpr double kRoundOff = 8.0 * std::numeric_limits<double>::epsilon();
    if (!end_rate_valid || !(std::abs(t - end_time) <= kRoundOff * std::max(1.0, std::abs(t)))) return false;
    for (int k = 0; k < kDimension; ++k) {
      if (!(std::abs(w(k) - end_point(k)) <= kRoundOff * std::abs(end_point(k)))) return false;
    }
    return true;
  }
  /// The same for the passive rate g(z⁺, y⁺, tₖ₊₁), given that the Birkhoffian part belongs.
  bool end_passive_rate_belongs_to(const PassiveVector<System, double>& y) const {
    constexpr double kRoundOff = 8.0 * std::numeric_limits<double>::epsilon();
    for (int k = 0; k < y.size(); ++k) {
      if (!(std::abs(y(k) - end_passive_point(k)) <= kRoundOff * std::abs(end_passive_point(k)))) return false;
    }
    return true;
  }
  void forget_jacobian() {
    jacobian_valid = false;
    cached = 0;
    next_slot = 0;
  }
  /// The stage points of `other` (times and rates), as starting values for a step that covers them
  /// (a shadow step over two of other's steps: richardson_shadow.h); J and the inverses stay.
  void take_stage_points(const CollocationMemory& other) {
    count = other.count;
    times = other.times;
    for (int m = 0; m < other.count; ++m) rates[m] = other.rates[m];
  }

  /// A side step's memory from the grid's (`grid`, after its last accepted step): that step's stage
  /// points, for starting values (eq. (B.32)), and J, without cached inverses or end rates; the solve
  /// stops at `limit` (stage_change_limit). Where the grid has no J, `stand_in` (when given) is taken:
  /// the side steps' own J from the grid point before (the same whichever instant asks first, so a
  /// side step's result depends on the grid and its instant only).
  void start_side_step_from(const CollocationMemory& grid, double limit,
                            const Eigen::Matrix<double, kDimension, kDimension>* stand_in) {
    copy_history_from(grid);
    if (!jacobian_valid && stand_in != nullptr) set_jacobian(*stand_in);
    forget_end_rate();
    stage_change_limit = limit;
  }
  /// J = ∂ẇ/∂w from elsewhere (a side step's), without cached inverses.
  void set_jacobian(const Eigen::Matrix<double, kDimension, kDimension>& given) {
    jacobian = given;
    jacobian_valid = true;
    cached = 0;
    next_slot = 0;
  }

  /// The stage history and J of `other`, without its cached inverses (a side step's copy: the
  /// inverses are h-specific and large).
  void copy_history_from(const CollocationMemory& other) {
    stage_change_limit = other.stage_change_limit;
    count = other.count;
    times = other.times;
    for (int m = 0; m < other.count; ++m) rates[m] = other.rates[m];
    jacobian_valid = other.jacobian_valid;
    jacobian = other.jacobian;
    cached = 0;
    next_slot = 0;
    end_rate_valid = other.end_rate_valid;
    end_time = other.end_time;
    end_point = other.end_point;
    end_rate = other.end_rate;
    end_passive_point = other.end_passive_point;
    end_passive_rate = other.end_passive_rate;
  }
};

}  // namespace birkhoff_cart
