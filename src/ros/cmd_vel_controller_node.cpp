// cmd_vel_controller's ROS side (see cmd_vel_controller_node.h): parameters, topics, stamps.
#include "birkhoff_cart/ros/cmd_vel_controller_node.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <boost/make_shared.hpp>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {
namespace {

// ros_controllers' has_*_limits switches: false lifts the limit (to ±∞ for values; very large for
// rates, which must stay finite).
bool read_switch(const ros::NodeHandle& node, const std::string& name) {
  XmlRpc::XmlRpcValue value;
  if (!node.getParam(name, value)) return true;
  if (value.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
    throw std::invalid_argument("parameter " + node.resolveName(name) + " must be a bool (true or false), got " +
                                describe_parameter_value(node, name));
  }
  return static_cast<bool>(value);
}

constexpr double kNoLimit = 1e9;  // stands for "unlimited" in a finite-limit slot

/// The settings as dynamic_reconfigure's config (cfg/CmdVelController.cfg names).
CmdVelControllerConfig to_config(const CmdVelControllerSettings& s) {
  CmdVelControllerConfig config;
  config.cmd_vel_timeout = s.cmd_vel_timeout;
  config.linear_x_max_velocity = s.max_velocity;
  config.linear_x_min_velocity = s.min_velocity;
  config.linear_x_max_acceleration = s.max_acceleration;
  config.linear_x_min_acceleration = s.min_acceleration;
  config.angular_z_max_velocity = s.max_yaw_rate;
  config.angular_z_max_acceleration = s.max_yaw_acceleration;
  config.steering_max_angle = s.max_steering_angle;
  config.steering_max_rate = s.max_steering_rate;
  config.steering_max_torque = s.max_steering_torque;
  config.steering_p = s.steering_p;
  config.steering_d = s.steering_d;
  config.drive_max_torque = s.max_drive_torque;
  config.drive_ff = s.drive_ff;
  config.drive_p = s.drive_p;
  config.drive_i = s.drive_i;
  config.drive_i_clamp = s.drive_i_clamp;
  return config;
}

}  // namespace

const std::vector<std::string>& cmd_vel_controller_parameter_names() {
  static const std::vector<std::string> names = {
      "wheel_separation_h", "cmd_vel_timeout", "zero_speed", "steering_joint", "linear/x/max_velocity",
      "linear/x/min_velocity", "linear/x/has_velocity_limits", "linear/x/max_acceleration", "linear/x/min_acceleration",
      "linear/x/has_acceleration_limits", "angular/z/max_velocity", "angular/z/has_velocity_limits",
      "angular/z/max_acceleration", "angular/z/has_acceleration_limits", "steering/max_angle", "steering/max_rate",
      "steering/max_torque", "steering/p", "steering/d", "drive/max_torque", "drive/ff", "drive/p", "drive/i",
      "drive/i_clamp",
      // dynamic_reconfigure's own copies (cfg/CmdVelController.cfg), left on the master by an earlier run
      "cmd_vel_timeout", "linear_x_max_velocity", "linear_x_min_velocity", "linear_x_max_acceleration",
      "linear_x_min_acceleration", "angular_z_max_velocity", "angular_z_max_acceleration", "steering_max_angle",
      "steering_max_rate", "steering_max_torque", "steering_p", "steering_d", "drive_max_torque", "drive_ff", "drive_p",
      "drive_i", "drive_i_clamp"};
  return names;
}

