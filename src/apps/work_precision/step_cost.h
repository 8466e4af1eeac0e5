// work_precision: the cost of one step of two methods on the free cart, measured side by side
// (alternating runs, so that both see the same machine load) — issue 11's "birkhoff2 step ≤ rk4 step".
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "bench_scene.h"
#include "birkhoff_cart/core/simulation.h"
#include "measurement.h"
#include "ours.h"

namespace birkhoff_cart {
namespace work_precision {

/// Alternates `rounds` runs of `steps` steps of each method at step h; writes per method the
/// median wall and CPU time per step and the rhs evaluations per step, and the ratios
/// method / baseline (of the medians, and the median of the per-round ratios).
inline void measure_step_cost(const Scene& free_cart, const std::vector<std::string>& methods, double h,
                              std::uint64_t steps, int rounds, std::FILE* out) {
  std::vector<std::unique_ptr<Simulation>> sims;
  for (const std::string& method : methods) sims.push_back(std::make_unique<Simulation>(configured(free_cart, method, h, 1e-10)));
  std::vector<std::vector<double>> walls(methods.size()), cpus(methods.size());
  for (int round = -1; round < rounds; ++round) {  // round −1: warm-up
    for (std::size_t m = 0; m < methods.size(); ++m) {
      Simulation& sim = *sims[m];
      sim.reset();
      const double w0 = wall_seconds(), c0 = cpu_seconds();
      for (std::uint64_t k = 0; k < steps; ++k) sim.step();
      const double wall = wall_seconds() - w0, cpu = cpu_seconds() - c0;
      if (round >= 0) {
        walls[m].push_back(wall / static_cast<double>(steps));
        cpus[m].push_back(cpu / static_cast<double>(steps));
      }
    }
  }
  for (std::size_t m = 0; m < methods.size(); ++m) {
    std::vector<double> round_ratios;
    for (int r = 0; r < rounds; ++r) round_ratios.push_back(cpus[m][r] / cpus[0][r]);
    const StepStatistics& s = sims[m]->statistics();
    const double rhs_per_step = static_cast<double>(s.rhs_evaluations) / static_cast<double>(s.steps);
    const double passive_per_step = static_cast<double>(s.passive_evaluations) / static_cast<double>(s.steps);
    const double iterations_per_step = static_cast<double>(s.newton_iterations_total) / static_cast<double>(s.steps);
    std::fprintf(out, "%s,%s,%.6g,%llu,%d,%.4e,%.4e,%.3f,%.3f,%.3f,%.4f,%.4f,%.4f\n", free_cart.name.c_str(),
                 methods[m].c_str(), h, static_cast<unsigned long long>(steps), rounds, median(walls[m]),
                 median(cpus[m]), rhs_per_step, passive_per_step, iterations_per_step,
                 median(walls[m]) / median(walls[0]), median(cpus[m]) / median(cpus[0]), median(round_ratios));
    std::fprintf(stderr, "  step cost h=%-6g %-18s wall %.3f us cpu %.3f us  (%.2f rhs, %.2f passive, %.2f it)/step  "
                 "cpu ratio to %s %.3f (median of rounds %.3f)\n",
                 h, methods[m].c_str(), 1e6 * median(walls[m]), 1e6 * median(cpus[m]), rhs_per_step, passive_per_step,
                 iterations_per_step, methods[0].c_str(), median(cpus[m]) / median(cpus[0]), median(round_ratios));
  }
  std::fflush(out);
}

inline void write_step_cost_header(std::FILE* out) {
  std::fprintf(out,
               "scene,method,step_size_s,steps,rounds,wall_per_step_s,cpu_per_step_s,rhs_per_step,passive_per_step,"
               "iterations_per_step,wall_ratio_to_first,cpu_ratio_to_first,median_round_cpu_ratio_to_first\n");
}

}  // namespace work_precision
}  // namespace birkhoff_cart
