// work_precision: what accuracy costs in time (issues 6 and 11). ROS-free; built by the normal build.
//
//   work_precision [--quick] [--repetitions N] [--output-dir DIR] [--scene-dir DIR] [--only PREFIX]
//   (defaults, relative to the working directory, i.e. the repository: bench/results, config/scenes;
//    scripts/run_benchmark.sh builds, runs from the repository and plots)
//
// Every registry member (integrator_names()) over a step sweep per member, our dopri5 over a
// tolerance sweep at simulator steps 0.1 s (restarting odeint's stepper at every one), 1 s and 10 s,
// and Boost.Odeint's runge_kutta4, controlled runge_kutta_dopri5, runge_kutta_fehlberg78 and
// bulirsch_stoer (one stepper over the whole run) on the same right-hand side, on the scenes
//   jackknife_whirl  stretched to 1000 s and to 10 000 s (free, reversible, periodic whirl),
//   sine_steer_torque (forced), drive_rr_drag (forced, dissipative, non-reversible),
//   paper_special    the paper's case on (π/2, π − 0.05) against its closed form (docs eq. (3.9)).
// Per run: the final position error of the hinge B [m], heading error [rad], π1 relative error,
// the max energy-balance residual |T* − T*₀ − W| [J] and p2-balance residual |p2 − p2₀ − I2|
// [kg·m²/s] (sampled every 0.1 s of simulated time, and after every accepted adaptive step),
// median wall and CPU time (measurement.h: timed), rhs and passive evaluations, implicit-solve
// iterations; on jackknife_whirl also the errors at checkpoints 1, 2, 5, 10, …, 10 000 s.
//
// References (reference.h): jackknife_whirl — odeint rkf78 in long double at 1e-17 (checked
// against long double bulirsch_stoer 1e-17 and rkf78 1e-15); the forced scenes — our dopri5 at
// 1e-13 (checked against 1e-12); paper_special — the closed form.
//
// Outputs (DIR, default bench/results):
//   work_precision.csv    one row per (scene, method, step size or tolerance)
//   error_vs_time.csv     jackknife_whirl: every run's position error and running max energy
//                         residual at the checkpoints (crossover horizons, long-run plot)
//   reference_check.csv   per scene and checkpoint: the reference's distance from its checks
//   step_cost.csv         birkhoff2 and the other members against rk4, per step, side by side
//   paper_relative_error.csv  relative error of π1 against the closed form at τ = 0.001 (paper figs. 1–2)
// --quick: jackknife_whirl at 100 s only with two settings per method, the other scenes with
// three, 3 repetitions (a smoke run, < 1 min).
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "birkhoff_cart/core/version.h"
#include "work_precision/bench_scene.h"
#include "work_precision/measurement.h"
#include "work_precision/odeint_peers.h"
#include "work_precision/ours.h"
#include "work_precision/output.h"
#include "work_precision/paper_figures.h"
#include "work_precision/reference.h"
#include "work_precision/single_task.h"
#include "work_precision/step_cost.h"

namespace {

using namespace birkhoff_cart;
using namespace birkhoff_cart::work_precision;

constexpr long kMaxRepetitions = 1000;  // --repetitions limit [-]

struct Options {
  bool quick = false;
  int repetitions = 5;
  std::string output_dir = "bench/results";
  std::string scene_dir = "config/scenes";
  std::string only;  ///< run only the scenes whose label starts with this
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
    else if (arg == "--only") options.only = value();
    else throw std::invalid_argument("unknown argument '" + arg + "'");
  }
  if (options.quick && !repetitions_given) options.repetitions = 3;
  return options;
}

/// first, first/2, … (count values) [s].
std::vector<double> halving(double first, int count) {
  std::vector<double> steps;
  for (int i = 0; i < count; ++i) steps.push_back(first / std::pow(2.0, i));
  return steps;
}

