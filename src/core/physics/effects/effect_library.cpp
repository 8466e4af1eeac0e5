// The effect table (one row per effect) and build_effects: from the scene's EffectSpecs to the
// EffectSet of the enabled effects.
#include "birkhoff_cart/core/physics/effect_library.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

#include "birkhoff_cart/core/support/closest_name.h"
#include "birkhoff_cart/core/physics/effects/air_drag.h"
#include "birkhoff_cart/core/physics/effects/drive_torque.h"
#include "birkhoff_cart/core/physics/effects/rolling_resistance.h"
#include "birkhoff_cart/core/physics/effects/steering_damping.h"
#include "birkhoff_cart/core/physics/effects/steering_stiffness.h"
#include "birkhoff_cart/core/physics/effects/steering_torque.h"
#include "birkhoff_cart/core/physics/effects/torque_source.h"

namespace birkhoff_cart {
namespace {

[[noreturn]] void fail(const std::string& effect_name, const std::string& problem) {
  throw std::invalid_argument("effect '" + effect_name + "': " + problem);
}

/// Every coefficient of the row present in `spec`, and no other.
void require_row_coefficients(const EffectEntry& entry, const EffectSpec& spec) {
  const std::vector<std::string> known = coefficient_keys(entry);
  for (const auto& [key, value] : spec.coefficients) {
    static_cast<void>(value);
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      fail(spec.name, "unknown coefficient '" + key + "' (known: " + (known.empty() ? "none" : name_list(known)) + ")");
    }
  }
  for (const std::string& key : known) {
    if (spec.coefficients.count(key) == 0) fail(spec.name, "missing coefficient '" + key + "'");
  }
}

TorqueProfile constant_profile(double value) {
  TorqueProfile profile;
  profile.kind = TorqueProfile::Kind::kConstant;
  profile.value = value;  // [N·m]
  return profile;
}

TorqueProfile cosine_profile(double amplitude, double frequency) {
  TorqueProfile profile;
  profile.kind = TorqueProfile::Kind::kCosine;
  profile.amplitude = amplitude;  // [N·m]
  profile.frequency = frequency;  // [Hz]
  return profile;
}

/// The effect table. Each row: name, equation of docs/derivation.md, coefficients (key, range,
/// unit, typical value, the random scenes' range), torque channel, typical profile (torque
/// effects), the random scenes' chance, factory.
std::vector<EffectEntry> make_effect_table() {
  using Range = CoefficientRange;
  using P = const EffectParameters&;
  using Made = std::unique_ptr<Effect>;
  return {
      {"steering_torque", "(4.1)", {}, TorqueChannel::kSteering, cosine_profile(3.0, 0.4), 0.4,
       [](P p) -> Made { return std::make_unique<SteeringTorque>(*p.torque); }},
      {"drive_torque", "(4.2)", {}, TorqueChannel::kDrive, constant_profile(25.0), 0.4,
       [](P p) -> Made { return std::make_unique<DriveTorque>(*p.torque, p.model.parameters().rear_wheel_radius); }},
      {"rolling_resistance", "(4.3)",
       {{"coefficient", Range::kNonNegative, "-", 0.015, 0.001, 0.05},
        {"speed_epsilon", Range::kPositive, "m/s", 0.05, 0.01, 0.2}},
       TorqueChannel::kNone, {}, 0.3,
       [](P p) -> Made {
         return std::make_unique<RollingResistance>(p.model, p.coefficient("coefficient"), p.coefficient("speed_epsilon"));
       }},
      {"air_drag", "(4.4)", {{"coefficient", Range::kNonNegative, "kg/m", 0.4, 0.01, 2.0}}, TorqueChannel::kNone, {}, 0.3,
       [](P p) -> Made { return std::make_unique<AirDrag>(p.coefficient("coefficient")); }},
      {"steering_damping", "(4.5)", {{"coefficient", Range::kNonNegative, "N·m·s/rad", 2.0, 0.01, 5.0}}, TorqueChannel::kNone, {}, 0.2,
       [](P p) -> Made { return std::make_unique<SteeringDamping>(p.coefficient("coefficient")); }},
      {"steering_stiffness", "(4.6)", {{"coefficient", Range::kNonNegative, "N·m/rad", 15.0, 0.01, 20.0}}, TorqueChannel::kNone, {}, 0.2,
       [](P p) -> Made { return std::make_unique<SteeringStiffness>(p.coefficient("coefficient")); }},
  };
}

/// A torque source; for `command` profiles also a fresh CommandInput, stored in `command`.
TorqueSource torque_source(const EffectSpec& spec, std::shared_ptr<CommandInput>& command,
                           std::shared_ptr<TorqueActuator> actuator = nullptr) {
  validate_torque_profile(spec.name, spec.profile);
  if (spec.profile.kind == TorqueProfile::Kind::kCommand) {
    command = std::make_shared<CommandInput>();
    command->value = spec.profile.value;
  }
  return TorqueSource(spec.profile, command, std::move(actuator));
}

const char* profile_kind_name(TorqueProfile::Kind kind) {
  switch (kind) {
    case TorqueProfile::Kind::kConstant: return "constant";
    case TorqueProfile::Kind::kCosine: return "cosine";
    case TorqueProfile::Kind::kStep: return "step";
    case TorqueProfile::Kind::kRamp: return "ramp";
    case TorqueProfile::Kind::kSmoothSwitchOff: return "smooth_switch_off";
    case TorqueProfile::Kind::kCommand: return "command";
  }
  return "?";
}

/// The actuator of section `section` for the torque effect `spec` (nullptr without settings).
std::shared_ptr<TorqueActuator> actuator_for(const std::string& section, const std::optional<TorqueActuatorSettings>& settings,
                                             const EffectSpec* spec, double start_time) {
  if (!settings) return nullptr;
  validate_torque_actuator(section, *settings);
  const std::string effect = section == "steering_actuator" ? "steering_torque" : "drive_torque";
  if (!spec) throw std::invalid_argument(section + " needs the effect '" + effect + "' to act on; the scene has none");
  const TorqueProfile::Kind kind = spec->profile.kind;
  if (kind != TorqueProfile::Kind::kCommand && kind != TorqueProfile::Kind::kConstant &&
      kind != TorqueProfile::Kind::kStep) {
    throw std::invalid_argument(section + " needs a piecewise-constant input: effect '" + effect +
                                "' has profile '" + profile_kind_name(kind) +
                                "' (use source command, or a constant or step profile)");
  }
  return std::make_shared<TorqueActuator>(*settings, start_time, spec->profile.at(start_time));
}

/// The actuator at rest at `start_time` for the input of `spec`, a step profile's step pending.
void start_actuator(TorqueActuator& actuator, const EffectSpec& spec, double start_time) {
  const double initial = spec.profile.kind == TorqueProfile::Kind::kCommand ? spec.profile.value
                                                                            : spec.profile.at(start_time);
  actuator = TorqueActuator(actuator.settings(), start_time, initial);
  if (spec.profile.kind == TorqueProfile::Kind::kStep && spec.profile.step_time > start_time) {
    actuator.command(spec.profile.step_time, spec.profile.final);
  }
}

const EffectSpec* find_spec(const std::vector<EffectSpec>& specs, const std::string& name) {
  for (const EffectSpec& spec : specs) {
    if (spec.name == name) return &spec;
  }
  return nullptr;
}

}  // namespace

