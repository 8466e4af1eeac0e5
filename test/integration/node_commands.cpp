// rostest node_commands: steering commands reach the physics (positive torque → positive χ),
// over-limit commands are clamped, the watchdog zeroes a stale command, NaN is rejected and counted
// while the simulation keeps running, and ~pause / ~reset work; drive commands speed the cart up
// (half the torque on each rear wheel), are clamped, time out and have their NaN rejected, too.
// Every wait is on the node's messages (scene-time stamps), except the pause window, which shows
// that no scene time passes while wall time does.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>

#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;          // [s of wall time], only against hangs
constexpr double kTorqueTolerance = 1e-12;     // [N·m]
constexpr double kCommandTimeout = 0.5;        // cart_sim's ~command_timeout in node_commands.yaml [s]
constexpr double kMaxSteeringTorque = 5.0;     // cart_sim's ~max_steering_torque [N·m]
constexpr double kTurnedSteeringAngle = 0.02;  // χ after ~1 s of +3 N·m is well above this [rad]
constexpr double kMaxDriveTorque = 60.0;       // cart_sim's ~max_drive_torque in node_commands.yaml [N·m]
constexpr double kPublishRate = 50.0;          // cart_sim's ~publish_rate in node_commands.yaml [Hz]
constexpr double kSpeedGain = 0.2;             // 1 s of 40 N·m speeds the ~170 kg cart up by more [m/s]

class NodeCommands : public testing::Test {
 protected:
  void SetUp() override {
    joint_subscriber_ = node_.subscribe<sensor_msgs::JointState>(
        "joint_states", 100, [this](const sensor_msgs::JointState::ConstPtr& message) { latest_joints_ = *message; ++joint_count_; });
    diagnostics_subscriber_ = node_.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& message) {
          for (const auto& status : message->status) {
            if (status.name.find("simulation") == std::string::npos) continue;
            for (const auto& pair : status.values) diagnostic_values_[pair.key] = pair.value;
            ++diagnostic_count_;
          }
        });
    odom_subscriber_ = node_.subscribe<nav_msgs::Odometry>(
        "odom", 100, [this](const nav_msgs::Odometry::ConstPtr& message) { latest_odom_ = *message; });
    steering_publisher_ = node_.advertise<std_msgs::Float64>("steering_torque", 10);
    drive_publisher_ = node_.advertise<std_msgs::Float64>("drive_torque", 10);
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [this] { return joint_subscriber_.getNumPublishers() > 0 && steering_publisher_.getNumSubscribers() > 0 &&
                        drive_publisher_.getNumSubscribers() > 0 && odom_subscriber_.getNumPublishers() > 0 &&
                        diagnostics_subscriber_.getNumPublishers() > 0; },
        kWaitTimeout));
    ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", false));
    ASSERT_TRUE(birkhoff_cart_test::wait_for([this] { return joint_count_ > 0; }, kWaitTimeout));
  }

  double stamp() const { return latest_joints_.header.stamp.toSec(); }
  double steering_angle() const { return latest_joints_.position.at(0); }
  double steering_effort() const { return latest_joints_.effort.at(0); }
  /// The rear wheels' efforts (joints 1, 2) [N·m]: each carries half the drive torque.
  double rear_left_effort() const { return latest_joints_.effort.at(1); }
  double rear_right_effort() const { return latest_joints_.effort.at(2); }
  /// v_A = ω1 cos χ [m/s].
  double rear_axle_speed() const { return latest_odom_.twist.twist.linear.x; }

  void send(double torque, ros::Publisher* publisher = nullptr) {
    std_msgs::Float64 message;
    message.data = torque;
    (publisher ? *publisher : steering_publisher_).publish(message);
  }
  /// Sends `torque` repeatedly (every ~0.1 s of scene time) until the scene time passes `until`.
  void keep_sending(double torque, double until, ros::Publisher* publisher = nullptr) {
    double last_sent = -1.0;
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [&] {
          if (stamp() - last_sent >= 0.1) {
            send(torque, publisher);
            last_sent = stamp();
          }
          return stamp() > until;
        },
        kWaitTimeout));
  }
  /// Pauses through ~pause and returns the scene time the node reports ("paused at t = X s") [s];
  /// NaN when the call fails.
  double pause() {
    std_srvs::SetBool call;
    call.request.data = true;
    if (!ros::service::call("/cart_sim/pause", call) || !call.response.success) return std::nan("");
    const std::string& text = call.response.message;
    const std::size_t at = text.find("t = ");
    return at == std::string::npos ? std::nan("") : std::stod(text.substr(at + 4));
  }
  /// Waits for a fresh /diagnostics report and returns the integer value of `key`.
  long diagnostic(const std::string& key) {
    const int seen = diagnostic_count_;
    EXPECT_TRUE(birkhoff_cart_test::wait_for([&] { return diagnostic_count_ > seen + 1; }, kWaitTimeout));
    const auto found = diagnostic_values_.find(key);
    if (found == diagnostic_values_.end()) {
      ADD_FAILURE() << "no diagnostic value '" << key << "'";
      return -1;
    }
    return std::stol(found->second);
  }

  ros::NodeHandle node_;
  ros::Subscriber joint_subscriber_;
  ros::Subscriber diagnostics_subscriber_;
  ros::Subscriber odom_subscriber_;
  ros::Publisher steering_publisher_;
  ros::Publisher drive_publisher_;
  sensor_msgs::JointState latest_joints_;
  nav_msgs::Odometry latest_odom_;
  int joint_count_ = 0;
  int diagnostic_count_ = 0;
  std::map<std::string, std::string> diagnostic_values_;
};

