// work_precision: what accuracy costs in time (issue 6). ROS-free; built by the normal build.
//
//   work_precision [--quick] [--repetitions N] [--output-dir DIR] [--scene-dir DIR]
//   (defaults, relative to the working directory, i.e. the repository: bench/results, config/scenes;
//    scripts/run_benchmark.sh builds, runs from the repository and plots)
//
// For every integrator (birkhoff2, birkhoff4, rk2, rk4, midpoint over a sweep of step sizes h,
// dopri5 over a sweep of tolerances) and for Boost.Odeint's own runge_kutta4 and
// runge_kutta_dopri5 on the same right-hand side, on the scenes
//   jackknife_whirl  stretched to 1000 s (free, reversible, periodic whirl),
//   sine_steer_torque (forced), drive_rr_drag (forced, dissipative, non-reversible),
//   paper_special    the paper's case on (π/2, π − 0.05) against its closed form (docs eq. (3.9)),
// it records the final-state error against the reference (position of the hinge B [m], heading
// θ [rad], relative arc length π1 [-]), the maximum energy-balance residual |T* − T*₀ − W| [J] and
// p2-balance residual |p2 − p2₀ − I2| [kg·m²/s] over the run (sampled every 0.1 s of simulated
// time), the median wall and CPU time of ≥5 repetitions after a warm-up run, right-hand-side
// evaluations and Newton iterations.
//
// References: the closed form for paper_special; otherwise our dopri5 at tolerance 1e-13, whose own
// error is estimated by its distance to dopri5 at 1e-12 (written to reference_check.csv).
//
// Outputs (DIR, default bench/results):
//   work_precision.csv    one row per (scene, method, step size or tolerance)
//   reference_check.csv   per scene: the reference and its estimated error
//   long_run.csv          jackknife_whirl 1000 s: energy and p2 residuals every 1 s, one method each
//                         at comparable cost (the sweep run whose CPU time is nearest birkhoff4's at h = 0.01 s)
//   paper_relative_error.csv  relative error of π1 against the closed form at τ = 0.001 (paper figs. 1–2)
// --quick: 3 repetitions, jackknife_whirl stretched to 100 s only, fewer step sizes (a smoke run).
#include <time.h>

#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/reference_solution.h"
#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/core/simulation.h"
#include "birkhoff_cart/core/version.h"

namespace {

using namespace birkhoff_cart;

constexpr double kSampleInterval = 0.1;          // energy / p2 residual sampling period [s] (simulated)
constexpr double kLongRunSampleInterval = 1.0;   // long-run time-series period [s] (simulated)
constexpr double kReferenceTolerance = 1e-13;    // dopri5 reference tolerance [-]
constexpr double kReferenceCheckTolerance = 1e-12;  // its check run [-]
constexpr double kPaperStep = 1e-3;              // the paper's τ [s]
constexpr double kPaperEndMargin = 0.05;         // paper window ends at π − 0.05 [s]
constexpr double kLongRunCostStep = 0.01;
constexpr long kMaxRepetitions = 1000;           // --repetitions limit [-]        // birkhoff4 step whose cost the long-run methods match [s]

// ---------------------------------------------------------------------------------------------
// Timing
double cpu_seconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}
double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// ---------------------------------------------------------------------------------------------
// What one run measures.
struct RunErrors {
  double position_error = NAN;         ///< |B − B_ref| at the end [m]
  double heading_error = NAN;          ///< |θ − θ_ref| at the end [rad]
  double arc_length_rel_error = NAN;   ///< |π1 − π1_ref| / |π1_ref| at the end [-]
  double max_energy_residual = 0.0;    ///< max |T* − T*₀ − W| over the samples [J]
  double max_p2_residual = 0.0;        ///< max |p2 − p2₀ − I2| over the samples [kg·m²/s]
  double energy_scale = NAN;           ///< T*₀ [J], for relative numbers
  CartState final_state;
};

