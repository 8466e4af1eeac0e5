// rostest cmd_vel_figure_eight: a figure eight given only as geometry_msgs/Twist on cmd_vel. The
// test acts as a teleop would: it publishes cmd_vel at every odom instant (100 Hz of scene time)
// and decides the next leg from odom alone (heading and scene time). Checks, in scene time:
//   - from rest up to 1.5 m/s straight: v_A settles at v*;
//   - a full turn left at r* = +0.75 rad/s, then a full turn right at −0.75 rad/s: once settled,
//     v_A and θ̇ match the command and the path is a circle of radius v*/|r*| = 2 m;
//   - silence on cmd_vel: after the controller's cmd_vel_timeout the cart brakes to rest.
// Bounds are wider than the unit test's closed loop (test/ros_unit/cmd_vel_controller_test.cpp),
// because over topics a torque reaches the physics a few steps after the state it answers.
#include <gtest/gtest.h>

#include <cmath>

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <tf2/utils.h>

#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 120.0;      // [s of wall time], only against hangs
constexpr double kSpeed = 1.5;              // v* [m/s]
constexpr double kYawRate = 0.75;           // |r*| [rad/s]
constexpr double kSpeedTolerance = 0.05;    // |v_A − v*| once settled [m/s]
constexpr double kYawRateTolerance = 0.05;  // |θ̇ − r*| once settled [rad/s]
constexpr double kRadiusTolerance = 0.1;    // | |A − c| − v*/r* | on a settled circle [m]
constexpr double kSettleTime = 1.5;         // after a change of command [s of scene time]
constexpr double kRestSpeed = 0.02;         // at rest [m/s]
constexpr double kBrakeTime = 2.5;          // silence after which the cart is at rest: timeout 0.5 s + 1.5 m/s at 3 m/s² + margin [s]

struct Sample {
  double time = 0.0;     // [s]
  double x = 0.0, y = 0.0;  // A [m]
  double heading = 0.0;  // θ, unwrapped [rad]
  double speed = 0.0;    // v_A [m/s]
  double yaw_rate = 0.0; // θ̇ [rad/s]
};

