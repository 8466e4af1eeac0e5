// work_precision: our registry's integrators, run through Simulation exactly as the CLI and the
// node run them.
#pragma once

#include <cstdio>
#include <exception>
#include <string>

#include "bench_scene.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "measurement.h"

namespace birkhoff_cart {
namespace work_precision {

constexpr double kSampleInterval = 0.1;  // energy / p2 residual sampling period [s] (simulated)

/// A method of the study: a registry member, with the suffix `_adaptive` or `_reversible` for a
/// Birkhoffian member under that step control (its tolerance is then the position tolerance [m]).
struct OurMethod {
  std::string member;                       ///< the registry's name
  StepControl control = StepControl::kFixed;
};

inline OurMethod parse_our_method(const std::string& method) {
  for (StepControl control : {StepControl::kAdaptive, StepControl::kReversible}) {
    const std::string suffix = std::string("_") + to_string(control);
    if (method.size() > suffix.size() && method.compare(method.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return {method.substr(0, method.size() - suffix.size()), control};
    }
  }
  return {method, StepControl::kFixed};
}

/// Our member `method` reads a tolerance (dopri5's, or a step control's position tolerance) instead
/// of stepping at h alone; false for a name the registry lacks (Simulation then refuses it by name).
inline bool takes_tolerance(const std::string& method) {
  const OurMethod ours = parse_our_method(method);
  if (ours.control != StepControl::kFixed) return true;
  const IntegratorEntry* member = find_integrator(ours.member);
  return member != nullptr && member->takes_tolerance();
}

/// The scene with this method and step (for dopri5: the simulator step; tolerance used by dopri5).
inline Scene configured(const Scene& base, const std::string& method, double step, double tolerance) {
  const OurMethod ours = parse_our_method(method);
  Scene scene = base;
  scene.integrator.name = ours.member;
  scene.integrator.step_size = step;
  // The Birkhoffian members' local error estimate off at fixed steps (one more rhs evaluation a step),
  // so that the comparisons stay those of the methods alone (docs/benchmarks.md); the adaptive
  // control reads it, and turns it on itself.
  scene.integrator.local_error_estimate = false;
  scene.integrator.step_control = ours.control;
  if (ours.control != StepControl::kFixed) {
    scene.integrator.position_tolerance = tolerance;
  } else if (takes_tolerance(method)) {
    scene.integrator.tolerance = tolerance;
  }
  return scene;
}

/// Runs `steps` steps; samples the residuals every `sample_every` steps, at the checkpoints and
/// at the end.
inline RunErrors run_simulation(const BenchScene& bench, Simulation& sim, std::uint64_t steps,
                                std::uint64_t sample_every, const std::vector<std::uint64_t>& checkpoints) {
  RunErrors errors;
  errors.energy_scale = sim.diagnostics().energy;
  std::size_t next = 0;
  for (std::uint64_t k = 1; k <= steps; ++k) {
    sim.step();
    while (next < checkpoints.size() && checkpoints[next] < k) ++next;  // skipped checkpoints (index 0)
    const bool at_checkpoint = next < checkpoints.size() && checkpoints[next] == k;
    if (k % sample_every == 0 || at_checkpoint) {
      const Diagnostics d = sim.diagnostics();
      errors.max_energy_residual = std::max(errors.max_energy_residual, std::abs(d.energy_balance_residual));
      errors.max_p2_residual = std::max(errors.max_p2_residual, std::abs(d.p2_balance_residual));
    }
    if (at_checkpoint) errors.checkpoints.push_back(checkpoint_error(bench, next++, sim.state(), errors.max_energy_residual));
  }
  errors.final_state = sim.state();
  return errors;
}

/// A run with its own steps (a step control, dopri5): from checkpoint to checkpoint (each one landed
/// on exactly), the residuals sampled after every accepted step of its grid, as for odeint's
/// controlled peers (no dense output in between: the method's cost alone).
inline RunErrors run_controlled(const BenchScene& bench, Simulation& sim) {
  RunErrors errors;
  errors.energy_scale = sim.diagnostics().energy;
  const double start = sim.state().time;
  sim.observe_grid([&](const CartState& grid_state) {
    const Diagnostics d = sim.balances_of(grid_state);
    errors.max_energy_residual = std::max(errors.max_energy_residual, std::abs(d.energy_balance_residual));
    errors.max_p2_residual = std::max(errors.max_p2_residual, std::abs(d.p2_balance_residual));
  });
  for (std::size_t j = 0; j < bench.checkpoint_times.size(); ++j) {
    const double t = start + bench.checkpoint_times[j];
    sim.land_on(t);
    sim.advance_output_to(t);
    errors.checkpoints.push_back(checkpoint_error(bench, j, sim.state(), errors.max_energy_residual));
  }
  sim.observe_grid(nullptr);
  errors.final_state = sim.state();
  return errors;
}

/// One of our methods at nominal step h (fixed-step methods) or at `tolerance` with Simulation
/// step `simulator_step` (dopri5, which restarts odeint's stepper at every Simulation step).
inline RunRecord measure_ours(const BenchScene& bench, const std::string& method, double nominal_step,
                              double tolerance, double simulator_step, int repetitions) {
  RunRecord record;
  record.scene = bench.label;
  record.method = method;
  record.kind = "ours";
  record.duration = bench.scene.duration;
  const bool adaptive = takes_tolerance(method);
  if (adaptive) {
    char name[96];
    std::snprintf(name, sizeof name, "%s_sim%gs", method.c_str(), simulator_step);
    record.method = simulator_step == kSampleInterval ? method : name;
  }
  const std::uint64_t steps = step_count(bench.scene.duration, adaptive ? simulator_step : nominal_step);
  const double h = bench.scene.duration / static_cast<double>(steps);
  const std::uint64_t sample_every = std::max<std::uint64_t>(1, std::llround(kSampleInterval / h));
  if (adaptive) {
    record.tolerance = tolerance;
    record.simulator_step = h;
  } else {
    record.step_size = h;
  }
  const std::vector<std::uint64_t> checkpoints = checkpoint_steps(bench, steps);
  // Its own steps (a step control, or dopri5's one run): measured from checkpoint to checkpoint.
  const bool controlled = adaptive;
  try {
    StepStatistics statistics;
    Simulation sim(configured(bench.scene, method, h, tolerance));  // built outside the timed region
    const RunErrors errors = timed(repetitions, record, [&] {
      sim.reset();
      RunErrors e = controlled ? run_controlled(bench, sim) : run_simulation(bench, sim, steps, sample_every, checkpoints);
      statistics = sim.statistics();
      return e;
    });
    record.steps = controlled ? statistics.internal_steps : statistics.steps;  // a control: its own steps
    record.rhs_evaluations = statistics.rhs_evaluations;
    record.passive_evaluations = statistics.passive_evaluations;
    record.iterations = statistics.newton_iterations_total;
    record.errors = errors;
    fill_final_errors(bench, errors.final_state, record.errors);
  } catch (const std::exception& error) {
    record.status = std::string("failed: ") + error.what();
  }
  return record;
}

}  // namespace work_precision
}  // namespace birkhoff_cart
