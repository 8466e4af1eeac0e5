// What the Birkhoffian collocation members carry from one step to the next (docs/birkhoffian.md §10.4):
// the point (z, y) with its compensated-summation remainders, the steering angle χ and heading θ
// reduced to (−π, π] with whole turns kept apart (the cart's rates are 2π-periodic in θ always and in χ
// unless a steering spring is enabled, so the ulp of χ no longer grows with the turns: at χ ≈ 2262 rad
// it was 4.5e-13 rad), and the memory of stage derivatives and Newton matrices. The CartState handed
// out carries each angle as hi + lo (state.h), so that diagnostics keep those bits too.
#pragma once

#include <cmath>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/angle_reduction.h"
#include "birkhoff_cart/core/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "birkhoff_cart/core/state.h"

namespace birkhoff_cart {

/// Steppers with advance_compensated(system, CompensatedPoint&, CollocationMemory&, t, h, statistics).
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

/// The memory of a carried state that only hands states out (an adapter's last output).
struct NoStepMemory {
  void clear() {}
};

/// `PointSystem`: the system whose point is carried — System itself, or a system built on it with
/// the same leading coordinates (the time-transformed system: y with t appended).
template <class System, class Memory, class PointSystem = System>
struct CarriedCartState {
  bool valid = false;
  CompensatedPoint<PointSystem> point;
  Memory memory;
  double steering_turns = 0.0;  ///< whole turns removed from χ [-]
  double heading_turns = 0.0;   ///< whole turns removed from θ [-]
  bool periodic_in_steering_angle = true;  ///< rates 2π-periodic in χ (no steering spring)
  CartState last_output;        ///< what the adapter last handed out

  /// Is `state` exactly the state this carried state produced (every field but the time, bit for
  /// bit)? The time is left out: callers set t = t₀ + n·h themselves (simulation.cpp), which may
  /// differ from tₖ + h by an ulp.
  bool continues(const CartState& state) const {
    if (!valid) return false;
    const CartState& a = state;
    const CartState& b = last_output;
    return a.x == b.x && a.y == b.y && a.heading == b.heading &&
           a.steering_angle == b.steering_angle && a.wheel_spin_angle == b.wheel_spin_angle &&
           a.arc_length == b.arc_length && a.forward_speed == b.forward_speed && a.steering_rate == b.steering_rate &&
           a.applied_work == b.applied_work && a.steering_impulse == b.steering_impulse &&
           a.steering_angle_low == b.steering_angle_low && a.heading_low == b.heading_low;
  }

  /// Starts afresh from a cart state: p = M(χ) ω, the angles' low parts as remainders, no memory.
  void start_from(const System& system, const CartState& state) {
    const CartBirkhoffianPoint fresh = system.to_birkhoffian(state);
    point.z = fresh.z;
    point.y = fresh.y;
    point.z_remainder.setZero();
    point.y_remainder.setZero();
    point.z_remainder(kSteeringAngleIndex) = state.steering_angle_low;
    point.y_remainder(kHeadingIndex) = state.heading_low;
    memory.clear();
    steering_turns = 0.0;
    heading_turns = 0.0;
    periodic_in_steering_angle = system.periodic_in_steering_angle();
    reduce_angles();
    valid = true;
  }

  void reduce_angles() {
    if (periodic_in_steering_angle) {
      reduce_angle(point.z(kSteeringAngleIndex), point.z_remainder(kSteeringAngleIndex), steering_turns);
    }
    reduce_angle(point.y(kHeadingIndex), point.y_remainder(kHeadingIndex), heading_turns);
  }

  /// The cart state at time t [s], angles unwrapped again as hi + lo; remembered for continues().
  CartState output(const System& system, double t) {
    CartState state = system.to_cart_state(point.z, point.y, t);
    unwrap_angle(point.z(kSteeringAngleIndex), point.z_remainder(kSteeringAngleIndex), steering_turns,
                 state.steering_angle, state.steering_angle_low);
    unwrap_angle(point.y(kHeadingIndex), point.y_remainder(kHeadingIndex), heading_turns, state.heading,
                 state.heading_low);
    last_output = state;
    return state;
  }
};

}  // namespace birkhoff_cart
