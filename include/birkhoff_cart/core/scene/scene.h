// A scene: the cart, its initial state, the effects it enables, the integrator and the reference.
// Loaded from YAML (config/scenes/*.yaml, schema in docs/scenes.md) and validated; the
// struct itself is plain data.
#pragma once

#include <cstddef>
#include <limits>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/physics/actuators/actuator_settings.h"
#include "birkhoff_cart/core/physics/effect_spec.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/physics/parameters.h"
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// A scene file that cannot be used. what() is one line naming the file and the key.
class SceneError : public std::runtime_error {
 public:
  SceneError(const std::string& file, const std::string& key, const std::string& problem);
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }

 private:
  std::string file_;
  std::string key_;
};

/// What the simulation compares itself against, computed only when asked for.
struct ReferenceSettings {
  enum class Kind { kNone, kPaperAnalytic, kShadowRun };
  Kind kind = Kind::kNone;
  IntegratorSettings shadow;                      ///< for kShadowRun (e.g. dopri5 at 1e-12)
};

struct Scene {
  std::string name;                    ///< file stem, e.g. "free_coast"
  std::string source_path;             ///< the YAML file it came from
  std::string description;             ///< one line
  CartParameters cart;                 ///< validated
  bool paper_special_case = false;     ///< μ = μ1 = 0, ν = 1, l = 1 (paper eq. (20))
  CartState initial_state;             ///< includes the start time
  double duration = 0.0;               ///< simulated time after the start [s], > 0
  IntegratorSettings integrator;
  double output_rate = 100.0;          ///< CSV / publish rate [Hz]
  std::vector<EffectSpec> effects;     ///< only the enabled ones
  ReferenceSettings reference;
  AccuracyRequirements accuracy;       ///< the `accuracy` section (defaults: docs/accuracy.md §2)
  /// The `odometry_sensor` section: odometry from simulated encoders (docs/odometry_sensor.md);
  /// none = odometry is the exact state.
  std::optional<OdometrySensorSettings> odometry_sensor;
  /// The `steering_actuator`, `drive_actuator` and `steering_end_stops` sections (docs/actuators.md);
  /// none = commands reach the cart unchanged and χ has no stops.
  ActuatorSettings actuators;
};

/// The largest scene a face reads [bytes] (the study runner's cap, MAX_SCENE_BYTES): a longer file is
/// refused before it is parsed, a pipe or device read no further (docs/scenes.md "Limits").
constexpr std::size_t kMaxSceneBytes = 1024 * 1024;
/// The deepest nesting of maps and lists in a scene (its root map is level 1; the shipped scenes
/// use at most 4).
constexpr int kMaxSceneDepth = 64;

/// The text of the scene file at `path`, read within kMaxSceneBytes. SceneError (key "(file)") for a
/// file that cannot be opened, a directory, or a longer file, pipe or device.
std::string read_scene_file(const std::string& path);

/// Loads and validates a scene (its text by read_scene_file). Throws SceneError naming the file and
/// the key.
Scene load_scene(const std::string& path);

/// The same from the YAML text of a scene document; `source` stands for the file in the scene's
/// name (its stem), source_path and every SceneError (the Python module: a dict, or a file with
/// overrides). Within the same bounds: at most kMaxSceneBytes, nested at most kMaxSceneDepth deep,
/// UTF-8 (each refused by the key where it happens, before the document is built).
Scene load_scene_text(const std::string& text, const std::string& source);

}  // namespace birkhoff_cart
