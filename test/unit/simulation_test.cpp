// Simulation: exact step times, reset, transactional failures, command inputs, diagnostics and
// the reference (computed only when the scene asks for one).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "birkhoff_cart/core/run/reference_solution.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {
namespace {

constexpr double kPaperReferenceTolerance = 1e-6;  // π1 relative [-], position [m], heading [rad] after 0.5 s, h = 1e-3 (measured ≤ 2.3e-7)
constexpr double kShadowTolerance = 1e-6;           // birkhoff2 at 1e-3 vs dopri5 at 1e-12 after 2 s [m], [rad] (measured 1.4e-7)
constexpr double kBalanceTolerance = 5e-5;          // energy [J] and p2 [N·m·s] balance residuals, 2 s driven (measured 5.7e-6 J)

Scene load(const std::string& name) {
  return load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/" + name + ".yaml");
}

bool bit_identical(const CartState& a, const CartState& b) { return std::memcmp(&a, &b, sizeof(CartState)) == 0; }

TEST(Simulation, TimeIsStartPlusStepCountTimesStepExactly) {
  Simulation simulation(load("paper_special"));  // t₀ = π/2: a sum of h's would drift off t₀ + n h
  const double t0 = simulation.scene().initial_state.time;
  const double h = simulation.step_size();
  double accumulated = t0;
  bool accumulation_differs = false;
  for (int n = 1; n <= 1000; ++n) {
    simulation.step();
    accumulated += h;
    accumulation_differs = accumulation_differs || accumulated != t0 + n * h;
    ASSERT_EQ(simulation.state().time, t0 + static_cast<double>(n) * h) << "step " << n;
  }
  EXPECT_TRUE(accumulation_differs) << "the test cannot tell t0 + n h from a running sum";
  EXPECT_EQ(simulation.statistics().steps, 1000u);
}

TEST(Simulation, AdvanceToStopsAtTheLastStepNotAfterTheTime) {
  Simulation simulation(load("free_coast"));
  simulation.advance_to(0.0104);  // h = 1e-3: 10 steps, the 11th would pass 0.0104 + h/2
  EXPECT_EQ(simulation.statistics().steps, 10u);
  simulation.advance_to(0.02);
  EXPECT_EQ(simulation.state().time, 20 * 1e-3);
}

TEST(Simulation, StepToLandsOnAnEndTimeOffTheGridAndEndsTheRun) {
  Simulation simulation(load("paper_special"));  // from π/2 to 3.0: the end is off the grid t₀ + n h
  const double end = simulation.end_time();
  while (simulation.state().time + simulation.step_size() <= end) simulation.step();
  EXPECT_THROW(simulation.step_to(end + simulation.step_size()), std::invalid_argument);  // more than h
  EXPECT_THROW(simulation.step_to(simulation.state().time), std::invalid_argument);       // zero length
  simulation.step_to(end);
  EXPECT_EQ(simulation.state().time, end);
  const Diagnostics diagnostics = simulation.diagnostics();
  EXPECT_LT(diagnostics.reference_arc_length_relative_error, kPaperReferenceTolerance * 10);
  EXPECT_THROW(simulation.step(), std::logic_error);  // the run is over until reset
  simulation.reset();
  simulation.step();
  EXPECT_EQ(simulation.state().time, simulation.scene().initial_state.time + simulation.step_size());
}

TEST(Simulation, PlanRunSetsTheRunsOwnEndOrNoneAndResetRestoresTheScenes) {
  Simulation simulation(load("paper_special"));  // t₀ = π/2, h = 1e-3
  const double t0 = simulation.scene().initial_state.time;
  const double h = simulation.step_size();
  const double scene_end = simulation.end_time();
  // A run of 0.0105 s from t₀: 10 whole steps, then the final one of 0.5 h onto t₀ + 0.0105.
  simulation.plan_run(0.0105);
  EXPECT_TRUE(simulation.has_end());
  EXPECT_EQ(simulation.end_time(), t0 + 0.0105);
  EXPECT_EQ(simulation.schedule().whole_steps, 10u);
  int steps = 0;
  while (!simulation.at_end()) {
    const double expected = simulation.next_step_time();
    simulation.step_on_schedule();
    EXPECT_EQ(simulation.state().time, steps < 10 ? t0 + static_cast<double>(steps + 1) * h : t0 + 0.0105);
    EXPECT_NEAR(simulation.state().time, expected, 1e-15);
    ++steps;
  }
  EXPECT_EQ(steps, 11);
  EXPECT_THROW(simulation.plan_run(1.0), std::logic_error);  // only at a run's start
  EXPECT_THROW(simulation.step_on_schedule(), std::logic_error);
  simulation.reset();
  EXPECT_EQ(simulation.end_time(), scene_end);  // reset plans the scene's run again
  // A duration the rule refuses changes nothing.
  EXPECT_THROW(simulation.plan_run(0.0), TimeLimitError);
  EXPECT_THROW(simulation.plan_run(-1.0), TimeLimitError);
  EXPECT_EQ(simulation.end_time(), scene_end);
  EXPECT_TRUE(simulation.has_end());
  // Without end: whole steps for ever, never at_end (free_coast: 6 s, h = 1 ms).
  Simulation endless(load("free_coast"));
  endless.plan_run(std::numeric_limits<double>::infinity());
  EXPECT_FALSE(endless.has_end());
  EXPECT_EQ(endless.end_time(), std::numeric_limits<double>::infinity());
  for (int n = 1; n <= 6500; ++n) endless.step_on_schedule();  // beyond the scene's 6 s
  EXPECT_FALSE(endless.at_end());
  EXPECT_EQ(endless.state().time, 6500.0 * 1e-3);
}

TEST(Simulation, ResetRestoresEverythingAndTheRunRepeatsBitForBit) {
  Scene scene = load("driven");
  scene.integrator.name = "dopri5";  // also carries an adaptive step-size guess between steps
  Simulation simulation(scene);
  const CartState initial = simulation.state();
  const Diagnostics initial_diagnostics = simulation.diagnostics();
  auto drive = [&simulation]() {
    simulation.set_drive_command(20.0);
    simulation.set_steering_command(0.8);
    for (int k = 0; k < 300; ++k) simulation.step();
    simulation.set_steering_command(-0.5);
    for (int k = 0; k < 300; ++k) simulation.step();
    return simulation.state();
  };
  const CartState first = drive();
  const StepStatistics first_statistics = simulation.statistics();
  ASSERT_FALSE(bit_identical(first, initial));

  simulation.reset();
  EXPECT_TRUE(bit_identical(simulation.state(), initial));
  EXPECT_EQ(simulation.statistics().steps, 0u);
  EXPECT_EQ(simulation.statistics().rhs_evaluations, 0u);
  EXPECT_EQ(simulation.steering_command(), 0.0);
  EXPECT_EQ(simulation.drive_command(), 0.0);
  EXPECT_EQ(simulation.diagnostics().energy, initial_diagnostics.energy);

  const CartState second = drive();
  EXPECT_TRUE(bit_identical(first, second));
  EXPECT_EQ(simulation.statistics().rhs_evaluations, first_statistics.rhs_evaluations);
}

TEST(Simulation, FailingStepThrowsAndLeavesStateUntouched) {
  // The paper's special case started on χ = 0, where M(χ) = [[0, sin χ], [sin χ, 1]] is singular.
  Scene scene = load("paper_special");
  scene.reference.kind = ReferenceSettings::Kind::kNone;
  scene.initial_state.steering_angle = 0.0;
  for (const std::string name : {"birkhoff2", "rk4"}) {
    scene.integrator.name = name;
    Simulation simulation(scene);
    const CartState before = simulation.state();
    EXPECT_THROW(simulation.step(), StepError) << name;
    EXPECT_TRUE(bit_identical(simulation.state(), before)) << name;
    EXPECT_EQ(simulation.statistics().steps, 0u) << name;
  }
}

TEST(Simulation, StepsOntoChiEqualsPiFailCleanlyBeforeThePole) {
  // Stepping the paper's case across χ = π (t = π), where the analytic ω1 = 1/sin t blows up: the
  // singular-steering guard refuses the step onto the pole (pinned: it must throw, before t = π,
  // with the state kept and every state before it finite).
  Scene scene = load("paper_special");
  scene.duration = 2.0;  // past t = π
  Simulation simulation(scene);
  bool failed = false;
  while (simulation.state().time < M_PI + 0.1 && !failed) {
    const CartState before = simulation.state();
    try {
      simulation.step();
    } catch (const StepError& error) {
      failed = true;
      EXPECT_TRUE(bit_identical(simulation.state(), before));
      EXPECT_NE(std::string(error.what()).find("t = "), std::string::npos) << error.what();
      std::printf("paper case: step failed near chi = pi: %s\n", error.what());
    }
    ASSERT_TRUE(std::isfinite(simulation.state().forward_speed));
  }
  EXPECT_TRUE(failed) << "stepped across chi = pi to t = " << simulation.state().time << " s";
  EXPECT_LT(simulation.state().time, M_PI);
  EXPECT_GT(simulation.state().time, M_PI - 2.0 * simulation.step_size());
}

TEST(Simulation, CommandsOnlyForCommandSourcedEffects) {
  Simulation free_cart(load("free_coast"));
  EXPECT_FALSE(free_cart.accepts_steering_command());
  EXPECT_FALSE(free_cart.accepts_drive_command());
  EXPECT_THROW(free_cart.set_steering_command(1.0), std::logic_error);
  EXPECT_THROW(free_cart.set_drive_command(1.0), std::logic_error);

  Simulation profiled(load("sine_steer_torque"));  // its steering torque follows a profile
  EXPECT_FALSE(profiled.accepts_steering_command());
  EXPECT_THROW(profiled.set_steering_command(1.0), std::logic_error);

  Simulation driven(load("driven"));
  ASSERT_TRUE(driven.accepts_steering_command());
  ASSERT_TRUE(driven.accepts_drive_command());
  driven.set_steering_command(0.5);
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(driven.set_steering_command(bad), std::invalid_argument);
    EXPECT_THROW(driven.set_drive_command(bad), std::invalid_argument);
  }
  EXPECT_EQ(driven.steering_command(), 0.5);  // the torque in force is kept
  EXPECT_EQ(driven.drive_command(), 0.0);

