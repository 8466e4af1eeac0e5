// Effect-cost benchmark: the per-evaluation cost of the cart's reduced right-hand side grows only
// with the effects a scene enables. For 0..6 enabled effects it times N evaluations of
//   Q = EffectSet::evaluate (via generalized_force),  ω̇ = M⁻¹(Q − h)  (eq. (3.4)),
//   (ẋ, ẏ, θ̇, φ̇)  (eqs. (2.3)–(2.4)),
// and a scene that lists every effect with `enabled: false` (which must cost what the free cart
// costs). Then the cost of a whole birkhoff_gauss4 step with commanded torques, without actuators,
// with the steering and drive actuators of docs/actuators.md, and with the steering end stops too
// (which must add nothing while the axle is free and nothing at all when the scene has no sections).
// Median of the repetitions after a warm-up; a volatile sink keeps the work alive.
//
// Usage: effects_benchmark [evaluations_per_repetition=200000] [repetitions=7]
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/support/version.h"

namespace {

using namespace birkhoff_cart;

volatile double g_sink = 0.0;  // defeats dead-code elimination of the timed work

/// Inputs cycled through by the timed loop (varied so nothing is loop-invariant).
struct Sample {
  double time;            // t [s]
  double heading;         // θ [rad]
  double steering_angle;  // χ [rad]
  Vector2<double> quasi_velocity;  // (ω1 [m/s], ω2 [rad/s])
};

std::vector<Sample> make_samples() {
  std::vector<Sample> samples;
  for (int i = 0; i < 64; ++i) {
    const double phase = 0.1 * i;
    samples.push_back({0.05 * i, 0.3 * std::sin(phase), 0.6 * std::sin(1.7 * phase),
                       Vector2<double>(3.0 * std::cos(0.9 * phase), 0.8 * std::sin(2.3 * phase))});
  }
  return samples;
}

/// Wall time of `evaluations` right-hand sides [ns per evaluation].
double time_right_hand_side(const CartModel& model, const EffectSet& effects, const std::vector<Sample>& samples,
                            long evaluations) {
  double accumulated = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (long k = 0; k < evaluations; ++k) {
    const Sample& sample = samples[static_cast<std::size_t>(k) & 63u];
    const Vector2<double> force =
        effects.generalized_force<double>(sample.time, sample.steering_angle, sample.quasi_velocity);
    const Vector2<double> acceleration = model.quasi_acceleration(sample.steering_angle, sample.quasi_velocity, force);
    const CoordinateRates<double> rates = model.coordinate_rates(sample.heading, sample.steering_angle, sample.quasi_velocity);
    accumulated += acceleration(0) + acceleration(1) + rates.x_rate + rates.y_rate + rates.heading_rate +
                   rates.wheel_spin_rate[0] + rates.wheel_spin_rate[3];
  }
  const auto stop = std::chrono::steady_clock::now();
  g_sink = g_sink + accumulated;
  return std::chrono::duration<double, std::nano>(stop - start).count() / static_cast<double>(evaluations);
}

double median_time(const CartModel& model, const EffectSet& effects, const std::vector<Sample>& samples,
                   long evaluations, int repetitions) {
  time_right_hand_side(model, effects, samples, evaluations / 4 + 1);  // warm-up
  std::vector<double> times;
  for (int repetition = 0; repetition < repetitions; ++repetition) {
    times.push_back(time_right_hand_side(model, effects, samples, evaluations));
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

EffectSpec torque(const std::string& name, double amplitude, double frequency) {
  EffectSpec spec;
  spec.name = name;
  spec.profile.kind = TorqueProfile::Kind::kCosine;
  spec.profile.amplitude = amplitude;  // [N·m]
  spec.profile.frequency = frequency;  // [Hz]
  return spec;
}

EffectSpec coefficients(const std::string& name, std::map<std::string, double> values) {
  EffectSpec spec;
  spec.name = name;
  spec.coefficients = std::move(values);
  return spec;
}

/// A scene file listing all six effects, each with `enabled: false` (written to a temp file).
Scene load_all_disabled_scene() {
  char path[] = "/tmp/effects_benchmark_XXXXXX";
  const int descriptor = mkstemp(path);
  if (descriptor < 0) throw std::runtime_error("cannot create a temporary scene file");
  close(descriptor);
  // The default cart, coasting, with every effect listed and switched off.
  const std::string text =
      "description: every effect listed, none enabled\n"
      "cart: {wheelbase: 1.05, rear_half_track: 0.55, front_half_track: 0.5, rear_wheel_radius: 0.14,\n"
      "       front_wheel_radius: 0.13, rear_body_mass: 140.0, rear_body_yaw_inertia: 30.0,\n"
      "       front_axle_mass: 12.0, front_axle_yaw_inertia: 1.0, rear_wheel_mass: 3.0,\n"
      "       rear_wheel_spin_inertia: 0.03, rear_wheel_yaw_inertia: 0.025, front_wheel_mass: 2.2,\n"
      "       front_wheel_spin_inertia: 0.019, front_wheel_yaw_inertia: 0.013, gravity: 9.81}\n"
      "initial_state: {steering_angle: 0.0, forward_speed: 3.0, steering_rate: 0.5}\n"
      "duration: 6.0\n"
      "integrator: {name: birkhoff2, step_size: 1.0e-3}\n"
      "effects:\n"
      "  steering_torque: {profile: cosine, amplitude: 3.0, frequency: 0.5, enabled: false}\n"
      "  drive_torque: {profile: cosine, amplitude: 40.0, frequency: 0.1, enabled: false}\n"
      "  rolling_resistance: {coefficient: 0.015, speed_epsilon: 0.05, enabled: false}\n"
      "  air_drag: {coefficient: 0.3, enabled: false}\n"
      "  steering_damping: {coefficient: 5.0, enabled: false}\n"
      "  steering_stiffness: {coefficient: 2000.0, enabled: false}\n";
  std::ofstream(path) << text;
  Scene scene = load_scene(path);
  std::remove(path);
  return scene;
}

/// Wall time of one Simulation::step of `scene` with commands that change every 10 steps [ns per step].
double median_step_time(const Scene& scene, long steps, int repetitions) {
  std::vector<double> times;
  for (int repetition = 0; repetition <= repetitions; ++repetition) {  // the first is the warm-up
    Simulation simulation(scene);
    const auto start = std::chrono::steady_clock::now();
    for (long k = 0; k < steps; ++k) {
      if (k % 10 == 0) {
        simulation.set_steering_command(0.4 * std::sin(0.01 * static_cast<double>(k)));  // [N·m]
        simulation.set_drive_command(3.0 + std::cos(0.01 * static_cast<double>(k)));     // [N·m]
      }
      simulation.step();
    }
    const auto stop = std::chrono::steady_clock::now();
    g_sink = g_sink + simulation.state().x;
    if (repetition > 0) times.push_back(std::chrono::duration<double, std::nano>(stop - start).count() / steps);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

/// The step-cost table: commanded torques without actuators, with them, with end stops too.
void print_actuator_costs(const Scene& base, long steps, int repetitions) {
  Scene scene = base;
  scene.integrator.name = "birkhoff_gauss4";
  scene.integrator.step_size = 0.01;  // [s]
  scene.duration = 0.01 * static_cast<double>(steps) + 1.0;
  scene.initial_state.steering_rate = 0.0;
  scene.effects.clear();
  EffectSpec steering;
  steering.name = "steering_torque";
  steering.profile.kind = TorqueProfile::Kind::kCommand;
  EffectSpec drive = steering;
  drive.name = "drive_torque";
  scene.effects = {steering, drive, coefficients("steering_damping", {{"coefficient", 2.0}})};
  TorqueActuatorSettings motor;
  motor.time_constant = 0.1;  // [s]
  motor.dead_time = 0.025;    // [s], not a multiple of h: each command's response ends a sub-step
  motor.rate_limit = 10.0;    // [N·m/s]
  motor.torque_limit = 4.0;   // [N·m]
  motor.dead_band = 0.02;     // [N·m]

  std::printf("\nOne birkhoff_gauss4 step (h = 0.01 s) with commanded torques changing every 10 steps, %ld steps x %d "
              "repetitions, median\n\n",
              steps, repetitions);
  std::printf("%-44s  %12s  %14s\n", "scene", "ns/step", "ratio to none");
  const double none = median_step_time(scene, steps, repetitions);
  std::printf("%-44s  %12.1f  %14.2f\n", "no actuator sections", none, 1.0);
  Scene stops_only = scene;
  stops_only.actuators.end_stops = SteeringEndStopSettings{0.6, 0.0};
  const double stops = median_step_time(stops_only, steps, repetitions);
  std::printf("%-44s  %12.1f  %14.2f\n", "steering_end_stops (axle free)", stops, stops / none);
  Scene actuated = scene;
  actuated.actuators.steering = motor;
  actuated.actuators.drive = motor;
  const double motors = median_step_time(actuated, steps, repetitions);
  std::printf("%-44s  %12.1f  %14.2f\n", "steering_actuator + drive_actuator", motors, motors / none);
  actuated.actuators.end_stops = stops_only.actuators.end_stops;
  const double all = median_step_time(actuated, steps, repetitions);
  std::printf("%-44s  %12.1f  %14.2f\n", "both actuators + steering_end_stops", all, all / none);
  const double none_again = median_step_time(scene, steps, repetitions);
  std::printf("%-44s  %12.1f  %14.2f\n", "no actuator sections, again", none_again, none_again / none);
}

/// A whole number in [low, high] from `text`, or -1 (not a number, trailing junk or out of range).
long parse_count(const char* text, long low, long high) {
  errno = 0;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || errno == ERANGE || value < low || value > high) return -1;
  return value;
}

constexpr long kMaxEvaluations = 1000000000L;  // 1e9 evaluations: minutes per repetition already
constexpr long kMaxRepetitions = 1000;
const char* const kUsage =
    "usage: effects_benchmark [evaluations 1..1e9 (default 200000)] [repetitions 5..1000 (default 7)]\n"
    "       effects_benchmark --help | -h | --version\n"
    "Times the reduced right-hand side with each effect added in turn; prints ns per evaluation.\n"
    "Exit status: 0 done; 2 bad arguments; 4 failed.\n";

int run(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  if (print_version_if_asked(argc, argv, "effects_benchmark")) return 0;
  const long evaluations = argc > 1 ? parse_count(argv[1], 1, kMaxEvaluations) : 200000;
  const long repetitions_argument = argc > 2 ? parse_count(argv[2], 5, kMaxRepetitions) : 7;
  if (evaluations < 1 || repetitions_argument < 5 || argc > 3) {
    std::fprintf(stderr, "effects_benchmark: bad arguments\n%s", kUsage);
    return 2;
  }
  const int repetitions = static_cast<int>(repetitions_argument);
  const CartModel model{CartParameters{}};
  const std::vector<Sample> samples = make_samples();
  const std::vector<EffectSpec> ladder = {
      torque("steering_torque", 3.0, 0.5),
      torque("drive_torque", 40.0, 0.1),
      coefficients("rolling_resistance", {{"coefficient", 0.015}, {"speed_epsilon", 0.05}}),
      coefficients("air_drag", {{"coefficient", 0.3}}),
      coefficients("steering_damping", {{"coefficient", 5.0}}),
      coefficients("steering_stiffness", {{"coefficient", 2000.0}}),
  };

  std::printf("Reduced right-hand side (effects + eq. (3.4) + eqs. (2.3)-(2.4)), %ld evaluations x %d "
              "repetitions, median\n\n",
              evaluations, repetitions);
  std::printf("%-2s  %-26s  %12s  %14s\n", "n", "last effect added", "ns/eval", "ratio to free");
  double free_cart = 0.0;
  for (std::size_t enabled = 0; enabled <= ladder.size(); ++enabled) {
    const std::vector<EffectSpec> specs(ladder.begin(), ladder.begin() + static_cast<long>(enabled));
    const EffectSet effects = build_effects(specs, model);
    const double nanoseconds = median_time(model, effects, samples, evaluations, repetitions);
    if (enabled == 0) free_cart = nanoseconds;
    std::printf("%-2zu  %-26s  %12.1f  %14.2f\n", enabled, enabled == 0 ? "(free cart)" : specs.back().name.c_str(),
                nanoseconds, nanoseconds / free_cart);
  }

  const Scene disabled = load_all_disabled_scene();
  const EffectSet disabled_effects = build_effects(disabled.effects, model);
  const double disabled_time = median_time(model, disabled_effects, samples, evaluations, repetitions);
  std::printf("%-2zu  %-26s  %12.1f  %14.2f\n", disabled_effects.size(), "(all six, enabled: false)", disabled_time,
              disabled_time / free_cart);
  // Re-time the free cart last, so drift of the machine during the run shows.
  const double free_again = median_time(model, build_effects({}, model), samples, evaluations, repetitions);
  std::printf("%-2d  %-26s  %12.1f  %14.2f\n", 0, "(free cart, again)", free_again, free_again / free_cart);
  print_actuator_costs(disabled, std::max(100L, evaluations / 100), repetitions);
  std::printf("\nsink %.6g\n", static_cast<double>(g_sink));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {  // no exception leaves main
    return run(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "effects_benchmark: %s\n", error.what());
  } catch (...) {
    std::fprintf(stderr, "effects_benchmark: unexpected error of unknown type\n");
  }
  return 4;
}
