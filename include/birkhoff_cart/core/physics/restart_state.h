// What a state must be for a run to restart from it (Simulation::restart_from: the node's
// ~set_state and initialpose teleports). Checked before anything changes, each failure an
// std::invalid_argument naming the field, its value and the limit (docs/ros_interface.md, "~set_state"):
//   - every field finite, and the kinetic energy T* finite;
//   - positions and angles a double still resolves: |x|, |y| <= kLargestRestartPosition (the hinge
//     B), |θ|, |χ| <= kLargestRestartAngle; beyond, a step's motion is lost in the rounding of the
//     coordinate (at x = 1e20 m one ulp is 16 km: the cart would never move);
//   - speeds one step resolves: in a step of h the front axle turns by at most kLargestStepFraction
//     rad (|ω2| h <= 0.1 rad) and the hinge travels at most kLargestStepFraction of the wheelbase
//     (|ω1| h <= 0.1 l, so the body turns by at most 0.1 rad: θ̇ = ω1 sin χ / l). From states at
//     0.5, 0.9 and 1 times these limits, χ from 0 to π, every member of the registry stepped 3000
//     steps without a failure on six shipped scenes (seven members on the other seven); at 1 rad
//     per step a jackknifed cart broke within 10 steps (a singular Newton matrix, a non-finite π1);
//   - no singular steering angle within the next step (the paper's special case, docs/hard_cases.md §1);
//   - a steering angle within the scene's end stops.
// The trial step from the state (a stepper of its own) is Simulation::restart_from's.
#pragma once

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// Largest |x|, |y| of the hinge a restart may place the cart at [m]: one ulp there is 1.2e-10 m.
constexpr double kLargestRestartPosition = 1e6;
/// Largest |θ|, |χ| a restart may set [rad]: one ulp there is 1.2e-10 rad.
constexpr double kLargestRestartAngle = 1e6;
/// Largest turn of χ in one step from a restart state [rad], and the largest travel of the hinge in
/// one step as a fraction of the wheelbase [-].
constexpr double kLargestStepFraction = 0.1;

/// Throws std::invalid_argument ("restart state: <field> ...") when `state` breaks a rule above for
/// `model` and `effects` (end stops) at step size `step_size` [s].
void check_restart_state(const CartModel& model, const EffectSet& effects, const CartState& state, double step_size);

}  // namespace birkhoff_cart
