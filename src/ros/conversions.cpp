// Pure translations from core state and diagnostics to ROS messages (see conversions.h).
#include "birkhoff_cart/ros/conversions.h"

#include <cmath>
#include <stdexcept>

#include <tf2/LinearMath/Quaternion.h>

namespace birkhoff_cart {
namespace ros_conversions {
namespace {

void set_yaw_quaternion(geometry_msgs::Quaternion& message, double yaw) {
  tf2::Quaternion rotation;
  rotation.setRPY(0.0, 0.0, yaw);
  message.x = rotation.x();
  message.y = rotation.y();
  message.z = rotation.z();
  message.w = rotation.w();
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

FrameNames prefixed_frames(const std::string& prefix, const std::string& odom, const std::string& base_link,
                           const std::string& ground_truth) {
  FrameNames frames;
  frames.odom = prefix + odom;
  frames.base_link = prefix + base_link;
  frames.ground_truth = prefix + ground_truth;
  frames.joint_prefix = prefix;
  return frames;
}

void fill_odometry(nav_msgs::Odometry& odometry, const CartState& state, const CartModel& model,
                   const FrameNames& frames, const OdometryCovariance& covariance) {
  const Eigen::Vector2d rear_axle_midpoint = model.rear_axle_midpoint(state);  // A [m]
  const Vector2<double> quasi_velocity(state.forward_speed, state.steering_rate);
  const CoordinateRates<double> rates = model.coordinate_rates(state.heading, state.steering_angle, quasi_velocity);

  odometry.header.stamp = to_ros_time(state.time);
  odometry.header.frame_id = frames.odom;  // copy-assignments reuse the strings' capacity
  odometry.child_frame_id = frames.base_link;
  odometry.pose.pose.position.x = rear_axle_midpoint.x();
  odometry.pose.pose.position.y = rear_axle_midpoint.y();
  odometry.pose.pose.position.z = 0.0;
  set_yaw_quaternion(odometry.pose.pose.orientation, state.heading);
  set_diagonal(odometry.pose.covariance, covariance.pose_diagonal);
  // v_A = ω1 cos χ along e: A has no lateral speed (eq. (2.3), constraint (15)) [m/s].
  odometry.twist.twist.linear.x = state.forward_speed * std::cos(state.steering_angle);
  odometry.twist.twist.linear.y = 0.0;
  odometry.twist.twist.linear.z = 0.0;
  odometry.twist.twist.angular.x = 0.0;
  odometry.twist.twist.angular.y = 0.0;
  odometry.twist.twist.angular.z = rates.heading_rate;  // θ̇ = ω1 sin χ / l [rad/s]
  set_diagonal(odometry.twist.covariance, covariance.twist_diagonal);
}

void fill_odometry(nav_msgs::Odometry& odometry, const OdometryEstimate& estimate, const FrameNames& frames,
                   const OdometryCovariance& planar) {
  odometry.header.stamp = to_ros_time(estimate.time);
  odometry.header.frame_id = frames.odom;
  odometry.child_frame_id = frames.base_link;
  odometry.pose.pose.position.x = estimate.x;
  odometry.pose.pose.position.y = estimate.y;
  odometry.pose.pose.position.z = 0.0;
  set_yaw_quaternion(odometry.pose.pose.orientation, estimate.heading);
  // (x, y, yaw) from the sensor's propagated covariance (docs/odometry_sensor.md eq. (O6)); z, roll,
  // pitch keep the planar model's configured variances. Row-major 6×6, order x y z roll pitch yaw.
  set_diagonal(odometry.pose.covariance, planar.pose_diagonal);
  constexpr int kPoseIndex[3] = {0, 1, 5};
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      odometry.pose.covariance[kPoseIndex[row] * 6 + kPoseIndex[column]] = estimate.pose_covariance(row, column);
    }
  }
  odometry.twist.twist.linear.x = estimate.speed;  // v̂_A [m/s]
  odometry.twist.twist.linear.y = 0.0;
  odometry.twist.twist.linear.z = 0.0;
  odometry.twist.twist.angular.x = 0.0;
  odometry.twist.twist.angular.y = 0.0;
  odometry.twist.twist.angular.z = estimate.heading_rate;  // [rad/s]
  set_diagonal(odometry.twist.covariance, planar.twist_diagonal);  // linear.y: A has no lateral speed
  constexpr int kTwistIndex[2] = {0, 5};
  for (int row = 0; row < 2; ++row) {
    for (int column = 0; column < 2; ++column) {
      odometry.twist.covariance[kTwistIndex[row] * 6 + kTwistIndex[column]] = estimate.twist_covariance(row, column);
    }
  }
}

void fill_transform(geometry_msgs::TransformStamped& transform, const OdometryEstimate& estimate,
                    const FrameNames& frames) {
  transform.header.stamp = to_ros_time(estimate.time);
  transform.header.frame_id = frames.odom;
  transform.child_frame_id = frames.base_link;
  transform.transform.translation.x = estimate.x;
  transform.transform.translation.y = estimate.y;
  transform.transform.translation.z = 0.0;
  set_yaw_quaternion(transform.transform.rotation, estimate.heading);
}

geometry_msgs::TransformStamped world_to_odom_transform(const FrameNames& frames, double time) {
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = to_ros_time(time);
  transform.header.frame_id = frames.world;
  transform.child_frame_id = frames.odom;
  transform.transform.rotation.w = 1.0;
  return transform;
}

nav_msgs::Odometry to_odometry(const CartState& state, const CartModel& model, const FrameNames& frames,
                               const OdometryCovariance& covariance) {
  nav_msgs::Odometry odometry;
  fill_odometry(odometry, state, model, frames, covariance);
  return odometry;
}

void fill_transform(geometry_msgs::TransformStamped& transform, const CartState& state, const CartModel& model,
                    const FrameNames& frames) {
  const Eigen::Vector2d rear_axle_midpoint = model.rear_axle_midpoint(state);  // A [m]
  transform.header.stamp = to_ros_time(state.time);
  transform.header.frame_id = frames.odom;
  transform.child_frame_id = frames.base_link;
  transform.transform.translation.x = rear_axle_midpoint.x();
  transform.transform.translation.y = rear_axle_midpoint.y();
  transform.transform.translation.z = 0.0;
  set_yaw_quaternion(transform.transform.rotation, state.heading);
}

geometry_msgs::TransformStamped to_transform(const CartState& state, const CartModel& model,
                                             const FrameNames& frames) {
  geometry_msgs::TransformStamped transform;
  fill_transform(transform, state, model, frames);
  return transform;
}

void fill_joint_state(sensor_msgs::JointState& joints, const CartState& state, const CartModel& model,
                      const ActuatorEfforts& efforts, const std::string& joint_prefix) {
  const Vector2<double> quasi_velocity(state.forward_speed, state.steering_rate);
  const CoordinateRates<double> rates = model.coordinate_rates(state.heading, state.steering_angle, quasi_velocity);

  joints.header.stamp = to_ros_time(state.time);
  const auto& names = joint_names();
  joints.name.resize(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string& name = joints.name[i];  // rebuilt only when it is not already prefix + name
    if (name.size() != joint_prefix.size() + names[i].size() || name.compare(0, joint_prefix.size(), joint_prefix) != 0 ||
        name.compare(joint_prefix.size(), std::string::npos, names[i]) != 0) {
      name = joint_prefix + names[i];
    }
  }
  joints.position.resize(5);
  joints.velocity.resize(5);
  joints.effort.resize(5);
  joints.position[0] = state.steering_angle;
  joints.velocity[0] = state.steering_rate;
  for (int wheel = 0; wheel < 4; ++wheel) {
    joints.position[1 + wheel] = state.wheel_spin_angle[wheel];
    joints.velocity[1 + wheel] = rates.wheel_spin_rate[wheel];
  }
  // The drive torque is the total on the rear axle; each rear wheel carries half of it.
  joints.effort[0] = efforts.steering_torque;
  joints.effort[1] = 0.5 * efforts.drive_torque;
  joints.effort[2] = 0.5 * efforts.drive_torque;
  joints.effort[3] = 0.0;
  joints.effort[4] = 0.0;
}

sensor_msgs::JointState to_joint_state(const CartState& state, const CartModel& model,
                                       const ActuatorEfforts& efforts, const std::string& joint_prefix) {
  sensor_msgs::JointState joints;
  fill_joint_state(joints, state, model, efforts, joint_prefix);
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
  // With actuators the joints feel what the actuators apply, not what was commanded (docs/actuators.md).
  const Simulation::ActuatorStatus actuators = simulation.actuator_status();
  if (actuators.steering_actuator) efforts.steering_torque = actuators.steering_applied;
  if (actuators.drive_actuator) efforts.drive_torque = actuators.drive_applied;
  return efforts;
}

void fill_integration_error(IntegrationError& message, const CartState& state, const Diagnostics& diagnostics,
                            const StepStatistics& statistics, const std::string& integrator, double step_size,
                            double wall_time_per_step) {
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
}

IntegrationError to_integration_error(const CartState& state, const Diagnostics& diagnostics,
                                      const StepStatistics& statistics, const std::string& integrator,
                                      double step_size, double wall_time_per_step) {
  IntegrationError message;
  fill_integration_error(message, state, diagnostics, statistics, integrator, step_size, wall_time_per_step);
  return message;
}

}  // namespace ros_conversions
}  // namespace birkhoff_cart