class CmdVelFigureEight : public testing::Test {
 protected:
  void SetUp() override {
    odometry_subscriber_ = node_.subscribe<nav_msgs::Odometry>("odom", 1000, [this](const nav_msgs::Odometry::ConstPtr& m) {
      Sample sample;
      sample.time = m->header.stamp.toSec();
      sample.x = m->pose.pose.position.x;
      sample.y = m->pose.pose.position.y;
      const double yaw = tf2::getYaw(m->pose.pose.orientation);
      // Unwrap: the figure eight turns through 2π each way.
      sample.heading = count_ == 0 ? yaw : latest_.heading + std::remainder(yaw - latest_.heading, 2.0 * M_PI);
      sample.speed = m->twist.twist.linear.x;
      sample.yaw_rate = m->twist.twist.angular.z;
      latest_ = sample;
      ++count_;
      if (sending_) {  // a teleop's habit: one cmd_vel per state seen
        geometry_msgs::Twist command;
        command.linear.x = speed_;
        command.angular.z = yaw_rate_;
        cmd_vel_publisher_.publish(command);
      }
      if (on_sample_) on_sample_(latest_);
    });
    cmd_vel_publisher_ = node_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
    torque_subscriber_ = node_.subscribe<std_msgs::Float64>(
        "drive_torque", 100, [this](const std_msgs::Float64::ConstPtr&) { ++torques_seen_; });
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [this] { return odometry_subscriber_.getNumPublishers() > 0 && cmd_vel_publisher_.getNumSubscribers() > 0; },
        kWaitTimeout));
    ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", false));
    ASSERT_TRUE(birkhoff_cart_test::wait_for([this] { return count_ > 0; }, kWaitTimeout));
  }

  void command(double speed, double yaw_rate) {
    speed_ = speed;
    yaw_rate_ = yaw_rate;
    sending_ = true;
  }
  /// Spins until `condition` holds on the latest odometry.
  void until(const std::function<bool(const Sample&)>& condition) {
    ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return condition(latest_); }, kWaitTimeout))
        << "stuck at t = " << latest_.time << " s";
  }
  void for_scene_time(double duration) {
    const double end = latest_.time + duration;
    until([end](const Sample& s) { return s.time >= end; });
  }
  /// A settled turn for `duration` [s]: checks v_A, θ̇ and the distance to the circle's centre, fixed
  /// at the first sample as A + R n (n the left normal, R = v*/r* signed).
  void check_circle(double yaw_rate, double duration) {
    const double radius = kSpeed / yaw_rate;
    const double cx = latest_.x - radius * std::sin(latest_.heading);
    const double cy = latest_.y + radius * std::cos(latest_.heading);
    double worst_speed = 0.0, worst_yaw_rate = 0.0, worst_radius = 0.0;
    on_sample_ = [&](const Sample& s) {
      worst_speed = std::max(worst_speed, std::abs(s.speed - kSpeed));
      worst_yaw_rate = std::max(worst_yaw_rate, std::abs(s.yaw_rate - yaw_rate));
      worst_radius = std::max(worst_radius, std::abs(std::hypot(s.x - cx, s.y - cy) - std::abs(radius)));
    };
    for_scene_time(duration);
    on_sample_ = nullptr;
    std::printf("turn at r* = %+.2f rad/s: worst |v_A - v*| %.4f m/s, |r - r*| %.4f rad/s, |R - v*/r*| %.4f m\n",
                yaw_rate, worst_speed, worst_yaw_rate, worst_radius);
    EXPECT_LT(worst_speed, kSpeedTolerance);
    EXPECT_LT(worst_yaw_rate, kYawRateTolerance);
    EXPECT_LT(worst_radius, kRadiusTolerance);
  }

  ros::NodeHandle node_;
  ros::Subscriber odometry_subscriber_;
  ros::Publisher cmd_vel_publisher_;
  ros::Subscriber torque_subscriber_;
  long torques_seen_ = 0;  // drive_torque messages of the controller
  Sample latest_;
  long count_ = 0;
  bool sending_ = false;
  double speed_ = 0.0, yaw_rate_ = 0.0;
  std::function<void(const Sample&)> on_sample_;
};

TEST_F(CmdVelFigureEight, FollowsTheTwistAndBrakesOnSilence) {
  // driven.yaml starts at 2 m/s; before any cmd_vel the controller brakes it to rest, from its first
  // torque on (its subscriptions may connect a little after the test's).
  ASSERT_TRUE(birkhoff_cart_test::wait_for([this] { return torques_seen_ > 0; }, kWaitTimeout));
  for_scene_time(kBrakeTime);
  std::printf("braked from the scene's 2 m/s: |v_A| = %.4f m/s after %.1f s\n", std::abs(latest_.speed), kBrakeTime);
  EXPECT_LT(std::abs(latest_.speed), kRestSpeed);

  command(kSpeed, 0.0);
  for_scene_time(3.0);
  EXPECT_NEAR(latest_.speed, kSpeed, kSpeedTolerance);
  const double start_heading = latest_.heading;

  command(kSpeed, kYawRate);
  for_scene_time(kSettleTime);
  check_circle(kYawRate, 4.0);
  until([&](const Sample& s) { return s.heading >= start_heading + 2.0 * M_PI; });

  command(kSpeed, -kYawRate);
  for_scene_time(kSettleTime);
  check_circle(-kYawRate, 4.0);
  until([&](const Sample& s) { return s.heading <= start_heading; });

  sending_ = false;  // silence: the controller's cmd_vel_timeout brakes the cart
  for_scene_time(kBrakeTime);
  std::printf("braked on silence: |v_A| = %.4f m/s after %.1f s\n", std::abs(latest_.speed), kBrakeTime);
  EXPECT_LT(std::abs(latest_.speed), kRestSpeed);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "cmd_vel_figure_eight");
  return RUN_ALL_TESTS();
}
