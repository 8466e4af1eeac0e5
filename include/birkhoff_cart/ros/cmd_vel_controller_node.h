// cmd_vel_controller: the ROS side of CmdVelController (docs/ros_interface.md, "Node cmd_vel_controller").
//
// Subscribes cmd_vel (geometry_msgs/Twist: linear.x = v* of base_link [m/s], angular.z = r* [rad/s]),
// odom (v_A = twist.linear.x) and joint_states (χ, χ̇ of ~steering_joint); publishes steering_torque
// and drive_torque (std_msgs/Float64 [N·m]) for cart_sim on a scene whose torques come from
// commands (config/scenes/driven.yaml).
//
// Timing: one control update per simulator instant, when odom and joint_states with the same stamp
// have both arrived, so the loop runs at cart_sim's ~publish_rate of scene time in real-time and in
// fast/lockstep mode alike and never reads the wall clock. A cmd_vel counts as received at the
// stamp of the latest simulator instant seen, so ~cmd_vel_timeout is scene time even when
// /use_sim_time is false.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <sensor_msgs/JointState.h>

#include "birkhoff_cart/CmdVelControllerConfig.h"

#include "birkhoff_cart/core/node_logic/cmd_vel_controller.h"
#include "birkhoff_cart/core/node_logic/missing_joint_check.h"

namespace birkhoff_cart {

/// Reads every private parameter (names as in ros_controllers: cmd_vel_timeout, wheel_separation_h,
/// linear/x/max_velocity, ..., steering/p, drive/max_torque ...). Throws std::invalid_argument
/// naming the first bad one.
CmdVelControllerSettings load_cmd_vel_controller_settings(const ros::NodeHandle& private_node);

/// Every private parameter the node reads (load_cmd_vel_controller_settings and the node itself),
/// and dynamic_reconfigure's copies: a private parameter not in the list is reported at start-up
/// with the closest listed name (a typo). docs/ros_interface.md's table lists the same
/// (parameter_names_test).
const std::vector<std::string>& cmd_vel_controller_parameter_names();

class CmdVelControllerNode {
 public:
  /// Throws std::invalid_argument for a bad parameter. `shut_down_on_refusal`: a refusal shuts roscpp
  /// down (the node's process ends); false for a nodelet, which then only stops its own subscriptions.
  CmdVelControllerNode(ros::NodeHandle node, ros::NodeHandle private_node, bool shut_down_on_refusal = true);

  /// How long joint_states may come without ~steering_joint before the controller refuses to run
  /// [s of wall time]: a wrong joint name is a configuration error, as at a peer controller's load.
  static constexpr double kJointGrace = 1.0;
  /// Why the controller stopped itself ("" while it runs): ~steering_joint is not in joint_states.
  const std::string& refusal() const { return refusal_; }

 private:
  /// Refuses (ROS_FATAL, ros::shutdown) when joint_states has come for kJointGrace without the joint.
  void check_joint_names(const ros::WallTimerEvent&);
  /// A dynamic_reconfigure request: the new limits and gains, or a refusal by name (old ones kept).
  void on_reconfigure(CmdVelControllerConfig& config, std::uint32_t level);
  void on_cmd_vel(const geometry_msgs::Twist::ConstPtr& message);
  void on_odometry(const nav_msgs::Odometry::ConstPtr& message);
  void on_joint_states(const sensor_msgs::JointState::ConstPtr& message);
  /// Runs the law when odom and joint_states of the same instant are both in.
  void update_if_complete();

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  bool shut_down_on_refusal_;
  CmdVelController controller_;
  std::string steering_joint_;  ///< ~steering_joint: the hinge's name in joint_states

  ros::Subscriber cmd_vel_subscriber_;
  ros::Subscriber odometry_subscriber_;
  ros::Subscriber joint_state_subscriber_;
  ros::Publisher steering_publisher_;
  ros::Publisher drive_publisher_;

  ros::Time odometry_stamp_;      ///< stamp of the latest odom
  double base_speed_ = 0.0;       ///< its v_A [m/s]
  ros::Time joint_stamp_;         ///< stamp of the latest joint_states holding ~steering_joint
  double steering_angle_ = 0.0;   ///< χ [rad]
  double steering_rate_ = 0.0;    ///< χ̇ [rad/s]
  ros::Time last_update_stamp_;   ///< the instant the law last ran on
  ros::Time latest_stamp_;        ///< the latest simulator instant seen (cmd_vel arrival time)
  bool timeout_reported_ = false;
  MissingJointCheck joint_check_state_;  ///< ~steering_joint in joint_states, or its refusal after kJointGrace
  ros::WallTimer joint_check_;
  std::string refusal_;
  /// The server's mutex, ours so that updateConfig() at start-up is safe (the server warns otherwise).
  boost::recursive_mutex reconfigure_mutex_;
  /// ~set_parameters etc. (cfg/CmdVelController.cfg): what may change while running.
  std::unique_ptr<dynamic_reconfigure::Server<CmdVelControllerConfig>> reconfigure_server_;
};

}  // namespace birkhoff_cart
