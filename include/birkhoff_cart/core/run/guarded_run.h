// A simulation run to its output instants with its accuracy guard: the Simulation stepped on its
// schedule, and the guard checking the state at the start, at every output instant
// t₀ + k/output_rate on the step grid and at the end (and at every instant of a time grid the
// caller asks for), so that a run's verdict does not depend on how the caller cuts it into calls.
// The one run loop of every face: cart_simulate writes a CSV row at each instant step() returns,
// the Python module (birkhoff_cart.simulator: docs/python.md) drives advance() and states_at(), and
// cart_sim steps it between its publish instants, where it checks the guard itself (OutputInstants::kCaller).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {

/// The torque commands of one step [N·m]; NaN: keep the command in force.
struct StepCommands {
  double steering = std::numeric_limits<double>::quiet_NaN();
  double drive = std::numeric_limits<double>::quiet_NaN();
};

/// Where the guard checks the run.
enum class OutputInstants {
  kOutputRate,  ///< the start, t₀ + k/output_rate (every step when 1/output_rate is no whole number of steps), the end
  kCaller,      ///< only where the caller calls check() (cart_sim: its publish instants)
};

/// The step count n at which a run on `schedule` stands at `time` [s]: an instant t0 + n·h of its
/// whole steps, or its end (total_steps()), each to kTimeResolution·h. std::invalid_argument naming
/// the time and the schedule otherwise (`member`: the integrator, which steps at fixed steps and
/// has no states between them).
std::uint64_t schedule_step_at(const StepSchedule& schedule, double time, const std::string& member);

class GuardedRun {
 public:
  /// Builds the simulation (std::invalid_argument, TimeLimitError as Simulation's) and, under
  /// kOutputRate, checks the initial state.
  explicit GuardedRun(const Scene& scene, OutputInstants instants = OutputInstants::kOutputRate);

  Simulation& simulation() { return simulation_; }
  const Simulation& simulation() const { return simulation_; }
  AccuracyGuard& guard() { return guard_; }
  const AccuracyGuard& guard() const { return guard_; }

  /// Steps between the guard's checks: the output interval 1/output_rate in steps when it is a
  /// whole number of them, else 1 (every step).
  std::uint64_t steps_between_checks() const { return steps_between_checks_; }
  /// Throws std::invalid_argument (steps_per_interval's, naming both) unless the output interval
  /// 1/output_rate is a whole number of steps: cart_simulate's rows are all on output instants.
  void require_output_instants_on_steps() const;

  /// One step of the run's schedule (Simulation::step_on_schedule; StepError as it). Under
  /// kOutputRate, when the step lands on an output instant or on the run's end, the guard checks
  /// the state there and the instant's time [s] is returned (t₀ + k/output_rate, exactly as a row's).
  std::optional<double> step();
  /// The guard's check of the state now, at scene time `time` [s] (with its `diagnostics`, when the
  /// caller has them: cart_sim publishes them too).
  void check(double time);
  void check(double time, const Diagnostics& diagnostics);

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
  /// the last one; `observe` sees the simulation at each, after the guard checked it. A member with
  /// its own steps (a step control; dopri5) gives any instant, from its dense output
  /// (Simulation::advance_output_to); the run then continues only through states_at() and
  /// run_to_end() (advance() refuses). A member at fixed steps gives the instants of the step
  /// schedule (t₀ + n·h, and the end). std::invalid_argument names a time that is not finite, not
  /// increasing, in the past, beyond the end or (fixed steps) off the grid, before any step is taken.
  std::vector<CartState> states_at(const std::vector<double>& times,
                                   const std::function<void(const Simulation&)>& observe = {});

  /// Did states_at() take the run off the step grid (dense output of a member with its own steps)?
  bool off_grid() const { return off_grid_; }

  /// Back to the scene's start: the simulation's reset() and a fresh guard (which, under
  /// kOutputRate, checks the initial state).
  void reset();

 private:
  void check_start();
  std::vector<CartState> dense_states_at(const std::vector<double>& times,
                                         const std::function<void(const Simulation&)>& observe);
  std::vector<CartState> grid_states_at(const std::vector<double>& times,
                                        const std::function<void(const Simulation&)>& observe);

  Simulation simulation_;
  AccuracyGuard guard_;
  OutputInstants instants_;
  std::uint64_t steps_between_checks_ = 1;
  bool checks_at_output_instants_ = false;  ///< the output interval is a whole number of steps
  bool off_grid_ = false;                   ///< states_at() used the member's dense output
};

}  // namespace birkhoff_cart
