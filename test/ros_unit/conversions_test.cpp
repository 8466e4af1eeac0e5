// Message conversions: odom, tf, joint states and actuator efforts carry the core's state exactly,
// in the documented frames, units and joint order.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <tf2/utils.h>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/conversions.h"

namespace birkhoff_cart {
namespace {

constexpr double kExact = 1e-15;         // [m], [rad], [m/s]: pure copies and one trig evaluation
constexpr double kQuaternion = 1e-14;    // [rad]: yaw through a quaternion and back

CartState moving_state() {
  CartState state;
  state.time = 2.5;
  state.x = 3.0;
  state.y = -1.0;
  state.heading = 0.7;
  state.steering_angle = 0.3;
  state.wheel_spin_angle = {1.0, 2.0, 3.0, 4.0};
  state.forward_speed = 2.0;
  state.steering_rate = -0.4;
  return state;
}

TEST(Conversions, OdometryIsBaseLinkAtTheRearAxleMidpoint) {
  const CartModel model{CartParameters{}};
  const CartState state = moving_state();
  const nav_msgs::Odometry odometry = ros_conversions::to_odometry(state, model, {});
  const double l = model.parameters().wheelbase;
  EXPECT_EQ(odometry.header.stamp, ros::Time(2.5));
  EXPECT_EQ(odometry.header.frame_id, "odom");
  EXPECT_EQ(odometry.child_frame_id, "base_link");
  EXPECT_NEAR(odometry.pose.pose.position.x, 3.0 - l * std::cos(0.7), kExact);  // A = B − l e
  EXPECT_NEAR(odometry.pose.pose.position.y, -1.0 - l * std::sin(0.7), kExact);
  EXPECT_EQ(odometry.pose.pose.position.z, 0.0);
  EXPECT_NEAR(tf2::getYaw(odometry.pose.pose.orientation), 0.7, kQuaternion);
  EXPECT_NEAR(odometry.twist.twist.linear.x, 2.0 * std::cos(0.3), kExact);      // v_A = ω1 cos χ
  EXPECT_EQ(odometry.twist.twist.linear.y, 0.0);                                 // no lateral slip at A
  EXPECT_NEAR(odometry.twist.twist.angular.z, 2.0 * std::sin(0.3) / l, kExact);  // θ̇ = ω1 sin χ / l
  const ros_conversions::OdometryCovariance defaults;
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(odometry.pose.covariance[i * 7], defaults.pose_diagonal[i]);
    EXPECT_EQ(odometry.twist.covariance[i * 7], defaults.twist_diagonal[i]);
    EXPECT_GT(odometry.pose.covariance[i * 7], 0.0) << "a zero variance cannot be inverted by a filter";
  }
  EXPECT_GT(defaults.pose_diagonal[0], 1e-10) << "x: the default scene's integration error is ~1e-5 m";
}

TEST(Conversions, OdometryCarriesTheGivenCovariance) {
  const CartModel model{CartParameters{}};
  ros_conversions::OdometryCovariance covariance;
  covariance.pose_diagonal = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
  covariance.twist_diagonal = {7.0, 8.0, 9.0, 10.0, 11.0, 12.0};
  const nav_msgs::Odometry odometry = ros_conversions::to_odometry(moving_state(), model, {}, covariance);
  for (int row = 0; row < 6; ++row) {
    for (int column = 0; column < 6; ++column) {
      EXPECT_EQ(odometry.pose.covariance[row * 6 + column], row == column ? row + 1.0 : 0.0);
      EXPECT_EQ(odometry.twist.covariance[row * 6 + column], row == column ? row + 7.0 : 0.0);
    }
  }
}

TEST(Conversions, FramePrefixGoesBeforeFramesAndJoints) {
  const CartModel model{CartParameters{}};
  const ros_conversions::FrameNames frames = ros_conversions::prefixed_frames("cart2/", "odom", "base_link");
  const nav_msgs::Odometry odometry = ros_conversions::to_odometry(moving_state(), model, frames);
  EXPECT_EQ(odometry.header.frame_id, "cart2/odom");
  EXPECT_EQ(odometry.child_frame_id, "cart2/base_link");
  EXPECT_EQ(frames.ground_truth, "cart2/base_link_ground_truth");
  const sensor_msgs::JointState joints =
      ros_conversions::to_joint_state(moving_state(), model, {}, frames.joint_prefix);
  ASSERT_EQ(joints.name.size(), 5u);
  EXPECT_EQ(joints.name[0], "cart2/steering_joint");
  EXPECT_EQ(joints.name[4], "cart2/front_right_wheel_joint");
}

TEST(Conversions, TransformMatchesOdometry) {
  const CartModel model{CartParameters{}};
  const CartState state = moving_state();
  ros_conversions::FrameNames frames;
  frames.odom = "world_odom";
  frames.base_link = "cart";
  const nav_msgs::Odometry odometry = ros_conversions::to_odometry(state, model, frames);
  const geometry_msgs::TransformStamped transform = ros_conversions::to_transform(state, model, frames);
  EXPECT_EQ(transform.header.stamp, odometry.header.stamp);
  EXPECT_EQ(transform.header.frame_id, "world_odom");
  EXPECT_EQ(transform.child_frame_id, "cart");
  EXPECT_EQ(transform.transform.translation.x, odometry.pose.pose.position.x);
  EXPECT_EQ(transform.transform.translation.y, odometry.pose.pose.position.y);
  EXPECT_EQ(transform.transform.rotation.z, odometry.pose.pose.orientation.z);
  EXPECT_EQ(transform.transform.rotation.w, odometry.pose.pose.orientation.w);
}

TEST(Conversions, JointStatesInUrdfOrderWithRimKinematics) {
  const CartModel model{CartParameters{}};
  const CartState state = moving_state();
  ros_conversions::ActuatorEfforts efforts;
  efforts.steering_torque = 1.25;
  efforts.drive_torque = 30.0;
  const sensor_msgs::JointState joints = ros_conversions::to_joint_state(state, model, efforts);
  ASSERT_EQ(joints.name.size(), 5u);
  EXPECT_EQ(joints.name[0], "steering_joint");
  EXPECT_EQ(joints.name[1], "rear_left_wheel_joint");
  EXPECT_EQ(joints.name[2], "rear_right_wheel_joint");
  EXPECT_EQ(joints.name[3], "front_left_wheel_joint");
  EXPECT_EQ(joints.name[4], "front_right_wheel_joint");
  EXPECT_EQ(joints.position[0], 0.3);
  EXPECT_EQ(joints.velocity[0], -0.4);
  for (int wheel = 0; wheel < 4; ++wheel) EXPECT_EQ(joints.position[wheel + 1], wheel + 1.0);
  // Eq. (2.4): r1 φ̇1,2 = ω1 (cos χ ∓ a sin χ / l); r2 φ̇3,4 = ω1 (1 ∓ c sin χ / l) ∓ c ω2.
  const CartParameters& p = model.parameters();
  const double s = std::sin(0.3), c = std::cos(0.3), w1 = 2.0, w2 = -0.4;
  const double l = p.wheelbase, a = p.rear_half_track, cf = p.front_half_track;
  EXPECT_NEAR(joints.velocity[1], w1 * (c - a * s / l) / p.rear_wheel_radius, 1e-14);
  EXPECT_NEAR(joints.velocity[2], w1 * (c + a * s / l) / p.rear_wheel_radius, 1e-14);
  EXPECT_NEAR(joints.velocity[3], (w1 * (1 - cf * s / l) - cf * w2) / p.front_wheel_radius, 1e-14);
  EXPECT_NEAR(joints.velocity[4], (w1 * (1 + cf * s / l) + cf * w2) / p.front_wheel_radius, 1e-14);
  EXPECT_EQ(joints.effort[0], 1.25);
  EXPECT_EQ(joints.effort[1], 15.0);
  EXPECT_EQ(joints.effort[2], 15.0);
  EXPECT_EQ(joints.effort[3], 0.0);
  EXPECT_EQ(joints.effort[4], 0.0);
}

TEST(Conversions, NegativeOrNonFiniteTimeIsNoRosTime) {
  EXPECT_THROW(ros_conversions::to_ros_time(-1e-3), std::invalid_argument);
  EXPECT_THROW(ros_conversions::to_ros_time(std::nan("")), std::invalid_argument);
  EXPECT_EQ(ros_conversions::to_ros_time(1.5), ros::Time(1, 500000000));
}

TEST(Conversions, ActuatorEffortsFollowCommandsAndProfiles) {
  Simulation driven(load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/driven.yaml"));
  driven.set_steering_command(-2.0);
  driven.set_drive_command(12.0);
  const ros_conversions::ActuatorEfforts commanded = ros_conversions::actuator_efforts(driven);
  EXPECT_EQ(commanded.steering_torque, -2.0);
  EXPECT_EQ(commanded.drive_torque, 12.0);

  Simulation constant(load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/const_steer_torque.yaml"));
  const ros_conversions::ActuatorEfforts profiled = ros_conversions::actuator_efforts(constant);
  EXPECT_EQ(profiled.steering_torque, 0.4);
  EXPECT_EQ(profiled.drive_torque, 0.0) << "no drive effect in that scene";
}

TEST(Conversions, IntegrationErrorCarriesTheLocalErrorEstimateOrSaysThereIsNone) {
  const CartState state = moving_state();
  const Diagnostics diagnostics;
  StepStatistics statistics;
  const IntegrationError none = ros_conversions::to_integration_error(state, diagnostics, statistics, "birkhoff2", 1e-3, 0.0);
  EXPECT_FALSE(none.has_local_error_estimate);
  EXPECT_TRUE(std::isnan(none.local_error_estimate));
  EXPECT_EQ(none.local_error_estimate_sum, 0.0);
  record_local_error_estimate(statistics, 3e-9);
  record_local_error_estimate(statistics, 1e-9);
  const IntegrationError some = ros_conversions::to_integration_error(state, diagnostics, statistics, "rk4", 1e-3, 0.0);
  EXPECT_TRUE(some.has_local_error_estimate);
  EXPECT_EQ(some.local_error_estimate, 1e-9);
  EXPECT_EQ(some.local_error_estimate_max, 3e-9);
  EXPECT_DOUBLE_EQ(some.local_error_estimate_sum, 4e-9);
}

}  // namespace
}  // namespace birkhoff_cart
