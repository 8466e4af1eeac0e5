// rostest node_commands: steering commands reach the physics (positive torque → positive χ),
// over-limit commands are clamped, the watchdog zeroes a stale command, NaN is rejected and counted
// while the simulation keeps running, and ~pause / ~reset work.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>

#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;          // [s of wall time], only against hangs
constexpr double kTorqueTolerance = 1e-12;     // [N·m]
constexpr double kCommandTimeout = 0.5;        // cart_sim's ~command_timeout in node_commands.yaml [s]
constexpr double kMaxSteeringTorque = 5.0;     // cart_sim's ~max_steering_torque [N·m]
constexpr double kTurnedSteeringAngle = 0.02;  // χ after ~1 s of +3 N·m is well above this [rad]

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
    steering_publisher_ = node_.advertise<std_msgs::Float64>("steering_torque", 10);
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [this] { return joint_subscriber_.getNumPublishers() > 0 && steering_publisher_.getNumSubscribers() > 0 &&
                        diagnostics_subscriber_.getNumPublishers() > 0; },
        kWaitTimeout));
    ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", false));
    ASSERT_TRUE(birkhoff_cart_test::wait_for([this] { return joint_count_ > 0; }, kWaitTimeout));
  }

  double stamp() const { return latest_joints_.header.stamp.toSec(); }
  double steering_angle() const { return latest_joints_.position.at(0); }
  double steering_effort() const { return latest_joints_.effort.at(0); }

  void send(double torque) {
    std_msgs::Float64 message;
    message.data = torque;
    steering_publisher_.publish(message);
  }
  /// Sends `torque` repeatedly (every ~0.1 s of scene time) until the scene time passes `until`.
  void keep_sending(double torque, double until) {
    double last_sent = -1.0;
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [&] {
          if (stamp() - last_sent >= 0.1) {
            send(torque);
            last_sent = stamp();
          }
          return stamp() > until;
        },
        kWaitTimeout));
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
  ros::Publisher steering_publisher_;
  sensor_msgs::JointState latest_joints_;
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
  ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", true));
  ros::WallDuration(0.2).sleep();  // let messages already in flight arrive
  ros::spinOnce();
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

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_commands_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
