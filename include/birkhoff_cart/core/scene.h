// A scene: the cart, its initial state, the effects it enables, the integrator and the reference.
// Loaded from YAML (config/scenes/*.yaml, schema in docs/scenes.md) and validated; the
// struct itself is plain data.
#pragma once

#include <map>
#include <stdexcept>
#include <limits>
#include <string>
#include <vector>

#include "birkhoff_cart/core/accuracy_guard.h"
#include "birkhoff_cart/core/parameters.h"
#include "birkhoff_cart/core/state.h"

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

/// A time profile of a torque, or the command source (written by the ROS node).
struct TorqueProfile {
  enum class Kind {
    kConstant,         ///< value
    kCosine,           ///< amplitude·cos(2π frequency t + phase)
    kStep,             ///< initial for t < step_time, final after
    kRamp,             ///< initial → final linearly over [start_time, end_time]
    kSmoothSwitchOff,  ///< initial · ½(1 − tanh((t − switch_off_time)/width))
    kCommand,          ///< the latest command (zero-order hold), initial value `value`
  };
  Kind kind = Kind::kConstant;
  double value = 0.0;            ///< constant / initial command [N·m]
  double amplitude = 0.0;        ///< [N·m]
  double frequency = 0.0;        ///< [Hz]
  double phase = 0.0;            ///< [rad]
  double initial = 0.0;          ///< [N·m]
  double final = 0.0;            ///< [N·m]
  double step_time = 0.0;        ///< [s]
  double start_time = 0.0;       ///< [s]
  double end_time = 0.0;         ///< [s]
  double switch_off_time = 0.0;  ///< [s]
  /// The first time > t [s] where the profile is not smooth (a step, a ramp's corners); +∞ if none.
  double next_kink_after(double t) const;
  double width = 1.0;            ///< [s]

  /// The torque at time t [N·m] (for kCommand: `value`; the effect reads its command input).
  double at(double time) const;
};

/// One enabled effect as the scene names it.
struct EffectSpec {
  std::string name;                           ///< steering_torque, drive_torque, rolling_resistance, ...
  TorqueProfile profile;                      ///< for steering_torque and drive_torque
  std::map<std::string, double> coefficients; ///< for the others, e.g. {"coefficient": 0.015, "speed_epsilon": 0.05}
};

/// Integrator choice and its settings.
struct IntegratorSettings {
  std::string name = "birkhoff2";                 ///< a name from integrator_names()
  double step_size = 1e-3;                        ///< h [s]
  double tolerance = 1e-10;                       ///< dopri5 absolute and relative tolerance [-]
  std::string birkhoffian_form = "autonomous";    ///< "autonomous" (z = (π1, χ, p1, p2), K = K₀) or "paper" (K = eᵗ J)
  int max_newton_iterations = 30;                 ///< per implicit step
  double newton_tolerance = 1e-14;                ///< on the scaled Newton update [-]
  bool compensated_summation = true;              ///< Birkhoffian members: Kahan/TwoSum state update
  bool local_error_estimate = true;               ///< Birkhoffian members: compute ê (one more rhs evaluation a step)
  /// "fixed": steps of step_size. "reversible" (symmetric Birkhoffian members): internal steps
  /// chosen by the reversible controller (docs/birkhoffian.md §11) for `tolerance` as the position
  /// error [m] the run may reach by `tolerance_horizon`; step_size is then only the output step.
  std::string step_control = "fixed";
  double tolerance_horizon = 0.0;   ///< reversible: the time the tolerance is for [s]; 0: the scene's duration
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
};

/// Loads and validates a scene. Throws SceneError naming the file and the key.
Scene load_scene(const std::string& path);

}  // namespace birkhoff_cart
