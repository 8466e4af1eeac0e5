// cart_sim's outputs at a publish instant (docs/ros_interface.md, "Topics"): odom, ground_truth,
// joint_states, ~integration_error, odom → base_link on /tf (once per stamp), /clock, and the
// identity world → odom latched on /tf_static; the same messages into the run's bag. The messages
// are InstantMessages filled in place, so an instant allocates nothing here; the controllers' inputs
// go out as shared messages (zero-copy to a nodelet in the same manager). Part of CartSimNode.
#pragma once

#include <string>

#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/instant_messages.h"
#include "birkhoff_cart/ros/output.h"
#include "birkhoff_cart/ros/run_record.h"

namespace birkhoff_cart {

class InstantPublisher {
 public:
  /// Advertises the topics (`node`: odom, ground_truth, joint_states; `private_node`:
  /// integration_error; /clock with ~publish_clock, /tf with ~publish_tf) and latches world → odom
  /// stamped `start_time` [s] (with ~publish_tf and ~publish_world_tf).
  InstantPublisher(ros::NodeHandle& node, ros::NodeHandle& private_node, const CartSimParameters& parameters,
                   double start_time);

  /// /clock at scene time `time` [s] (with ~publish_clock), and this process's ROS time with it.
  void publish_clock(double time);
  /// One publish instant of `simulation`: its `diagnostics` and the `guard` checked with them,
  /// `wall_time_per_step` [s], the odometry sensor's `estimate` (none: odom is the exact state);
  /// into `record` too when there is one (ground_truth only beside a sensor's odom).
  void publish(const Simulation& simulation, const Diagnostics& diagnostics, const AccuracyGuard& guard,
               double wall_time_per_step, const OdometryEstimate* estimate, RunRecord* record);
  /// A new run (~reset, a teleport): its first instant sends /tf even at a stamp sent before.
  void restart() { last_transform_stamp_ = ros::Time(); }

  /// Subscribers of joint_states (lockstep waits for its controller).
  std::uint32_t joint_state_subscribers() const { return joints_.subscribers(); }
  /// Someone subscribes to a topic of an instant (odom, ground_truth, joint_states,
  /// integration_error, /clock, /tf): the last instant's messages have somewhere to go.
  bool listened() const;

 private:
  const CartSimParameters& parameters_;
  Output<nav_msgs::Odometry> odometry_;
  Output<nav_msgs::Odometry> ground_truth_;
  Output<sensor_msgs::JointState> joints_;
  Output<IntegrationError> integration_error_;
  Output<rosgraph_msgs::Clock> clock_;       ///< with ~publish_clock
  Output<tf2_msgs::TFMessage> transforms_;   ///< /tf (tf2_msgs/TFMessage), as tf2_ros::TransformBroadcaster advertises it
  Output<tf2_msgs::TFMessage> static_transforms_;  ///< /tf_static, latched: the identity world → odom
  tf2_msgs::TFMessage world_transform_;  ///< world → odom, published once and recorded into each bag
  InstantMessages messages_;             ///< filled in place at each publish instant
  rosgraph_msgs::Clock clock_message_;
  ros::Time last_transform_stamp_;  ///< never the same tf stamp twice
};

}  // namespace birkhoff_cart
