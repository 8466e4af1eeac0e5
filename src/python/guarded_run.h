// What the Python module (birkhoff_cart.simulator) drives: a Simulation with the accuracy guard that
// cart_simulate keeps beside it, checked at the same instants (the start, every output instant
// t₀ + k/output_rate on the step grid, the end; and every instant of a time grid the caller asks
// for), so that a run's verdict does not depend on how the caller cuts it into calls. Plain C++ (no Python types): the bindings in simulator_module.cpp only
// convert. docs/python.md.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "birkhoff_cart/core/accuracy_guard.h"
#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/core/simulation.h"

namespace birkhoff_cart {
namespace python {

/// The torque commands of one step [N·m]; NaN: keep the command in force.
struct StepCommands {
  double steering = std::numeric_limits<double>::quiet_NaN();
  double drive = std::numeric_limits<double>::quiet_NaN();
};

class GuardedRun {
 public:
  /// Builds the simulation (std::invalid_argument, TimeLimitError as Simulation's) and checks the
  /// initial state.
  explicit GuardedRun(const Scene& scene);

  Simulation& simulation() { return simulation_; }
  const Simulation& simulation() const { return simulation_; }
  const AccuracyGuard& guard() const { return guard_; }

  /// Steps between the guard's checks: the output interval 1/output_rate in steps when it is a
  /// whole number of them (as cart_simulate requires), else 1 (every step).
  std::uint64_t steps_between_checks() const { return steps_between_checks_; }

  /// Up to `count` steps of the run's schedule (fewer when it ends), each after applying
  /// commands[k] (when commands is not empty it has `count` entries; a NaN keeps the command). With
  /// `record`, appends each step's state to `states`. Returns the steps taken. A failing step
  /// (StepError) or command (std::invalid_argument, std::logic_error) leaves the state after the
  /// steps already taken and rethrows.
  std::uint64_t advance(std::uint64_t count, const std::vector<StepCommands>& commands, bool record,
                        std::vector<CartState>* states);

  /// Steps to the run's end (after states_at() left the step grid: the member's dense output to
  /// the end).
  void run_to_end();

  /// The state at each of `times` [s] (increasing, from now to the run's end), advancing the run to
  /// the last one; `observe` sees the simulation at each, after the guard checked it. The one place
  /// the module turns times into states. A member with its own steps (a step control; dopri5) gives
  /// any instant, from its dense output (Simulation::advance_output_to); the run then continues only
  /// through states_at() and run_to_end() (advance() refuses). A member at fixed steps gives the
  /// instants of the step schedule (t₀ + n·h, and the end). std::invalid_argument names a time that
  /// is not finite, not increasing, in the past, beyond the end or (fixed steps) off the grid, before
  /// any step is taken.
  std::vector<CartState> states_at(const std::vector<double>& times,
                                   const std::function<void(const Simulation&)>& observe = {});

  /// Did states_at() take the run off the step grid (dense output of a member with its own steps)?
  bool off_grid() const { return off_grid_; }

  /// Back to the scene's start: the simulation's reset() and a fresh guard.
  void reset();

 private:
  void step_once();
  void check_if_due();

  Simulation simulation_;
  AccuracyGuard guard_;
  std::uint64_t steps_between_checks_ = 1;
  bool checks_at_output_instants_ = false;  ///< the output interval is a whole number of steps
  bool off_grid_ = false;                   ///< states_at() used the member's dense output
  std::vector<CartState> dense_states_at(const std::vector<double>& times,
                                         const std::function<void(const Simulation&)>& observe);
  std::vector<CartState> grid_states_at(const std::vector<double>& times,
                                        const std::function<void(const Simulation&)>& observe);
};

}  // namespace python
}  // namespace birkhoff_cart