std::vector<double> decades(int from_exponent, int to_exponent) {  // 10^from … 10^to, descending
  std::vector<double> values;
  for (int e = from_exponent; e >= to_exponent; --e) values.push_back(std::pow(10.0, e));
  return values;
}

/// Checkpoints 1, 2, 5, 10, 20, 50, … up to and including the duration [s].
std::vector<double> checkpoints_until(double duration) {
  std::vector<double> times;
  for (double decade = 1.0; decade < duration; decade *= 10.0) {
    for (double factor : {1.0, 2.0, 5.0}) {
      if (factor * decade < duration * (1.0 - 1e-12)) times.push_back(factor * decade);
    }
  }
  times.push_back(duration);
  return times;
}

/// The step sweeps of the jackknife_whirl scene over `duration` [s]: each member from ~1e-3 m down
/// to below 1e-8 m final position error where it can within the run-time budget; the low-order
/// members stop earlier (they cannot reach 1e-8 m at any affordable h).
std::vector<std::pair<std::string, std::vector<double>>> jackknife_sweeps(double duration, bool quick) {
  const bool longest = duration > 2000.0;
  if (quick) {
    return {{"birkhoff2", {0.01, 0.0025}},       {"birkhoff4", {0.02, 0.005}},
            {"rk2", {0.01, 0.0025}},             {"rk4", {0.01, 0.0025}},
            {"midpoint", {0.01}},                {"birkhoff_gauss4", {0.02, 0.005}},
            {"birkhoff_gauss6", {0.1, 0.025}},   {"birkhoff_gauss8", {0.2, 0.05}},
            {"birkhoff4_suzuki", {0.02, 0.005}}, {"birkhoff6_kahan_li", {0.1, 0.025}},
            {"birkhoff8_kahan_li", {0.2, 0.05}}};
  }
  return {{"birkhoff2", halving(0.01, longest ? 4 : 5)},   // 0.01 … 0.000625 s
          {"birkhoff4", halving(0.04, longest ? 5 : 6)},   // 0.04 … 0.00125 s
          {"rk2", halving(0.01, longest ? 3 : 4)},
          {"rk4", halving(0.02, longest ? 5 : 6)},         // 0.02 … 0.000625 s
          {"midpoint", halving(0.01, 3)},
          {"birkhoff_gauss4", halving(0.04, 6)},           // 0.04 … 0.00125 s
          {"birkhoff_gauss6", halving(0.1, 5)},            // 0.1 … 0.00625 s
          {"birkhoff_gauss8", halving(0.2, 5)},            // 0.2 … 0.0125 s
          {"birkhoff4_suzuki", halving(0.04, 6)},
          {"birkhoff6_kahan_li", halving(0.1, 5)},
          {"birkhoff8_kahan_li", halving(0.2, 5)}};
}

