// Pure translations from core state and diagnostics to ROS messages (see conversions.h).
#include "birkhoff_cart/ros/conversions.h"

#include <cmath>
#include <stdexcept>

#include <tf2/LinearMath/Quaternion.h>

namespace birkhoff_cart {
namespace ros_conversions {
namespace {

geometry_msgs::Quaternion yaw_quaternion(double yaw) {
  tf2::Quaternion rotation;
  rotation.setRPY(0.0, 0.0, yaw);
  geometry_msgs::Quaternion message;
  message.x = rotation.x();
  message.y = rotation.y();
  message.z = rotation.z();
  message.w = rotation.w();
  return message;
}

void set_diagonal(boost::array<double, 36>& covariance, const std::array<double, 6>& variances) {
  covariance.fill(0.0);
  for (int i = 0; i < 6; ++i) covariance[i * 6 + i] = variances[i];
}

const TorqueProfile* find_profile(const Scene& scene, const std::string& effect_name) {
  for (const EffectSpec& effect : scene.effects) {
    if (effect.name == effect_name) return &effect.profile;
  }
  return nullptr;
}

}  // namespace

const std::array<std::string, 5>& joint_names() {
  static const std::array<std::string, 5> names = {"steering_joint", "rear_left_wheel_joint",
                                                   "rear_right_wheel_joint", "front_left_wheel_joint",
                                                   "front_right_wheel_joint"};
  return names;
}

ros::Time to_ros_time(double time) {
  if (!std::isfinite(time) || time < 0.0 || time >= kLatestRosTime) {
    throw std::invalid_argument("scene time " + std::to_string(time) +
                                " s cannot be a ROS time (must be finite, >= 0 and < 2^32 - 1 s)");
  }
  return ros::Time(time);
}

FrameNames prefixed_frames(const std::string& prefix, const std::string& odom, const std::string& base_link) {
  FrameNames frames;
  frames.odom = prefix + odom;
  frames.base_link = prefix + base_link;
  frames.joint_prefix = prefix;
  return frames;
}

nav_msgs::Odometry to_odometry(const CartState& state, const CartModel& model, const FrameNames& frames,
                               const OdometryCovariance& covariance) {
  const Eigen::Vector2d rear_axle_midpoint = model.rear_axle_midpoint(state);  // A [m]
  const Vector2<double> quasi_velocity(state.forward_speed, state.steering_rate);
  const CoordinateRates<double> rates = model.coordinate_rates(state.heading, state.steering_angle, quasi_velocity);

  nav_msgs::Odometry odometry;
  odometry.header.stamp = to_ros_time(state.time);
  odometry.header.frame_id = frames.odom;
  odometry.child_frame_id = frames.base_link;
  odometry.pose.pose.position.x = rear_axle_midpoint.x();
  odometry.pose.pose.position.y = rear_axle_midpoint.y();
  odometry.pose.pose.position.z = 0.0;
  odometry.pose.pose.orientation = yaw_quaternion(state.heading);
  set_diagonal(odometry.pose.covariance, covariance.pose_diagonal);
  // v_A = ω1 cos χ along e: A has no lateral speed (eq. (2.3), constraint (15)) [m/s].
  odometry.twist.twist.linear.x = state.forward_speed * std::cos(state.steering_angle);
  odometry.twist.twist.angular.z = rates.heading_rate;  // θ̇ = ω1 sin χ / l [rad/s]
  set_diagonal(odometry.twist.covariance, covariance.twist_diagonal);
  return odometry;
}

geometry_msgs::TransformStamped to_transform(const CartState& state, const CartModel& model,
                                             const FrameNames& frames) {
  const Eigen::Vector2d rear_axle_midpoint = model.rear_axle_midpoint(state);  // A [m]
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = to_ros_time(state.time);
  transform.header.frame_id = frames.odom;
  transform.child_frame_id = frames.base_link;
  transform.transform.translation.x = rear_axle_midpoint.x();
  transform.transform.translation.y = rear_axle_midpoint.y();
  transform.transform.translation.z = 0.0;
  transform.transform.rotation = yaw_quaternion(state.heading);
  return transform;
}

sensor_msgs::JointState to_joint_state(const CartState& state, const CartModel& model,
                                       const ActuatorEfforts& efforts, const std::string& joint_prefix) {
  const Vector2<double> quasi_velocity(state.forward_speed, state.steering_rate);
  const CoordinateRates<double> rates = model.coordinate_rates(state.heading, state.steering_angle, quasi_velocity);

  sensor_msgs::JointState joints;
  joints.header.stamp = to_ros_time(state.time);
  const auto& names = joint_names();
  joints.name.reserve(names.size());
  for (const std::string& name : names) joints.name.push_back(joint_prefix + name);
  joints.position = {state.steering_angle, state.wheel_spin_angle[0], state.wheel_spin_angle[1],
                     state.wheel_spin_angle[2], state.wheel_spin_angle[3]};
  joints.velocity = {state.steering_rate, rates.wheel_spin_rate[0], rates.wheel_spin_rate[1],
                     rates.wheel_spin_rate[2], rates.wheel_spin_rate[3]};
  // The drive torque is the total on the rear axle; each rear wheel carries half of it.
  joints.effort = {efforts.steering_torque, 0.5 * efforts.drive_torque, 0.5 * efforts.drive_torque, 0.0, 0.0};
  return joints;
}

ActuatorEfforts actuator_efforts(const Simulation& simulation) {
  const double time = simulation.state().time;
  ActuatorEfforts efforts;
  if (const TorqueProfile* steering = find_profile(simulation.scene(), "steering_torque")) {
    efforts.steering_torque = simulation.accepts_steering_command() ? simulation.steering_command()
                                                                    : steering->at(time);
  }
  if (const TorqueProfile* drive = find_profile(simulation.scene(), "drive_torque")) {
    efforts.drive_torque = simulation.accepts_drive_command() ? simulation.drive_command() : drive->at(time);
  }
  return efforts;
}

IntegrationError to_integration_error(const CartState& state, const Diagnostics& diagnostics,
                                      const StepStatistics& statistics, const std::string& integrator,
                                      double step_size, double wall_time_per_step) {
  IntegrationError message;
  message.header.stamp = to_ros_time(state.time);
  message.integrator = integrator;
  message.step_size = step_size;
  message.steps_taken = statistics.steps;
  message.energy = diagnostics.energy;
  message.energy_balance_residual = diagnostics.energy_balance_residual;
  message.p2_balance_residual = diagnostics.p2_balance_residual;
  message.max_constraint_residual = diagnostics.max_constraint_residual;
  message.has_reference = diagnostics.has_reference;
  message.reference_position_error = diagnostics.reference_position_error;
  message.reference_heading_error = diagnostics.reference_heading_error;
  message.reference_arc_length_relative_error = diagnostics.reference_arc_length_relative_error;
  message.newton_iterations_last_step = statistics.newton_iterations_last_step;
  message.newton_iterations_total = statistics.newton_iterations_total;
  message.wall_time_per_step = wall_time_per_step;
  message.has_local_error_estimate = has_local_error_estimate(statistics);
  message.local_error_estimate = statistics.local_error_estimate_last_step;  // NaN without an estimate
  message.local_error_estimate_max = statistics.local_error_estimate_max;
  message.local_error_estimate_sum = statistics.local_error_estimate_sum;
  return message;
}

}  // namespace ros_conversions
}  // namespace birkhoff_cart
