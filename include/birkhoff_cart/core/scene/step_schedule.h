// How a run is cut into steps and where it ends: the one rule that cart_simulate, cart_sim and the
// benchmarks share, so that no start time, duration, step size or output rate can disagree with
// Simulation::step / Simulation::step_to. Also the limits on scene time that make the rule safe.
//
// The rule, for a run from t₀ over a duration T with step size h (t_end = t₀ + T as a double):
//   1. Whole steps land on the grid tₙ = t₀ + n·h (computed exactly so, as Simulation::step does,
//      never as a running sum).
//   2. N = the number of whole steps = the largest n with tₙ ≤ t_end; when t_N = t_end the run ends
//      there (no further step).
//   3. Otherwise one final, shorter step of length r = t_end − t_N lands exactly on t_end.
//   4. No sliver: when that final step would be shorter than kMinFinalStepFraction·h, the last whole
//      step is dropped instead and the final step (from t_{N−1}, length h + r ≤ (1 + kMinFinalStepFraction)·h)
//      lands on t_end. So every run ends exactly at t_end and no step is shorter than
//      kMinFinalStepFraction·h or longer than (1 + kMinFinalStepFraction)·h.
//
// Scene time limits (TimeLimitError names the key that breaks them):
//   - t₀ finite; T finite and > 0; h finite and > 0.
//   - Time resolution: ulp(max(|t₀|, |t_end|)) ≤ kTimeResolution·h, i.e. every step time is resolved
//     to about a millionth of a step. Below that, t + h rounds visibly (at t₀ = 1e300, t + h = t and
//     time stood still). With h = 1 ms this allows |t| up to 2²² s ≈ 48 days; with h = 10 ms, ≈ 1.3 years.
//   - Step count: N + 1 ≤ kMaxStepCount (2⁵³: every count is exact in a double and fits int64).
//   - For a consumer with a clock of limited range (ROS time: 0 … 2³² − 1 s), check_times_within().
//
// Use (the CLI; the node and the benchmark likewise):
//   Simulation simulation(scene);                  // plans with plan_steps(t₀, T, h) and keeps it
//   while (!simulation.at_end()) simulation.step_on_schedule();   // N whole steps, then the final one
//   // or, by hand: const StepSchedule s = plan_steps(t0, T, h); N = s.whole_steps; if (s.final_step) step_to(s.end_time)
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace birkhoff_cart {

/// Every step time is resolved to this fraction of h: ulp(|t|) ≤ kTimeResolution·h [-] (2⁻²⁰ ≈ 9.5e-7).
constexpr double kTimeResolution = 1.0 / 1048576.0;
/// A final step shorter than this fraction of h is merged into the step before it [-].
/// Larger than the worst rounding of tₙ (≈ 2 ulp ≤ 2e-6 h under kTimeResolution).
constexpr double kMinFinalStepFraction = 1e-5;
/// At most this many steps in one planned run: 2⁵³, exact in a double [-].
constexpr std::uint64_t kMaxStepCount = std::uint64_t{1} << 53;

/// A run's times break a limit above. key() is the scene key to blame: "initial_state.time",
/// "duration" or "integrator.step_size" (callers with other names, e.g. a CLI option, map it).
class TimeLimitError : public std::invalid_argument {
 public:
  TimeLimitError(std::string key, const std::string& problem)
      : std::invalid_argument(key + ": " + problem), key_(std::move(key)), problem_(problem) {}
  const std::string& key() const { return key_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string key_;
  std::string problem_;
};

/// How one run from start_time over duration with step_size is cut into steps (the rule above).
struct StepSchedule {
  double start_time = 0.0;         ///< t₀ [s]
  double end_time = 0.0;           ///< t_end = t₀ + T, where the run ends exactly [s]
  double step_size = 0.0;          ///< h [s]
  std::uint64_t whole_steps = 0;   ///< N: steps of h onto the grid tₙ = t₀ + n h
  bool final_step = false;         ///< then one step of length end_time − t_N onto end_time

  std::uint64_t total_steps() const { return whole_steps + (final_step ? 1 : 0); }
  /// tₙ = t₀ + n·h, exactly as Simulation::step computes it [s].
  double grid_time(std::uint64_t n) const { return start_time + static_cast<double>(n) * step_size; }
};

/// The schedule for a run; throws TimeLimitError when the times break a limit above.
StepSchedule plan_steps(double start_time, double duration, double step_size);

/// Throws TimeLimitError unless the run's start and end lie in [earliest, latest] (e.g. ROS time,
/// [0, 4294967295] s); `clock` names that clock in the message ("ROS time").
void check_times_within(double start_time, double end_time, double earliest, double latest, const std::string& clock);

/// Whole multiple: the number m ≥ 1 with interval = m·h to a relative 1e-9, range-checked
/// (m ≤ kMaxStepCount); throws std::invalid_argument naming both numbers otherwise.
std::uint64_t steps_per_interval(double interval, double step_size);

}  // namespace birkhoff_cart