  // The command acts: a steering torque turns the front axle, none leaves χ at 0.
  for (int k = 0; k < 200; ++k) driven.step();
  Simulation idle(load("driven"));
  for (int k = 0; k < 200; ++k) idle.step();
  EXPECT_GT(driven.state().steering_angle, 1e-3);
  EXPECT_EQ(idle.state().steering_angle, 0.0);
}

TEST(Simulation, DiagnosticsBalanceEnergyAndSteeringMomentum) {
  Simulation simulation(load("drive_rr_drag"));
  for (int k = 0; k < 2000; ++k) simulation.step();
  const Diagnostics diagnostics = simulation.diagnostics();
  std::printf("drive_rr_drag, birkhoff2, 2 s: T* = %.6f J, energy residual %.3e J, p2 residual %.3e N·m·s, "
              "constraints %.3e m/s\n",
              diagnostics.energy, diagnostics.energy_balance_residual, diagnostics.p2_balance_residual,
              diagnostics.max_constraint_residual);
  EXPECT_GT(simulation.state().applied_work, 1.0);  // the loads did work: the balance is not trivial
  EXPECT_LE(std::abs(diagnostics.energy_balance_residual), kBalanceTolerance);
  EXPECT_LE(std::abs(diagnostics.p2_balance_residual), kBalanceTolerance);
  EXPECT_LE(diagnostics.max_constraint_residual, 1e-12);
  EXPECT_FALSE(diagnostics.has_reference);
  EXPECT_TRUE(std::isnan(diagnostics.reference_position_error));
  EXPECT_TRUE(std::isnan(diagnostics.reference_arc_length_relative_error));
}

