// The `odometry_sensor` section of a scene file (docs/scenes.md "odometry_sensor",
// docs/odometry_sensor.md): present, it enables the sensor; every key is optional (noise off).
//
//   odometry_sensor:
//     seed: 7
//     wheel_encoder_counts: 2048
//     wheel_radius_error: [0.002, -0.001]
//     wheel_distance_noise: 0.002
//     heading_source: wheels          # wheels | steering | gyro
//     ...
#include <cmath>
#include <limits>
#include <string>

#include "scene_reader.h"

namespace birkhoff_cart {
namespace scene_detail {
namespace {

/// The non-negative integer `name` of `parent` up to `largest`, or `fallback` when absent.
std::uint64_t optional_count(const SceneReader& reader, const YAML::Node& parent, const std::string& name,
                             std::uint64_t largest, std::uint64_t fallback) {
  if (!reader.has(parent, name)) return fallback;
  const std::string key = SceneReader::join("odometry_sensor", name);
  const double value = reader.number(reader.required(parent, "odometry_sensor", name), key, Range::kNonNegative);
  if (value != std::floor(value) || value > static_cast<double>(largest)) {
    reader.fail(key, "must be an integer from 0 to " + std::to_string(largest) + ", got " +
                         reader.required(parent, "odometry_sensor", name).Scalar());
  }
  return static_cast<std::uint64_t>(value);
}

}  // namespace

std::optional<OdometrySensorSettings> read_odometry_sensor(const SceneReader& reader, const YAML::Node& node) {
  if (!node) return std::nullopt;
  if (node.IsNull()) reader.fail("odometry_sensor", "is empty: give its keys, or leave the section out (sensor off)");
  reader.require_map(node, "odometry_sensor",
                     {"seed", "wheel_encoder_counts", "wheel_radius_error", "wheel_distance_noise", "heading_source",
                      "steering_encoder_counts", "steering_offset", "steering_noise", "gyro_noise_density",
                      "gyro_bias"});
  OdometrySensorSettings settings;
  constexpr std::uint64_t kLargestCount = 1u << 30;
  settings.seed = optional_count(reader, node, "seed", (std::uint64_t{1} << 53), settings.seed);
  settings.wheel_encoder_counts =
      static_cast<std::uint32_t>(optional_count(reader, node, "wheel_encoder_counts", kLargestCount, 0));
  settings.steering_encoder_counts =
      static_cast<std::uint32_t>(optional_count(reader, node, "steering_encoder_counts", kLargestCount, 0));
  if (reader.has(node, "wheel_radius_error")) {
    const YAML::Node errors = reader.required(node, "odometry_sensor", "wheel_radius_error");
    const std::string key = "odometry_sensor.wheel_radius_error";
    if (!errors.IsSequence() || errors.size() != 2) {
      reader.fail(key, "must be a list of two relative errors [rear_left, rear_right]");
    }
    for (std::size_t wheel = 0; wheel < 2; ++wheel) {
      const double error = reader.number(errors[wheel], key, Range::kFinite);
      if (!(std::abs(error) < 0.5)) reader.fail(key, "each error must be within (-0.5, 0.5), got " + errors[wheel].Scalar());
      settings.wheel_radius_error[wheel] = error;
    }
  }
  settings.wheel_distance_noise =
      reader.optional_number(node, "odometry_sensor", "wheel_distance_noise", Range::kNonNegative, 0.0);
  if (reader.has(node, "heading_source")) {
    settings.heading_source =
        heading_source_from_string(reader.choice(node, "odometry_sensor", "heading_source", {"wheels", "steering", "gyro"}));
  }
  settings.steering_offset = reader.optional_number(node, "odometry_sensor", "steering_offset", Range::kFinite, 0.0);
  settings.steering_noise = reader.optional_number(node, "odometry_sensor", "steering_noise", Range::kNonNegative, 0.0);
  settings.gyro_noise_density =
      reader.optional_number(node, "odometry_sensor", "gyro_noise_density", Range::kNonNegative, 0.0);
  settings.gyro_bias = reader.optional_number(node, "odometry_sensor", "gyro_bias", Range::kFinite, 0.0);
  return settings;
}

}  // namespace scene_detail
}  // namespace birkhoff_cart