struct RunRecord {
  std::string scene, method, kind;  // kind: "ours" or "odeint"
  double step_size = NAN;           ///< fixed step [s] (NaN for adaptive)
  double tolerance = NAN;           ///< dopri5 tolerance [-] (NaN for fixed step)
  std::uint64_t steps = 0, rhs_evaluations = 0, newton_iterations = 0;
  double wall_median = NAN, wall_min = NAN, cpu_median = NAN;  ///< [s]
  RunErrors errors;
  std::string status = "ok";
};

/// One scene of the benchmark with its reference.
struct BenchScene {
  Scene scene;                       ///< reference kind none; duration as benchmarked
  std::vector<double> step_sizes;    ///< nominal h [s]
  std::vector<double> tolerances;    ///< dopri5 [-]
  bool analytic = false;             ///< paper_special: compare with PaperAnalyticSolution
  CartState reference_final;         ///< when !analytic
  double reference_error_position = NAN, reference_error_heading = NAN;  ///< estimates [m], [rad]
};

/// The number of steps N and the exact h = duration / N nearest the nominal step.
std::uint64_t step_count(double duration, double nominal_step) {
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(duration / nominal_step)));
}

void fill_final_errors(const BenchScene& bench, const CartState& state, RunErrors& errors) {
  CartState reference = bench.reference_final;
  if (bench.analytic) reference = PaperAnalyticSolution{bench.scene.initial_state}.at(state.time);
  errors.position_error = std::hypot(state.x - reference.x, state.y - reference.y);
  errors.heading_error = std::abs(state.heading - reference.heading);
  errors.arc_length_rel_error = std::abs(state.arc_length - reference.arc_length) / std::abs(reference.arc_length);
  errors.final_state = state;
}

// ---------------------------------------------------------------------------------------------
// Our integrators through Simulation (what the CLI and the node use).

/// The scene with this method and step (for dopri5: the simulator step is the sample interval).
Scene configured(const Scene& base, const std::string& method, double step, double tolerance) {
  Scene scene = base;
  scene.integrator.name = method;
  scene.integrator.step_size = step;
  if (method == "dopri5") scene.integrator.tolerance = tolerance;
  return scene;
}

/// Runs the scene to its end by the shared step schedule (step_schedule.h); samples residuals every
/// `sample_every` steps (and at the end); `observer(sim)` (optional) is called at every sample.
RunErrors run_simulation(Simulation& sim, std::uint64_t sample_every,
                         const std::function<void(const Simulation&)>& observer = nullptr) {
  RunErrors errors;
  errors.energy_scale = sim.diagnostics().energy;
  while (!sim.at_end()) {
    sim.step_on_schedule();
    if (sim.steps_taken() % sample_every == 0 || sim.at_end()) {
      const Diagnostics d = sim.diagnostics();
      errors.max_energy_residual = std::max(errors.max_energy_residual, std::abs(d.energy_balance_residual));
      errors.max_p2_residual = std::max(errors.max_p2_residual, std::abs(d.p2_balance_residual));
      if (observer) observer(sim);
    }
  }
  errors.final_state = sim.state();
  return errors;
}

/// Times `run` (warm-up + repetitions); returns the last run's errors.
template <class Run>
RunErrors timed(int repetitions, RunRecord& record, Run run) {
  run();  // warm-up (caches, page faults, branch predictors)
  std::vector<double> walls, cpus;
  RunErrors errors;
  for (int r = 0; r < repetitions; ++r) {
    const double w0 = wall_seconds(), c0 = cpu_seconds();
    errors = run();
    walls.push_back(wall_seconds() - w0);
    cpus.push_back(cpu_seconds() - c0);
  }
  record.wall_median = median(walls);
  record.wall_min = *std::min_element(walls.begin(), walls.end());
  record.cpu_median = median(cpus);
  return errors;
}

