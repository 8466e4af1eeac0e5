// build_effects: from the scene's EffectSpecs to the EffectSet of the enabled effects.
#include "birkhoff_cart/core/effect_library.h"

#include <cmath>
#include <map>
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
TorqueSource torque_source(const EffectSpec& spec, std::shared_ptr<CommandInput>& command) {
  validate_torque_profile(spec.name, spec.profile);
  if (spec.profile.kind == TorqueProfile::Kind::kCommand) {
    command = std::make_shared<CommandInput>();
    command->value = spec.profile.value;
  }
  return TorqueSource(spec.profile, command);
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
  EffectSet effects;
  std::set<std::string> seen;
  for (const EffectSpec& spec : specs) {
    reject_unknown_coefficients(spec);  // also rejects an unknown effect name
    if (!seen.insert(spec.name).second) fail(spec.name, "named twice");
    if (spec.name == "steering_torque") {
      std::shared_ptr<CommandInput> command;
      effects.add(std::make_unique<SteeringTorque>(torque_source(spec, command)));
      if (command) effects.set_steering_command_input(command);
    } else if (spec.name == "drive_torque") {
      std::shared_ptr<CommandInput> command;
      effects.add(std::make_unique<DriveTorque>(torque_source(spec, command), model.parameters().rear_wheel_radius));
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
  return effects;
}

}  // namespace birkhoff_cart