CmdVelControllerSettings load_cmd_vel_controller_settings(const ros::NodeHandle& p) {
  CmdVelControllerSettings s;
  s.wheel_separation_h = read_double_parameter(p, "wheel_separation_h", s.wheel_separation_h);
  s.cmd_vel_timeout = read_double_parameter(p, "cmd_vel_timeout", s.cmd_vel_timeout);
  s.zero_speed = read_double_parameter(p, "zero_speed", s.zero_speed);
  s.max_velocity = read_double_parameter(p, "linear/x/max_velocity", s.max_velocity);
  s.min_velocity = read_double_parameter(p, "linear/x/min_velocity", s.min_velocity);
  if (!read_switch(p, "linear/x/has_velocity_limits")) {
    s.max_velocity = kNoLimit;
    s.min_velocity = -kNoLimit;
  }
  s.max_acceleration = read_double_parameter(p, "linear/x/max_acceleration", s.max_acceleration);
  s.min_acceleration = read_double_parameter(p, "linear/x/min_acceleration", s.min_acceleration);
  if (!read_switch(p, "linear/x/has_acceleration_limits")) {
    s.max_acceleration = kNoLimit;
    s.min_acceleration = -kNoLimit;
  }
  s.max_yaw_rate = read_double_parameter(p, "angular/z/max_velocity", s.max_yaw_rate);
  if (!read_switch(p, "angular/z/has_velocity_limits")) s.max_yaw_rate = kNoLimit;
  s.max_yaw_acceleration = read_double_parameter(p, "angular/z/max_acceleration", s.max_yaw_acceleration);
  if (!read_switch(p, "angular/z/has_acceleration_limits")) s.max_yaw_acceleration = kNoLimit;
  s.max_steering_angle = read_double_parameter(p, "steering/max_angle", s.max_steering_angle);
  s.max_steering_rate = read_double_parameter(p, "steering/max_rate", s.max_steering_rate);
  s.max_steering_torque = read_double_parameter(p, "steering/max_torque", s.max_steering_torque);
  s.steering_p = read_double_parameter(p, "steering/p", s.steering_p);
  s.steering_d = read_double_parameter(p, "steering/d", s.steering_d);
  s.max_drive_torque = read_double_parameter(p, "drive/max_torque", s.max_drive_torque);
  s.drive_ff = read_double_parameter(p, "drive/ff", s.drive_ff);
  s.drive_p = read_double_parameter(p, "drive/p", s.drive_p);
  s.drive_i = read_double_parameter(p, "drive/i", s.drive_i);
  s.drive_i_clamp = read_double_parameter(p, "drive/i_clamp", s.drive_i_clamp);
  try {
    validate(s);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument("parameter " + p.resolveName("") + "/" + error.what());
  }
  return s;
}

CmdVelControllerNode::CmdVelControllerNode(ros::NodeHandle node, ros::NodeHandle private_node, bool shut_down_on_refusal)
    : node_(node),
      private_node_(private_node),
      shut_down_on_refusal_(shut_down_on_refusal),
      controller_(load_cmd_vel_controller_settings(private_node)),
      steering_joint_(private_node.param<std::string>("steering_joint", "steering_joint")),
      joint_check_state_(steering_joint_, kJointGrace) {
  steering_publisher_ = node_.advertise<std_msgs::Float64>("steering_torque", 10);
  drive_publisher_ = node_.advertise<std_msgs::Float64>("drive_torque", 10);
  cmd_vel_subscriber_ = node_.subscribe("cmd_vel", 10, &CmdVelControllerNode::on_cmd_vel, this);
  odometry_subscriber_ = node_.subscribe("odom", 10, &CmdVelControllerNode::on_odometry, this,
                                         ros::TransportHints().tcpNoDelay());
  joint_state_subscriber_ = node_.subscribe("joint_states", 10, &CmdVelControllerNode::on_joint_states, this,
                                            ros::TransportHints().tcpNoDelay());
  for (const std::string& report : unknown_private_parameters(private_node_, cmd_vel_controller_parameter_names())) {
    ROS_WARN("cmd_vel_controller: %s", report.c_str());
  }
  reconfigure_server_ =
      std::make_unique<dynamic_reconfigure::Server<CmdVelControllerConfig>>(reconfigure_mutex_, private_node_);
  reconfigure_server_->updateConfig(to_config(controller_.settings()));  // the start-up values, not the cfg's
  reconfigure_server_->setCallback(
      [this](CmdVelControllerConfig& config, std::uint32_t level) { on_reconfigure(config, level); });
  joint_check_ = node_.createWallTimer(ros::WallDuration(0.1), &CmdVelControllerNode::check_joint_names, this);
  const CmdVelControllerSettings& s = controller_.settings();
  ROS_INFO("cmd_vel_controller: %s -> %s, %s; l = %g m, v in [%g, %g] m/s, |r| <= %g rad/s, |chi| <= %g rad, "
           "|tau| <= %g N m, |T| <= %g N m, cmd_vel_timeout %g s",
           cmd_vel_subscriber_.getTopic().c_str(), steering_publisher_.getTopic().c_str(),
           drive_publisher_.getTopic().c_str(), s.wheel_separation_h, s.min_velocity, s.max_velocity, s.max_yaw_rate,
           s.max_steering_angle, s.max_steering_torque, s.max_drive_torque, s.cmd_vel_timeout);
}

