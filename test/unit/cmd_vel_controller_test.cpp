// CmdVelController: the rules of the cmd_vel → (τ, T) law, and its closed loop with a core
// Simulation of config/scenes/driven.yaml (no master: the same law the node runs, on the same
// 100 Hz instants cart_sim publishes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/node_logic/cmd_vel_controller.h"

namespace birkhoff_cart {
namespace {

constexpr double kControlPeriod = 0.01;  // cart_sim's default ~publish_rate of 100 Hz [s]

CartFeedback feedback_at(double time, double speed = 0.0, double steering_angle = 0.0, double steering_rate = 0.0) {
  CartFeedback feedback;
  feedback.time = time;
  feedback.base_speed = speed;
  feedback.steering_angle = steering_angle;
  feedback.steering_rate = steering_rate;
  return feedback;
}

TEST(CmdVelController, SteersTowardTheKinematicAngleForwardAndInReverse) {
  CmdVelControllerSettings settings;
  settings.max_acceleration = 100.0;  // no slew in the way: v_ref = v* after one update
  settings.min_acceleration = -100.0;
  settings.max_yaw_acceleration = 100.0;
  for (const double speed : {1.0, -0.8}) {
    CmdVelController controller(settings);
    controller.update(feedback_at(0.0, speed));
    const double yaw_rate = 0.3;  // [rad/s]
    ASSERT_TRUE(controller.set_command(speed, yaw_rate, 0.0));
    const ActuatorCommand command = controller.update(feedback_at(0.1, speed));
    // θ̇ = v_A tan χ / l  ⇒  χ* = atan(r l / v): positive forward, negative in reverse for r > 0.
    EXPECT_NEAR(controller.steering_target(), std::atan(yaw_rate * settings.wheel_separation_h / speed), 1e-15);
    EXPECT_GT(command.steering_torque * speed, 0.0) << "speed " << speed;
  }
}

TEST(CmdVelController, ClampsSpeedYawRateAndSteeringAngle) {
  CmdVelControllerSettings settings;
  CmdVelController controller(settings);
  controller.update(feedback_at(0.0));
  // Drives the law for `duration` [s] under (v*, r*), the feedback at the speed reference.
  double time = 0.0;
  const auto hold = [&](double speed, double yaw_rate, double duration) {
    for (const double end = time + duration; time < end;) {
      time += kControlPeriod;
      controller.set_command(speed, yaw_rate, time);
      controller.update(feedback_at(time, controller.speed_reference()));
    }
  };
  hold(10.0, 5.0, 10.0);
  EXPECT_EQ(controller.speed_reference(), settings.max_velocity);
  EXPECT_EQ(controller.yaw_rate_reference(), settings.max_yaw_rate);
  hold(0.5, 5.0, 10.0);  // atan(1.5 · 1.05 / 0.5) = 1.26 rad wanted
  EXPECT_EQ(controller.steering_target(), settings.max_steering_angle);
  hold(-10.0, -5.0, 10.0);
  EXPECT_EQ(controller.speed_reference(), settings.min_velocity);
  EXPECT_EQ(controller.yaw_rate_reference(), -settings.max_yaw_rate);
}

TEST(CmdVelController, LimitsAccelerationAndSteeringRate) {
  CmdVelControllerSettings settings;
  CmdVelController controller(settings);
  controller.update(feedback_at(0.0));
  controller.set_command(settings.max_velocity, 1.0, 0.0);
  controller.update(feedback_at(0.1));
  EXPECT_NEAR(controller.speed_reference(), settings.max_acceleration * 0.1, 1e-12);
  EXPECT_NEAR(std::abs(controller.steering_reference()), settings.max_steering_rate * 0.1, 1e-12);
  // Braking is limited by min_acceleration (< 0).
  CmdVelController braking(settings);
  braking.update(feedback_at(0.0, 2.0));
  braking.set_command(0.0, 0.0, 0.0);
  braking.update(feedback_at(0.1, 2.0));
  EXPECT_NEAR(braking.speed_reference(), 2.0 + settings.min_acceleration * 0.1, 1e-12);
}

TEST(CmdVelController, ClampsTorques) {
  CmdVelControllerSettings settings;
  CmdVelController controller(settings);
  controller.update(feedback_at(0.0));
  controller.set_command(1.0, 0.0, 0.0);
  // Far from the reference: both loops saturate at their limits.
  const ActuatorCommand command = controller.update(feedback_at(0.01, -50.0, 1.4, 20.0));
  EXPECT_EQ(command.drive_torque, settings.max_drive_torque);
  EXPECT_EQ(command.steering_torque, -settings.max_steering_torque);
}

TEST(CmdVelController, TimeoutBrakesToRestAndHoldsTheSteering) {
  CmdVelControllerSettings settings;
  CmdVelController controller(settings);
  controller.update(feedback_at(0.0, 1.0));
  controller.set_command(1.0, 0.2, 0.0);
  controller.update(feedback_at(settings.cmd_vel_timeout, 1.0));
  EXPECT_FALSE(controller.timed_out()) << "a silence of exactly the timeout is still in time";
  const double steering_before = controller.steering_target();
  const ActuatorCommand command = controller.update(feedback_at(settings.cmd_vel_timeout + kControlPeriod, 1.0));
  EXPECT_TRUE(controller.timed_out());
  EXPECT_EQ(controller.timeouts(), 1u);
  EXPECT_LT(command.drive_torque, 0.0) << "a rolling cart is braked";
  EXPECT_EQ(controller.steering_target(), steering_before) << "at v* = 0 no angle turns the cart: hold it";
  controller.update(feedback_at(settings.cmd_vel_timeout + 2 * kControlPeriod, 1.0));
  EXPECT_EQ(controller.timeouts(), 1u) << "one silence, one timeout";
  controller.set_command(0.5, 0.0, 1.0);
  controller.update(feedback_at(1.0 + kControlPeriod, 0.5));
  EXPECT_FALSE(controller.timed_out());
}

TEST(CmdVelController, NoCommandMeansStandStill) {
  CmdVelController controller{CmdVelControllerSettings{}};
  const ActuatorCommand at_rest = controller.update(feedback_at(0.0));
  EXPECT_EQ(at_rest.drive_torque, 0.0);
  EXPECT_EQ(at_rest.steering_torque, 0.0);
  const ActuatorCommand later = controller.update(feedback_at(5.0));
  EXPECT_EQ(later.drive_torque, 0.0);
  EXPECT_FALSE(controller.timed_out()) << "nothing received, nothing timed out";
}

TEST(CmdVelController, RejectsNonFiniteCommandsKeepingThePrevious) {
  CmdVelController controller{CmdVelControllerSettings{}};
  ASSERT_TRUE(controller.set_command(1.0, 0.1, 0.0));
  EXPECT_FALSE(controller.set_command(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.1));
  EXPECT_FALSE(controller.set_command(1.0, std::numeric_limits<double>::infinity(), 0.1));
  controller.update(feedback_at(0.0, 1.0));
  controller.update(feedback_at(0.1, 1.0));
  EXPECT_GT(controller.yaw_rate_reference(), 0.0);
}

TEST(CmdVelController, TimeGoingBackRestartsFromTheFeedback) {
  CmdVelController controller{CmdVelControllerSettings{}};
  controller.update(feedback_at(0.0));
  for (int k = 1; k <= 100; ++k) {
    controller.set_command(2.0, 0.0, k * kControlPeriod);
    controller.update(feedback_at(k * kControlPeriod, controller.speed_reference()));
  }
  ASSERT_GT(controller.speed_reference(), 1.0);
  controller.update(feedback_at(0.0, 0.0, 0.1));  // the simulator was reset to t0 = 0
  EXPECT_EQ(controller.speed_reference(), 0.0);
  EXPECT_EQ(controller.steering_reference(), 0.1);
  // The command from before the reset still counts, and still times out.
  controller.update(feedback_at(0.6));
  EXPECT_TRUE(controller.timed_out());
}

TEST(CmdVelController, RefusesBadSettingsByName) {
  const auto refused = [](auto change, const std::string& name) {
    CmdVelControllerSettings settings;
    change(settings);
    try {
      CmdVelController controller(settings);
      ADD_FAILURE() << name << " accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
    }
  };
  refused([](CmdVelControllerSettings& s) { s.wheel_separation_h = 0.0; }, "wheel_separation_h");
  refused([](CmdVelControllerSettings& s) { s.cmd_vel_timeout = -1.0; }, "cmd_vel_timeout");
  refused([](CmdVelControllerSettings& s) { s.min_velocity = 0.5; }, "linear/x/min_velocity");
  refused([](CmdVelControllerSettings& s) { s.min_acceleration = 1.0; }, "linear/x/min_acceleration");
  refused([](CmdVelControllerSettings& s) { s.max_steering_angle = 1.6; }, "steering/max_angle");
  refused([](CmdVelControllerSettings& s) { s.steering_p = std::nan(""); }, "steering/p");
  refused([](CmdVelControllerSettings& s) { s.max_drive_torque = 0.0; }, "drive/max_torque");
}

// dynamic_reconfigure's path: new limits and gains take effect at the next update, the command
// carries on; a bad set or a new geometry is refused by name and the running settings stay.
TEST(CmdVelController, NewSettingsWhileRunningOrARefusalThatKeepsTheOld) {
  CmdVelController controller{CmdVelControllerSettings{}};
  ASSERT_TRUE(controller.set_command(10.0, 0.0, 0.0));
  CmdVelControllerSettings slower = controller.settings();
  slower.max_velocity = 2.0;
  slower.steering_p = 200.0;
  controller.set_settings(slower);
  EXPECT_EQ(controller.settings().max_velocity, 2.0);
  EXPECT_EQ(controller.settings().steering_p, 200.0);
  CartFeedback feedback;
  feedback.time = 0.01;
  controller.update(feedback);
  for (int k = 2; k <= 400; ++k) {  // 4 s of a 10 m/s command, renewed before its timeout
    feedback.time = 0.01 * k;
    ASSERT_TRUE(controller.set_command(10.0, 0.0, feedback.time));
    controller.update(feedback);
  }
  EXPECT_EQ(controller.speed_reference(), 2.0) << "the new limit holds the received 10 m/s";
  CmdVelControllerSettings bad = controller.settings();
  bad.min_acceleration = 0.0;
  EXPECT_THROW(controller.set_settings(bad), std::invalid_argument);
  CmdVelControllerSettings longer = controller.settings();
  longer.wheel_separation_h = 2.0;
  try {
    controller.set_settings(longer);
    ADD_FAILURE() << "a new wheel_separation_h was accepted while running";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("wheel_separation_h"), std::string::npos) << error.what();
  }
  EXPECT_EQ(controller.settings().min_acceleration, -3.0);
  EXPECT_EQ(controller.settings().wheel_separation_h, 1.05);
  EXPECT_EQ(controller.settings().max_velocity, 2.0);
}

// ---------------------------------------------------------------------------------------------
// The closed loop: driven.yaml (torques from commands) stepped by the core, the law updated at every
// 10 ms instant with the state of that instant, its torques held until the next one (as cart_sim's
// zero-order hold does).
class ClosedLoop {
 public:
  ClosedLoop() : simulation_(load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/driven.yaml")),
                 controller_(CmdVelControllerSettings{}) {}

  /// Runs for `duration` [s] of scene time under the command (v*, r*), or silent when `send` is false.
  void drive(double speed, double yaw_rate, double duration, bool send = true) {
    const double end = simulation_.state().time + duration;
    while (simulation_.state().time + 0.5 * kControlPeriod < end) {
      const CartState& state = simulation_.state();
      if (send) controller_.set_command(speed, yaw_rate, state.time);
      const ActuatorCommand command = controller_.update(feedback());
      simulation_.set_steering_command(command.steering_torque);
      simulation_.set_drive_command(command.drive_torque);
      simulation_.advance_to(state.time + kControlPeriod);
    }
  }
  CartFeedback feedback() const {
    const CartState& state = simulation_.state();
    return feedback_at(state.time, base_speed(), state.steering_angle, state.steering_rate);
  }
  double base_speed() const {  // v_A = ω1 cos χ [m/s]
    return simulation_.state().forward_speed * std::cos(simulation_.state().steering_angle);
  }
  double yaw_rate() const {  // θ̇ = ω1 sin χ / l [rad/s]
    const CartState& state = simulation_.state();
    return state.forward_speed * std::sin(state.steering_angle) / simulation_.scene().cart.wheelbase;
  }
  Eigen::Vector2d position() const { return simulation_.model().rear_axle_midpoint(simulation_.state()); }
  double heading() const { return simulation_.state().heading; }
  const CmdVelController& controller() const { return controller_; }

 private:
  Simulation simulation_;
  CmdVelController controller_;
};

// Stated bounds of the closed loop (defaults of CmdVelControllerSettings).
constexpr double kSpeedTolerance = 0.02;      // |v_A − v*| once settled [m/s]
constexpr double kYawRateTolerance = 0.02;    // |θ̇ − r*| once settled [rad/s]
constexpr double kRadiusTolerance = 0.03;     // |R − v*/r*| of the settled circles [m]
constexpr double kCentreDrift = 0.03;         // spread of a settled circle's centre [m]
constexpr double kCentreDistanceTolerance = 0.1;  // |c_left − c_right| − 2R: the lag of the swap [m]
constexpr double kRestSpeed = 0.01;           // "at rest" after braking [m/s]

// The centre of the circle the cart is on: A + R n, R = v_A/θ̇ (signed), n the left normal.
Eigen::Vector2d curvature_centre(const ClosedLoop& loop) {
  const double radius = loop.base_speed() / loop.yaw_rate();
  return loop.position() + radius * Eigen::Vector2d(-std::sin(loop.heading()), std::cos(loop.heading()));
}

// Runs a settled turn for `duration` [s] and checks it is one circle of radius v*/|r*|; returns its centre.
Eigen::Vector2d settled_circle(ClosedLoop& loop, double speed, double yaw_rate, double duration) {
  const Eigen::Vector2d centre = curvature_centre(loop);
  double largest_drift = 0.0;
  for (double elapsed = 0.0; elapsed < duration; elapsed += 0.1) {
    loop.drive(speed, yaw_rate, 0.1);
    EXPECT_NEAR(loop.base_speed(), speed, kSpeedTolerance);
    EXPECT_NEAR(loop.yaw_rate(), yaw_rate, kYawRateTolerance);
    EXPECT_NEAR((loop.position() - centre).norm(), speed / std::abs(yaw_rate), kRadiusTolerance);
    largest_drift = std::max(largest_drift, (curvature_centre(loop) - centre).norm());
  }
  EXPECT_LT(largest_drift, kCentreDrift);
  return centre;
}

TEST(CmdVelClosedLoop, DrivesAFigureEightAndBrakesOnSilence) {
  ClosedLoop loop;
  // driven.yaml starts at ω1 = 2 m/s: with no command the law brakes the cart to rest.
  loop.drive(0.0, 0.0, 2.0, /*send=*/false);
  std::printf("braked from 2 m/s: |v_A| = %.2e m/s after 2 s\n", std::abs(loop.base_speed()));
  EXPECT_LT(std::abs(loop.base_speed()), kRestSpeed);

  // Up to 1.5 m/s straight, then the figure eight: one full turn left, one right (r = ±0.75 rad/s,
  // radius v/r = 2 m), each turn ended by the heading.
  const double speed = 1.5, yaw_rate = 0.75, radius = speed / yaw_rate;  // [m/s], [rad/s], [m]
  loop.drive(speed, 0.0, 3.0);
  EXPECT_NEAR(loop.base_speed(), speed, kSpeedTolerance);
  const Eigen::Vector2d start = loop.position();
  const double start_heading = loop.heading();
  loop.drive(speed, yaw_rate, 1.0);  // steering in (≤ 0.4 s at steering/max_rate) and settling
  const Eigen::Vector2d left_centre = settled_circle(loop, speed, yaw_rate, 5.0);
  while (loop.heading() < start_heading + 2.0 * M_PI) loop.drive(speed, yaw_rate, kControlPeriod);
  loop.drive(speed, -yaw_rate, 1.5);  // the swap from +χ to −χ (≤ 0.7 s) and settling
  const Eigen::Vector2d right_centre = settled_circle(loop, speed, -yaw_rate, 5.0);
  while (loop.heading() > start_heading) loop.drive(speed, -yaw_rate, kControlPeriod);
  EXPECT_NEAR((left_centre - right_centre).norm(), 2.0 * radius, kCentreDistanceTolerance);
  std::printf("figure eight: centres %.4f m apart (2R = %.4f m); back at the start heading %.4f m from the start\n",
              (left_centre - right_centre).norm(), 2.0 * radius, (loop.position() - start).norm());

  // Silence: after cmd_vel_timeout the law brakes to rest.
  loop.drive(0.0, 0.0, 3.0, /*send=*/false);
  std::printf("braked on silence from 1.5 m/s: |v_A| = %.2e m/s after 3 s\n", std::abs(loop.base_speed()));
  EXPECT_EQ(loop.controller().timeouts(), 1u);
  EXPECT_LT(std::abs(loop.base_speed()), kRestSpeed);

  // Reverse at 0.5 m/s, turning at +0.3 rad/s: χ* < 0 and the cart still turns at +r*.
  loop.drive(-0.5, 0.3, 5.0);
  EXPECT_NEAR(loop.base_speed(), -0.5, kSpeedTolerance);
  EXPECT_NEAR(loop.yaw_rate(), 0.3, kYawRateTolerance);
}

}  // namespace
}  // namespace birkhoff_cart
