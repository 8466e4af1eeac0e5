// The effect library: the table of the effects a scene can enable (one row each: name,
// coefficients with their ranges, units and typical values, and the factory that builds the
// effect), and build_effects, which builds the EffectSet of a scene from its EffectSpecs. Only the
// effects a scene names are constructed, so an absent (disabled) effect is never evaluated.
// Whatever names, reads, checks or builds an effect reads the table: effect_names(), the scene
// reader (the keys it allows and each coefficient's range, checked there once), build_effects, the
// random scenes (random_scene.h) and the tests' all-effects set. A new effect is its own files (header and source in effects/) and one
// row of the table (src/core/physics/effects/effect_library.cpp; docs/developing.md, "Adding an effect").
// Formulas: docs/derivation.md §4, eqs. (4.1)–(4.6).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/actuators/actuator_settings.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/effect_spec.h"
#include "birkhoff_cart/core/physics/torque_profile.h"

namespace birkhoff_cart {

class TorqueSource;

/// The values a coefficient may take (the scene reader checks it: docs/scenes.md "effects").
enum class CoefficientRange {
  kNonNegative,  ///< finite and ≥ 0
  kPositive,     ///< finite and > 0
};

/// One coefficient of an effect.
struct EffectCoefficient {
  const char* key;         ///< its key in the scene's effect map (effects.<effect>.<key>)
  CoefficientRange range;  ///< checked by the scene reader
  const char* unit;        ///< SI unit, for documentation ("-" when dimensionless)
  double typical;          ///< a typical value, in `unit` (the tests' all-effects set)
  double random_low;       ///< the random scenes draw it log-uniform from random_low …
  double random_high;      ///< … to random_high, in `unit` (random_scene.h)
};

/// The command input and actuator a torque effect takes its torque through (docs/actuators.md).
enum class TorqueChannel {
  kNone,      ///< a coefficient effect: no torque input
  kSteering,  ///< the steering torque: Simulation::set_steering_command, section steering_actuator
  kDrive,     ///< the drive torque: Simulation::set_drive_command, section drive_actuator
};

/// What an effect's factory is built from: the cart, the spec's coefficients (each present and
/// checked by the scene reader) and, for a torque effect, its torque source.
struct EffectParameters {
  const CartModel& model;
  const EffectSpec& spec;
  const TorqueSource* torque;  ///< the torque effect's source (profile or command, actuator); null otherwise

  /// The coefficient `key` of the spec [the row's unit].
  double coefficient(const std::string& key) const;
};

/// Builds an effect of a row from its parameters.
using EffectFactory = std::unique_ptr<Effect> (*)(const EffectParameters& parameters);

/// One row of the effect table.
struct EffectEntry {
  const char* name;                            ///< the key under `effects` (e.g. air_drag)
  const char* equation;                        ///< its equation in docs/derivation.md, e.g. "(4.4)"
  std::vector<EffectCoefficient> coefficients;  ///< none for a torque effect
  TorqueChannel torque_channel;                ///< kNone for a coefficient effect
  TorqueProfile typical_profile;               ///< a torque effect's typical profile (the tests' all-effects set)
  /// The chance [-] that a random scene (random_scene.h) enables it: a torque effect with a random
  /// constant or cosine profile, a coefficient effect with each coefficient drawn in its range.
  double random_chance;
  EffectFactory make;

  /// A torque effect: takes a TorqueProfile (its `profile` key and fields) instead of coefficients.
  bool takes_profile() const { return torque_channel != TorqueChannel::kNone; }
};

/// The effect table, in the order of docs/derivation.md §4: steering_torque (4.1), drive_torque
/// (4.2), rolling_resistance (4.3), air_drag (4.4), steering_damping (4.5), steering_stiffness (4.6).
const std::vector<EffectEntry>& effect_table();

/// The row named `name`; nullptr when there is none.
const EffectEntry* find_effect(const std::string& name);

/// The row named `name`. Throws std::invalid_argument naming it, listing the known names and the
/// closest one to a typo ("unknown effect 'air_drug' (known: …; did you mean 'air_drag'?)").
const EffectEntry& effect_entry(const std::string& name);

/// The table's effect names, in its order.
const std::vector<std::string>& effect_names();

/// The coefficient keys of the row, in its order (empty for a torque effect).
std::vector<std::string> coefficient_keys(const EffectEntry& entry);

/// Builds the enabled effects. The model is copied into the effects that need geometry, masses or
/// gravity. An effect whose profile is `command` gets a fresh CommandInput (initial value
/// profile.value) that the EffectSet exposes through steering_command()/drive_command().
/// The specs' coefficients are taken as the scene reader checked them (each in its row's range).
/// Throws std::invalid_argument naming an unknown effect, a duplicated effect, a missing or unknown
/// coefficient, or a bad profile value (non-finite, negative frequency, zero width ...).
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
