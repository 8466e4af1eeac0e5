// Pure translations from the core's state and diagnostics to ROS messages. No publishing, no
// physics: rates and positions come from the core (CartModel, Simulation::diagnostics()).
// Frames follow REP-105: odom → base_link, base_link at the rear-axle midpoint A on the ground.
#pragma once

#include <array>
#include <string>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include "birkhoff_cart/core/node_logic/run_timeline.h"
#include "birkhoff_cart/IntegrationError.h"
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {
namespace ros_conversions {

/// Joint names of urdf/cart.urdf, in the order of JointState messages: χ, φ1, φ2, φ3, φ4.
const std::array<std::string, 5>& joint_names();

/// Frame and joint names of one cart. Several carts under one master each take a prefix
/// (cart_sim's ~frame_prefix, e.g. "cart1/"): it goes before both frames and every joint name.
struct FrameNames {
  std::string odom = "odom";            ///< fixed frame
  std::string base_link = "base_link";  ///< rear-axle midpoint A on the ground
  /// The ground truth's child frame: A where it truly is, in the world frame (base_link is where the
  /// odometry believes it is; one frame pair, one source).
  std::string ground_truth = "base_link_ground_truth";
  std::string joint_prefix;             ///< before every joint name in joint_states ("" = the URDF's)
  /// The world frame of the ground truth (REP-105 map; not prefixed: carts share the world). The
  /// odometry starts at the true pose, so world → odom is the identity (docs/odometry_sensor.md).
  std::string world = "map";
};

/// `prefix` + odom, `prefix` + base_link, `prefix` + ground_truth, and `prefix` as the joint prefix.
FrameNames prefixed_frames(const std::string& prefix, const std::string& odom, const std::string& base_link,
                           const std::string& ground_truth = "base_link_ground_truth");

/// The variances the odometry claims (diagonals of its pose and twist covariances, in the order
/// x, y, z, roll, pitch, yaw) [m², rad²; (m/s)², (rad/s)²]. cart_sim's ~pose_covariance_diagonal and
/// ~twist_covariance_diagonal (ros_controllers' names). The state is the integrated model's, so its
/// error is the integration error (the default scene ends 1e-5 m from its dopri5 reference after
/// 60 s): (1 mm)², (1 mrad)² and (1 mm/s)², (1 mrad/s)² bound it with room. z, roll and pitch are
/// zero by construction of the planar model: 1e-9, small but invertible for filters.
struct OdometryCovariance {
  std::array<double, 6> pose_diagonal = {1e-6, 1e-6, 1e-9, 1e-9, 1e-9, 1e-6};
  std::array<double, 6> twist_diagonal = {1e-6, 1e-6, 1e-9, 1e-9, 1e-9, 1e-6};
};

/// The torques the actuators apply at one instant (joint efforts).
struct ActuatorEfforts {
  double steering_torque = 0.0;  ///< τ on steering_joint [N·m]
  double drive_torque = 0.0;     ///< T, total on the rear axle, split equally on φ1, φ2 [N·m]
};

/// The end of ROS time: ros::Time holds unsigned 32-bit seconds, so t < 2^32 − 1 s [s].
constexpr double kLatestRosTime = birkhoff_cart::kLatestRosTime;

/// Scene time t [s] as ROS time (scene time t is ROS time t). Throws std::invalid_argument for a
/// negative or non-finite time, or one at or past kLatestRosTime.
ros::Time to_ros_time(double time);

/// nav_msgs/Odometry of base_link (A, heading θ) in odom; twist in base_link:
/// linear.x = v_A = ω1 cos χ, angular.z = θ̇ = ω1 sin χ / l (docs eqs. (2.3)); covariances diagonal.
nav_msgs::Odometry to_odometry(const CartState& state, const CartModel& model, const FrameNames& frames,
                               const OdometryCovariance& covariance = OdometryCovariance{});

/// to_odometry into an existing message, every field set (its strings keep their capacity: no
/// allocation once it has held these frame names).
void fill_odometry(nav_msgs::Odometry& odometry, const CartState& state, const CartModel& model,
                   const FrameNames& frames, const OdometryCovariance& covariance = OdometryCovariance{});

/// odom → base_link transform of the state (same pose as to_odometry).
geometry_msgs::TransformStamped to_transform(const CartState& state, const CartModel& model,
                                             const FrameNames& frames);

/// to_transform into an existing message (no allocation once filled).
void fill_transform(geometry_msgs::TransformStamped& transform, const CartState& state, const CartModel& model,
                    const FrameNames& frames);

/// nav_msgs/Odometry of the odometry sensor's dead-reckoned estimate (base_link in odom): the
/// (x, y, yaw) block of the pose covariance and the (v, yaw rate) block of the twist covariance are the
/// sensor's (docs/odometry_sensor.md eqs. (O6)–(O7)), the other entries `planar`'s diagonals. Filled
/// in place (no allocation once it has held the frame names).
void fill_odometry(nav_msgs::Odometry& odometry, const OdometryEstimate& estimate, const FrameNames& frames,
                   const OdometryCovariance& planar);

/// odom → base_link of the sensor's estimate (same pose as its odometry).
void fill_transform(geometry_msgs::TransformStamped& transform, const OdometryEstimate& estimate,
                    const FrameNames& frames);

/// The identity world → odom at `time` [s] (published on /tf_static).
geometry_msgs::TransformStamped world_to_odom_transform(const FrameNames& frames, double time);

/// Joint positions (χ, φ1..φ4) [rad], velocities (ω2, φ̇1..φ̇4) [rad/s] and actuator efforts
/// (τ, T/2, T/2, 0, 0) [N·m]. Joint names are `joint_prefix` + joint_names().
sensor_msgs::JointState to_joint_state(const CartState& state, const CartModel& model,
                                       const ActuatorEfforts& efforts, const std::string& joint_prefix = "");

/// to_joint_state into an existing message: names rebuilt only when they differ, the five values
/// per vector written in place (no allocation once filled).
void fill_joint_state(sensor_msgs::JointState& joints, const CartState& state, const CartModel& model,
                      const ActuatorEfforts& efforts, const std::string& joint_prefix = "");

/// The torques the scene's steering_torque and drive_torque effects apply at the simulation's
/// current time (the command in force for a command source, the profile otherwise; 0 without the
/// effect).
ActuatorEfforts actuator_efforts(const Simulation& simulation);

/// The integration_error message of one published instant.
IntegrationError to_integration_error(const CartState& state, const Diagnostics& diagnostics,
                                      const StepStatistics& statistics, const std::string& integrator,
                                      double step_size, double wall_time_per_step);

/// to_integration_error into an existing message (no allocation once it has held the integrator name).
void fill_integration_error(IntegrationError& message, const CartState& state, const Diagnostics& diagnostics,
                            const StepStatistics& statistics, const std::string& integrator, double step_size,
                            double wall_time_per_step);

}  // namespace ros_conversions
}  // namespace birkhoff_cart
