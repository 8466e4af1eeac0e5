// reversible_whirl: the step controls against the same member at fixed steps on the free
// jackknife_whirl (docs/accuracy.md §4.2). ROS-free.
//
//   reversible_whirl [--duration T] [--member NAME] [--output-dir DIR]
//   (defaults: 10 000 s, birkhoff_gauss8, bench/results; run from the repository)
//
// For the member at fixed steps h = 0.08 … 0.005 s and under the reversible and the adaptive
// control at tolerances 1e-3 … 1e-8 m (horizon T), through Simulation exactly as cart_simulate runs
// them (output every second): the final
// position error of hinge B against birkhoff_gauss8 at h = 2.5 ms (checked against h = 5 ms), the
// rhs evaluations (the reversible runs include their trial grids and step-density evaluations), CPU
// time, and the energy residual |T* − T*₀| every second (under a control: its max over the control's
// own steps in that second): its max over the first and the
// last tenth of the run. Prints the table and, for each reversible run, the fixed-step work needed
// for the same error (log–log interpolation of the fixed-step curve). Writes
// reversible_whirl.csv (the table) and reversible_whirl_trace.csv (t, energy residual and mean
// step over each second, for the fixed step and the reversible run of about the same error). A
// setting whose run stops with an error is printed as such and left out of the table.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/support/version.h"

namespace {

using namespace birkhoff_cart;

struct Run {
  StepControl control = StepControl::kFixed;  ///< fixed steps of h, or a step control's
  double setting = 0.0;     ///< h [s] or tolerance [m]
  double error = 0.0;       ///< final position error [m]
  double rhs = 0.0;         ///< rhs evaluations [-]
  double steps = 0.0;       ///< steps (fixed) or internal steps (controlled) [-]
  double cpu = 0.0;         ///< [s]
  double energy_first = 0.0, energy_last = 0.0;  ///< max |T* − T*₀| over the first / last tenth [J]
  std::vector<double> trace_energy, trace_step;  ///< per second: residual [J], mean internal step [s]
};

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

Scene whirl(const std::string& member, double duration) {
  Scene scene = load_scene("config/scenes/jackknife_whirl.yaml");
  scene.integrator.name = member;
  scene.duration = duration;
  return scene;
}

/// Runs `scene` with an output every second (fixed: whole steps of h inside each second).
Run run(const Scene& scene, double reference_x, double reference_y) {
  Run result;
  result.control = scene.integrator.step_control;
  const bool fixed = result.control == StepControl::kFixed;
  result.setting = fixed ? scene.integrator.step_size : scene.integrator.position_tolerance;
  Simulation simulation(scene);
  const double duration = scene.duration;
  const double start = cpu_seconds();
  const long seconds = std::lround(duration);
  const long steps_per_second = fixed ? std::lround(1.0 / scene.integrator.step_size) : 0;
  // Under a control the energy residual is the largest over the control's own steps in each second
  // (the integrator's; an output between steps adds the dense output's interpolation error).
  double grid_residual = 0.0;
  if (!fixed) {
    simulation.observe_grid([&](const CartState& state) {
      grid_residual = std::max(grid_residual, std::abs(simulation.balances_of(state).energy_balance_residual));
    });
  }
  std::uint64_t internal_before = 0;
  for (long second = 1; second <= seconds; ++second) {
    grid_residual = 0.0;
    if (fixed) {
      for (long k = 0; k < steps_per_second; ++k) simulation.step();
    } else {
      simulation.advance_output_to(static_cast<double>(second));
    }
    const double residual = fixed ? std::abs(simulation.diagnostics().energy_balance_residual) : grid_residual;
    if (second <= seconds / 10) result.energy_first = std::max(result.energy_first, residual);
    if (second > seconds - seconds / 10) result.energy_last = std::max(result.energy_last, residual);
    result.trace_energy.push_back(residual);
    const std::uint64_t internal = simulation.statistics().internal_steps;
    result.trace_step.push_back(fixed ? scene.integrator.step_size
                                      : 1.0 / static_cast<double>(std::max<std::uint64_t>(1, internal - internal_before)));
    internal_before = internal;
  }
  result.cpu = cpu_seconds() - start;
  result.rhs = static_cast<double>(simulation.statistics().rhs_evaluations);
  result.steps = static_cast<double>(fixed ? simulation.statistics().steps : simulation.statistics().internal_steps);
  result.error = std::hypot(simulation.state().x - reference_x, simulation.state().y - reference_y);
  return result;
}

/// Fixed-step rhs evaluations for `error` by log–log interpolation of the fixed runs (NaN outside).
double fixed_work_for(const std::vector<Run>& fixed, double error) {
  for (std::size_t i = 0; i + 1 < fixed.size(); ++i) {
    const Run& a = fixed[i];
    const Run& b = fixed[i + 1];
    if ((a.error - error) * (b.error - error) <= 0.0 && a.error != b.error) {
      const double s = std::log(error / a.error) / std::log(b.error / a.error);
      return std::exp(std::log(a.rhs) + s * std::log(b.rhs / a.rhs));
    }
  }
  return std::nan("");
}

}  // namespace

