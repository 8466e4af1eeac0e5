// cart_sim's command inputs and their watchdogs (docs/ros_interface.md, "Commands"): the
// steering_torque and drive_torque topics the scene takes commands on, each through a
// CommandChannel (hold, rejection of non-finite values, clamp, watchdog) into the Simulation, and
// the lockstep barrier's bookkeeping (which topics must answer each publish instant, which have,
// and the answers to record there in a fixed order). Part of CartSimNode; the waiting is the
// node's (cart_sim_pacing.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/core/node_logic/command_channel.h"

namespace birkhoff_cart {

class CommandInputs {
 public:
  /// Records one command message: its topic, the scene time it takes effect [s], the message.
  using RecordCommand = std::function<void(const std::string& topic, double time, const std_msgs::Float64& message)>;

  /// Channels for the commands `simulation`'s scene takes (limits and timeout from `parameters`),
  /// holding its initial torques from `start_time` [s]; in lockstep, the topics each instant
  /// waits for (~lockstep_topics, by default every command topic). Throws std::invalid_argument
  /// when ~lockstep_topics names a topic the scene takes no command on.
  CommandInputs(Simulation& simulation, const CartSimParameters& parameters, double start_time);

  /// Subscribes through `node` to the topics the scene takes (an idle subscription would be an
  /// unconnected one for roswtf). `record` receives each accepted message outside lockstep; in
  /// lockstep the answers wait for end_barrier().
  void subscribe(ros::NodeHandle& node, RecordCommand record);

  /// The channels' hold and watchdogs start again at scene time `time` [s] (~reset, teleports).
  void restart(double time);
  /// Before each step: a channel silent for its timeout falls to 0 N·m (warned once per silence).
  void apply_watchdogs();
  /// New limits while running (dynamic_reconfigure): the clamps [N·m] of later commands and the
  /// watchdog's timeout [s]. Throws std::invalid_argument naming a bad value; nothing changes then.
  void set_limits(double max_steering_torque, double max_drive_torque, double timeout);

  /// Lockstep: every expected topic has a publisher.
  bool controllers_connected() const;
  /// Lockstep: every expected topic has answered since the last end_barrier().
  bool answered() const;
  /// The expected topics' resolved names, "/steering_torque and /drive_torque" (a log line's).
  std::string expected_topics() const;
  /// The expected topics that have not answered, "steering_torque and drive_torque".
  std::string unanswered_topics() const;
  /// Lockstep, after the wait at instant `time` [s]: the answers go to subscribe()'s `record` in
  /// the order of their topics' names (answers arrive over separate connections in any order; so
  /// two identical runs record identical bags), and the next instant waits afresh.
  void end_barrier(double time);

  const std::optional<CommandChannel>& steering() const { return steering_channel_; }
  const std::optional<CommandChannel>& drive() const { return drive_channel_; }
  /// Non-finite commands rejected on both topics so far.
  std::uint64_t rejected() const;

 private:
  void on_steering_torque(const std_msgs::Float64::ConstPtr& message);
  void on_drive_torque(const std_msgs::Float64::ConstPtr& message);
  void receive(CommandChannel& channel, const std::string& topic, const std_msgs::Float64& message);

  Simulation& simulation_;
  const CartSimParameters& parameters_;
  RecordCommand record_;
  std::optional<CommandChannel> steering_channel_;
  std::optional<CommandChannel> drive_channel_;
  ros::Subscriber steering_subscriber_;
  ros::Subscriber drive_subscriber_;
  bool expect_steering_ = false;  ///< lockstep: each instant waits for steering_torque
  bool expect_drive_ = false;     ///< ... and for drive_torque
  bool steering_answered_ = false;
  bool drive_answered_ = false;
  std::vector<std::pair<std::string, std_msgs::Float64>> lockstep_records_;  ///< answers to record at the barrier
};

}  // namespace birkhoff_cart
