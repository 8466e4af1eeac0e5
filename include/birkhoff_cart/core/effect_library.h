// The effect library: builds the EffectSet of a scene from its EffectSpecs. Only the effects a
// scene names are constructed, so an absent (disabled) effect is never evaluated.
// Formulas: docs/derivation.md §4, eqs. (4.1)–(4.6).
#pragma once

#include <string>
#include <vector>

#include "birkhoff_cart/core/actuators/actuator_settings.h"
#include "birkhoff_cart/core/cart_model.h"
#include "birkhoff_cart/core/effects.h"
#include "birkhoff_cart/core/effect_spec.h"

namespace birkhoff_cart {

/// Known effect names, in the order of docs/derivation.md §4: steering_torque (4.1),
/// drive_torque (4.2), rolling_resistance (4.3), air_drag (4.4), steering_damping (4.5),
/// steering_stiffness (4.6).
const std::vector<std::string>& effect_names();

/// The coefficient names each coefficient effect takes (empty for the two torque effects, which
/// take a TorqueProfile instead). Throws std::invalid_argument for an unknown effect name.
const std::vector<std::string>& effect_coefficient_names(const std::string& effect_name);

/// Builds the enabled effects. The model is copied into the effects that need geometry, masses or
/// gravity. An effect whose profile is `command` gets a fresh CommandInput (initial value
/// profile.value) that the EffectSet exposes through steering_command()/drive_command().
/// Throws std::invalid_argument naming an unknown effect, a duplicated effect, a missing or
/// unknown coefficient, or a bad coefficient/profile value (non-finite, negative, zero width ...).
EffectSet build_effects(const std::vector<EffectSpec>& specs, const CartModel& model);

/// As above, with the scene's actuators between the inputs and the torque effects and its steering
/// end stops (docs/actuators.md), the actuators at rest at `start_time` [s]. An actuator needs its
/// torque effect with a piecewise-constant input (source command, or a constant or step profile);
/// std::invalid_argument names the section otherwise.
EffectSet build_effects(const std::vector<EffectSpec>& specs, const CartModel& model, const ActuatorSettings& actuators,
                        double start_time);

/// Puts the actuators of `effects` at rest at `start_time` [s] with their initial inputs (the
/// command's initial value or the profile's value there, a step profile's later step pending), and
/// the end stops out of contact (a run's start: reset()).
void start_actuators(const EffectSet& effects, const std::vector<EffectSpec>& specs, double start_time);

}  // namespace birkhoff_cart
