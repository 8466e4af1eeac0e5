// SteeringPdController (steering_pd_controller.h).
#include "birkhoff_cart/ros/steering_pd_controller.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <boost/make_shared.hpp>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {

SteeringPdController::SteeringPdController(ros::NodeHandle node, ros::NodeHandle private_node, bool inline_answers,
                                           bool shut_down_on_refusal)
    : kp_(read_double_parameter(private_node, "kp", 40.0)),
      kd_(read_double_parameter(private_node, "kd", 4.0)),
      amplitude_(read_double_parameter(private_node, "amplitude", 0.3)),
      frequency_(read_double_parameter(private_node, "frequency", 0.25)),
      drive_torque_(read_double_parameter(private_node, "drive_torque", 5.0)),
      steering_joint_(private_node.param<std::string>("steering_joint", "steering_joint")),
      shut_down_on_refusal_(shut_down_on_refusal),
      joint_check_state_(steering_joint_, kJointGrace) {
  if (!std::isfinite(kp_) || !std::isfinite(kd_) || !std::isfinite(amplitude_) || !std::isfinite(frequency_) ||
      !std::isfinite(drive_torque_)) {
    throw std::invalid_argument("~kp, ~kd, ~amplitude, ~frequency and ~drive_torque must be finite");
  }
  if (steering_joint_.empty()) throw std::invalid_argument("~steering_joint must name a joint (it is empty)");
  static const std::vector<std::string> kKnown = {"kp", "kd", "amplitude", "frequency", "drive_torque",
                                                  "steering_joint", "inline_answers"};
  for (const std::string& report : unknown_private_parameters(private_node, kKnown)) {
    ROS_WARN("steering_pd_controller: %s", report.c_str());
  }
  steering_publisher_ = node.advertise<std_msgs::Float64>("steering_torque", 100);
  drive_publisher_ = node.advertise<std_msgs::Float64>("drive_torque", 100);
  ros::NodeHandle subscribing = node;
  if (inline_answers) subscribing.setCallbackQueue(&inline_queue_);
  subscriber_ = subscribing.subscribe<sensor_msgs::JointState>(
      "joint_states", 100, &SteeringPdController::on_joint_states, this, ros::TransportHints().tcpNoDelay());
  joint_check_ = node.createWallTimer(ros::WallDuration(0.1), &SteeringPdController::check_joint_name, this);
  ROS_INFO("steering_pd_controller: chi_ref = %g sin(2 pi %g t) rad, kp = %g N m/rad, kd = %g N m s/rad, drive %g N m",
           amplitude_, frequency_, kp_, kd_, drive_torque_);
}

void SteeringPdController::on_joint_states(const sensor_msgs::JointState::ConstPtr& joints) {
  if (refused_) return;
  // Another publisher's partial joint_states may lack it; the name is refused only when no
  // message has held it within kJointGrace (check_joint_name).
  const std::optional<std::size_t> found = joint_check_state_.find(joints->name);
  if (!found) {
    joint_check_state_.note_missing(joints->name, ros::WallTime::now().toSec());
    return;
  }
  const std::size_t index = *found;
  if (index >= joints->position.size() || index >= joints->velocity.size()) {
    ROS_ERROR_THROTTLE(1.0, "steering_pd_controller: joint_states names %s without its position and velocity",
                       steering_joint_.c_str());
    return;
  }
  const double time = joints->header.stamp.toSec();                        // t [s]
  const double omega = 2.0 * M_PI * frequency_;                            // [rad/s]
  const double angle_reference = amplitude_ * std::sin(omega * time);      // χ_ref [rad]
  const double rate_reference = amplitude_ * omega * std::cos(omega * time);  // χ̇_ref [rad/s]
  auto steering = boost::make_shared<std_msgs::Float64>();
  steering->data = kp_ * (angle_reference - joints->position[index]) + kd_ * (rate_reference - joints->velocity[index]);
  auto drive = boost::make_shared<std_msgs::Float64>();
  drive->data = drive_torque_;
  drive_publisher_.publish(drive);
  steering_publisher_.publish(steering);
}

void SteeringPdController::check_joint_name(const ros::WallTimerEvent&) {
  if (joint_check_state_.seen()) {
    joint_check_.stop();
    return;
  }
  const std::optional<std::string> refusal =
      joint_check_state_.refusal(ros::WallTime::now().toSec(), "~steering_joint", subscriber_.getTopic());
  if (!refusal) return;
  refusal_ = *refusal;
  refused_ = true;
  ROS_FATAL("steering_pd_controller: %s", refusal_.c_str());
  joint_check_.stop();
  if (shut_down_on_refusal_) {
    ros::shutdown();
  } else {  // a nodelet: the manager and cart_sim go on
    subscriber_.shutdown();
  }
}

}  // namespace birkhoff_cart