TEST(Simulation, PaperAnalyticReferenceOnlyWhenAsked) {
  Scene scene = load("paper_special");
  Simulation simulation(scene);
  for (int k = 0; k < 500; ++k) simulation.step();
  const Diagnostics diagnostics = simulation.diagnostics();
  ASSERT_TRUE(diagnostics.has_reference);
  std::printf("paper case at t = %.4f s: pi1 relative error %.3e, position error %.3e m, heading error %.3e rad\n",
              simulation.state().time, diagnostics.reference_arc_length_relative_error,
              diagnostics.reference_position_error, diagnostics.reference_heading_error);
  EXPECT_LE(diagnostics.reference_arc_length_relative_error, kPaperReferenceTolerance);
  EXPECT_LE(diagnostics.reference_position_error, kPaperReferenceTolerance);
  EXPECT_LE(diagnostics.reference_heading_error, kPaperReferenceTolerance);
  EXPECT_GT(diagnostics.reference_arc_length_relative_error, 0.0);  // a real comparison, not a copy

  scene.reference.kind = ReferenceSettings::Kind::kNone;
  Simulation unreferenced(scene);
  unreferenced.step();
  EXPECT_FALSE(unreferenced.diagnostics().has_reference);
  EXPECT_TRUE(std::isnan(unreferenced.diagnostics().reference_heading_error));
}

