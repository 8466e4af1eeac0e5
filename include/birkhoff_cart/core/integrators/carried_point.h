// What a Birkhoffian member carries from one step to the next, for any system (docs/birkhoffian.md
// §10.4): the point (z, y) with its compensated-summation remainders, the memory of stage
// derivatives and Newton matrices, and each angle the system declares (system_traits.h,
// kAngleCoordinates) reduced to (−π, π] with its whole turns kept apart, so that the ulp of an angle
// that has turned many times does not decide the accuracy of what is periodic in it. The step
// controls (adaptive_step_control.h, reversible_step_control.h) carry their grids in it.
#pragma once

#include <array>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/integrators/angle_reduction.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/compensated_summation.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

/// Steppers with advance_compensated(system, CompensatedPoint&, Memory&, t, h, statistics).
template <class Stepper, class System, class = void>
struct CarriesStateTrait : std::false_type {};
template <class Stepper, class System>
struct CarriesStateTrait<Stepper, System,
                         std::void_t<decltype(std::declval<const Stepper&>().advance_compensated(
                             std::declval<const System&>(), std::declval<CompensatedPoint<System>&>(),
                             std::declval<typename Stepper::template Memory<System>&>(), 0.0, 0.0,
                             std::declval<StepStatistics&>()))>>
    : std::true_type {};
template <class Stepper, class System>
constexpr bool kCarriesState = CarriesStateTrait<Stepper, System>::value;

/// The memory of a carried point that only hands points out (a seed, an adapter's last output).
struct NoStepMemory {
  void clear() {}
};

/// The whole turns taken out of each angle of `System` [-], in the order of kAngleCoordinates.
template <class System>
using AngleTurns = std::array<double, system_traits::kAngleCount<System>>;

/// `PointSystem`: the system whose point is carried — System itself, or a system built on it with
/// the same leading coordinates (the time-transformed system: y with t appended); the angles are
/// System's.
template <class System, class Memory, class PointSystem = System>
struct CarriedPoint {
  bool valid = false;
  CompensatedPoint<PointSystem> point;
  Memory memory;
  AngleTurns<System> turns{};  ///< whole turns removed from each angle [-]
  /// Bit k: angle k is reduced (the rates are 2π-periodic in it: system_traits::periodic_angles).
  unsigned periodic_angles = ~0u;

  /// Reduces each periodic angle into (−π, π], its turns added to `turns`.
  void reduce_angles() {
    constexpr auto angles = system_traits::kAngleCoordinates<System>;
    for (std::size_t k = 0; k < angles.size(); ++k) {
      if (!(periodic_angles & (1u << k))) continue;
      const int i = angles[k].index;
      if (angles[k].passive) {
        reduce_angle(point.y(i), point.y_remainder(i), turns[k]);
      } else {
        reduce_angle(point.z(i), point.z_remainder(i), turns[k]);
      }
    }
  }

  /// Takes the point (z, the leading coordinates of y, their remainders) and the turns of `from`, a
  /// carried point of the same System (over any PointSystem, or a grid point); not its memory, its
  /// periodicity, nor `valid`.
  template <class From>
  void take_point(const From& from) {
    point.z = from.point.z;
    point.z_remainder = from.point.z_remainder;
    point.y.template head<System::kPassiveDimension>() = from.point.y.template head<System::kPassiveDimension>();
    point.y_remainder.template head<System::kPassiveDimension>() =
        from.point.y_remainder.template head<System::kPassiveDimension>();
    turns = from.turns;
  }
};

/// Adds back to `point` (a CompensatedPoint over System or a system with its leading coordinates)
/// the angles' turns `to` took out since `from`: 2π (to − from) on each angle [rad], so that two
/// points carried on different branches compare on one.
template <class System, class Point>
void unreduce_angles(Point& point, const AngleTurns<System>& to, const AngleTurns<System>& from) {
  constexpr double kTwoPi = 6.283185307179586476925286766559;
  constexpr auto angles = system_traits::kAngleCoordinates<System>;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const int i = angles[k].index;
    if (angles[k].passive) {
      point.y(i) += kTwoPi * (to[k] - from[k]);
    } else {
      point.z(i) += kTwoPi * (to[k] - from[k]);
    }
  }
}

}  // namespace birkhoff_cart
