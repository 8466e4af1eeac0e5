// What a node's run has cost in wall time (docs/ros_interface.md, the summary and
// integration_error.wall_time_per_step): steps taken and scene time advanced over the whole run
// (resets included), wall time spent stepping and paused, the mean wall time per step between two
// publish instants, the run's real-time factor, and the fast mode's progress lines (at most one per
// second of wall time). ROS-free: unit-tested without a master (run_work_meter_test).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

namespace birkhoff_cart {

class RunWorkMeter {
 public:
  using Clock = std::chrono::steady_clock;

  /// The run starts at wall time `now` and scene time `scene_time` [s].
  void start(Clock::time_point now, double scene_time);
  /// One step advanced the scene by `advanced` [s].
  void count_step(double advanced);
  /// A batch of steps took `seconds` of wall time.
  void add_stepping(double seconds);
  /// The run stood paused for `seconds` of wall time.
  void add_paused(double seconds);
  /// At a publish instant: the mean wall time per step since the last instant [s] (0 without a
  /// step), and the next period starts.
  double end_period();

  /// Scene time advanced / wall time not paused since start(), at `now` [-] (0 before any).
  double real_time_factor(Clock::time_point now) const;
  /// Wall time since start() at `now` [s].
  double wall_time(Clock::time_point now) const;
  /// At most once per `period` [s] of wall time: the real-time factor since the last line (or the
  /// start) at scene time `scene_time` [s]; nothing before `period` has passed.
  std::optional<double> progress(Clock::time_point now, double scene_time, double period = 1.0);

  std::uint64_t steps() const { return steps_; }                  ///< over the whole run, resets included
  std::uint64_t published_instants() const { return instants_; }  ///< end_period() calls
  double stepping_wall_time() const { return stepping_; }         ///< [s]
  double paused_wall_time() const { return paused_; }             ///< [s]
  double last_wall_time_per_step() const { return last_per_step_; }  ///< the last end_period()'s [s]

 private:
  Clock::time_point start_;
  Clock::time_point last_progress_wall_;
  double last_progress_time_ = 0.0;  ///< scene time of the last progress line [s]
  double stepping_ = 0.0;            ///< [s]
  double paused_ = 0.0;              ///< [s]
  double period_stepping_ = 0.0;     ///< since the last instant [s]
  std::uint64_t period_steps_ = 0;
  double last_per_step_ = 0.0;  ///< [s]
  std::uint64_t steps_ = 0;
  std::uint64_t instants_ = 0;
  double simulated_ = 0.0;  ///< scene time advanced [s]
};

}  // namespace birkhoff_cart
