// work_precision: what one run measures, and how it is timed (median of repetitions).
#pragma once

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {
namespace work_precision {

inline double cpu_seconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}
inline double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Errors at one checkpoint time of a run (error against the reference at that time).
struct CheckpointError {
  double time = NAN;                  ///< simulated time from the start [s]
  double position_error = NAN;        ///< |B − B_ref| [m]
  double max_energy_residual = NAN;   ///< running max |T* − T*₀ − W| up to this time [J]
};

/// What one run measures.
struct RunErrors {
  double position_error = NAN;         ///< |B − B_ref| at the end [m]
  double heading_error = NAN;          ///< |θ − θ_ref| at the end [rad]
  double arc_length_rel_error = NAN;   ///< |π1 − π1_ref| / |π1_ref| at the end [-]
  double max_energy_residual = 0.0;    ///< max |T* − T*₀ − W| over the samples [J]
  double max_p2_residual = 0.0;        ///< max |p2 − p2₀ − I2| over the samples [kg·m²/s]
  double energy_scale = NAN;           ///< T*₀ [J], for relative numbers
  CartState final_state;
  std::vector<CheckpointError> checkpoints;  ///< in time order; the last one is the end
};

struct RunRecord {
  std::string scene, method, kind;  // kind: "ours" or "odeint"
  double duration = NAN;            ///< simulated time [s]
  double step_size = NAN;           ///< fixed step [s] (NaN for adaptive)
  double tolerance = NAN;           ///< adaptive methods' absolute = relative tolerance [-]
  double simulator_step = NAN;      ///< our dopri5: the Simulation step it restarts at [s]
  std::uint64_t steps = 0, rhs_evaluations = 0, passive_evaluations = 0, iterations = 0;
  int repetitions = 0;              ///< timed runs the medians are over
  double wall_median = NAN, wall_min = NAN, cpu_median = NAN;  ///< [s]
  RunErrors errors;
  std::string status = "ok";
};

/// A run whose first execution lasts longer than this is not repeated `repetitions` times but
/// three times in all, the first one counting (the warm-up matters only for short runs) [s].
constexpr double kLongRunWall = 1.0;

/// Times `run`: one warm-up, then `repetitions` runs; a long run (first execution ≥ kLongRunWall)
/// counts its first execution and is run twice more. Returns the last run's errors.
template <class Run>
RunErrors timed(int repetitions, RunRecord& record, Run run) {
  std::vector<double> walls, cpus;
  double w0 = wall_seconds(), c0 = cpu_seconds();
  RunErrors errors = run();
  const double first_wall = wall_seconds() - w0, first_cpu = cpu_seconds() - c0;
  int remaining = repetitions;
  if (first_wall >= kLongRunWall) {
    walls.push_back(first_wall);
    cpus.push_back(first_cpu);
    remaining = std::min(repetitions, 3) - 1;
  }
  for (int r = 0; r < remaining; ++r) {
    w0 = wall_seconds();
    c0 = cpu_seconds();
    errors = run();
    walls.push_back(wall_seconds() - w0);
    cpus.push_back(cpu_seconds() - c0);
  }
  record.repetitions = static_cast<int>(walls.size());
  record.wall_median = median(walls);
  record.wall_min = *std::min_element(walls.begin(), walls.end());
  record.cpu_median = median(cpus);
  return errors;
}

}  // namespace work_precision
}  // namespace birkhoff_cart
