// rostest integrator_names: sim.launch integrator:=birkhoff_gauss6 step_size:=0.01 runs that member
// in cart_sim (the name and step reach ~integration_error; the diagnostics stay finite and small).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <ros/ros.h>

#include "birkhoff_cart/IntegrationError.h"
#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;  // [s of wall time], only against hangs
constexpr std::size_t kMessages = 50;  // 0.5 s of scene time at 100 Hz

TEST(IntegratorNames, GaussSixChosenByTheLaunchFileRunsInTheNode) {
  ros::NodeHandle node;
  std::vector<birkhoff_cart::IntegrationError> messages;
  auto subscriber = node.subscribe<birkhoff_cart::IntegrationError>(
      "/cart_sim/integration_error", 1000,
      [&](const birkhoff_cart::IntegrationError::ConstPtr& message) { messages.push_back(*message); });
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return messages.size() >= kMessages; }, kWaitTimeout))
      << messages.size() << " integration_error messages";
  for (const birkhoff_cart::IntegrationError& message : messages) {
    EXPECT_EQ(message.integrator, "birkhoff_gauss6");
    EXPECT_DOUBLE_EQ(message.step_size, 0.01);
    EXPECT_TRUE(std::isfinite(message.energy));
    // The default scene's loads over ≤ a few s: gauss6 at 10 ms balances energy to ~1e-9 J.
    EXPECT_LT(std::abs(message.energy_balance_residual), 1e-6) << message.header.stamp;
    EXPECT_GT(message.newton_iterations_total, 0u);
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "integrator_names");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