RunRecord measure_ours(const BenchScene& bench, const std::string& method, double nominal_step, double tolerance,
                       int repetitions) {
  RunRecord record;
  record.scene = bench.scene.name;
  record.method = method;
  record.kind = "ours";
  const bool adaptive = method == "dopri5";
  const std::uint64_t steps = step_count(bench.scene.duration, adaptive ? kSampleInterval : nominal_step);
  const double h = bench.scene.duration / static_cast<double>(steps);
  const std::uint64_t sample_every = adaptive ? 1 : std::max<std::uint64_t>(1, std::llround(kSampleInterval / h));
  if (adaptive) record.tolerance = tolerance;
  else record.step_size = h;
  const Scene scene = configured(bench.scene, method, h, tolerance);
  try {
    StepStatistics statistics;
    Simulation sim(scene);  // built outside the timed region; reset() restores the initial state
    const RunErrors errors = timed(repetitions, record, [&] {
      sim.reset();
      RunErrors e = run_simulation(sim, sample_every);
      statistics = sim.statistics();
      return e;
    });
    record.steps = statistics.steps;
    record.rhs_evaluations = statistics.rhs_evaluations;
    record.newton_iterations = statistics.newton_iterations_total;
    record.errors = errors;
    fill_final_errors(bench, errors.final_state, record.errors);
  } catch (const std::exception& error) {
    record.status = std::string("failed: ") + error.what();
  }
  return record;
}

// ---------------------------------------------------------------------------------------------
// Boost.Odeint baselines on the same right-hand side (the scene's Birkhoffian form).
constexpr int kJointSize = kBirkhoffianSize + kPassiveSize;
using Joint = std::array<double, kJointSize>;

template <class System>
struct JointRates {
  const System* system;
  std::uint64_t* evaluations;
  void operator()(const Joint& x, Joint& rate, double t) const {
    Eigen::Matrix<double, kBirkhoffianSize, 1> z;
    Eigen::Matrix<double, kPassiveSize, 1> y;
    for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x[i];
    for (int i = 0; i < kPassiveSize; ++i) y(i) = x[kBirkhoffianSize + i];
    const auto z_rate = birkhoffian_rates(*system, z, t);               // ż = K⁻¹(∇B + ∂R/∂t + Λ)
    const auto y_rate = passive_coordinate_rates(*system, z, y, t);     // ẏ = g(z, y, t)
    for (int i = 0; i < kBirkhoffianSize; ++i) rate[i] = z_rate(i);
    for (int i = 0; i < kPassiveSize; ++i) rate[kBirkhoffianSize + i] = y_rate(i);
    ++*evaluations;
  }
};

/// Residuals of a joint state (z, y) like Simulation::diagnostics().
template <class System>
void sample_joint(const System& system, const Joint& x, double energy0, double p20, RunErrors& errors) {
  Eigen::Matrix<double, kBirkhoffianSize, 1> z;
  for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x[i];
  const double energy = system.hamiltonian(z);  // T* = ½ pᵀM⁻¹p [J]
  const double work = x[kBirkhoffianSize + kAppliedWorkIndex];
  const double impulse = x[kBirkhoffianSize + kSteeringImpulseIndex];
  errors.max_energy_residual = std::max(errors.max_energy_residual, std::abs(energy - energy0 - work));
  errors.max_p2_residual = std::max(errors.max_p2_residual, std::abs(z(kSteeringMomentumIndex) - p20 - impulse));
}

