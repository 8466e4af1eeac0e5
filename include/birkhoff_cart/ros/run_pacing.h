// When cart_sim's next steps may run (docs/ros_interface.md, "Running modes"): the real-time
// deadlines (WallClockPacing), the wait of a paused run, and a follower's leader (~follow_clock):
// the /clock it hears from another node, the leader's reset (its clock going back), the wait for
// the leader's clock to reach a batch's end, and a whole run's start placed on it. The node's
// callbacks run while it waits. Part of CartSimNode.
#pragma once

#include <functional>
#include <optional>

#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include "birkhoff_cart/core/node_logic/run_work_meter.h"
#include "birkhoff_cart/core/node_logic/wall_clock_pacing.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/signaling_callback_queue.h"

namespace birkhoff_cart {

class RunPacing {
 public:
  /// Paced by ~fast, ~real_time_factor and ~follow_clock; without ~publish_clock it hears /clock
  /// through `node` (whose callbacks go through `queue`). `work` counts the paused wall time;
  /// `stop_requested`: the node is stopping. All outlive the pacing.
  RunPacing(ros::NodeHandle& node, const CartSimParameters& parameters, SignalingCallbackQueue& queue,
            RunWorkMeter& work, std::function<bool()> stop_requested);

  /// Stamps are scene time, and a node on wall time would see them decades in the past: warns when
  /// /use_sim_time is false (for a run from scene time `start_time` [s]); std::invalid_argument
  /// when ~follow_clock has no /clock to follow.
  static void check_sim_time(const ros::NodeHandle& node, const CartSimParameters& parameters, double start_time);

  /// The real-time deadlines (restarted by the node where scene time and wall time part).
  WallClockPacing& deadlines() { return deadlines_; }

  /// Real-time mode: sleeps until scene time `time` [s] is due or a message arrives (the caller
  /// runs its callbacks). True when `time` is due.
  bool wait_until_due(double time);
  /// Paused at scene time `time` [s]: waits for a message (~pause, ~reset) or 0.1 s, runs the
  /// callbacks, counts the paused wall time; the next deadline starts from now.
  void wait_while_paused(double time);

  /// ~follow_clock: waits until the leader's /clock reaches scene time `time` [s] (the end of the
  /// next batch of steps), so this cart's stamps are instants of that clock, never ahead; stops
  /// early when `interrupted()`.
  void wait_for_clock(double time, const std::function<bool()>& interrupted);
  /// ~follow_clock: the leader's /clock went back (the leader was reset), heard on the loop's thread.
  bool leader_went_back() const { return leader_went_back_; }
  /// Logs the leader's reset and forgets it (the node resets this cart onto the new clock).
  void take_leader_reset();

  /// ~follow_clock: a whole run waits to start on the leader's clock, catching up at most
  /// `catch_up` [s] of the leader's lead by stepping (start_on_leader_clock).
  void start_on_leader_clock_next(double catch_up) { start_catch_up_ = catch_up; }
  /// A whole run waits to start on the leader's clock.
  bool starting_on_leader_clock() const { return start_catch_up_.has_value(); }
  /// The leader's time and the start on it [s] of a run at scene time `scene_time` with publish
  /// period `publish_period` [s] (start_on_leader_clock); the wait to start then ends. None while no
  /// /clock has been heard (after waiting a moment for it, callbacks run).
  struct LeaderStart {
    double leader_time;  ///< [s]
    double start;        ///< [s]
  };
  std::optional<LeaderStart> leader_start(double scene_time, double publish_period);

 private:
  /// /clock from the leader: this process's ROS time; a clock that goes back is noted.
  void hear_clock(const rosgraph_msgs::Clock::ConstPtr& clock);

  const CartSimParameters& parameters_;
  SignalingCallbackQueue& queue_;
  RunWorkMeter& work_;
  std::function<bool()> stop_requested_;
  WallClockPacing deadlines_;
  ros::Subscriber clock_subscriber_;  ///< /clock from elsewhere when ~publish_clock is false
  std::optional<double> start_catch_up_;  ///< [s]; none: the run has started
  bool leader_went_back_ = false;
  double leader_time_before_ = 0.0;  ///< the leader's /clock before it went back [s]
};

}  // namespace birkhoff_cart
