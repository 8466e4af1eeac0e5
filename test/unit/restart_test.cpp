// Simulation::restart_from(): a teleport is a restart of the run from the given state (the node's
// ~set_state and /initialpose). The restarted run must be the run of a scene that starts there, bit
// for bit; reset() must still return to the loaded scene; every refusal leaves the run as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "birkhoff_cart/core/physics/restart_state.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {
namespace {

Scene load(const std::string& name) {
  return load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/" + name + ".yaml");
}

constexpr double kBalanceTolerance = 5e-5;  // energy [J] and p2 [N·m·s] balance residuals after 0.5 s driven (as simulation_test)

bool bit_identical(const CartState& a, const CartState& b) { return std::memcmp(&a, &b, sizeof(CartState)) == 0; }

/// A state away from the scene's: another pose, steering angle and speeds, at time `time` [s].
CartState teleport_target(double time) {
  CartState target;
  target.time = time;
  target.x = 3.0;              // [m]
  target.y = -1.5;             // [m]
  target.heading = 0.7;        // [rad]
  target.steering_angle = -0.4;  // [rad]
  target.forward_speed = 1.2;  // [m/s]
  target.steering_rate = 0.3;  // [rad/s]
  return target;
}

TEST(Restart, TheRestartedRunIsTheRunOfASceneStartingThereBitForBit) {
  for (const std::string integrator : {"birkhoff_gauss4", "birkhoff2", "dopri5"}) {
    Scene scene = load("default");  // shadow reference on
    scene.integrator.name = integrator;
    Simulation simulation(scene);
    for (int k = 0; k < 250; ++k) simulation.step();
    const CartState target = teleport_target(simulation.state().time);
    simulation.restart_from(target);
    EXPECT_TRUE(bit_identical(simulation.state(), target)) << integrator;
    EXPECT_EQ(simulation.steps_taken(), 0u) << integrator;
    EXPECT_EQ(simulation.statistics().rhs_evaluations, 0u) << integrator;
    EXPECT_EQ(simulation.diagnostics().reference_position_error, 0.0) << integrator;  // reference restarted there
    EXPECT_EQ(simulation.diagnostics().energy_balance_residual, 0.0) << integrator;

    Scene starting_there = scene;
    starting_there.initial_state = target;
    Simulation fresh(starting_there);
    for (int k = 0; k < 400; ++k) {
      simulation.step();
      fresh.step();
    }
    EXPECT_TRUE(bit_identical(simulation.state(), fresh.state())) << integrator;
    EXPECT_EQ(simulation.statistics().rhs_evaluations, fresh.statistics().rhs_evaluations) << integrator;
    EXPECT_EQ(simulation.diagnostics().reference_position_error, fresh.diagnostics().reference_position_error)
        << integrator;
    EXPECT_GT(simulation.diagnostics().reference_position_error, 0.0) << integrator;  // a real comparison
    EXPECT_EQ(simulation.schedule().end_time, fresh.schedule().end_time) << integrator;
  }
}

TEST(Restart, ResetAfterARestartReturnsToTheLoadedScene) {
  Scene scene = load("driven");
  Simulation loaded(scene);
  for (int k = 0; k < 300; ++k) loaded.step();

  Simulation simulation(scene);
  for (int k = 0; k < 100; ++k) simulation.step();
  simulation.restart_from(teleport_target(simulation.state().time));
  for (int k = 0; k < 100; ++k) simulation.step();
  simulation.reset();
  EXPECT_TRUE(bit_identical(simulation.state(), scene.initial_state));
  EXPECT_EQ(simulation.schedule().end_time, loaded.schedule().end_time);
  for (int k = 0; k < 300; ++k) simulation.step();
  EXPECT_TRUE(bit_identical(simulation.state(), loaded.state()));
  EXPECT_EQ(simulation.diagnostics().energy_balance_residual, loaded.diagnostics().energy_balance_residual);
}

TEST(Restart, ATeleportFromTheCurrentStateStartsTheBalancesAgain) {
  // The node teleports by editing a copy of the current state, which carries the run's work and
  // impulse integrals (W = ∫ω·Q dt, I2 = ∫Q2 dt): the restarted run's balances start from zero.
  Scene scene = load("driven");
  Simulation simulation(scene);
  simulation.set_drive_command(40.0);
  simulation.set_steering_command(1.0);
  for (int k = 0; k < 500; ++k) simulation.step();
  ASSERT_GT(std::abs(simulation.state().applied_work), 1.0);  // [J]: the drive has done work
  CartState target = simulation.state();
  target.x += 3.0;
  target.forward_speed = 0.5;
  simulation.restart_from(target);
  EXPECT_EQ(simulation.state().applied_work, 0.0);
  EXPECT_EQ(simulation.state().steering_impulse, 0.0);
  EXPECT_EQ(simulation.diagnostics().energy_balance_residual, 0.0);
  EXPECT_EQ(simulation.diagnostics().p2_balance_residual, 0.0);
  for (int k = 0; k < 500; ++k) simulation.step();
  const Diagnostics diagnostics = simulation.diagnostics();
  std::printf("driven, 0.5 s after a teleport from the current state: energy balance %.3e J, p2 balance %.3e N m s\n",
              diagnostics.energy_balance_residual, diagnostics.p2_balance_residual);
  EXPECT_LT(std::abs(diagnostics.energy_balance_residual), kBalanceTolerance);
  EXPECT_LT(std::abs(diagnostics.p2_balance_residual), kBalanceTolerance);
}

/// Expects restart_from(`target`) to throw std::invalid_argument naming `expected`, and the run to
/// go on exactly as if it had not been asked.
void expect_refused(const Scene& scene, const CartState& target, const std::string& expected) {
  Simulation simulation(scene);
  Simulation untouched(scene);
  for (int k = 0; k < 50; ++k) {
    simulation.step();
    untouched.step();
  }
  try {
    simulation.restart_from(target);
    ADD_FAILURE() << "accepted a restart that should name '" << expected << "'";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
  }
  EXPECT_TRUE(bit_identical(simulation.state(), untouched.state())) << expected;
  EXPECT_EQ(simulation.steps_taken(), untouched.steps_taken()) << expected;
  for (int k = 0; k < 50; ++k) {
    simulation.step();
    untouched.step();
  }
  EXPECT_TRUE(bit_identical(simulation.state(), untouched.state())) << expected;
  const double error = simulation.diagnostics().reference_position_error;  // [m]; NaN without a reference
  const double untouched_error = untouched.diagnostics().reference_position_error;
  EXPECT_TRUE(error == untouched_error || (std::isnan(error) && std::isnan(untouched_error))) << expected;
}

TEST(Restart, RefusesByNameAndLeavesTheRunUntouched) {
  const Scene scene = load("default");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CartState target = teleport_target(0.05);
  target.x = nan;
  expect_refused(scene, target, "x must be finite");
  target = teleport_target(0.05);
  target.steering_angle = std::numeric_limits<double>::infinity();
  expect_refused(scene, target, "steering_angle must be finite");
  target = teleport_target(0.05);
  target.steering_rate = nan;
  expect_refused(scene, target, "steering_rate must be finite");
  target = teleport_target(1e300);
  expect_refused(scene, target, "");  // a time beyond the schedule's limits (named by step_schedule.h)

  // The paper's special case: M(χ) is singular at χ = kπ (docs/hard_cases.md §1).
  Scene paper = load("paper_special");
  paper.reference.kind = ReferenceSettings::Kind::kNone;
  target = paper.initial_state;
  target.time += 0.05;
  target.steering_angle = M_PI;
  expect_refused(paper, target, "singular steering angle");
  // Its analytic reference exists only on the analytic solution.
  target = load("paper_special").initial_state;
  target.forward_speed = 2.0;
  expect_refused(load("paper_special"), target, "paper_analytic");
}

TEST(Restart, RefusesStatesNoStepResolvesByName) {
  // Regression: ~set_state 1 1 0 0 1e200 0 was accepted and the next step killed the node;
  // x = 1e20 (the cart never moved again), heading and chi 1e300, 1e6 m/s were accepted too.
  const Scene scene = load("default");  // h = 10 ms, l = 1.05 m
  struct Case {
    const char* field;
    double CartState::*member;
    double value;
    const char* expected;
  };
  const Case cases[] = {
      {"forward_speed", &CartState::forward_speed, 1e200, "forward_speed 1e+200 m/s is beyond +-10.5 m/s"},
      {"forward_speed", &CartState::forward_speed, -1e6, "forward_speed -1e+06 m/s is beyond +-10.5 m/s"},
      {"steering_rate", &CartState::steering_rate, 1e6, "steering_rate 1e+06 rad/s is beyond +-10 rad/s"},
      {"x", &CartState::x, 1e20, "x 1e+20 m is beyond +-1e+06 m"},
      {"y", &CartState::y, -2e6, "y -2e+06 m is beyond +-1e+06 m"},
      {"heading", &CartState::heading, 1e300, "heading 1e+300 rad is beyond +-1e+06 rad"},
      {"steering_angle", &CartState::steering_angle, 1e300, "steering_angle 1e+300 rad is beyond +-1e+06 rad"},
  };
  for (const Case& c : cases) {
    CartState target = teleport_target(0.5);
    target.*c.member = c.value;
    expect_refused(scene, target, c.expected);
  }
  // Just inside the limits: accepted, and the run steps on (every member steps 3000 steps from the
  // corners of these limits on the shipped scenes, restart_state.h).
  Simulation simulation(scene);
  CartState target = teleport_target(0.0);
  target.steering_angle = M_PI - 1e-3;  // jackknifed
  target.forward_speed = 0.999 * kLargestStepFraction * 1.05 / 0.01;
  target.steering_rate = -0.999 * kLargestStepFraction / 0.01;
  ASSERT_NO_THROW(simulation.restart_from(target));
  for (int k = 0; k < 300; ++k) ASSERT_NO_THROW(simulation.step()) << "step " << k;
}

TEST(Restart, RefusesAStateWhoseTrialStepFailsAndKeepsTheRun) {
  // A command no step survives (the node clamps commands; the core does not): the teleport's trial
  // step fails and names why, and the run is as it was.
  const Scene scene = load("driven");
  Simulation simulation(scene);
  for (int k = 0; k < 20; ++k) simulation.step();
  simulation.set_steering_command(1e300);
  const CartState before = simulation.state();
  try {
    simulation.restart_from(teleport_target(before.time));
    ADD_FAILURE() << "accepted a restart whose first step fails";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("restart state: a trial step of h = 0.001 s from it fails: "),
              std::string::npos)
        << error.what();
  }
  EXPECT_TRUE(bit_identical(simulation.state(), before));
  EXPECT_EQ(simulation.steps_taken(), 20u);
}

}  // namespace
}  // namespace birkhoff_cart