template <class System>
RunRecord measure_odeint_typed(const BenchScene& bench, const std::string& method, double nominal_step,
                               double tolerance, int repetitions) {
  namespace odeint = boost::numeric::odeint;
  RunRecord record;
  record.scene = bench.scene.name;
  record.method = method;
  record.kind = "odeint";
  const bool adaptive = method == "odeint_dopri5";
  const std::uint64_t steps = step_count(bench.scene.duration, adaptive ? kSampleInterval : nominal_step);
  const double h = bench.scene.duration / static_cast<double>(steps);
  const std::uint64_t sample_every = adaptive ? 1 : std::max<std::uint64_t>(1, std::llround(kSampleInterval / h));
  if (adaptive) record.tolerance = tolerance;
  else record.step_size = h;
  const Simulation holder(configured(bench.scene, "rk4", h, tolerance));  // model and effects
  System system(holder.model(), holder.effects());
  const double t0 = bench.scene.initial_state.time;
  system.begin_step(t0);  // rep (a): structure epoch at the start (runs here are ≤ 1000 s only for rep (b))
  const CartBirkhoffianPoint start = system.to_birkhoffian(bench.scene.initial_state);
  Joint x0;
  for (int i = 0; i < kBirkhoffianSize; ++i) x0[i] = start.z(i);
  for (int i = 0; i < kPassiveSize; ++i) x0[kBirkhoffianSize + i] = start.y(i);
  const double energy0 = system.hamiltonian(start.z);
  const double p20 = start.z(kSteeringMomentumIndex);
  std::uint64_t evaluations = 0;
  const JointRates<System> rates{&system, &evaluations};
  Joint x_end{};
  try {
    RunErrors errors = timed(repetitions, record, [&] {
      evaluations = 0;
      RunErrors e;
      e.energy_scale = energy0;
      Joint x = x0;
      if (adaptive) {
        auto controlled = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<Joint>());
        // x(t0 + k h) ← adaptive dopri5 steps, observed every h; odeint's own loop carries the
        // step-size guess and the FSAL rate from one observation interval to the next. The end
        // t0 + (N + ½) h makes its loop stop after exactly N intervals despite round-off in t.
        odeint::integrate_const(controlled, rates, x, t0, t0 + (static_cast<double>(steps) + 0.5) * h, h,
                                [&](const Joint& state, double) { sample_joint(system, state, energy0, p20, e); });
      } else {
        odeint::runge_kutta4<Joint> stepper;
        for (std::uint64_t k = 1; k <= steps; ++k) {
          stepper.do_step(rates, x, t0 + static_cast<double>(k - 1) * h, h);  // x ← RK4 step
          if (k % sample_every == 0 || k == steps) sample_joint(system, x, energy0, p20, e);
        }
      }
      x_end = x;
      return e;
    });
    Eigen::Matrix<double, kBirkhoffianSize, 1> z;
    Eigen::Matrix<double, kPassiveSize, 1> y;
    for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x_end[i];
    for (int i = 0; i < kPassiveSize; ++i) y(i) = x_end[kBirkhoffianSize + i];
    record.steps = adaptive ? 0 : steps;
    record.rhs_evaluations = evaluations;
    record.errors = errors;
    fill_final_errors(bench, system.to_cart_state(z, y, t0 + bench.scene.duration), record.errors);
  } catch (const std::exception& error) {
    record.status = std::string("failed: ") + error.what();
  }
  return record;
}

RunRecord measure_odeint(const BenchScene& bench, const std::string& method, double step, double tolerance,
                         int repetitions) {
  if (bench.scene.integrator.birkhoffian_form == "paper") {
    return measure_odeint_typed<CartPaperBirkhoffian>(bench, method, step, tolerance, repetitions);
  }
  return measure_odeint_typed<CartAutonomousBirkhoffian>(bench, method, step, tolerance, repetitions);
}

// ---------------------------------------------------------------------------------------------
// References

CartState dopri5_final_state(const Scene& base, double tolerance) {
  const std::uint64_t steps = step_count(base.duration, kSampleInterval);
  Simulation sim(configured(base, "dopri5", base.duration / static_cast<double>(steps), tolerance));
  while (!sim.at_end()) sim.step_on_schedule();
  return sim.state();
}

void prepare_reference(BenchScene& bench, std::FILE* check) {
  if (bench.analytic) {
    std::fprintf(check, "%s,paper_analytic,0,0,0\n", bench.scene.name.c_str());
    return;
  }
  const double w0 = wall_seconds();
  bench.reference_final = dopri5_final_state(bench.scene, kReferenceTolerance);
  const CartState other = dopri5_final_state(bench.scene, kReferenceCheckTolerance);
  bench.reference_error_position =
      std::hypot(other.x - bench.reference_final.x, other.y - bench.reference_final.y);
  bench.reference_error_heading = std::abs(other.heading - bench.reference_final.heading);
  std::fprintf(check, "%s,dopri5_tol_%.0e_vs_%.0e,%.3e,%.3e,%.2f\n", bench.scene.name.c_str(), kReferenceTolerance,
               kReferenceCheckTolerance, bench.reference_error_position, bench.reference_error_heading,
               wall_seconds() - w0);
  std::fflush(check);
}

// ---------------------------------------------------------------------------------------------
// Output

