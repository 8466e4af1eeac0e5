// cart_simulate: runs a scene in batch and writes the trajectory as CSV (no ROS master needed).
//
//   cart_simulate --scene FILE [--integrator NAME] [--step H] [--tolerance TOL] [--duration T]
//                 [--output-rate HZ] [--birkhoffian-form F] [--on-accuracy-error fail|warn]
//                 --output FILE.csv
//
// Columns: t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,local_error_estimate (SI
// units; energy is T* [J], p2 the front axle's yaw momentum [kg·m²/s], local_error_estimate the
// last step's ê [-], empty when the integrator has none: docs/accuracy.md); one row per output
// instant t0 + k/HZ from the start to the end, both included; values printed with %.17g
// (round-trip exact). At the end a summary goes to stdout, with the accuracy guard's verdict
// (the scene's `accuracy` limits, checked at every row).
// Exit status: 0 done; 2 bad arguments (usage on stderr); 3 unusable scene or settings;
// 4 a step failed (the rows written so far are kept); 5 the accuracy guard reached ERROR (all rows
// written; with --on-accuracy-error warn the run exits 0 and the summary still says ERROR).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/accuracy_guard.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/paper_form_drift.h"
#include "birkhoff_cart/core/run_summary.h"
#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/core/simulation.h"

namespace {

using birkhoff_cart::CartState;
using birkhoff_cart::Scene;
using birkhoff_cart::Simulation;

constexpr int kExitUsage = 2;
constexpr int kExitSettings = 3;
constexpr int kExitStepFailed = 4;
constexpr int kExitAccuracy = 5;
constexpr double kCommensurabilityTolerance = 1e-9;  // relative, for "1/HZ is a multiple of h" [-]

const char* const kUsage =
    "usage: cart_simulate --scene FILE [--integrator NAME] [--step H] [--tolerance TOL]\n"
    "                     [--duration T] [--output-rate HZ] [--birkhoffian-form F]\n"
    "                     [--on-accuracy-error fail|warn] --output FILE.csv\n"
    "  --scene FILE            scene YAML (config/scenes/*.yaml); it provides every default\n"
    "  --integrator NAME       birkhoff2, birkhoff4, rk2, rk4, dopri5 or midpoint\n"
    "  --step H                step size [s], > 0; 1/HZ must be a whole multiple of it\n"
    "  --tolerance TOL         dopri5 absolute and relative tolerance [-], > 0\n"
    "  --duration T            simulated time after the start [s], > 0\n"
    "  --output-rate HZ        output rows per simulated second [Hz], > 0\n"
    "  --birkhoffian-form F    autonomous or paper\n"
    "  --on-accuracy-error A   fail (default: exit 5 when the scene's accuracy guard reaches ERROR)\n"
    "                          or warn (exit 0; the summary still names the quantity)\n"
    "  --output FILE.csv       where to write t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,\n"
    "                          local_error_estimate\n"
    "The rows are at t0 + k/HZ from the start to the end, both included; when the duration is not a\n"
    "whole number of output intervals, a last row is written at the end time t0 + T itself (reached\n"
    "by one shorter final step).\n";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double parse_positive(const std::string& option, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value) || !(value > 0.0)) {
    throw UsageError("option " + option + " needs a finite number > 0, got '" + text + "'");
  }
  return value;
}

std::map<std::string, std::string> parse_arguments(int argc, char** argv) {
  static const char* const kOptions[] = {"--scene",       "--integrator",       "--step",  "--tolerance",
                                         "--duration",    "--output-rate",      "--birkhoffian-form", "--output",
                                         "--on-accuracy-error"};
  std::map<std::string, std::string> values;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    bool known = false;
    for (const char* candidate : kOptions) known = known || option == candidate;
    if (!known) throw UsageError("unknown argument '" + option + "'");
    if (i + 1 >= argc) throw UsageError("option " + option + " needs a value");
    if (values.count(option)) throw UsageError("option " + option + " given twice");
    values[option] = argv[++i];
  }
  if (!values.count("--scene")) throw UsageError("missing --scene FILE");
  if (!values.count("--output")) throw UsageError("missing --output FILE.csv");
  return values;
}

/// Applies the command-line overrides to the scene's settings.
void apply_overrides(const std::map<std::string, std::string>& arguments, Scene& scene) {
  for (const auto& [option, text] : arguments) {
    if (option == "--integrator") scene.integrator.name = text;
    if (option == "--step") scene.integrator.step_size = parse_positive(option, text);
    if (option == "--tolerance") scene.integrator.tolerance = parse_positive(option, text);
    if (option == "--duration") scene.duration = parse_positive(option, text);
    if (option == "--output-rate") scene.output_rate = parse_positive(option, text);
    if (option == "--birkhoffian-form") {
      if (text != "autonomous" && text != "paper") {
        throw UsageError("option --birkhoffian-form must be 'autonomous' or 'paper', got '" + text + "'");
      }
      scene.integrator.birkhoffian_form = text;
    }
    if (option == "--on-accuracy-error" && text != "fail" && text != "warn") {
      throw UsageError("option --on-accuracy-error must be 'fail' or 'warn', got '" + text + "'");
    }
  }
}

/// n such that 1/HZ = n h, or an error when there is no such whole number.
long steps_per_output(const Scene& scene) {
  const double ratio = 1.0 / (scene.output_rate * scene.integrator.step_size);
  const long steps = std::lround(ratio);
  if (steps < 1 || std::abs(ratio - static_cast<double>(steps)) > kCommensurabilityTolerance * ratio) {
    char message[256];
    std::snprintf(message, sizeof message,
                  "the output interval 1/%.17g s is not a whole number of steps of %.17g s (ratio %.17g)",
                  scene.output_rate, scene.integrator.step_size, ratio);
    throw std::invalid_argument(message);
  }
  return steps;
}

