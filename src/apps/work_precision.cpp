// work_precision: one measurement of what accuracy costs in time, per process (docs/studies.md,
// docs/benchmarks.md). ROS-free; the study runner (scripts/study) runs it once per task.
//
//   work_precision --measure ...        one method at one setting on one scene: one JSON row
//   work_precision --reference-run ...  a reference (or its check setting) at the checkpoints
//   work_precision --price ...          the price of an evaluation per method and control, per scene
//
// The methods: every registry member (integrator_names()) through Simulation, as the CLI and the
// node run them, and Boost.Odeint's runge_kutta4, controlled runge_kutta_dopri5,
// runge_kutta_fehlberg78, bulirsch_stoer and bulirsch_stoer_dense_out on the same right-hand side.
// Per run: the final position error of the hinge B [m], heading error [rad], π1 relative error,
// the max energy-balance residual |T* − T*₀ − W| [J] and p2-balance residual |p2 − p2₀ − I2|
// [kg·m²/s] (sampled every 0.1 s of simulated time, and after every accepted adaptive step),
// median wall and CPU time (measurement.h: timed), rhs and passive evaluations, implicit-solve
// iterations, and the errors at every checkpoint. References (reference.h): odeint rkf78 in long
// double at 1e-18 (check: odeint bulirsch_stoer in long double at 1e-18) for the free cart; our
// dopri5 at 1e-13 (check: 1e-12); the paper case's closed form.
#include <cstdio>
#include <exception>
#include <string>

#include "birkhoff_cart/core/support/version.h"
#include "work_precision/price.h"
#include "work_precision/single_task.h"

using namespace birkhoff_cart::work_precision;

const char* const kUsage =
    "usage: work_precision --measure --scene FILE --duration T --method NAME (--step H | --tolerance TOL)\n"
    "                      [--simulator-step S] [--checkpoints t1,t2,...] [--repetitions N] [--label L]\n"
    "                      (--reference-file REF.csv | --analytic-reference)\n"
    "       work_precision --reference-run --scene FILE --duration T --reference-kind extended_precision|dopri5\n"
    "                      [--checkpoints t1,t2,...] [--check-setting] --output REF.csv\n"
    "       work_precision --price [--scene NAME] [--scenes-dir DIR] [--tolerance TOL] [--peer-tolerance TOL]\n"
    "                      [--repetitions N] [--callgrind]\n"
    "       work_precision --help | -h | --version\n"
    "One task of a study (scripts/study, docs/studies.md): one JSON row on stdout. The whole benchmark:\n"
    "bash scripts/run_benchmark.sh. --price: the price table of docs/benchmarks.md (ns per evaluation).\n"
    "Exit status: 0 done; 1 failed (a file cannot be written, a scene cannot be loaded); 2 bad arguments;\n"
    "4 the measured run failed (its row says why).\n";

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  if (birkhoff_cart::print_version_if_asked(argc, argv, "work_precision")) return 0;
  if (argc > 1 && std::string(argv[1]) == "--price") {
    PriceSettings settings;
    try {
      settings = parse_price_settings(argc, argv);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "work_precision: %s\n%s", error.what(), kUsage);
      return 2;
    }
    try {
      return run_price(settings);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "work_precision: %s\n", error.what());
      return 1;
    }
  }
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
  } catch (...) {
    std::fprintf(stderr, "work_precision: unexpected error of unknown type\n");
    return 1;
  }
}
