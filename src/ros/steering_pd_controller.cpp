// SteeringPdController (steering_pd_controller.h).
#include "birkhoff_cart/ros/steering_pd_controller.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <boost/make_shared.hpp>
#include <std_msgs/Float64.h>

namespace birkhoff_cart {

SteeringPdController::SteeringPdController(ros::NodeHandle node, ros::NodeHandle private_node, bool inline_answers)
    : kp_(private_node.param("kp", 40.0)),
      kd_(private_node.param("kd", 4.0)),
      amplitude_(private_node.param("amplitude", 0.3)),
      frequency_(private_node.param("frequency", 0.25)),
      drive_torque_(private_node.param("drive_torque", 5.0)) {
  if (!std::isfinite(kp_) || !std::isfinite(kd_) || !std::isfinite(amplitude_) || !std::isfinite(frequency_) ||
      !std::isfinite(drive_torque_)) {
    throw std::invalid_argument("~kp, ~kd, ~amplitude, ~frequency and ~drive_torque must be finite");
  }
  steering_publisher_ = node.advertise<std_msgs::Float64>("steering_torque", 100);
  drive_publisher_ = node.advertise<std_msgs::Float64>("drive_torque", 100);
  ros::NodeHandle subscribing = node;
  if (inline_answers) subscribing.setCallbackQueue(&inline_queue_);
  subscriber_ = subscribing.subscribe<sensor_msgs::JointState>(
      "joint_states", 100, &SteeringPdController::on_joint_states, this, ros::TransportHints().tcpNoDelay());
  ROS_INFO("steering_pd_controller: chi_ref = %g sin(2 pi %g t) rad, kp = %g N m/rad, kd = %g N m s/rad, drive %g N m",
           amplitude_, frequency_, kp_, kd_, drive_torque_);
}

void SteeringPdController::on_joint_states(const sensor_msgs::JointState::ConstPtr& joints) {
  const auto found = std::find(joints->name.begin(), joints->name.end(), "steering_joint");
  const std::size_t index = static_cast<std::size_t>(std::distance(joints->name.begin(), found));
  if (found == joints->name.end() || index >= joints->position.size() || index >= joints->velocity.size()) {
    ROS_ERROR_THROTTLE(1.0, "steering_pd_controller: joint_states without steering_joint position and velocity");
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

}  // namespace birkhoff_cart