std::vector<BenchScene> make_scenes(const Options& options) {
  std::vector<BenchScene> scenes;
  const auto load = [&](const std::string& name) {
    BenchScene bench;
    bench.scene = load_scene(options.scene_dir + "/" + name + ".yaml");
    bench.scene.reference = ReferenceSettings{};  // errors are computed here, not in lockstep
    bench.label = name;
    return bench;
  };
  for (double duration : options.quick ? std::vector<double>{100.0} : std::vector<double>{1000.0, 10000.0}) {
    BenchScene bench = load("jackknife_whirl");
    bench.scene.duration = duration;  // stretched: long horizon [s]
    char label[64];
    std::snprintf(label, sizeof label, "jackknife_whirl_%.0fs", duration);
    bench.label = label;
    bench.step_sweeps = jackknife_sweeps(duration, options.quick);
    bench.tolerances = options.quick ? std::vector<double>{1e-7, 1e-10} : decades(-5, -13);
    bench.dopri5_simulator_steps = options.quick ? std::vector<double>{0.1, 10.0} : std::vector<double>{0.1, 1.0, 10.0};
    bench.odeint_high_order = true;
    bench.checkpoint_times = checkpoints_until(duration);
    scenes.push_back(bench);
  }
  const int fixed_count = options.quick ? 3 : 7;
  const std::vector<double> tolerances = options.quick ? decades(-4, -10) : decades(-4, -12);
  const auto every_member = [&](double first) {
    std::vector<std::pair<std::string, std::vector<double>>> sweeps;
    for (const std::string& method : integrator_names()) {
      if (method != "dopri5") sweeps.push_back({method, halving(first, fixed_count)});
    }
    return sweeps;
  };
  for (const char* name : {"sine_steer_torque", "drive_rr_drag"}) {
    BenchScene bench = load(name);
    bench.step_sweeps = every_member(0.05);  // 0.05 … 0.00078 s
    bench.tolerances = tolerances;
    bench.dopri5_simulator_steps = {kSampleInterval};
    bench.checkpoint_times = {bench.scene.duration};
    scenes.push_back(bench);
  }
  {
    BenchScene bench = load("paper_special");
    bench.scene.duration = (M_PI - kPaperEndMargin) - bench.scene.initial_state.time;  // (π/2, π − 0.05)
    bench.step_sweeps = every_member(0.01);  // 0.01 … 0.00016 s
    bench.tolerances = tolerances;
    bench.dopri5_simulator_steps = {kSampleInterval};
    bench.checkpoint_times = {bench.scene.duration};
    bench.analytic = true;
    scenes.push_back(bench);
  }
  std::vector<BenchScene> chosen;
  for (BenchScene& bench : scenes) {
    if (bench.label.compare(0, options.only.size(), options.only) == 0) chosen.push_back(bench);
  }
  if (chosen.empty()) throw std::invalid_argument("--only '" + options.only + "' matches no scene");
  return chosen;
}

/// The tolerances of an odeint peer: the scene's, and for the high-order steppers tighter ones.
std::vector<double> odeint_tolerances(const BenchScene& bench, const std::string& method, bool quick) {
  if (method == "odeint_dopri5") return bench.tolerances;
  if (quick) return {1e-8, 1e-12};
  return decades(-6, -15);
}

void run_scene(BenchScene& bench, const ReferenceSet* shared, const Options& options, std::FILE* table,
               std::FILE* check, std::FILE* curves, std::FILE* paper) {
  std::fprintf(stderr, "scene %s (%g s)\n", bench.label.c_str(), bench.scene.duration);
  prepare_reference(bench, shared, check);
  const auto keep = [&](const RunRecord& record) {
    write_record(table, bench, record);
    if (bench.checkpoint_times.size() > 1) write_checkpoints(curves, record);
  };
  for (const std::string& method : integrator_names()) {
    if (method == "dopri5") {
      for (double simulator_step : bench.dopri5_simulator_steps) {
        for (double tolerance : bench.tolerances) {
          keep(measure_ours(bench, method, NAN, tolerance, simulator_step, options.repetitions));
        }
      }
      continue;
    }
    for (const auto& [name, steps] : bench.step_sweeps) {
      if (name != method) continue;
      for (double h : steps) keep(measure_ours(bench, method, h, NAN, NAN, options.repetitions));
    }
  }
  for (const auto& [name, steps] : bench.step_sweeps) {
    if (name != "rk4") continue;
    for (double h : steps) keep(measure_odeint(bench, "odeint_rk4", h, NAN, options.repetitions));
  }
  std::vector<std::string> adaptive = {"odeint_dopri5"};
  if (bench.odeint_high_order) adaptive.insert(adaptive.end(), {"odeint_rkf78", "odeint_bulirsch_stoer"});
  for (const std::string& method : adaptive) {
    for (double tolerance : odeint_tolerances(bench, method, options.quick)) {
      keep(measure_odeint(bench, method, NAN, tolerance, options.repetitions));
    }
  }
  if (bench.analytic) write_paper_relative_error(bench.scene, paper);
}

}  // namespace

