// The `effects` section of a scene file: effect name → its parameters (docs/scenes.md "effects"), as
// the effect table (effect_library.h) names them, with each coefficient in its row's range.
#include <map>

#include "birkhoff_cart/core/physics/effect_library.h"
#include "scene_reader.h"

namespace birkhoff_cart {
namespace scene_detail {
namespace {

using Kind = TorqueProfile::Kind;

struct ProfileKeys {
  Kind kind;
  std::vector<std::string> required;  ///< number keys that must be given
  std::vector<std::string> optional;  ///< number keys with a default (0)
};

const std::map<std::string, ProfileKeys>& profile_keys() {
  static const std::map<std::string, ProfileKeys> kProfiles = {
      {"constant", {Kind::kConstant, {"value"}, {}}},
      {"cosine", {Kind::kCosine, {"amplitude", "frequency"}, {"phase"}}},
      {"step", {Kind::kStep, {"initial", "final", "step_time"}, {}}},
      {"ramp", {Kind::kRamp, {"initial", "final", "start_time", "end_time"}, {}}},
      {"smooth_switch_off", {Kind::kSmoothSwitchOff, {"initial", "switch_off_time", "width"}, {}}},
      {"command", {Kind::kCommand, {}, {"value"}}},
  };
  return kProfiles;
}

void set_profile_field(TorqueProfile& profile, const std::string& field, double value) {
  if (field == "value") profile.value = value;
  if (field == "amplitude") profile.amplitude = value;
  if (field == "frequency") profile.frequency = value;
  if (field == "phase") profile.phase = value;
  if (field == "initial") profile.initial = value;
  if (field == "final") profile.final = value;
  if (field == "step_time") profile.step_time = value;
  if (field == "start_time") profile.start_time = value;
  if (field == "end_time") profile.end_time = value;
  if (field == "switch_off_time") profile.switch_off_time = value;
  if (field == "width") profile.width = value;
}

TorqueProfile read_profile(const SceneReader& reader, const YAML::Node& node, const std::string& key) {
  std::vector<std::string> profile_names;
  for (const auto& [name, keys] : profile_keys()) profile_names.push_back(name);
  if (!node.IsMap()) reader.fail(key, "must be a map with a 'profile' key");
  const std::string profile_name = reader.choice(node, key, "profile", profile_names);
  const ProfileKeys& keys = profile_keys().at(profile_name);
  std::vector<std::string> allowed = {"profile", "enabled"};
  allowed.insert(allowed.end(), keys.required.begin(), keys.required.end());
  allowed.insert(allowed.end(), keys.optional.begin(), keys.optional.end());
  reader.require_map(node, key, allowed);

  TorqueProfile profile;
  profile.kind = keys.kind;
  for (const auto& field : keys.required) {
    const Range range = field == "frequency" ? Range::kNonNegative : field == "width" ? Range::kPositive : Range::kFinite;
    set_profile_field(profile, field, reader.required_number(node, key, field, range));
  }
  for (const auto& field : keys.optional) {
    set_profile_field(profile, field, reader.optional_number(node, key, field, Range::kFinite, 0.0));
  }
  if (profile.kind == Kind::kRamp && !(profile.end_time > profile.start_time)) {
    reader.fail(SceneReader::join(key, "end_time"), "must be later than start_time");
  }
  return profile;
}

}  // namespace

std::vector<EffectSpec> read_effects(const SceneReader& reader, const YAML::Node& effects) {
  std::vector<EffectSpec> specs;
  if (!effects || effects.IsNull()) return specs;  // free cart
  reader.require_map(effects, "effects", effect_names());
  for (const auto& entry : effects) {
    EffectSpec spec;
    spec.name = entry.first.Scalar();
    const std::string key = SceneReader::join("effects", spec.name);
    const YAML::Node& node = entry.second;
    const EffectEntry& row = effect_entry(spec.name);  // known: require_map allowed only the table's names
    if (row.takes_profile()) {
      spec.profile = read_profile(reader, node, key);
    } else {
      const std::vector<std::string> coefficient_names = coefficient_keys(row);
      if (!node.IsMap()) reader.fail(key, "must be a map of coefficients (" + join_names(coefficient_names) + ")");
      std::vector<std::string> allowed = coefficient_names;
      allowed.push_back("enabled");
      reader.require_map(node, key, allowed);
      // Each coefficient checked here, once: in the range its row of the effect table states.
      for (const EffectCoefficient& coefficient : row.coefficients) {
        const Range range = coefficient.range == CoefficientRange::kPositive ? Range::kPositive : Range::kNonNegative;
        spec.coefficients[coefficient.key] = reader.required_number(node, key, coefficient.key, range);
      }
    }
    // `enabled: false` keeps the parameters in the file but leaves the effect out of the scene.
    if (reader.optional_boolean(node, key, "enabled", true)) specs.push_back(spec);
  }
  return specs;
}

}  // namespace scene_detail
}  // namespace birkhoff_cart
