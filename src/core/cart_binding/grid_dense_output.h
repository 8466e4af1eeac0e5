// The dense output of a step control's grid for the cart (docs/birkhoffian.md §12.3): the grid
// points in (z, y) with the system's angles (χ and θ) kept on one branch — the whole turns the grid
// took out of a point are put back relative to the newest point — and their Hermite interpolant
// (hermite_dense_output.h), whose error is estimated on the state: the position (x, y) in metres,
// the Birkhoffian z (with the momenta), the heading and the wheel angles in ê's weights
// (error_estimate.h), as the grid's own steps are judged. Private to the core library.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/carried_point.h"
#include "birkhoff_cart/core/integrators/hermite_dense_output.h"
#include "birkhoff_cart/core/integrators/system_traits.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// The last `Points` grid points of a run and their Hermite interpolant in (z, y): of degree
/// 2·Points − 1, its position error estimated against the one through Points − 1.
template <class System, int Points>
class GridDenseOutput {
 public:
  static constexpr int kSize = System::kDimension + System::kPassiveDimension;
  using Joint = Eigen::Matrix<double, kSize, 1>;

  /// Forget the points (a restart of the grid).
  void clear() { history_.clear(); }
  int size() const { return history_.size(); }
  /// The time of held point j (0: the newest) [s]; needs j < size().
  double time(int j) const { return history_.time(j); }

  /// Adds the grid point of `grid` (a CarriedPoint) at time t [s]; with an identity chart, the
  /// rates its step's local error estimate evaluated there come along (first same as last: no
  /// evaluation later).
  template <class Carried>
  void push(const Carried& grid, double t) {
    push_point(grid.point, grid.turns, t);
    if constexpr (system_traits::kDarbouxChartIsIdentity<System>) {
      const auto& memory = grid.memory;
      if (memory.end_rate_valid && memory.end_time == t) set_newest_rate(memory.end_rate, memory.end_passive_rate);
    }
  }

  /// Adds a grid point (a CompensatedPoint whose z and leading y are the system's; t [s]) with the
  /// turns taken out of its angles.
  template <class Point>
  void push_point(const Point& point, const AngleTurns<System>& turns, double t) {
    // Keep the held points on the newest point's branch: shift them by the turns it took out.
    if (history_.size() > 0) {
      constexpr auto angles = system_traits::kAngleCoordinates<System>;
      for (std::size_t k = 0; k < angles.size(); ++k) {
        const int component = angles[k].passive ? System::kDimension + angles[k].index : angles[k].index;
        history_.shift_component(component, kTwoPi * (turns_[k] - turns[k]));
      }
    }
    turns_ = turns;
    Joint x;
    x << point.z + point.z_remainder, (point.y + point.y_remainder).template head<System::kPassiveDimension>();
    history_.push(t, x);
  }

  /// The newest point's rates ż, ẏ [per second], when known without an evaluation.
  template <class ZRate, class YRate>
  void set_newest_rate(const ZRate& z_rate, const YRate& y_rate) {
    Joint rate;
    rate << z_rate, y_rate.template head<System::kPassiveDimension>();
    history_.set_rate(0, rate);
  }

  /// The carried point at t [s] (inside the newest step) in `out`, with the newest point's turns.
  /// The rates of the points that lack them are evaluated here, once each. Returns an estimate of
  /// the interpolant's error (against the interpolant one point shorter: a conservative one; NaN
  /// with a single point): the larger of the position's [m] and every other state component's in
  /// ê's weights [-], both read against a position tolerance's number. The position alone would pass
  /// rows whose speeds are far off where the held points crowd at one end of a long newest step (a
  /// start's first steps grow 100× each: the interpolant is then a Taylor polynomial far from its
  /// centre, and the position is still near zero).
  template <class Carried>
  double at(System& system, double t, Carried& out, StepStatistics& statistics) {
    for (int j = 0; j < history_.size(); ++j) {
      if (history_.has_rate(j)) continue;
      const Joint& x = history_.value(j);
      const StateVector<System, double> z = x.template head<System::kDimension>();
      const PassiveVector<System, double> y = x.template tail<System::kPassiveDimension>();
      const double time = history_.time(j);
      Joint rate;
      rate << birkhoffian_rates(system, z, time), passive_coordinate_rates(system, z, y, time);
      ++statistics.rhs_evaluations;
      ++statistics.passive_evaluations;
      history_.set_rate(j, rate);
    }
    Joint difference;
    const Joint x = history_.at(t, &difference);
    out.point.z = x.template head<System::kDimension>();
    out.point.y = x.template tail<System::kPassiveDimension>();
    out.point.z_remainder.setZero();
    out.point.y_remainder.setZero();
    out.turns = turns_;
    constexpr int kX = System::kDimension + kXIndex;
    constexpr int kY = System::kDimension + kYIndex;
    double estimate = std::hypot(difference(kX), difference(kY));  // [m]
    for (int i = 0; i < kConfigurationEnd; ++i) {
      if (i == kX || i == kY) continue;
      estimate = std::max(estimate, std::abs(difference(i)) / std::max(1.0, std::abs(x(i))));  // [-]
    }
    return estimate;
  }

 private:
  static constexpr double kTwoPi = 6.283185307179586476925286766559;
  /// The components a row's estimate judges: z and the passive coordinates up to the wheel angles;
  /// not the applied work W and impulse I2 after them, quadratures for the balance diagnostics (the
  /// scene's accuracy guard judges those balances on every row).
  static constexpr int kConfigurationEnd = System::kDimension + kAppliedWorkIndex;

  HermiteDenseOutput<kSize, Points> history_{Points};
  AngleTurns<System> turns_{};  ///< of the newest point [-]
};

}  // namespace birkhoff_cart