const char* const kUsage =
    "usage: work_precision [--quick] [--repetitions N] [--output-dir DIR] [--scene-dir DIR] [--only PREFIX]\n"
    "       work_precision --measure --scene FILE --duration T --method NAME (--step H | --tolerance TOL)\n"
    "                      [--simulator-step S] [--checkpoints t1,t2,...] [--repetitions N] [--label L]\n"
    "                      (--reference-file REF.csv | --analytic-reference)\n"
    "       work_precision --reference-run --scene FILE --duration T --reference-kind extended_precision|dopri5\n"
    "                      [--checkpoints t1,t2,...] --output REF.csv\n"
    "       work_precision --help | -h | --version\n"
    "--measure and --reference-run are one task of a study (scripts/study, docs/studies.md): one JSON row on stdout.\n"
    "Exit status: 0 done; 1 failed (a file cannot be written, a scene cannot be loaded); 2 bad arguments;\n"
    "4 the measured run failed (its row says why).\n";

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  if (print_version_if_asked(argc, argv, "work_precision")) return 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg != "--measure" && arg != "--reference-run") continue;
    SingleTask task;
    try {
      task = parse_single_task(argc, argv);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "work_precision: %s\n%s", error.what(), kUsage);
      return 2;
    }
    try {
      return task.mode == "measure" ? run_measure_task(task) : run_reference_task(task);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "work_precision: %s\n", error.what());
      return 1;
    }
  }
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
    std::FILE* curves = open_output(dir + "/error_vs_time.csv");
    std::FILE* costs = open_output(dir + "/step_cost.csv");
    std::FILE* paper = open_output(dir + "/paper_relative_error.csv");
    write_header(table);
    write_reference_check_header(check);
    write_checkpoint_header(curves);
    write_step_cost_header(costs);
    std::fprintf(stderr, "work_precision: %d repetitions after a warm-up%s\n", options.repetitions,
                 options.quick ? " (quick)" : "");
    // birkhoff2 (and every member) against rk4 per step on the free cart, side by side.
    {
      Scene free_cart = load_scene(options.scene_dir + "/jackknife_whirl.yaml");
      free_cart.reference = ReferenceSettings{};
      std::vector<std::string> methods = {"rk4", "birkhoff2", "midpoint", "rk2"};
      for (const std::string& name : integrator_names()) {
        if (name.compare(0, 8, "birkhoff") == 0 && name != "birkhoff2") methods.push_back(name);
      }
      const int rounds = options.quick ? 3 : 9;
      std::fprintf(stderr, "step cost on the free cart (%d alternating rounds)\n", rounds);
      for (double h : {0.01, 0.001}) {
        const double simulated = (options.quick ? 5.0 : 50.0) * (h < 0.005 ? 0.2 : 1.0);  // per run [s]
        measure_step_cost(free_cart, methods, h, static_cast<std::uint64_t>(std::llround(simulated / h)), rounds, costs);
      }
    }
    // jackknife_whirl's extended-precision reference, once for its longest horizon.
    const BenchScene* longest = nullptr;
    for (const BenchScene& bench : scenes) {
      if (bench.odeint_high_order && (!longest || bench.scene.duration > longest->scene.duration)) longest = &bench;
    }
    ReferenceSet shared;
    if (longest) {
      std::fprintf(stderr, "extended-precision reference over %g s\n", longest->scene.duration);
      shared = extended_precision_reference(*longest, longest->checkpoint_times);
    }
    for (BenchScene& bench : scenes) {
      run_scene(bench, bench.odeint_high_order ? &shared : nullptr, options, table, check, curves, paper);
    }
    for (std::FILE* file : {table, check, curves, costs, paper}) std::fclose(file);
    std::fprintf(stderr, "wrote %s/{work_precision,error_vs_time,reference_check,step_cost,paper_relative_error}.csv\n",
                 dir.c_str());
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "work_precision: %s\n", error.what());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "work_precision: unexpected error of unknown type\n");
    return 1;
  }
}