TEST_F(NodeCommands, SteeringWatchdogRejectionPauseAndReset) {
  // A positive steering torque turns χ positive, and the actuator effort reports it.
  keep_sending(3.0, stamp() + 1.0);
  EXPECT_NEAR(steering_effort(), 3.0, kTorqueTolerance);
  EXPECT_GT(steering_angle(), kTurnedSteeringAngle);

  // Over the limit: clamped to ~max_steering_torque and counted.
  keep_sending(50.0, stamp() + 0.3);
  EXPECT_NEAR(steering_effort(), kMaxSteeringTorque, kTorqueTolerance);
  EXPECT_GE(diagnostic("steering_torque commands clamped"), 1);

  // Silence: after ~command_timeout of scene time the watchdog zeroes the torque (and counts it).
  const double silence_start = stamp();
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() > silence_start + kCommandTimeout + 0.3; }, kWaitTimeout));
  EXPECT_EQ(steering_effort(), 0.0);
  EXPECT_GE(diagnostic("steering_torque command timeouts"), 1);

  // NaN and Inf: rejected, counted, the held torque unchanged, the simulation keeps running.
  const long rejected_before = diagnostic("steering_torque commands rejected");
  send(1.0);
  send(std::numeric_limits<double>::quiet_NaN());
  send(std::numeric_limits<double>::infinity());
  const double after_nan = stamp();
  // 0.2 s of scene time: the simulation runs on, well before the 0.5 s watchdog.
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() > after_nan + 0.2; }, kWaitTimeout))
      << "the simulation stopped after a NaN command";
  EXPECT_NEAR(steering_effort(), 1.0, kTorqueTolerance);
  EXPECT_TRUE(std::isfinite(steering_angle()));
  EXPECT_EQ(diagnostic("steering_torque commands rejected"), rejected_before + 2);

  // Pause: the scene time stops (nothing new is published); resume: it moves again.
  const double paused_time = pause();
  ASSERT_TRUE(std::isfinite(paused_time));
  // Messages already in flight: every instant up to the reported pause time arrives.
  const double last_instant = std::floor(paused_time * kPublishRate + 1e-6) / kPublishRate;
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() >= last_instant - 1e-9; }, kWaitTimeout))
      << "paused at t = " << paused_time << " s, last heard " << stamp() << " s";
  const double paused_at = stamp();
  const int paused_count = joint_count_;
  ros::WallDuration(0.5).sleep();  // at factor 2 this would be 1 s of scene time if running
  ros::spinOnce();
  EXPECT_EQ(joint_count_, paused_count);
  EXPECT_EQ(stamp(), paused_at);
  ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", false));
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() > paused_at + 0.1; }, kWaitTimeout));

  // Reset: back to the scene's start (t0 = 0, χ = 0, torque back to the scene's initial 0).
  const double before_reset = stamp();
  ASSERT_GT(before_reset, 1.0);
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("/cart_sim/reset", reset));
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() < 0.5; }, kWaitTimeout)) << "no reset seen";
  EXPECT_LT(std::abs(steering_angle()), 1e-2);
  EXPECT_EQ(steering_effort(), 0.0);
}

TEST_F(NodeCommands, DriveTorqueSpeedsTheCartUpIsClampedTimesOutAndRejectsNaN) {
  // Drive torque at node level: 40 N·m for 1 s of scene time speeds the cart up, half on each rear wheel.
  keep_sending(0.0, stamp() + 0.2, &drive_publisher_);
  const double speed_before = rear_axle_speed();
  keep_sending(40.0, stamp() + 1.0, &drive_publisher_);
  EXPECT_NEAR(rear_left_effort(), 20.0, kTorqueTolerance);
  EXPECT_NEAR(rear_right_effort(), 20.0, kTorqueTolerance);
  EXPECT_GT(rear_axle_speed(), speed_before + kSpeedGain) << "before " << speed_before;
  EXPECT_GE(diagnostic("drive_torque commands received"), 10);

  // Over the limit: clamped to ~max_drive_torque and counted.
  keep_sending(500.0, stamp() + 0.3, &drive_publisher_);
  EXPECT_NEAR(rear_left_effort() + rear_right_effort(), kMaxDriveTorque, kTorqueTolerance);
  EXPECT_GE(diagnostic("drive_torque commands clamped"), 1);

  // NaN and Inf: rejected and counted, the held torque unchanged, the simulation keeps running.
  const long rejected_before = diagnostic("drive_torque commands rejected");
  send(30.0, &drive_publisher_);
  send(std::numeric_limits<double>::quiet_NaN(), &drive_publisher_);
  send(-std::numeric_limits<double>::infinity(), &drive_publisher_);
  const double after_nan = stamp();
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() > after_nan + 0.2; }, kWaitTimeout))
      << "the simulation stopped after a NaN drive command";
  EXPECT_NEAR(rear_left_effort() + rear_right_effort(), 30.0, kTorqueTolerance);
  EXPECT_TRUE(std::isfinite(rear_axle_speed()));
  EXPECT_EQ(diagnostic("drive_torque commands rejected"), rejected_before + 2);

  // Silence: after ~command_timeout of scene time the watchdog zeroes the drive torque.
  const double silence_start = stamp();
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return stamp() > silence_start + kCommandTimeout + 0.3; }, kWaitTimeout));
  EXPECT_EQ(rear_left_effort() + rear_right_effort(), 0.0);
  EXPECT_GE(diagnostic("drive_torque command timeouts"), 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_commands_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