TEST(Simulation, PaperAnalyticSolutionSolvesTheReducedEquations) {
  // The closed form used by the reference, differentiated by central differences, against the
  // kinematics ẋ = ω1 cos(θ+χ), ẏ = ω1 sin(θ+χ), θ̇ = ω1 sin χ / l, π̇1 = ω1 (docs eq. (2.3)), l = 1.
  PaperAnalyticSolution solution;
  solution.initial = load("paper_special").initial_state;
  solution.initial.heading = 0.3;
  solution.initial.x = -0.2;
  constexpr double kDelta = 1e-5;  // [s]
  for (double t : {1.7, 2.2, 2.9}) {
    const CartState now = solution.at(t), ahead = solution.at(t + kDelta), behind = solution.at(t - kDelta);
    const double front = now.heading + now.steering_angle;
    EXPECT_NEAR((ahead.x - behind.x) / (2 * kDelta), now.forward_speed * std::cos(front), 1e-8) << t;
    EXPECT_NEAR((ahead.y - behind.y) / (2 * kDelta), now.forward_speed * std::sin(front), 1e-8) << t;
    EXPECT_NEAR((ahead.heading - behind.heading) / (2 * kDelta), now.forward_speed * std::sin(now.steering_angle),
                1e-8)
        << t;
    EXPECT_NEAR((ahead.arc_length - behind.arc_length) / (2 * kDelta), now.forward_speed, 1e-8) << t;
  }
  EXPECT_TRUE(PaperAnalyticSolution::matches(solution.initial));
  CartState off = solution.initial;
  off.steering_rate = 1.1;
  EXPECT_FALSE(PaperAnalyticSolution::matches(off));
}

TEST(Simulation, PaperAnalyticReferenceRefusesAStateOffTheSolution) {
  Scene scene = load("paper_special");
  scene.initial_state.forward_speed = 2.0;
  EXPECT_THROW(Simulation{scene}, std::invalid_argument);
}

TEST(Simulation, ShadowRunReferenceRunsInLockstep) {
  Scene scene = load("default");
  ASSERT_EQ(scene.reference.kind, ReferenceSettings::Kind::kShadowRun);
  Simulation simulation(scene);
  EXPECT_EQ(simulation.diagnostics().reference_position_error, 0.0);  // same initial state
  for (int k = 0; k < 2000; ++k) simulation.step();
  const Diagnostics diagnostics = simulation.diagnostics();
  ASSERT_TRUE(diagnostics.has_reference);
  std::printf("default scene, birkhoff2 vs dopri5 shadow at t = %.3f s: position %.3e m, heading %.3e rad, "
              "pi1 relative %.3e\n",
              simulation.state().time, diagnostics.reference_position_error, diagnostics.reference_heading_error,
              diagnostics.reference_arc_length_relative_error);
  EXPECT_GT(diagnostics.reference_position_error, 0.0);
  EXPECT_LE(diagnostics.reference_position_error, kShadowTolerance);
  EXPECT_LE(diagnostics.reference_heading_error, kShadowTolerance);
  simulation.reset();
  EXPECT_EQ(simulation.diagnostics().reference_position_error, 0.0);
}

TEST(Simulation, RejectsUnusableSettings) {
  Scene scene = load("free_coast");
  scene.integrator.name = "euler";
  EXPECT_THROW(Simulation{scene}, std::invalid_argument);
  scene = load("free_coast");
  scene.integrator.step_size = 0.0;
  EXPECT_THROW(Simulation{scene}, std::invalid_argument);
  scene = load("free_coast");
  scene.duration = -1.0;
  EXPECT_THROW(Simulation{scene}, std::invalid_argument);
}

}  // namespace
}  // namespace birkhoff_cart