/// One CSV row at `time`, and the accuracy guard's check of the state there.
void write_row(std::FILE* file, double time, const Simulation& simulation, birkhoff_cart::AccuracyGuard& guard) {
  const CartState& state = simulation.state();
  const birkhoff_cart::CartModel& model = simulation.model();
  std::fprintf(file, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,", time,
               state.x, state.y, state.heading, state.steering_angle, state.wheel_spin_angle[0],
               state.wheel_spin_angle[1], state.wheel_spin_angle[2], state.wheel_spin_angle[3], state.arc_length,
               state.forward_speed, state.steering_rate, model.energy(state), model.steering_momentum(state));
  const birkhoff_cart::StepStatistics& statistics = simulation.statistics();
  const double estimate = statistics.local_error_estimate_last_step;  // ê [-]; none before the first step
  if (birkhoff_cart::has_local_error_estimate(statistics) && std::isfinite(estimate)) {
    std::fprintf(file, "%.17g", estimate);
  }
  std::fprintf(file, "\n");
  guard.check(time, simulation.diagnostics(), statistics);
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> arguments;
  Scene scene;
  try {
    arguments = parse_arguments(argc, argv);
    scene = birkhoff_cart::load_scene(arguments.at("--scene"));
    apply_overrides(arguments, scene);
  } catch (const UsageError& error) {
    std::fprintf(stderr, "cart_simulate: %s\n%s", error.what(), kUsage);
    return kExitUsage;
  } catch (const birkhoff_cart::SceneError& error) {
    std::fprintf(stderr, "cart_simulate: %s\n", error.what());
    return kExitSettings;
  }

  std::unique_ptr<Simulation> simulation;
  long steps_between_rows = 0;
  long output_intervals = 0;
  bool ends_off_grid = false;  // the end time t0 + duration is not on the 1/HZ grid
  try {
    simulation = std::make_unique<Simulation>(scene);
    const std::string drift = birkhoff_cart::paper_form_drift_warning(scene);  // the eᵗ form's h² drift
    if (!drift.empty()) std::fprintf(stderr, "cart_simulate: %s\n", drift.c_str());
    steps_between_rows = steps_per_output(scene);
    const double intervals = scene.duration * scene.output_rate;
    output_intervals = static_cast<long>(std::floor(intervals * (1.0 + kCommensurabilityTolerance)));
    ends_off_grid =
        std::abs(intervals - static_cast<double>(output_intervals)) > kCommensurabilityTolerance * intervals;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "cart_simulate: %s\n", error.what());
    return kExitSettings;
  }

  const std::string output_path = arguments.at("--output");
  std::FILE* file = std::fopen(output_path.c_str(), "w");
  if (!file) {
    std::fprintf(stderr, "cart_simulate: cannot write '%s': %s\n", output_path.c_str(), std::strerror(errno));
    return kExitSettings;
  }
  std::fprintf(file, "t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,local_error_estimate\n");
  const double start_time = scene.initial_state.time;  // t0 [s]
  birkhoff_cart::AccuracyGuard guard(scene.accuracy);
  long rows = 0;
  try {
    for (long k = 0; k <= output_intervals; ++k) {
      if (k > 0) {
        for (long n = 0; n < steps_between_rows; ++n) simulation->step();
      }
      write_row(file, start_time + static_cast<double>(k) / scene.output_rate, *simulation, guard);
      ++rows;
    }
    if (ends_off_grid) {
      // The last row is at the end time itself: whole steps while they fit, then one shorter
      // final step that lands on t0 + duration (the paper's case runs from π/2 to 3.0).
      const double end_time = simulation->end_time();  // [s]
      const double h = scene.integrator.step_size;     // [s]
      while (simulation->state().time + h * (1.0 + kCommensurabilityTolerance) <= end_time) simulation->step();
      if (end_time - simulation->state().time > kCommensurabilityTolerance * std::max(1.0, std::abs(end_time))) {
        simulation->step_to(end_time);
      }
      write_row(file, end_time, *simulation, guard);
      ++rows;
    }
  } catch (const birkhoff_cart::StepError& error) {
    std::fflush(file);
    std::fclose(file);
    std::fprintf(stderr, "cart_simulate: step failed after t = %.17g s (%ld rows written to %s): %s\n",
                 simulation->state().time, rows, output_path.c_str(), error.what());
    std::printf("cart_simulate %s", birkhoff_cart::run_summary(*simulation, guard).c_str());
    return kExitStepFailed;
  }
  if (std::fclose(file) != 0) {
    std::fprintf(stderr, "cart_simulate: error writing '%s': %s\n", output_path.c_str(), std::strerror(errno));
    return kExitSettings;
  }
  std::printf("cart_simulate %s", birkhoff_cart::run_summary(*simulation, guard).c_str());
  if (guard.level() == birkhoff_cart::AccuracyLevel::kError) {
    const bool warn_only = arguments.count("--on-accuracy-error") && arguments.at("--on-accuracy-error") == "warn";
    std::fprintf(stderr, "cart_simulate: accuracy %s%s\n", guard.summary().c_str(),
                 warn_only ? " (--on-accuracy-error warn: exit 0)" : "");
    if (!warn_only) return kExitAccuracy;
  }
  return 0;
}
