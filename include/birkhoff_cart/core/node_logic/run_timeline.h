// Where cart_sim's run starts and ends in scene time, and the ROS-time rules on it (ROS-free,
// unit-tested; docs/ros_interface.md, "Node cart_sim"):
//   - the run's length T: ~duration when > 0; the scene's duration when ~duration < 0; without end
//     (+inf) when ~duration is 0 or +inf;
//   - its end t0 + T as the step rule of step_schedule.h lands it (the same plan as cart_simulate's);
//   - scene time is ROS time: the start must be >= 0 and the start and a finite end below
//     kLatestRosTime (ros::Time holds 32-bit seconds);
//   - a whole run (the start, ~reset, a follower's start on its leader's clock) is planned over T,
//     the rest of a run after a teleport up to the end in force.
// A refusal is a RunTimelineError whose message names the parameter or scene key to blame.
#pragma once

#include <stdexcept>
#include <string>

namespace birkhoff_cart {

/// The latest scene time cart_sim may publish [s]: ros::Time holds 32-bit seconds (2³² − 1 s).
constexpr double kLatestRosTime = 4294967295.0;

class RunTimelineError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class RunTimeline {
 public:
  /// `duration_parameter` [s]: ~duration (< 0: the scene's, 0 or +inf: without end);
  /// `scene_duration`, `step_size` [s]: the scene's T and h; `scene_path` names the scene in
  /// messages. Plans a whole run from `start_time` [s] (start_at()); throws RunTimelineError.
  RunTimeline(double duration_parameter, double scene_duration, double step_size, std::string scene_path,
              double start_time);

  /// A whole run from `start_time` [s]: from the scene's t0, or (a follower) from its leader's
  /// clock. Throws RunTimelineError naming the problem, with nothing changed.
  void start_at(double start_time);
  /// Why start_at(`start_time`) would refuse (its message); "" when it would not. Nothing changes.
  std::string refusal_to_start_at(double start_time) const;

  /// T, the length of a whole run [s]; +inf: without end.
  double duration() const { return duration_; }
  /// Where the current whole run started [s].
  double start_time() const { return start_time_; }
  /// Where the run stops exactly [s] (t0 + T as the step rule lands it); +inf: never.
  double end_time() const { return end_time_; }
  /// The length to plan from `time` [s] (Simulation::plan_run): T for a whole run, the rest up to
  /// end_time() for the rest of one (a teleport); +inf without end.
  double length_from(double time, bool whole_run) const;

 private:
  double duration_parameter_;  ///< [s]
  double step_size_;           ///< [s]
  std::string scene_path_;
  double duration_;            ///< T [s]
  double start_time_ = 0.0;    ///< [s]
  double end_time_ = 0.0;      ///< [s]
};

/// How far a leader's clock may be ahead of a follower's start before the follower's run moves
/// there [s of scene time]: a follower catches up a lag by stepping as fast as it can; a leader far
/// ahead (the follower reset, or started late) would be a burst replaying the leader's past.
constexpr double kLongestCatchUp = 1.0;

/// Where a follower's (~follow_clock) run starts: at `scene_start` [s] while `leader_time` [s] is at
/// most `longest_catch_up` [s] ahead of it (kLongestCatchUp at its start and after the leader's
/// reset; 0 after its own ~reset, whose new stamps must not repeat those it sent); else on the
/// leader's clock, not in its past: the latest of its own publish instants `scene_start` +
/// k·`publish_period` (k >= 1) at or before `leader_time`, so its instants fall on the leader's when
/// both publish at one rate.
double start_on_leader_clock(double scene_start, double leader_time, double publish_period,
                             double longest_catch_up = kLongestCatchUp);

/// The pace of cart_sim's run [-] (WallClockPacing): ~real_time_factor when > 0; 1 in real-time
/// mode and 0 (unpaced) in fast mode when it is 0; 0 when following a leader's /clock (its clock is
/// the pace).
double pacing_factor(bool fast, double real_time_factor, bool follow_clock);

}  // namespace birkhoff_cart