void CmdVelControllerNode::on_cmd_vel(const geometry_msgs::Twist::ConstPtr& message) {
  const double time = latest_stamp_.toSec();
  if (!controller_.set_command(message->linear.x, message->angular.z, time)) {
    ROS_ERROR_THROTTLE(1.0, "cmd_vel_controller: ignoring a non-finite cmd_vel (linear.x %g, angular.z %g)",
                       message->linear.x, message->angular.z);
    return;
  }
  const CmdVelControllerSettings& s = controller_.settings();
  if (message->linear.x > s.max_velocity || message->linear.x < s.min_velocity ||
      std::abs(message->angular.z) > s.max_yaw_rate) {
    ROS_WARN_THROTTLE(2.0, "cmd_vel_controller: cmd_vel (%g m/s, %g rad/s) beyond the limits [%g, %g] m/s, "
                      "|r| <= %g rad/s: clamped", message->linear.x, message->angular.z, s.min_velocity,
                      s.max_velocity, s.max_yaw_rate);
  }
  if (message->linear.y != 0.0 || message->angular.x != 0.0 || message->angular.y != 0.0 ||
      message->linear.z != 0.0) {
    ROS_WARN_THROTTLE(5.0, "cmd_vel_controller: a cart moves only along x and turns only about z: ignoring the "
                      "other components of cmd_vel");
  }
  timeout_reported_ = false;
}

void CmdVelControllerNode::on_reconfigure(CmdVelControllerConfig& config, std::uint32_t /*level*/) {
  CmdVelControllerSettings settings = controller_.settings();
  settings.cmd_vel_timeout = config.cmd_vel_timeout;
  settings.max_velocity = config.linear_x_max_velocity;
  settings.min_velocity = config.linear_x_min_velocity;
  settings.max_acceleration = config.linear_x_max_acceleration;
  settings.min_acceleration = config.linear_x_min_acceleration;
  settings.max_yaw_rate = config.angular_z_max_velocity;
  settings.max_yaw_acceleration = config.angular_z_max_acceleration;
  settings.max_steering_angle = config.steering_max_angle;
  settings.max_steering_rate = config.steering_max_rate;
  settings.max_steering_torque = config.steering_max_torque;
  settings.steering_p = config.steering_p;
  settings.steering_d = config.steering_d;
  settings.max_drive_torque = config.drive_max_torque;
  settings.drive_ff = config.drive_ff;
  settings.drive_p = config.drive_p;
  settings.drive_i = config.drive_i;
  settings.drive_i_clamp = config.drive_i_clamp;
  try {
    controller_.set_settings(settings);
    ROS_INFO("cmd_vel_controller: reconfigured: v in [%g, %g] m/s, |r| <= %g rad/s, steering p %g d %g, drive p %g i %g, "
             "cmd_vel_timeout %g s", settings.min_velocity, settings.max_velocity, settings.max_yaw_rate,
             settings.steering_p, settings.steering_d, settings.drive_p, settings.drive_i, settings.cmd_vel_timeout);
  } catch (const std::invalid_argument& error) {
    // The set answers with the settings in force (dynamic_reconfigure returns `config`), and the
    // line names the value typed (the cfg does not clamp: the node sees what was typed).
    ROS_WARN("cmd_vel_controller: dynamic_reconfigure set refused, the running settings stay: %s", error.what());
    config = to_config(controller_.settings());
  }
}

