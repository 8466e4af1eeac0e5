// rostest node_consistency: what cart_sim publishes (odom, the odom → base_link transform, joint
// states, /clock) agrees with itself and with a core Simulation stepped to the same stamps.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <tf2/utils.h>
#include <tf2_ros/transform_listener.h>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/conversions.h"
#include "test_helpers.h"

namespace {

constexpr double kPositionTolerance = 1e-9;  // [m]
constexpr double kAngleTolerance = 1e-9;     // [rad]
constexpr double kRateTolerance = 1e-9;      // [m/s] and [rad/s]
constexpr double kStampTolerance = 1e-9;     // [s] (ROS stamps hold nanoseconds)
constexpr double kWaitTimeout = 60.0;        // [s of wall time], only against hangs

double wrapped_difference(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

TEST(NodeConsistency, OdomTfJointStatesAndCoreAgreeAtTheSameStamps) {
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  std::string scene_path;
  ASSERT_TRUE(private_node.getParam("scene", scene_path));
  double duration = 0.0, publish_rate = 0.0;
  ASSERT_TRUE(node.getParam("/cart_sim/duration", duration));
  ASSERT_TRUE(node.getParam("/cart_sim/publish_rate", publish_rate));

  std::vector<nav_msgs::Odometry> odometry;
  std::vector<sensor_msgs::JointState> joints;
  std::vector<rosgraph_msgs::Clock> clocks;
  auto odometry_subscriber = node.subscribe<nav_msgs::Odometry>(
      "odom", 1000, [&](const nav_msgs::Odometry::ConstPtr& message) { odometry.push_back(*message); });
  auto joint_subscriber = node.subscribe<sensor_msgs::JointState>(
      "joint_states", 1000, [&](const sensor_msgs::JointState::ConstPtr& message) { joints.push_back(*message); });
  auto clock_subscriber = node.subscribe<rosgraph_msgs::Clock>(
      "/clock", 1000, [&](const rosgraph_msgs::Clock::ConstPtr& message) { clocks.push_back(*message); });
  tf2_ros::Buffer buffer(ros::Duration(60.0));
  tf2_ros::TransformListener listener(buffer);
  // The listener's /tf connection is made in the background like this one; unpausing before it
  // exists lost the first transforms (seen once in a full run under load).
  auto tf_probe = node.subscribe<tf2_msgs::TFMessage>(
      "/tf", 10, [&](const tf2_msgs::TFMessage::ConstPtr&) {});

  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return odometry_subscriber.getNumPublishers() > 0 && joint_subscriber.getNumPublishers() > 0 &&
                   clock_subscriber.getNumPublishers() > 0 && tf_probe.getNumPublishers() > 0; },
      kWaitTimeout));
  ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", false));

  const std::size_t expected = static_cast<std::size_t>(std::llround(duration * publish_rate));
  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return odometry.size() >= expected && joints.size() >= expected; }, kWaitTimeout))
      << odometry.size() << " odom, " << joints.size() << " joint_states of " << expected;
  ros::WallDuration(0.3).sleep();  // anything beyond the expected count would arrive now
  ros::spinOnce();
  EXPECT_EQ(odometry.size(), expected);
  EXPECT_EQ(joints.size(), expected);

  // The core, on the same scene, stepped to every stamp.
  birkhoff_cart::Simulation simulation(birkhoff_cart::load_scene(scene_path));
  const double start_time = simulation.state().time;
  const double step_size = simulation.step_size();
  ASSERT_FALSE(clocks.empty());
  EXPECT_NEAR(clocks.front().clock.toSec(), start_time + step_size, kStampTolerance) << "first /clock is t0 + h";
  EXPECT_GT(clocks.front().clock.toSec(), 0.0);
  for (std::size_t i = 1; i < clocks.size(); ++i) EXPECT_GT(clocks[i].clock, clocks[i - 1].clock);

  const std::array<std::string, 5>& names = birkhoff_cart::ros_conversions::joint_names();
  for (std::size_t k = 0; k < odometry.size() && k < joints.size(); ++k) {
    const nav_msgs::Odometry& odom = odometry[k];
    const sensor_msgs::JointState& joint = joints[k];
    const double stamp = odom.header.stamp.toSec();
    SCOPED_TRACE("instant " + std::to_string(k) + " at t = " + std::to_string(stamp));
    EXPECT_NEAR(stamp, start_time + static_cast<double>(k + 1) / publish_rate, kStampTolerance);
    EXPECT_EQ(odom.header.stamp, joint.header.stamp);
    EXPECT_EQ(odom.header.frame_id, "odom");
    EXPECT_EQ(odom.child_frame_id, "base_link");
    if (k > 0) EXPECT_GT(odom.header.stamp, odometry[k - 1].header.stamp) << "a stamp repeated";

    simulation.advance_to(stamp);
    const birkhoff_cart::CartState& state = simulation.state();
    ASSERT_NEAR(state.time, stamp, kStampTolerance);
    const Eigen::Vector2d rear_axle_midpoint = simulation.model().rear_axle_midpoint(state);

    // odom against the core
    EXPECT_NEAR(odom.pose.pose.position.x, rear_axle_midpoint.x(), kPositionTolerance);
    EXPECT_NEAR(odom.pose.pose.position.y, rear_axle_midpoint.y(), kPositionTolerance);
    const double odom_yaw = tf2::getYaw(odom.pose.pose.orientation);
    EXPECT_NEAR(wrapped_difference(odom_yaw, state.heading), 0.0, kAngleTolerance);
    EXPECT_NEAR(odom.twist.twist.linear.x, state.forward_speed * std::cos(state.steering_angle), kRateTolerance);
    EXPECT_NEAR(odom.twist.twist.angular.z,
                state.forward_speed * std::sin(state.steering_angle) / simulation.scene().cart.wheelbase,
                kRateTolerance);

    // tf against odom (and hence the core)
    geometry_msgs::TransformStamped transform;
    ASSERT_NO_THROW(transform = buffer.lookupTransform("odom", "base_link", odom.header.stamp));
    EXPECT_EQ(transform.header.stamp, odom.header.stamp);
    EXPECT_NEAR(transform.transform.translation.x, odom.pose.pose.position.x, kPositionTolerance);
    EXPECT_NEAR(transform.transform.translation.y, odom.pose.pose.position.y, kPositionTolerance);
    EXPECT_NEAR(wrapped_difference(tf2::getYaw(transform.transform.rotation), odom_yaw), 0.0, kAngleTolerance);

    // joint_states against the core
    ASSERT_EQ(joint.name.size(), 5u);
    ASSERT_EQ(joint.position.size(), 5u);
    ASSERT_EQ(joint.velocity.size(), 5u);
    ASSERT_EQ(joint.effort.size(), 5u);
    for (int j = 0; j < 5; ++j) EXPECT_EQ(joint.name[j], names[j]);
    EXPECT_NEAR(joint.position[0], state.steering_angle, kAngleTolerance);
    EXPECT_NEAR(joint.velocity[0], state.steering_rate, kRateTolerance);
    const birkhoff_cart::CoordinateRates<double> rates = simulation.model().coordinate_rates(
        state.heading, state.steering_angle, birkhoff_cart::Vector2<double>(state.forward_speed, state.steering_rate));
    for (int wheel = 0; wheel < 4; ++wheel) {
      EXPECT_NEAR(joint.position[wheel + 1], state.wheel_spin_angle[wheel], kAngleTolerance);
      EXPECT_NEAR(joint.velocity[wheel + 1], rates.wheel_spin_rate[wheel], kRateTolerance);
    }
    // const_steer_torque: the steering actuator applies its constant torque, no drive.
    EXPECT_NEAR(joint.effort[0], simulation.scene().effects.front().profile.value, 1e-12);
    EXPECT_EQ(joint.effort[1], 0.0);
  }
  // The cart really moved: the comparison is not between two resting carts.
  EXPECT_GT(std::abs(odometry.back().pose.pose.position.x - odometry.front().pose.pose.position.x), 1.0);
  EXPECT_GT(std::abs(joints.back().position[0]), 1e-3);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_consistency_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
