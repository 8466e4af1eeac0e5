// The cart's mutable state, kept apart from the constant model (parameters, effects).
#pragma once

#include <array>

namespace birkhoff_cart {

/// Full state of the cart at one instant. Coordinates follow the paper (§4) and DESIGN.md §4.
struct CartState {
  double time = 0.0;                              ///< t [s] (scene time)
  double x = 0.0;                                 ///< x of hinge B [m]
  double y = 0.0;                                 ///< y of hinge B [m]
  double heading = 0.0;                           ///< θ: rear body heading [rad]
  double steering_angle = 0.0;                    ///< χ: front axle relative to rear body, unwrapped [rad]
  std::array<double, 4> wheel_spin_angle{};       ///< φ1..φ4 (rear-left, rear-right, front-left, front-right) [rad]
  double arc_length = 0.0;                        ///< π1: signed arc length travelled by B [m]
  double forward_speed = 0.0;                     ///< ω1: speed of B along the front axle heading [m/s]
  double steering_rate = 0.0;                     ///< ω2 = χ̇ [rad/s]
  double applied_work = 0.0;                      ///< W = ∫ ω·Q dt since the start [J] (energy balance)
  double steering_impulse = 0.0;                  ///< I2 = ∫ Q2 dt since the start [N·m·s] (p2 balance)
  /// Low parts of the unwrapped angles: χ = steering_angle + steering_angle_low, θ = heading + heading_low
  /// exactly (to ~1e-30 rad). The integrators keep angles reduced with their turns apart; an unwrapped
  /// double alone would lose the ulp of a many-times-turned angle (4.5e-13 rad at 2262 rad) in every
  /// function periodic in it. Zero for a state set by hand; readers that need no such precision ignore them.
  double steering_angle_low = 0.0;                ///< [rad]
  double heading_low = 0.0;                       ///< [rad]
};

/// Indices of the Birkhoffian variables z = (π1, χ, p1, p2) of the cart (docs/birkhoffian.md).
enum BirkhoffianIndex : int {
  kArcLengthIndex = 0,        ///< π1 [m]
  kSteeringAngleIndex = 1,    ///< χ [rad]
  kForwardMomentumIndex = 2,  ///< p1 = ∂T*/∂ω1 [kg·m/s]
  kSteeringMomentumIndex = 3, ///< p2 = ∂T*/∂ω2 [kg·m²/s]
  kBirkhoffianSize = 4
};

/// Indices of the coordinates reconstructed alongside z ("passive": they do not feed back).
enum PassiveIndex : int {
  kXIndex = 0,                 ///< x [m]
  kYIndex = 1,                 ///< y [m]
  kHeadingIndex = 2,           ///< θ [rad]
  kWheel1Index = 3,            ///< φ1 [rad]; φ2, φ3, φ4 follow
  kAppliedWorkIndex = 7,       ///< W [J]
  kSteeringImpulseIndex = 8,   ///< I2 [N·m·s]
  kPassiveSize = 9
};

}  // namespace birkhoff_cart