void write_header(std::FILE* out) {
  std::fprintf(out,
               "scene,method,kind,step_size_s,tolerance,steps,rhs_evaluations,newton_iterations,wall_median_s,"
               "wall_min_s,cpu_median_s,position_error_m,heading_error_rad,arc_length_rel_error,"
               "max_energy_residual_J,max_energy_residual_rel,max_p2_residual,reference_position_error_m,status\n");
}

void write_record(std::FILE* out, const BenchScene& bench, const RunRecord& r) {
  std::string status = r.status;
  std::replace(status.begin(), status.end(), ',', ';');
  std::replace(status.begin(), status.end(), '\n', ' ');
  std::fprintf(out, "%s,%s,%s,%.9g,%.3g,%llu,%llu,%llu,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.3e,%s\n",
               r.scene.c_str(), r.method.c_str(), r.kind.c_str(), r.step_size, r.tolerance,
               static_cast<unsigned long long>(r.steps), static_cast<unsigned long long>(r.rhs_evaluations),
               static_cast<unsigned long long>(r.newton_iterations), r.wall_median, r.wall_min, r.cpu_median,
               r.errors.position_error, r.errors.heading_error, r.errors.arc_length_rel_error,
               r.errors.max_energy_residual, r.errors.max_energy_residual / r.errors.energy_scale,
               r.errors.max_p2_residual, bench.reference_error_position, status.c_str());
  std::fflush(out);
  std::fprintf(stderr, "  %-16s %-14s h=%-10.4g tol=%-8.1g cpu=%9.4f s  pos=%9.2e  dE=%9.2e  dp2=%9.2e %s\n",
               r.scene.c_str(), r.method.c_str(), r.step_size, r.tolerance, r.cpu_median, r.errors.position_error,
               r.errors.max_energy_residual, r.errors.max_p2_residual, r.status == "ok" ? "" : r.status.c_str());
}

/// Long run: energy and p2 residuals every second for the chosen (method, h or tolerance).
void write_long_run(const BenchScene& bench, const std::vector<RunRecord>& records, std::FILE* out) {
  double target_cpu = NAN;
  for (const RunRecord& r : records) {
    if (r.method == "birkhoff4" && r.status == "ok" && std::abs(r.step_size - kLongRunCostStep) < 1e-9) {
      target_cpu = r.cpu_median;
    }
  }
  if (!std::isfinite(target_cpu)) return;
  std::fprintf(out, "# methods at comparable cost: the sweep run with CPU time nearest birkhoff4 at h = %g s (%.4f s)\n",
               kLongRunCostStep, target_cpu);
  std::fprintf(out, "method,step_size_s,tolerance,cpu_median_s,t,energy_residual_J,p2_residual\n");
  for (const std::string& method : integrator_names()) {
    const RunRecord* best = nullptr;
    for (const RunRecord& r : records) {
      if (r.method != method || r.status != "ok") continue;
      if (!best || std::abs(std::log(r.cpu_median / target_cpu)) < std::abs(std::log(best->cpu_median / target_cpu))) {
        best = &r;
      }
    }
    if (!best) continue;
    const bool adaptive = method == "dopri5";
    const double h = adaptive ? bench.scene.duration / static_cast<double>(step_count(bench.scene.duration, kSampleInterval))
                              : best->step_size;
    const std::uint64_t every = std::max<std::uint64_t>(1, std::llround(kLongRunSampleInterval / h));
    Simulation sim(configured(bench.scene, method, h, best->tolerance));
    while (!sim.at_end()) {
      sim.step_on_schedule();
      if (sim.steps_taken() % every == 0) {
        const Diagnostics d = sim.diagnostics();
        std::fprintf(out, "%s,%.9g,%.3g,%.6e,%.6f,%.6e,%.6e\n", method.c_str(), best->step_size, best->tolerance,
                     best->cpu_median, sim.state().time, d.energy_balance_residual, d.p2_balance_residual);
      }
    }
  }
  std::fflush(out);
}

