// The two core pieces under the Python module's solve() and its events: locate_crossing
// (crossing.h) finds a root inside a bracket to the time asked, in few evaluations, also where
// plain regula falsi stalls; and Simulation::newest_step_state reads a member's dense output on its
// newest own step without moving the run: exactly the grid point at the step's end, the state the
// run itself hands out at an instant inside the step, nothing outside it, and nothing for a member
// at fixed steps; and Simulation::state_by_one_step, a fixed-step member's step beside the run.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/crossing.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::scene_path;

TEST(LocateCrossing, FindsASmoothRootToTheToleranceAsked) {
  const auto g = [](double t) { return std::cos(t) - 0.3; };  // root acos(0.3) in [0, 2]
  const double exact = std::acos(0.3);
  const Crossing crossing = locate_crossing(g, 0.0, g(0.0), 2.0, g(2.0), 1e-13);
  EXPECT_NEAR(crossing.time, exact, 1e-13);
  EXPECT_LE(crossing.bracket_width, 1e-13);
  EXPECT_LE(crossing.evaluations, 20u);
}

TEST(LocateCrossing, ShrinksTheBracketWherePlainRegulaFalsiStalls) {
  // Convex on the bracket: regula falsi keeps one end for ever; the Illinois halving and the
  // bisection safeguard still close in on the root 0.5^(1/8).
  const auto g = [](double t) { return std::pow(t, 8) - 0.5; };
  const double exact = std::pow(0.5, 1.0 / 8.0);
  const Crossing crossing = locate_crossing(g, 0.0, g(0.0), 1.0, g(1.0), 1e-14);
  EXPECT_NEAR(crossing.time, exact, 1e-14);
  EXPECT_LE(crossing.bracket_width, 1e-14);
  EXPECT_LE(crossing.evaluations, 60u);
}

TEST(LocateCrossing, AZeroAtAnEndIsThatEnd) {
  const auto g = [](double t) { return t - 1.0; };
  EXPECT_EQ(locate_crossing(g, 1.0, 0.0, 2.0, 1.0, 1e-12).time, 1.0);
  EXPECT_EQ(locate_crossing(g, 0.0, -1.0, 1.0, 0.0, 1e-12).time, 1.0);
  EXPECT_EQ(locate_crossing(g, 0.0, -1.0, 1.0, 0.0, 1e-12).evaluations, 0u);
}

/// sine_steer_torque for 2 s under `member` with its own steps, called for the end only.
Scene own_steps(const std::string& member) {
  Scene scene = load_scene(scene_path("sine_steer_torque"));
  scene.duration = 2.0;
  scene.reference = ReferenceSettings{};
  scene.integrator.name = member;
  scene.integrator.step_size = 0.05;
  if (member == "dopri5") {
    scene.integrator.tolerance = 1e-10;
  } else {
    scene.integrator.step_control = StepControl::kAdaptive;
    scene.integrator.position_tolerance = 1e-9;
  }
  return scene;
}

class NewestStepState : public ::testing::TestWithParam<std::string> {};