double EffectParameters::coefficient(const std::string& key) const {
  const auto found = spec.coefficients.find(key);
  if (found == spec.coefficients.end()) fail(spec.name, "missing coefficient '" + key + "'");
  return found->second;
}

const std::vector<EffectEntry>& effect_table() {
  static const std::vector<EffectEntry> kTable = make_effect_table();
  return kTable;
}

const EffectEntry* find_effect(const std::string& name) {
  for (const EffectEntry& entry : effect_table()) {
    if (name == entry.name) return &entry;
  }
  return nullptr;
}

const EffectEntry& effect_entry(const std::string& name) {
  const EffectEntry* entry = find_effect(name);
  if (entry == nullptr) throw std::invalid_argument(unknown_name_message("effect", name, effect_names()));
  return *entry;
}

const std::vector<std::string>& effect_names() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    for (const EffectEntry& entry : effect_table()) names.emplace_back(entry.name);
    return names;
  }();
  return kNames;
}

std::vector<std::string> coefficient_keys(const EffectEntry& entry) {
  std::vector<std::string> keys;
  for (const EffectCoefficient& coefficient : entry.coefficients) keys.emplace_back(coefficient.key);
  return keys;
}

EffectSet build_effects(const std::vector<EffectSpec>& specs, const CartModel& model) {
  return build_effects(specs, model, ActuatorSettings{}, 0.0);
}

void start_actuators(const EffectSet& effects, const std::vector<EffectSpec>& specs, double start_time) {
  if (effects.steering_actuator()) start_actuator(*effects.steering_actuator(), *find_spec(specs, "steering_torque"), start_time);
  if (effects.drive_actuator()) start_actuator(*effects.drive_actuator(), *find_spec(specs, "drive_torque"), start_time);
  if (effects.end_stops()) effects.end_stops()->set_contact(SteeringEndStops::Contact::kNone);
}

EffectSet build_effects(const std::vector<EffectSpec>& specs, const CartModel& model, const ActuatorSettings& actuators,
                        double start_time) {
  EffectSet effects;
  const std::shared_ptr<TorqueActuator> steering_actuator =
      actuator_for("steering_actuator", actuators.steering, find_spec(specs, "steering_torque"), start_time);
  const std::shared_ptr<TorqueActuator> drive_actuator =
      actuator_for("drive_actuator", actuators.drive, find_spec(specs, "drive_torque"), start_time);
  std::set<std::string> seen;
  for (const EffectSpec& spec : specs) {
    const EffectEntry& entry = effect_entry(spec.name);
    require_row_coefficients(entry, spec);
    if (!seen.insert(spec.name).second) fail(spec.name, "named twice");
    std::shared_ptr<CommandInput> command;
    std::optional<TorqueSource> torque;
    if (entry.torque_channel == TorqueChannel::kSteering) torque = torque_source(spec, command, steering_actuator);
    if (entry.torque_channel == TorqueChannel::kDrive) torque = torque_source(spec, command, drive_actuator);
    effects.add(entry.make(EffectParameters{model, spec, torque ? &*torque : nullptr}));
    if (command && entry.torque_channel == TorqueChannel::kSteering) effects.set_steering_command_input(command);
    if (command && entry.torque_channel == TorqueChannel::kDrive) effects.set_drive_command_input(command);
  }
  effects.set_steering_actuator(steering_actuator);
  effects.set_drive_actuator(drive_actuator);
  if (actuators.end_stops) effects.set_end_stops(std::make_shared<SteeringEndStops>(*actuators.end_stops, model));
  start_actuators(effects, specs, start_time);
  return effects;
}

}  // namespace birkhoff_cart
