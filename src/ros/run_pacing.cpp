// RunPacing (run_pacing.h): cart_sim's waits between batches of steps.
#include "birkhoff_cart/ros/run_pacing.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

#include "birkhoff_cart/core/node_logic/run_timeline.h"

namespace birkhoff_cart {
namespace {

using Clock = WallClockPacing::Clock;

/// How long a follower waits for a /clock at a time before it looks at its callbacks again [s].
constexpr double kClockPoll = 0.01;

}  // namespace

RunPacing::RunPacing(ros::NodeHandle& node, const CartSimParameters& parameters, SignalingCallbackQueue& queue,
                     RunWorkMeter& work, std::function<bool()> stop_requested)
    : parameters_(parameters), queue_(queue), work_(work), stop_requested_(std::move(stop_requested)),
      deadlines_(pacing_factor(parameters.fast, parameters.real_time_factor, parameters.follow_clock)) {
  // Without ~publish_clock the node hears /clock from the clock source as any node does (main()
  // moved roscpp's own subscription away: see InstantPublisher).
  if (!parameters_.publish_clock && ros::Time::isSimTime()) {
    ros::NodeHandle clock_node(node, "", ros::M_string{{"/clock", "/clock"}});
    clock_subscriber_ = clock_node.subscribe("/clock", 1, &RunPacing::hear_clock, this);
  }
}

void RunPacing::check_sim_time(const ros::NodeHandle& node, const CartSimParameters& parameters, double start_time) {
  bool use_sim_time = false;
  node.param("/use_sim_time", use_sim_time, false);
  if (parameters.follow_clock && !use_sim_time) {
    throw std::invalid_argument("~follow_clock is true but /use_sim_time is false: there is no /clock to follow; "
                                "set /use_sim_time true");
  }
  if (!use_sim_time) {
    ROS_WARN("cart_sim: /use_sim_time is false, but every stamp cart_sim publishes is scene time (from t0 = %s s) "
             "and it drives /clock: nodes on wall time (tf listeners, rviz, robot_state_publisher) will drop "
             "its messages as too old. Set /use_sim_time true before starting them (every launch file of "
             "birkhoff_cart does, but lockstep.launch, whose loop reads only stamps).",
             format_seconds(start_time).c_str());
  }
}

bool RunPacing::wait_until_due(double time) {
  // The deadline is computed from the anchor on every wake: a reset or pause in a callback moves
  // the anchor, and the next wait follows it.
  while (!stop_requested_()) {
    const Clock::time_point deadline =
        std::min(deadlines_.due(time), WallClockPacing::after(WallClockPacing::kLongestSleep));
    if (queue_.wait_until(deadline)) {
      return false;  // a message: the caller runs the steps due by now, then the callbacks
    }
    if (Clock::now() >= deadlines_.due(time)) return true;
  }
  return false;
}

void RunPacing::wait_while_paused(double time) {
  const Clock::time_point start = Clock::now();
  queue_.wait_until(WallClockPacing::after(WallClockPacing::kLongestSleep));
  queue_.call_pending();
  work_.add_paused(std::chrono::duration<double>(Clock::now() - start).count());
  // Scene time stood still: the next deadline starts from now.
  deadlines_.restart(Clock::now(), time);
}

void RunPacing::wait_for_clock(double time, const std::function<bool()>& interrupted) {
  // ros::Time::now() is the /clock of the node that drives it (hear_clock). 1 µs allows for the
  // nanosecond rounding of ROS time.
  constexpr double kStampRounding = 1e-6;  // [s]
  while (ros::Time::now().toSec() < time - kStampRounding && !interrupted()) {
    queue_.wait_until(WallClockPacing::after(kClockPoll));
    queue_.call_pending();
  }
}

void RunPacing::take_leader_reset() {
  leader_went_back_ = false;
  ROS_INFO("cart_sim: the leader's /clock went back from t = %s s to t = %s s (the leader was reset); this cart "
           "starts its scene again on the new clock",
           format_seconds(leader_time_before_).c_str(), format_seconds(ros::Time::now().toSec()).c_str());
}

std::optional<RunPacing::LeaderStart> RunPacing::leader_start(double scene_time, double publish_period) {
  if (ros::Time::now().isZero()) {  // no /clock heard yet: wait for the leader's first
    queue_.wait_until(WallClockPacing::after(kClockPoll));
    queue_.call_pending();
    return std::nullopt;
  }
  const double catch_up = *start_catch_up_;
  start_catch_up_.reset();
  const double leader_time = ros::Time::now().toSec();
  return LeaderStart{leader_time, start_on_leader_clock(scene_time, leader_time, publish_period, catch_up)};
}

void RunPacing::hear_clock(const rosgraph_msgs::Clock::ConstPtr& clock) {
  const ros::Time before = ros::Time::now();
  if (parameters_.follow_clock && clock->clock < before) {
    leader_went_back_ = true;
    leader_time_before_ = before.toSec();
  }
  ros::Time::setNow(clock->clock);  // what roscpp's own /clock subscription does
}

}  // namespace birkhoff_cart
