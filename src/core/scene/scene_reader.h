// Typed, range-checked reading of one scene file's YAML nodes. Every failure is a SceneError that
// names the file and the dotted key ("integrator.step_size"). Private to the scene loader.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {
namespace scene_detail {

/// Allowed range of a number read from a scene.
enum class Range {
  kFinite,       ///< any finite value
  kPositive,     ///< finite and > 0
  kNonNegative,  ///< finite and ≥ 0
};

class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

  /// "parent.key" (or "key" at the root).
  static std::string join(const std::string& parent, const std::string& key);

  /// `node` (at `key`) must be a map whose keys are all in `allowed` and none repeated.
  void require_map(const YAML::Node& node, const std::string& key, const std::vector<std::string>& allowed) const;
  /// The child `name` of map `parent` (at `parent_key`) must be present and not null.
  YAML::Node required(const YAML::Node& parent, const std::string& parent_key, const std::string& name) const;
  bool has(const YAML::Node& parent, const std::string& name) const;

  double number(const YAML::Node& node, const std::string& key, Range range) const;
  double required_number(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                         Range range) const;
  /// The number `name` of `parent`, or `fallback` when absent.
  double optional_number(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                         Range range, double fallback) const;
  int optional_positive_integer(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                                int fallback) const;
  std::string text(const YAML::Node& node, const std::string& key) const;
  /// The string `name` of `parent`, which must be one of `choices`.
  std::string choice(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                     const std::vector<std::string>& choices) const;
  bool optional_boolean(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                        bool fallback) const;

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

/// Refuses `text` (a scene document) longer than kMaxSceneBytes, nested deeper than kMaxSceneDepth
/// or holding a key or value that is not UTF-8, naming the key where it happens; YAML syntax errors
/// are the parser's (YAML::ParserException). One pass over the parser's events, no tree built.
void check_scene_structure(const SceneReader& reader, const std::string& text);

/// "a, b, c".
std::string join_names(const std::vector<std::string>& names);

/// Reads the `effects` map (enabled effects only, in file order).
std::vector<EffectSpec> read_effects(const SceneReader& reader, const YAML::Node& effects);

/// Reads the optional `odometry_sensor` map: absent, the sensor is off.
std::optional<OdometrySensorSettings> read_odometry_sensor(const SceneReader& reader, const YAML::Node& node);

/// Reads the optional steering_actuator, drive_actuator and steering_end_stops maps of the root.
ActuatorSettings read_actuators(const SceneReader& reader, const YAML::Node& root);

/// Reads the optional `accuracy` map over the defaults of AccuracyRequirements.
AccuracyRequirements read_accuracy(const SceneReader& reader, const YAML::Node& accuracy);

}  // namespace scene_detail
}  // namespace birkhoff_cart
