// What the cart's adapters carry from one step to the next (docs/birkhoffian.md §10.4): the generic
// carried point (carried_point.h) of a cart system — the point (z, y) with its compensated-summation
// remainders, the steering angle χ and heading θ reduced to (−π, π] with whole turns kept apart (the
// cart's rates are 2π-periodic in θ always and in χ unless a steering spring is enabled, so the ulp of
// χ no longer grows with the turns: at χ ≈ 2262 rad it was 4.5e-13 rad), and the memory of stage
// derivatives and Newton matrices — with its translation to and from the CartState. The CartState
// handed out carries each angle as hi + lo (state.h), so that diagnostics keep those bits too.
#pragma once

#include "birkhoff_cart/core/integrators/angle_reduction.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/carried_point.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// `PointSystem`: the system whose point is carried — System itself, or a system built on it with
/// the same leading coordinates (the time-transformed system: y with t appended).
template <class System, class Memory, class PointSystem = System>
struct CarriedCartState : CarriedPoint<System, Memory, PointSystem> {
  using Base = CarriedPoint<System, Memory, PointSystem>;
  using Base::memory;
  using Base::point;
  using Base::turns;
  using Base::valid;
  static constexpr std::size_t kSteering = System::kSteeringAngle;  ///< χ's turns in `turns`
  static constexpr std::size_t kHeading = System::kHeadingAngle;    ///< θ's turns in `turns`

  CartState last_output;  ///< what the adapter last handed out

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
    turns.fill(0.0);
    this->periodic_angles = system_traits::periodic_angles(system);
    this->reduce_angles();
    valid = true;
  }

  /// The cart state at time t [s], angles unwrapped again as hi + lo; remembered for continues().
  CartState output(const System& system, double t) {
    CartState state = system.to_cart_state(point.z, point.y, t);
    unwrap_angle(point.z(kSteeringAngleIndex), point.z_remainder(kSteeringAngleIndex), turns[kSteering],
                 state.steering_angle, state.steering_angle_low);
    unwrap_angle(point.y(kHeadingIndex), point.y_remainder(kHeadingIndex), turns[kHeading], state.heading,
                 state.heading_low);
    last_output = state;
    return state;
  }
};

}  // namespace birkhoff_cart