void CmdVelControllerNode::check_joint_names(const ros::WallTimerEvent&) {
  if (joint_check_state_.seen()) {
    joint_check_.stop();
    return;
  }
  const std::optional<std::string> refusal = joint_check_state_.refusal(
      ros::WallTime::now().toSec(), private_node_.resolveName("steering_joint"), joint_state_subscriber_.getTopic());
  if (!refusal) return;
  refusal_ = *refusal;
  ROS_FATAL("cmd_vel_controller: %s", refusal_.c_str());
  joint_check_.stop();
  if (shut_down_on_refusal_) {
    ros::shutdown();
  } else {  // a nodelet: the manager and its other nodelets go on
    cmd_vel_subscriber_.shutdown();
    odometry_subscriber_.shutdown();
    joint_state_subscriber_.shutdown();
  }
}

void CmdVelControllerNode::on_odometry(const nav_msgs::Odometry::ConstPtr& message) {
  odometry_stamp_ = message->header.stamp;
  base_speed_ = message->twist.twist.linear.x;
  update_if_complete();
}

void CmdVelControllerNode::on_joint_states(const sensor_msgs::JointState::ConstPtr& message) {
  // Another publisher's joints, or a wrong ~steering_joint (refused after kJointGrace).
  const std::optional<std::size_t> found = joint_check_state_.find(message->name);
  if (!found) {
    joint_check_state_.note_missing(message->name, ros::WallTime::now().toSec());
    return;
  }
  const std::size_t index = *found;
  if (index >= message->position.size() || index >= message->velocity.size()) {
    ROS_WARN_THROTTLE(5.0, "cmd_vel_controller: joint_states without position and velocity of %s",
                      steering_joint_.c_str());
    return;
  }
  joint_stamp_ = message->header.stamp;
  steering_angle_ = message->position[index];
  steering_rate_ = message->velocity[index];
  update_if_complete();
}

void CmdVelControllerNode::update_if_complete() {
  if (odometry_stamp_ != joint_stamp_ || odometry_stamp_ == last_update_stamp_) return;
  if (odometry_stamp_ < last_update_stamp_) {
    ROS_INFO("cmd_vel_controller: time went back to %.6f s (simulator reset): restarting", odometry_stamp_.toSec());
  }
  last_update_stamp_ = odometry_stamp_;
  latest_stamp_ = odometry_stamp_;
  CartFeedback feedback;
  feedback.time = odometry_stamp_.toSec();
  feedback.base_speed = base_speed_;
  feedback.steering_angle = steering_angle_;
  feedback.steering_rate = steering_rate_;
  const ActuatorCommand command = controller_.update(feedback);
  if (controller_.timed_out() && !timeout_reported_) {
    ROS_WARN("cmd_vel_controller: no cmd_vel for %g s at t = %.6f s: braking to rest",
             controller_.settings().cmd_vel_timeout, feedback.time);
    timeout_reported_ = true;
  }
  // Shared messages: zero-copy to cart_sim in the same nodelet manager.
  auto steering = boost::make_shared<std_msgs::Float64>();
  steering->data = command.steering_torque;
  steering_publisher_.publish(steering);
  auto drive = boost::make_shared<std_msgs::Float64>();
  drive->data = command.drive_torque;
  drive_publisher_.publish(drive);
}

}  // namespace birkhoff_cart