/// Paper figs. 1–2: relative error of π1 against the closed form at τ = 0.001 (every 10 steps),
/// on the paper's window (π/2, π − 0.05) and on (0.05, π − 0.05), which includes π1 = 0.
void write_paper_relative_error(const Scene& paper_scene, std::FILE* out) {
  std::fprintf(out, "window,method,form,t,arc_length,arc_length_exact,relative_error\n");
  struct Window {
    const char* name;
    double start;  // [s]
  };
  const Window windows[] = {{"paper", M_PI / 2.0}, {"wide", kPaperEndMargin}};
  const std::pair<std::string, std::string> methods[] = {
      {"birkhoff2", "paper"}, {"birkhoff2", "autonomous"}, {"rk2", "paper"}, {"birkhoff4", "paper"}, {"rk4", "paper"}};
  for (const Window& window : windows) {
    Scene scene = paper_scene;
    // On the analytic family through the paper's state (π1 = 1 at t = π/2): χ = t, ω1 = 1/sin t,
    // π1 = 1 + ln tan(t/2) (docs eq. (3.9)).
    const PaperAnalyticSolution family{paper_scene.initial_state};
    scene.initial_state = family.at(window.start);
    scene.duration = (M_PI - kPaperEndMargin) - window.start;
    for (const auto& [method, form] : methods) {
      Scene configured_scene = configured(scene, method, kPaperStep, 1e-10);
      configured_scene.integrator.birkhoffian_form = form;
      Simulation sim(configured_scene);
      const PaperAnalyticSolution exact{scene.initial_state};
      try {
        while (!sim.at_end()) {  // whole steps of τ, then one shorter step onto π − 0.05
          sim.step_on_schedule();
          if (sim.steps_taken() % 10 == 0 || sim.at_end()) {
            const CartState& s = sim.state();
            const double truth = exact.at(s.time).arc_length;
            std::fprintf(out, "%s,%s,%s,%.6f,%.12e,%.12e,%.6e\n", window.name, method.c_str(), form.c_str(), s.time,
                         s.arc_length, truth, std::abs(s.arc_length - truth) / std::abs(truth));
          }
        }
      } catch (const std::exception& error) {
        std::fprintf(stderr, "paper %s %s/%s: %s\n", window.name, method.c_str(), form.c_str(), error.what());
      }
    }
  }
  std::fflush(out);
}

// ---------------------------------------------------------------------------------------------

struct Options {
  bool quick = false;
  int repetitions = 5;
  std::string output_dir = "bench/results";
  std::string scene_dir = "config/scenes";
};

Options parse(int argc, char** argv) {
  Options options;
  bool repetitions_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--quick") options.quick = true;
    else if (arg == "--repetitions") {
      const std::string text = value();
      std::size_t used = 0;
      long repetitions = -1;
      try {
        repetitions = std::stol(text, &used);
      } catch (const std::exception&) {  // not a number, or beyond long
      }
      if (used != text.size() || repetitions < 1 || repetitions > kMaxRepetitions) {
        throw std::invalid_argument("--repetitions needs a whole number in 1..1000, got '" + text + "'");
      }
      options.repetitions = static_cast<int>(repetitions);
      repetitions_given = true;
    } else if (arg == "--output-dir") options.output_dir = value();
    else if (arg == "--scene-dir") options.scene_dir = value();
    else throw std::invalid_argument("unknown argument '" + arg + "'");
  }
  if (options.quick && !repetitions_given) options.repetitions = 3;
  return options;
}

std::vector<double> halving(double first, int count) {
  std::vector<double> steps;
  for (int i = 0; i < count; ++i) steps.push_back(first / std::pow(2.0, i));
  return steps;
}

