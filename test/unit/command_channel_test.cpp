// CommandChannel: zero-order hold, clamping, rejection of non-finite values and the watchdog
// (ROS-free rules of cart_sim's command topics).
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "birkhoff_cart/core/node_logic/command_channel.h"

namespace birkhoff_cart {
namespace {

constexpr double kMaxTorque = 5.0;  // [N·m]
constexpr double kTimeout = 0.5;    // [s]

TEST(CommandChannel, HoldsAcceptedCommands) {
  CommandChannel channel(0.0, kMaxTorque, kTimeout, 0.0);
  EXPECT_EQ(channel.torque(), 0.0);
  EXPECT_EQ(channel.receive(2.5, 0.1), CommandChannel::Outcome::kAccepted);
  EXPECT_EQ(channel.torque(), 2.5);
  EXPECT_EQ(channel.receive(-kMaxTorque, 0.2), CommandChannel::Outcome::kAccepted);  // the limit itself is fine
  EXPECT_EQ(channel.torque(), -kMaxTorque);
  EXPECT_EQ(channel.received(), 2u);
  EXPECT_EQ(channel.clamped(), 0u);
}

TEST(CommandChannel, ClampsToTheLimitWithTheSign) {
  CommandChannel channel(0.0, kMaxTorque, kTimeout, 0.0);
  EXPECT_EQ(channel.receive(50.0, 0.1), CommandChannel::Outcome::kClamped);
  EXPECT_EQ(channel.torque(), kMaxTorque);
  EXPECT_EQ(channel.receive(-7.0, 0.2), CommandChannel::Outcome::kClamped);
  EXPECT_EQ(channel.torque(), -kMaxTorque);
  EXPECT_EQ(channel.clamped(), 2u);
}

TEST(CommandChannel, RejectsNonFiniteAndKeepsTheHeldTorque) {
  CommandChannel channel(0.0, kMaxTorque, kTimeout, 0.0);
  channel.receive(1.5, 0.1);
  EXPECT_EQ(channel.receive(std::numeric_limits<double>::quiet_NaN(), 0.2), CommandChannel::Outcome::kRejected);
  EXPECT_EQ(channel.receive(std::numeric_limits<double>::infinity(), 0.3), CommandChannel::Outcome::kRejected);
  EXPECT_EQ(channel.receive(-std::numeric_limits<double>::infinity(), 0.3), CommandChannel::Outcome::kRejected);
  EXPECT_EQ(channel.torque(), 1.5);
  EXPECT_EQ(channel.rejected(), 3u);
  EXPECT_EQ(channel.received(), 4u);
  // A rejected command does not feed the watchdog: silence counts from the last accepted one.
  EXPECT_TRUE(channel.check_watchdog(0.1 + kTimeout + 1e-6));
}

TEST(CommandChannel, WatchdogZeroesAStaleCommandOncePerTimeout) {
  CommandChannel channel(0.0, kMaxTorque, kTimeout, 0.0);
  EXPECT_FALSE(channel.check_watchdog(10.0)) << "nothing held, nothing to time out";
  channel.receive(3.0, 1.0);
  EXPECT_FALSE(channel.check_watchdog(1.0 + kTimeout));  // exactly the timeout: still fresh
  EXPECT_EQ(channel.torque(), 3.0);
  EXPECT_TRUE(channel.check_watchdog(1.0 + kTimeout + 1e-3));
  EXPECT_EQ(channel.torque(), 0.0);
  EXPECT_FALSE(channel.check_watchdog(5.0)) << "warn once per timeout";
  EXPECT_EQ(channel.timeouts(), 1u);
  channel.receive(-2.0, 6.0);
  EXPECT_TRUE(channel.check_watchdog(7.0));
  EXPECT_EQ(channel.timeouts(), 2u);
}

TEST(CommandChannel, ZeroTimeoutDisablesTheWatchdog) {
  CommandChannel channel(0.0, kMaxTorque, 0.0, 0.0);
  channel.receive(3.0, 1.0);
  EXPECT_FALSE(channel.check_watchdog(1000.0));
  EXPECT_EQ(channel.torque(), 3.0);
}

TEST(CommandChannel, RestartReturnsToTheInitialTorque) {
  CommandChannel channel(0.7, kMaxTorque, kTimeout, 0.0);
  EXPECT_EQ(channel.torque(), 0.7);
  channel.receive(4.0, 1.0);
  channel.restart(0.0);
  EXPECT_EQ(channel.torque(), 0.7);
  EXPECT_EQ(channel.received(), 1u) << "statistics survive a reset";
  // A non-zero initial torque is watched as well.
  EXPECT_TRUE(channel.check_watchdog(kTimeout + 1e-3));
}

TEST(CommandChannel, NewLimitsApplyToLaterCommandsAndBadOnesChangeNothing) {
  CommandChannel channel(0.0, kMaxTorque, kTimeout, 0.0);
  channel.receive(kMaxTorque, 0.0);
  channel.set_limits(kMaxTorque / 2.0, 2.0 * kTimeout);
  EXPECT_EQ(channel.torque(), kMaxTorque) << "the held torque stays";
  EXPECT_EQ(channel.receive(kMaxTorque, 0.1), CommandChannel::Outcome::kClamped);
  EXPECT_EQ(channel.torque(), kMaxTorque / 2.0);
  EXPECT_FALSE(channel.check_watchdog(0.1 + 1.5 * kTimeout));  // the new, longer timeout
  EXPECT_TRUE(channel.check_watchdog(0.1 + 2.0 * kTimeout + 1e-9));
  EXPECT_THROW(channel.set_limits(0.0, kTimeout), std::invalid_argument);
  EXPECT_THROW(channel.set_limits(kMaxTorque, -1.0), std::invalid_argument);
  EXPECT_THROW(channel.set_limits(std::numeric_limits<double>::infinity(), kTimeout), std::invalid_argument);
  EXPECT_EQ(channel.max_torque(), kMaxTorque / 2.0);
  EXPECT_EQ(channel.timeout(), 2.0 * kTimeout);
}

TEST(CommandChannel, BadSettingsAreNamed) {
  EXPECT_THROW(CommandChannel(0.0, 0.0, kTimeout, 0.0), std::invalid_argument);
  EXPECT_THROW(CommandChannel(0.0, -1.0, kTimeout, 0.0), std::invalid_argument);
  EXPECT_THROW(CommandChannel(0.0, kMaxTorque, -0.1, 0.0), std::invalid_argument);
  EXPECT_THROW(CommandChannel(std::numeric_limits<double>::quiet_NaN(), kMaxTorque, kTimeout, 0.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace birkhoff_cart