int main(int argc, char** argv) try {
  birkhoff_cart::print_version_if_asked(argc, argv, "reversible_whirl");
  double duration = 10000.0;
  std::string member = "birkhoff_gauss8";
  std::string output_dir = "bench/results";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value");
    if (arg == "--duration") duration = std::stod(argv[++i]);
    else if (arg == "--member") member = argv[++i];
    else if (arg == "--output-dir") output_dir = argv[++i];
    else throw std::invalid_argument("unknown argument '" + arg + "'");
  }
  if (!(duration >= 10.0) || duration != std::round(duration)) {
    throw std::invalid_argument("--duration must be a whole number of seconds >= 10");
  }

  // Reference: gauss8 at 2.5 ms, checked against 5 ms.
  Scene reference_scene = whirl("birkhoff_gauss8", duration);
  reference_scene.integrator.step_size = 2.5e-3;
  Simulation reference(reference_scene);
  while (!reference.at_end()) reference.step_on_schedule();
  reference_scene.integrator.step_size = 5e-3;
  Simulation check(reference_scene);
  while (!check.at_end()) check.step_on_schedule();
  const double rx = reference.state().x, ry = reference.state().y;
  const double reference_spread = std::hypot(check.state().x - rx, check.state().y - ry);
  std::printf("reversible_whirl: jackknife_whirl over %.0f s, member %s; reference gauss8 h = 2.5 ms, "
              "which differs from h = 5 ms by %.2e m\n\n",
              duration, member.c_str(), reference_spread);

  std::vector<Run> fixed, reversible, adaptive;
  const auto attempt = [&](const Scene& scene, std::vector<Run>& into) {
    try {
      into.push_back(run(scene, rx, ry));
    } catch (const std::exception& error) {
      std::printf("%s %g: stopped: %s\n", to_string(scene.integrator.step_control),
                  scene.integrator.step_control == StepControl::kFixed ? scene.integrator.step_size
                                                                        : scene.integrator.position_tolerance,
                  error.what());
    }
  };
  for (double h : {0.08, 0.04, 0.02, 0.01, 0.005}) {
    Scene scene = whirl(member, duration);
    scene.integrator.step_size = h;
    attempt(scene, fixed);
  }
  for (StepControl control : {StepControl::kReversible, StepControl::kAdaptive}) {
    for (double tolerance : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8}) {
      Scene scene = whirl(member, duration);
      scene.integrator.step_control = control;
      scene.integrator.position_tolerance = tolerance;
      scene.integrator.step_size = 1.0;  // the output step
      attempt(scene, control == StepControl::kReversible ? reversible : adaptive);
    }
  }
  if (fixed.empty() || reversible.size() < 3) throw std::runtime_error("too few runs finished for the table");

  std::printf("%-10s %9s %11s %10s %12s %8s %12s %12s %7s %14s\n", "control", "setting", "error [m]", "steps", "rhs evals",
              "CPU [s]", "E first [J]", "E last [J]", "last/1st", "fixed rhs/ours");
  const std::string csv_path = output_dir + "/reversible_whirl.csv";
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) throw std::runtime_error("cannot write " + csv_path);
  std::fprintf(csv, "member,control,setting,error_m,steps,rhs_evaluations,cpu_s,energy_first_tenth_J,energy_last_tenth_J,"
                    "fixed_rhs_for_same_error\n");
  for (const std::vector<Run>* group : {&fixed, &reversible, &adaptive}) {
    for (const Run& r : *group) {
      const double fixed_work = r.control == StepControl::kFixed ? std::nan("") : fixed_work_for(fixed, r.error);
      std::printf("%-10s %9.3g %11.3e %10.4g %12.4g %8.2f %12.3e %12.3e %7.2f %14.3g\n", to_string(r.control), r.setting,
                  r.error, r.steps, r.rhs, r.cpu, r.energy_first, r.energy_last, r.energy_last / r.energy_first, fixed_work / r.rhs);
      std::fprintf(csv, "%s,%s,%.6g,%.6e,%.0f,%.0f,%.4f,%.6e,%.6e,%.6g\n", member.c_str(), to_string(r.control), r.setting,
                   r.error, r.steps, r.rhs, r.cpu, r.energy_first, r.energy_last, fixed_work);
    }
  }
  std::fclose(csv);

  // Trace: the reversible run at 1e-5 m and the fixed and adaptive runs closest to it in final error.
  const Run* pair_reversible = &reversible[std::min<std::size_t>(2, reversible.size() - 1)];
  const auto closest = [&](const std::vector<Run>& runs) {
    const Run* best = &runs.front();
    for (const Run& r : runs) {
      if (std::abs(std::log(r.error / pair_reversible->error)) < std::abs(std::log(best->error / pair_reversible->error))) best = &r;
    }
    return best;
  };
  const Run* pair_fixed = closest(fixed);
  const Run* pair_adaptive = adaptive.empty() ? nullptr : closest(adaptive);
  const std::string trace_path = output_dir + "/reversible_whirl_trace.csv";
  std::FILE* trace = std::fopen(trace_path.c_str(), "w");
  if (!trace) throw std::runtime_error("cannot write " + trace_path);
  std::fprintf(trace, "# %s over %.0f s: fixed h = %g s (final error %.3e m), reversible tolerance %g m (final error %.3e m)",
               member.c_str(), duration, pair_fixed->setting, pair_fixed->error, pair_reversible->setting, pair_reversible->error);
  if (pair_adaptive) std::fprintf(trace, ", adaptive tolerance %g m (final error %.3e m)", pair_adaptive->setting, pair_adaptive->error);
  std::fprintf(trace, "\nt_s,fixed_energy_residual_J,fixed_step_s,reversible_energy_residual_J,reversible_mean_step_s,"
                      "adaptive_energy_residual_J,adaptive_mean_step_s\n");
  for (std::size_t k = 0; k < pair_fixed->trace_energy.size(); ++k) {
    std::fprintf(trace, "%zu,%.6e,%.6g,%.6e,%.6g,%.6e,%.6g\n", k + 1, pair_fixed->trace_energy[k], pair_fixed->trace_step[k],
                 pair_reversible->trace_energy[k], pair_reversible->trace_step[k],
                 pair_adaptive ? pair_adaptive->trace_energy[k] : std::nan(""),
                 pair_adaptive ? pair_adaptive->trace_step[k] : std::nan(""));
  }
  std::fclose(trace);
  std::printf("\nwrote %s and %s\n", csv_path.c_str(), trace_path.c_str());
  return 0;
} catch (const std::exception& error) {
  std::fprintf(stderr, "reversible_whirl: %s\n", error.what());
  return 2;
}