std::vector<BenchScene> make_scenes(const Options& options) {
  std::vector<BenchScene> scenes;
  const auto load = [&](const std::string& name) {
    BenchScene bench;
    bench.scene = load_scene(options.scene_dir + "/" + name + ".yaml");
    bench.scene.reference = ReferenceSettings{};  // errors are computed here, not in lockstep
    return bench;
  };
  const int fixed_count = options.quick ? 4 : 7;
  const std::vector<double> tolerances =
      options.quick ? std::vector<double>{1e-4, 1e-6, 1e-8, 1e-10}
                    : std::vector<double>{1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  {
    BenchScene bench = load("jackknife_whirl");
    bench.scene.duration = options.quick ? 100.0 : 1000.0;  // stretched: long horizon [s]
    bench.step_sizes = halving(0.04, options.quick ? 4 : 7);  // 0.04 … 0.000625 s
    bench.tolerances = tolerances;
    // 1e-13 too (the reference itself, so no position error): can dopri5 reach 1e-8 J over 1000 s?
    if (!options.quick) bench.tolerances.push_back(kReferenceTolerance);
    scenes.push_back(bench);
  }
  for (const char* name : {"sine_steer_torque", "drive_rr_drag"}) {
    BenchScene bench = load(name);
    bench.step_sizes = halving(0.05, fixed_count);  // 0.05 … 0.00078 s
    bench.tolerances = tolerances;
    scenes.push_back(bench);
  }
  {
    BenchScene bench = load("paper_special");
    bench.scene.duration = (M_PI - kPaperEndMargin) - bench.scene.initial_state.time;  // (π/2, π − 0.05)
    bench.step_sizes = halving(0.01, fixed_count);  // 0.01 … 0.00016 s
    bench.tolerances = tolerances;
    bench.analytic = true;
    scenes.push_back(bench);
  }
  return scenes;
}

std::FILE* open_output(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) throw std::runtime_error("cannot write " + path);
  return file;
}

}  // namespace

const char* const kUsage =
    "usage: work_precision [--quick] [--repetitions N] [--output-dir DIR] [--scene-dir DIR]\n"
    "       work_precision --help | -h | --version\n"
    "Exit status: 0 done; 1 failed (a file cannot be written, a scene cannot be loaded); 2 bad arguments.\n";

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  if (print_version_if_asked(argc, argv, "work_precision")) return 0;
  Options options;
  try {
    options = parse(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "work_precision: %s\n%s", error.what(), kUsage);
    return 2;
  }
  try {
    std::vector<BenchScene> scenes = make_scenes(options);
    const std::string dir = options.output_dir;
    std::FILE* table = open_output(dir + "/work_precision.csv");
    std::FILE* check = open_output(dir + "/reference_check.csv");
    std::FILE* long_run = open_output(dir + "/long_run.csv");
    std::FILE* paper = open_output(dir + "/paper_relative_error.csv");
    write_header(table);
    std::fprintf(check, "scene,reference,position_difference_m,heading_difference_rad,wall_s\n");
    std::fprintf(stderr, "work_precision: %d repetitions after a warm-up%s\n", options.repetitions,
                 options.quick ? " (quick)" : "");
    for (BenchScene& bench : scenes) {
      std::fprintf(stderr, "scene %s (%g s)\n", bench.scene.name.c_str(), bench.scene.duration);
      prepare_reference(bench, check);
      std::vector<RunRecord> records;
      const auto keep = [&](RunRecord record) {
        write_record(table, bench, record);
        records.push_back(std::move(record));
      };
      for (const std::string& method : integrator_names()) {
        if (method == "dopri5") {
          for (double tolerance : bench.tolerances) keep(measure_ours(bench, method, NAN, tolerance, options.repetitions));
        } else {
          for (double h : bench.step_sizes) keep(measure_ours(bench, method, h, NAN, options.repetitions));
        }
      }
      for (double h : bench.step_sizes) keep(measure_odeint(bench, "odeint_rk4", h, NAN, options.repetitions));
      for (double tolerance : bench.tolerances) {
        keep(measure_odeint(bench, "odeint_dopri5", NAN, tolerance, options.repetitions));
      }
      if (bench.scene.name == "jackknife_whirl") write_long_run(bench, records, long_run);
      if (bench.analytic) write_paper_relative_error(bench.scene, paper);
    }
    std::fclose(table);
    std::fclose(check);
    std::fclose(long_run);
    std::fclose(paper);
    std::fprintf(stderr, "wrote %s/{work_precision,reference_check,long_run,paper_relative_error}.csv\n", dir.c_str());
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "work_precision: %s\n", error.what());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "work_precision: unexpected error of unknown type\n");
    return 1;
  }
}
