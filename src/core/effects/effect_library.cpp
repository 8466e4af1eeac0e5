// build_effects: from the scene's EffectSpecs to the EffectSet of the enabled effects.
#include "birkhoff_cart/core/effect_library.h"

#include <cmath>
#include <map>
#include <optional>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/effects/air_drag.h"
#include "birkhoff_cart/core/effects/drive_torque.h"
#include "birkhoff_cart/core/effects/rolling_resistance.h"
#include "birkhoff_cart/core/effects/steering_damping.h"
#include "birkhoff_cart/core/effects/steering_stiffness.h"
#include "birkhoff_cart/core/effects/steering_torque.h"
#include "birkhoff_cart/core/effects/torque_source.h"

namespace birkhoff_cart {
namespace {

std::string join(const std::vector<std::string>& names) {
  std::string joined;
  for (const auto& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

[[noreturn]] void fail(const std::string& effect_name, const std::string& problem) {
  throw std::invalid_argument("effect '" + effect_name + "': " + problem);
}

/// The coefficient `key` of `spec`: present, finite, ≥ 0 (> 0 when `strictly_positive`).
double coefficient(const EffectSpec& spec, const std::string& key, bool strictly_positive) {
  const auto found = spec.coefficients.find(key);
  if (found == spec.coefficients.end()) fail(spec.name, "missing coefficient '" + key + "'");
  const double value = found->second;
  if (!std::isfinite(value) || value < 0.0 || (strictly_positive && value == 0.0)) {
    std::ostringstream problem;
    problem << "coefficient '" << key << "' must be finite and " << (strictly_positive ? "> 0" : ">= 0")
            << ", got " << value;
    fail(spec.name, problem.str());
  }
  return value;
}

void reject_unknown_coefficients(const EffectSpec& spec) {
  const std::vector<std::string>& known = effect_coefficient_names(spec.name);
  for (const auto& [key, value] : spec.coefficients) {
    (void)value;
    bool is_known = false;
    for (const auto& name : known) is_known = is_known || name == key;
    if (!is_known) {
      fail(spec.name, "unknown coefficient '" + key + "' (known: " + (known.empty() ? "none" : join(known)) + ")");
    }
  }
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

const std::vector<std::string>& effect_names() {
  static const std::vector<std::string> kNames = {"steering_torque",  "drive_torque",     "rolling_resistance",
                                                  "air_drag",         "steering_damping", "steering_stiffness"};
  return kNames;
}

const std::vector<std::string>& effect_coefficient_names(const std::string& effect_name) {
  static const std::map<std::string, std::vector<std::string>> kCoefficients = {
      {"steering_torque", {}},
      {"drive_torque", {}},
      {"rolling_resistance", {"coefficient", "speed_epsilon"}},
      {"air_drag", {"coefficient"}},
      {"steering_damping", {"coefficient"}},
      {"steering_stiffness", {"coefficient"}},
  };
  const auto found = kCoefficients.find(effect_name);
  if (found == kCoefficients.end()) {
    throw std::invalid_argument("unknown effect '" + effect_name + "' (known: " + join(effect_names()) + ")");
  }
  return found->second;
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
    reject_unknown_coefficients(spec);  // also rejects an unknown effect name
    if (!seen.insert(spec.name).second) fail(spec.name, "named twice");
    if (spec.name == "steering_torque") {
      std::shared_ptr<CommandInput> command;
      effects.add(std::make_unique<SteeringTorque>(torque_source(spec, command, steering_actuator)));
      if (command) effects.set_steering_command_input(command);
    } else if (spec.name == "drive_torque") {
      std::shared_ptr<CommandInput> command;
      effects.add(std::make_unique<DriveTorque>(torque_source(spec, command, drive_actuator),
                                                model.parameters().rear_wheel_radius));
      if (command) effects.set_drive_command_input(command);
    } else if (spec.name == "rolling_resistance") {
      effects.add(std::make_unique<RollingResistance>(model, coefficient(spec, "coefficient", false),
                                                      coefficient(spec, "speed_epsilon", true)));
    } else if (spec.name == "air_drag") {
      effects.add(std::make_unique<AirDrag>(coefficient(spec, "coefficient", false)));
    } else if (spec.name == "steering_damping") {
      effects.add(std::make_unique<SteeringDamping>(coefficient(spec, "coefficient", false)));
    } else if (spec.name == "steering_stiffness") {
      effects.add(std::make_unique<SteeringStiffness>(coefficient(spec, "coefficient", false)));
    }
  }
  effects.set_steering_actuator(steering_actuator);
  effects.set_drive_actuator(drive_actuator);
  if (actuators.end_stops) effects.set_end_stops(std::make_shared<SteeringEndStops>(*actuators.end_stops, model));
  start_actuators(effects, specs, start_time);
  return effects;
}

}  // namespace birkhoff_cart
