// steering_pd_controller: an example controller for cart_sim's lockstep mode (docs/ros_interface.md, "Node
// steering_pd_controller"). On every joint_states message (stamped t) it answers once with
//   steering_torque τ = kp (χ_ref(t) − χ) + kd (χ̇_ref(t) − χ̇),  χ_ref(t) = amplitude · sin(2π frequency t)
// [N·m] (χ, χ̇: steering_joint's position [rad] and velocity [rad/s]) and drive_torque = ~drive_torque
// [N·m]. It computes only from the message, so a lockstep loop is the same on every run.
// Exit codes: 0 shut down, 2 refused at start (bad parameter, name or remapping), 4 unexpected error.
#include <algorithm>
#include <cmath>
#include <iterator>

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include "birkhoff_cart/core/version.h"
#include "birkhoff_cart/ros/node_main.h"

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "steering_pd_controller")) return 0;
  return birkhoff_cart::run_node_main("steering_pd_controller", [&] {
    ros::init(argc, argv, "steering_pd_controller");
    ros::NodeHandle node;
    ros::NodeHandle private_node("~");
    const double kp = private_node.param("kp", 40.0);                  // [N·m/rad]
    const double kd = private_node.param("kd", 4.0);                   // [N·m·s/rad]
    const double amplitude = private_node.param("amplitude", 0.3);     // χ_ref amplitude [rad]
    const double frequency = private_node.param("frequency", 0.25);    // χ_ref frequency [Hz]
    const double drive_torque = private_node.param("drive_torque", 5.0);  // [N·m]
    if (!std::isfinite(kp) || !std::isfinite(kd) || !std::isfinite(amplitude) || !std::isfinite(frequency) ||
        !std::isfinite(drive_torque)) {
      ROS_FATAL("steering_pd_controller: ~kp, ~kd, ~amplitude, ~frequency and ~drive_torque must be finite");
      return birkhoff_cart::kNodeExitRefused;
    }
    ros::Publisher steering_publisher = node.advertise<std_msgs::Float64>("steering_torque", 100);
    ros::Publisher drive_publisher = node.advertise<std_msgs::Float64>("drive_torque", 100);
    const auto on_joint_state = [&](const sensor_msgs::JointState::ConstPtr& joints) {
      const auto found = std::find(joints->name.begin(), joints->name.end(), "steering_joint");
      const std::size_t index = static_cast<std::size_t>(std::distance(joints->name.begin(), found));
      if (found == joints->name.end() || index >= joints->position.size() || index >= joints->velocity.size()) {
        ROS_ERROR_THROTTLE(1.0, "steering_pd_controller: joint_states without steering_joint position and velocity");
        return;
      }
      const double time = joints->header.stamp.toSec();                   // t [s]
      const double omega = 2.0 * M_PI * frequency;                         // [rad/s]
      const double angle_reference = amplitude * std::sin(omega * time);   // χ_ref [rad]
      const double rate_reference = amplitude * omega * std::cos(omega * time);  // χ̇_ref [rad/s]
      std_msgs::Float64 steering;
      steering.data =
          kp * (angle_reference - joints->position[index]) + kd * (rate_reference - joints->velocity[index]);
      std_msgs::Float64 drive;
      drive.data = drive_torque;
      drive_publisher.publish(drive);
      steering_publisher.publish(steering);
    };
    ros::Subscriber subscriber =
        node.subscribe<sensor_msgs::JointState>("joint_states", 100, on_joint_state, ros::VoidConstPtr(),
                                                ros::TransportHints().tcpNoDelay());
    ROS_INFO("steering_pd_controller: chi_ref = %g sin(2 pi %g t) rad, kp = %g N m/rad, kd = %g N m s/rad, "
             "drive %g N m", amplitude, frequency, kp, kd, drive_torque);
    ros::spin();
    return 0;
  });
}
