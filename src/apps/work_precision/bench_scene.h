// work_precision: one scene of the benchmark, its sweeps and its reference states.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "birkhoff_cart/core/run/reference_solution.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "measurement.h"

namespace birkhoff_cart {
namespace work_precision {

/// One scene with its sweeps and reference.
struct BenchScene {
  std::string label;                 ///< name in the tables (jackknife_whirl_1000s, ...)
  Scene scene;                       ///< reference kind none; duration as benchmarked
  /// Per registry member: nominal step sizes h [s] (members without an entry are not run).
  std::vector<std::pair<std::string, std::vector<double>>> step_sweeps;
  std::vector<double> tolerances;            ///< adaptive methods [-]
  std::vector<double> dopri5_simulator_steps;  ///< our dopri5's Simulation steps [s]
  bool odeint_high_order = false;             ///< also odeint rkf78 and bulirsch_stoer
  bool analytic = false;             ///< paper_special: compare with PaperAnalyticSolution
  /// Times from the start at which errors are recorded [s] (the last one is the duration), and
  /// the reference state at each (when !analytic).
  std::vector<double> checkpoint_times;
  std::vector<CartState> reference_states;
  double reference_error_position = NAN, reference_error_heading = NAN;  ///< estimates at the end [m], [rad]
  std::string reference_name;

  const CartState& reference_final() const { return reference_states.back(); }
};

/// The number of steps N and the exact h = duration / N nearest the nominal step.
inline std::uint64_t step_count(double duration, double nominal_step) {
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(duration / nominal_step)));
}

/// The step index of each checkpoint for a run of `steps` steps of h = duration / steps (a
/// checkpoint that is no step boundary gets index 0, i.e. is skipped).
inline std::vector<std::uint64_t> checkpoint_steps(const BenchScene& bench, std::uint64_t steps) {
  std::vector<std::uint64_t> indices;
  const double h = bench.scene.duration / static_cast<double>(steps);
  for (double t : bench.checkpoint_times) {
    const std::uint64_t k = static_cast<std::uint64_t>(std::llround(t / h));
    indices.push_back(std::abs(static_cast<double>(k) * h - t) <= 1e-9 * t ? k : 0);
  }
  indices.back() = steps;
  return indices;
}

/// The reference state at checkpoint j (analytic scenes: the closed form at the state's time).
inline CartState reference_at(const BenchScene& bench, std::size_t j, double time) {
  if (bench.analytic) return PaperAnalyticSolution{bench.scene.initial_state}.at(time);
  return bench.reference_states[j];
}

inline double position_distance(const CartState& a, const CartState& b) { return std::hypot(a.x - b.x, a.y - b.y); }
/// θ_a − θ_b with the low parts of the unwrapped headings (state.h) [rad].
inline double heading_difference(const CartState& a, const CartState& b) {
  return (a.heading - b.heading) + (a.heading_low - b.heading_low);
}

inline CheckpointError checkpoint_error(const BenchScene& bench, std::size_t j, const CartState& state,
                                        double max_energy_residual) {
  CheckpointError point;
  point.time = bench.checkpoint_times[j];
  point.position_error = position_distance(state, reference_at(bench, j, state.time));
  point.max_energy_residual = max_energy_residual;
  return point;
}

inline void fill_final_errors(const BenchScene& bench, const CartState& state, RunErrors& errors) {
  const CartState reference = reference_at(bench, bench.checkpoint_times.size() - 1, state.time);
  errors.position_error = position_distance(state, reference);
  errors.heading_error = std::abs(heading_difference(state, reference));
  errors.arc_length_rel_error = std::abs(state.arc_length - reference.arc_length) / std::abs(reference.arc_length);
  errors.final_state = state;
}

}  // namespace work_precision
}  // namespace birkhoff_cart
