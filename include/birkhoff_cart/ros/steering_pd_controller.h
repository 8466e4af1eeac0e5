// SteeringPdController: the example controller for cart_sim's lockstep mode (docs/ros_interface.md,
// "Node steering_pd_controller"), as a class that the node steering_pd_controller and the nodelet
// birkhoff_cart/SteeringPdController share. On every joint_states message (stamped t) it answers once
// with
//   steering_torque τ = kp (χ_ref(t) − χ) + kd (χ̇_ref(t) − χ̇),  χ_ref(t) = amplitude · sin(2π frequency t)
// [N·m] (χ, χ̇: the position [rad] and velocity [rad/s] of ~steering_joint) and drive_torque =
// ~drive_torque [N·m]. It computes only from the message, so a lockstep loop is the same on every run.
// It publishes shared messages: in one nodelet manager with cart_sim nothing is serialized. A
// ~steering_joint that joint_states does not hold is refused by name within a second (kJointGrace),
// as cmd_vel_controller refuses it: the node shuts down, the nodelet unsubscribes; `refusal()` says why.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "birkhoff_cart/core/node_logic/missing_joint_check.h"
#include "birkhoff_cart/ros/inline_callback_queue.h"

namespace birkhoff_cart {

class SteeringPdController {
 public:
  /// Reads ~kp, ~kd, ~amplitude, ~frequency, ~drive_torque, ~steering_joint; throws
  /// std::invalid_argument naming them when one is not finite or the joint name is empty, and warns
  /// of every private parameter it does not read (with the closest known name). With
  /// `inline_answers` joint_states is handled in the publisher's thread (InlineCallbackQueue: the
  /// nodelet in cart_sim's manager), otherwise on `node`'s queue. `shut_down_on_refusal`: a refused
  /// joint name shuts roscpp down (the node), or only stops the controller (a nodelet).
  SteeringPdController(ros::NodeHandle node, ros::NodeHandle private_node, bool inline_answers = false,
                       bool shut_down_on_refusal = true);

  /// Why the controller stopped (a ~steering_joint missing from joint_states), or empty.
  std::string refusal() const { return refused_ ? refusal_ : std::string(); }

  /// How long joint_states may lack ~steering_joint before the name is refused [s] (wall time).
  static constexpr double kJointGrace = 1.0;

 private:
  void on_joint_states(const sensor_msgs::JointState::ConstPtr& joints);
  void check_joint_name(const ros::WallTimerEvent&);

  double kp_;            ///< [N·m/rad]
  double kd_;            ///< [N·m·s/rad]
  double amplitude_;     ///< χ_ref amplitude [rad]
  double frequency_;     ///< χ_ref frequency [Hz]
  double drive_torque_;  ///< [N·m]
  std::string steering_joint_;  ///< the joint whose position and velocity are χ, χ̇
  bool shut_down_on_refusal_;
  MissingJointCheck joint_check_state_;  ///< ~steering_joint in joint_states, or its refusal after kJointGrace
  std::atomic<bool> refused_{false};
  std::string refusal_;  ///< written once, before refused_ is set
  ros::WallTimer joint_check_;
  InlineCallbackQueue inline_queue_;  ///< with inline_answers: joint_states served in the publisher's thread
  ros::Publisher steering_publisher_;
  ros::Publisher drive_publisher_;
  ros::Subscriber subscriber_;
};

}  // namespace birkhoff_cart
