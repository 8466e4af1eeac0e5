// work_precision: the CSV files it writes.
#pragma once

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "bench_scene.h"
#include "measurement.h"

namespace birkhoff_cart {
namespace work_precision {

inline std::FILE* open_output(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) throw std::runtime_error("cannot write " + path);
  return file;
}

inline void write_header(std::FILE* out) {
  std::fprintf(out,
               "scene,duration_s,method,kind,step_size_s,tolerance,simulator_step_s,steps,rhs_evaluations,"
               "passive_evaluations,iterations,iterations_per_step,rhs_per_simulated_second,repetitions,"
               "wall_median_s,wall_min_s,cpu_median_s,position_error_m,heading_error_rad,arc_length_rel_error,"
               "max_energy_residual_J,max_energy_residual_rel,max_p2_residual,reference_position_error_m,status\n");
}

inline void write_record(std::FILE* out, const BenchScene& bench, const RunRecord& r) {
  std::string status = r.status;
  std::replace(status.begin(), status.end(), ',', ';');
  std::replace(status.begin(), status.end(), '\n', ' ');
  const double iterations_per_step = r.steps ? static_cast<double>(r.iterations) / static_cast<double>(r.steps) : NAN;
  const double rhs_rate = static_cast<double>(r.rhs_evaluations) / r.duration;
  std::fprintf(out,
               "%s,%.9g,%s,%s,%.9g,%.3g,%.9g,%llu,%llu,%llu,%llu,%.4g,%.6g,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,"
               "%.6e,%.3e,%s\n",
               r.scene.c_str(), r.duration, r.method.c_str(), r.kind.c_str(), r.step_size, r.tolerance,
               r.simulator_step, static_cast<unsigned long long>(r.steps),
               static_cast<unsigned long long>(r.rhs_evaluations), static_cast<unsigned long long>(r.passive_evaluations),
               static_cast<unsigned long long>(r.iterations), iterations_per_step, rhs_rate, r.repetitions,
               r.wall_median, r.wall_min, r.cpu_median, r.errors.position_error, r.errors.heading_error,
               r.errors.arc_length_rel_error, r.errors.max_energy_residual,
               r.errors.max_energy_residual / r.errors.energy_scale, r.errors.max_p2_residual,
               bench.reference_error_position, status.c_str());
  std::fflush(out);
  std::fprintf(stderr, "  %-22s %-22s h=%-9.4g tol=%-7.1g wall=%8.4f s cpu=%8.4f s pos=%9.2e dE=%9.2e it/step=%5.2g %s\n",
               r.scene.c_str(), r.method.c_str(), r.step_size, r.tolerance, r.wall_median, r.cpu_median,
               r.errors.position_error, r.errors.max_energy_residual, iterations_per_step,
               r.status == "ok" ? "" : r.status.c_str());
}

inline void write_checkpoint_header(std::FILE* out) {
  std::fprintf(out,
               "scene,method,step_size_s,tolerance,simulator_step_s,wall_median_s,cpu_median_s,rhs_evaluations,"
               "duration_s,t,position_error_m,max_energy_residual_J\n");
}

/// error_vs_time.csv: a run's errors at every checkpoint.
inline void write_checkpoints(std::FILE* out, const RunRecord& r) {
  if (r.status != "ok") return;
  for (const CheckpointError& c : r.errors.checkpoints) {
    std::fprintf(out, "%s,%s,%.9g,%.3g,%.9g,%.6e,%.6e,%llu,%.9g,%.9g,%.6e,%.6e\n", r.scene.c_str(), r.method.c_str(),
                 r.step_size, r.tolerance, r.simulator_step, r.wall_median, r.cpu_median,
                 static_cast<unsigned long long>(r.rhs_evaluations), r.duration, c.time, c.position_error,
                 c.max_energy_residual);
  }
  std::fflush(out);
}

}  // namespace work_precision
}  // namespace birkhoff_cart