TEST_P(NewestStepState, IsTheGridPointAtTheStepsEndAndTheRunsOwnOutputInside) {
  const Scene scene = own_steps(GetParam());
  Simulation simulation(scene);
  Simulation outputs(scene);  // the same run, asked for the instants newest_step_state was asked for
  std::vector<double> middles;
  std::vector<CartState> read;
  StepStatistics reading;  // the work of the readings, apart from the run's
  double previous = scene.initial_state.time;
  int outside_refused = 0;
  simulation.observe_grid([&](const CartState& grid) {
    CartState at;
    if (grid.time <= simulation.end_time()) {
      ASSERT_TRUE(simulation.newest_step_state(grid.time, at));
      EXPECT_EQ(at.x, grid.x);
      EXPECT_EQ(at.y, grid.y);
      EXPECT_EQ(at.forward_speed, grid.forward_speed);
    }
    const double middle = previous + 0.37 * (std::min(grid.time, simulation.end_time()) - previous);
    ASSERT_TRUE(simulation.newest_step_state(middle, at, &reading));
    EXPECT_EQ(at.time, middle);
    middles.push_back(middle);
    read.push_back(at);
    outside_refused += simulation.newest_step_state(previous - 1e-3, at) ? 0 : 1;
    outside_refused += simulation.newest_step_state(grid.time + 1e-3, at) ? 0 : 1;
    previous = grid.time;
  });
  // Called for t0 + h first, as a run of steps h is (dopri5 takes the first call's length as its
  // first trial step), then for the end.
  const double first = scene.initial_state.time + scene.integrator.step_size;  // [s]
  simulation.advance_output_to(first);
  simulation.advance_output_to(simulation.end_time());
  outputs.advance_output_to(first);
  ASSERT_GT(middles.size(), 5u);
  EXPECT_EQ(outside_refused, static_cast<int>(2 * middles.size()));
  // The run unmoved by the reading: the same end as a run that read nothing.
  Simulation untouched(scene);
  untouched.advance_output_to(first);
  untouched.advance_output_to(untouched.end_time());
  EXPECT_EQ(simulation.state().x, untouched.state().x);
  EXPECT_EQ(simulation.state().y, untouched.state().y);
  EXPECT_EQ(simulation.state().heading, untouched.state().heading);
  // Its counters too: what the readings evaluate (the side steps where the interpolant's estimate
  // exceeds the tolerance, and the rates of held points the Hermite interpolant lacks, which the run's
  // next output then takes as known) is counted apart: the run's own count is the untouched run's,
  // less at most those held-point rates the readings paid for.
  EXPECT_LE(simulation.statistics().rhs_evaluations, untouched.statistics().rhs_evaluations);
  EXPECT_LE(untouched.statistics().rhs_evaluations - simulation.statistics().rhs_evaluations,
            reading.rhs_evaluations);
  // Inside a step: what the run hands out at that instant (its dense output or its side step), bit
  // for bit under the step control (a row depends on the grid and its instant only, whatever was
  // read or output before in the step), to the last digits for dopri5.
  double worst = 0.0;  // [m]
  for (std::size_t k = 0; k < middles.size(); ++k) {
    if (middles[k] <= outputs.state().time) continue;
    outputs.advance_output_to(middles[k]);
    worst = std::max(worst, std::hypot(outputs.state().x - read[k].x, outputs.state().y - read[k].y));
    if (GetParam() != "dopri5") {
      EXPECT_EQ(outputs.state().x, read[k].x) << middles[k];
      EXPECT_EQ(outputs.state().forward_speed, read[k].forward_speed) << middles[k];
      EXPECT_EQ(outputs.state().steering_rate, read[k].steering_rate) << middles[k];
    }
  }
  EXPECT_LE(worst, 1e-12) << GetParam();
  // Some readings here are side steps (at 1e-9 m), so the bit-for-bit check covers them; dopri5's
  // readings evaluate nothing.
  if (GetParam() == "dopri5") {
    EXPECT_EQ(reading.rhs_evaluations, 0u);
  } else {
    EXPECT_GT(reading.rhs_evaluations, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(OwnSteps, NewestStepState, ::testing::Values("birkhoff_gauss6", "dopri5"));

TEST(NewestStepStateAtFixedSteps, IsNone) {
  Scene scene = load_scene(scene_path("sine_steer_torque"));
  scene.duration = 0.1;
  scene.integrator.name = "birkhoff_gauss4";
  Simulation simulation(scene);
  simulation.step();
  CartState at;
  EXPECT_FALSE(simulation.newest_step_state(simulation.state().time - 0.5 * scene.integrator.step_size, at));
}

TEST(StateByOneStep, IsTheMembersStepBesideTheRunWhichItLeavesAsItWas) {
  for (const std::string member : {"birkhoff_gauss8", "rk4", "birkhoff2"}) {
    Scene scene = load_scene(scene_path("sine_steer_torque"));
    scene.duration = 1.0;
    scene.reference = ReferenceSettings{};
    scene.integrator.name = member;
    scene.integrator.step_size = 0.01;
    Simulation simulation(scene);
    Simulation untouched(scene);
    for (int k = 0; k < 40; ++k) {
      const CartState before = simulation.state();
      const CartState middle = simulation.state_by_one_step(before, before.time + 0.004);
      const CartState whole = simulation.state_by_one_step(before, before.time + 0.01);
      EXPECT_EQ(middle.time, before.time + 0.004);
      EXPECT_GT(std::hypot(middle.x - before.x, middle.y - before.y), 0.0);
      simulation.step();
      untouched.step();
      // One step of h from the run's state is the run's step, to round-off (a collocation member
      // starts it afresh from p = M(χ) ω instead of its carried point).
      EXPECT_NEAR(whole.x, simulation.state().x, 1e-12) << member;
      EXPECT_NEAR(whole.forward_speed, simulation.state().forward_speed, 1e-12) << member;
      EXPECT_EQ(simulation.state().x, untouched.state().x) << member;  // the run unmoved
    }
    EXPECT_EQ(simulation.statistics().rhs_evaluations, untouched.statistics().rhs_evaluations);
    EXPECT_THROW(simulation.state_by_one_step(simulation.state(), simulation.state().time + 0.02),
                 std::invalid_argument);
    EXPECT_THROW(simulation.state_by_one_step(simulation.state(), simulation.state().time), std::invalid_argument);
  }
  Simulation own(own_steps("birkhoff_gauss6"));
  EXPECT_THROW(own.state_by_one_step(own.state(), own.state().time + 0.01), std::logic_error);
  Simulation actuated(load_scene(scene_path("steering_actuator")));
  EXPECT_THROW(actuated.state_by_one_step(actuated.state(), actuated.state().time + 0.001), std::logic_error);
}

}  // namespace
}  // namespace birkhoff_cart
