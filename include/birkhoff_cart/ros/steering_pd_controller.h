// SteeringPdController: the example controller for cart_sim's lockstep mode (docs/ros_interface.md,
// "Node steering_pd_controller"), as a class that the node steering_pd_controller and the nodelet
// birkhoff_cart/SteeringPdController share. On every joint_states message (stamped t) it answers once
// with
//   steering_torque τ = kp (χ_ref(t) − χ) + kd (χ̇_ref(t) − χ̇),  χ_ref(t) = amplitude · sin(2π frequency t)
// [N·m] (χ, χ̇: steering_joint's position [rad] and velocity [rad/s]) and drive_torque = ~drive_torque
// [N·m]. It computes only from the message, so a lockstep loop is the same on every run. It publishes
// shared messages: in one nodelet manager with cart_sim nothing is serialized.
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "birkhoff_cart/ros/inline_callback_queue.h"

namespace birkhoff_cart {

class SteeringPdController {
 public:
  /// Reads ~kp, ~kd, ~amplitude, ~frequency, ~drive_torque; throws std::invalid_argument naming them
  /// when one is not finite. With `inline_answers` joint_states is handled in the publisher's thread
  /// (InlineCallbackQueue: the nodelet in cart_sim's manager), otherwise on `node`'s queue.
  SteeringPdController(ros::NodeHandle node, ros::NodeHandle private_node, bool inline_answers = false);

 private:
  void on_joint_states(const sensor_msgs::JointState::ConstPtr& joints);

  double kp_;            ///< [N·m/rad]
  double kd_;            ///< [N·m·s/rad]
  double amplitude_;     ///< χ_ref amplitude [rad]
  double frequency_;     ///< χ_ref frequency [Hz]
  double drive_torque_;  ///< [N·m]
  InlineCallbackQueue inline_queue_;  ///< with inline_answers: joint_states served in the publisher's thread
  ros::Publisher steering_publisher_;
  ros::Publisher drive_publisher_;
  ros::Subscriber subscriber_;
};

}  // namespace birkhoff_cart
