// The steering and drive actuators and the steering end stops (docs/actuators.md): the closed forms
// (A1)–(A5) of lag, rate limit, dead time, saturation and dead band; the cart's order of convergence
// with an actuator on (sub-steps end at its kinks); end stops as events (S1)–(S3): the axle stops at
// ±χ_s and stays there, p1 kept through the impact, the balances still close, release and bounce.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <limits>
#include <memory>
#include <string>

#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"
#include "birkhoff_cart/core/physics/actuators/torque_actuator.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/run/run_summary.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "generated_docs.h"

namespace birkhoff_cart {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

Scene driven_scene() {
  return load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/driven.yaml");
}

TorqueActuatorSettings lag(double time_constant) {
  TorqueActuatorSettings settings;
  settings.time_constant = time_constant;
  return settings;
}

TEST(TorqueActuator, FirstOrderLagFollowsItsClosedForm) {
  TorqueActuator actuator(lag(0.1), 0.0, 0.0);
  actuator.command(0.0, 2.0);
  for (double t : {0.0, 0.01, 0.1, 0.37, 1.0}) {
    EXPECT_NEAR(actuator.output_at(t), 2.0 * (1.0 - std::exp(-t / 0.1)), 1e-15) << t;  // (A2)
  }
  EXPECT_EQ(actuator.next_kink_after(0.0), kInfinity);  // a lag from its input's instant: smooth
  // Committing in 100 steps of 10 ms gives the same response as reading it from the start (semigroup).
  TorqueActuator stepped = actuator;
  for (int n = 1; n <= 100; ++n) stepped.advance_to(0.01 * n);
  EXPECT_NEAR(stepped.applied(), actuator.output_at(1.0), 4e-16);
  EXPECT_EQ(stepped.target(), 2.0);
}

TEST(TorqueActuator, RateLimitRampsThenLags) {
  TorqueActuatorSettings settings = lag(0.1);
  settings.rate_limit = 5.0;  // R [N·m/s]; the lag's initial rate 2/0.1 = 20 exceeds it
  TorqueActuator actuator(settings, 0.0, 0.0);
  actuator.command(0.0, 2.0);
  const double ramp_end = (2.0 - 5.0 * 0.1) / 5.0;  // (A4): |u − τ| = R T after 0.3 s
  EXPECT_NEAR(actuator.next_kink_after(0.0), ramp_end, 1e-15);
  EXPECT_NEAR(actuator.output_at(0.2), 1.0, 1e-15);  // R t
  EXPECT_NEAR(actuator.output_at(ramp_end), 1.5, 1e-15);
  EXPECT_NEAR(actuator.output_at(0.5), 2.0 - 0.5 * std::exp(-0.2 / 0.1), 1e-15);
  // The rate never exceeds R (finite differences over the whole response).
  double largest_rate = 0.0;
  for (int n = 0; n < 1000; ++n) {
    const double t = 1e-3 * n;
    largest_rate = std::max(largest_rate, (actuator.output_at(t + 1e-3) - actuator.output_at(t)) / 1e-3);
  }
  EXPECT_LE(largest_rate, 5.0 * (1.0 + 1e-9));
  EXPECT_GT(largest_rate, 5.0 * (1.0 - 1e-9));
  // Without lag: a pure ramp onto the target.
  TorqueActuatorSettings ramp_only;
  ramp_only.rate_limit = 4.0;
  TorqueActuator ramp(ramp_only, 0.0, 1.0);
  ramp.command(0.0, -1.0);
  EXPECT_NEAR(ramp.output_at(0.25), 0.0, 1e-15);
  EXPECT_EQ(ramp.output_at(0.6), -1.0);
  EXPECT_NEAR(ramp.next_kink_after(0.0), 0.5, 1e-15);
}

TEST(TorqueActuator, DeadTimeDelaysTheInput) {
  TorqueActuatorSettings settings = lag(0.1);
  settings.dead_time = 0.05;
  TorqueActuator actuator(settings, 0.0, 0.0);
  actuator.command(0.2, 1.0);
  EXPECT_EQ(actuator.pending_inputs(), 1u);
  EXPECT_NEAR(actuator.next_kink_after(0.0), 0.25, 1e-15);  // (A5)
  EXPECT_EQ(actuator.output_at(0.25), 0.0);
  EXPECT_NEAR(actuator.output_at(0.35), 1.0 - std::exp(-1.0), 1e-15);
  actuator.advance_to(0.3);
  EXPECT_EQ(actuator.pending_inputs(), 0u);
  EXPECT_NEAR(actuator.applied(), 1.0 - std::exp(-0.5), 1e-15);
  // An input out of order is refused by name and changes nothing.
  EXPECT_THROW(actuator.command(0.1, 3.0), std::invalid_argument);
  EXPECT_THROW(actuator.command(0.4, std::nan("")), std::invalid_argument);
  EXPECT_EQ(actuator.latest_input(), 1.0);
}

TEST(TorqueActuator, DeadBandAndSaturationShapeTheInput) {
  TorqueActuatorSettings settings;
  settings.dead_band = 0.1;
  settings.torque_limit = 2.0;
  const TorqueActuator actuator(settings, 0.0, 0.0);
  EXPECT_EQ(actuator.shaped(0.05), 0.0);  // (A1)
  EXPECT_EQ(actuator.shaped(-0.1), 0.0);
  EXPECT_NEAR(actuator.shaped(-0.5), -0.4, 1e-15);
  EXPECT_EQ(actuator.shaped(3.0), 2.0);
  EXPECT_EQ(actuator.shaped(-30.0), -2.0);
}

TEST(TorqueActuator, SettingsOutOfRangeAreRefusedByName) {
  auto refused = [](TorqueActuatorSettings settings, const std::string& key) {
    try {
      validate_torque_actuator("steering_actuator", settings);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what()).find("steering_actuator." + key) != std::string::npos;
    }
    return false;
  };
  TorqueActuatorSettings settings;
  settings.time_constant = -1.0;
  EXPECT_TRUE(refused(settings, "time_constant"));
  settings = {};
  settings.dead_time = std::nan("");
  EXPECT_TRUE(refused(settings, "dead_time"));
  settings = {};
  settings.rate_limit = 0.0;
  EXPECT_TRUE(refused(settings, "rate_limit"));
  settings = {};
  settings.torque_limit = -2.0;
  EXPECT_TRUE(refused(settings, "torque_limit"));
  settings = {};
  settings.dead_band = kInfinity;
  EXPECT_TRUE(refused(settings, "dead_band"));
}

/// The driven scene with a steering actuator, a constant 1.5 N·m command from t = 0 and a step of the
/// drive command, integrated with `integrator` at h over 4 s; returns the final state.
CartState actuated_run(const std::string& integrator, double step_size) {
  Scene scene = driven_scene();
  scene.integrator.name = integrator;
  scene.integrator.step_size = step_size;
  scene.duration = 4.0;
  TorqueActuatorSettings steering = lag(0.15);
  steering.dead_time = 0.0133;  // not a multiple of h: a kink inside a step
  steering.rate_limit = 4.0;
  scene.actuators.steering = steering;
  TorqueActuatorSettings drive = lag(0.3);
  drive.torque_limit = 5.0;
  scene.actuators.drive = drive;
  Simulation simulation(scene);
  simulation.set_steering_command(1.5);
  simulation.set_drive_command(8.0);
  while (simulation.state().time < 1.0 - 1e-9) simulation.step();
  simulation.set_steering_command(-1.0);  // a second input mid-run, its dead time ending inside a step
  while (!simulation.at_end()) simulation.step_on_schedule();
  return simulation.state();
}

double position_gap(const CartState& a, const CartState& b) { return std::hypot(a.x - b.x, a.y - b.y); }

TEST(ActuatedCart, KeepsTheOrderOfTheMethod) {
  // The actuator's torque is exact at every stage and the sub-steps end at its kinks, so the cart
  // converges with the method's order: gauss4 at h = 0.04, 0.02, 0.01 against gauss8 at 0.0025.
  const CartState reference = actuated_run("birkhoff_gauss8", 0.0025);
  const double coarse = position_gap(actuated_run("birkhoff_gauss4", 0.04), reference);
  const double middle = position_gap(actuated_run("birkhoff_gauss4", 0.02), reference);
  const double fine = position_gap(actuated_run("birkhoff_gauss4", 0.01), reference);
  const double order_coarse = std::log2(coarse / middle);
  const double order_fine = std::log2(middle / fine);
  std::printf("gauss4 position errors at h = 0.04, 0.02, 0.01: %.3e %.3e %.3e m (orders %.2f, %.2f)\n", coarse,
              middle, fine, order_coarse, order_fine);
  RecordProperty("errors", std::to_string(coarse) + " " + std::to_string(middle) + " " + std::to_string(fine));
  EXPECT_GT(order_coarse, 3.6) << coarse << " " << middle;
  EXPECT_GT(order_fine, 3.6) << middle << " " << fine;
  EXPECT_GT(coarse, 1e-9);  // the errors are above round-off, so the orders mean something
  // docs/actuators.md §2 quotes the errors (two digits) and the orders (to 0.01).
  const std::string page = "docs/actuators.md";
  const std::string row = "| position error after 4 s [m] | ";
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, row, 0, coarse, 0.06));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, row, 1, middle, 0.06));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, row, 2, fine, 0.06));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, "Observed orders ", 0, order_coarse, 0.0015));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, "Observed orders ", 1, order_fine, 0.0015));
}

TEST(ActuatedCart, TheCartReceivesTheActuatorsTorque) {
  Scene scene = driven_scene();
  scene.integrator.name = "birkhoff_gauss6";
  scene.integrator.step_size = 0.01;
  TorqueActuatorSettings steering = lag(0.2);
  steering.torque_limit = 1.0;
  scene.actuators.steering = steering;
  Simulation simulation(scene);
  simulation.set_steering_command(3.0);  // saturated to 1 N·m, then lagged
  for (int n = 0; n < 50; ++n) simulation.step();
  const Simulation::ActuatorStatus status = simulation.actuator_status();
  EXPECT_TRUE(status.steering_actuator);
  EXPECT_FALSE(status.drive_actuator);
  EXPECT_EQ(status.steering_input, 3.0);
  EXPECT_NEAR(status.steering_applied, 1.0 - std::exp(-0.5 / 0.2), 1e-12);
  // The p2 balance (eq. (3.8)) closes with the actuator's torque as Q2.
  EXPECT_LT(std::abs(simulation.diagnostics().p2_balance_residual), 1e-12);
  // reset() puts the actuator back at rest with the scene's initial command.
  simulation.reset();
  EXPECT_EQ(simulation.actuator_status().steering_applied, 0.0);
}

/// The driven scene rolling at 2 m/s with stops at ±0.5 rad and a constant steering command.
Simulation* stopped_cart(double restitution, double steering_torque) {
  Scene scene = driven_scene();
  scene.integrator.name = "birkhoff_gauss4";
  scene.integrator.step_size = 0.01;
  scene.duration = 20.0;
  SteeringEndStopSettings stops;
  stops.angle = 0.5;
  stops.restitution = restitution;
  scene.actuators.end_stops = stops;
  auto* simulation = new Simulation(scene);
  simulation->set_steering_command(steering_torque);
  return simulation;
}

TEST(EndStops, TheAxleStopsAtTheStopAndStaysThere) {
  std::unique_ptr<Simulation> simulation(stopped_cart(0.0, 3.0));
  double largest_angle = 0.0;
  for (int n = 0; n < 500; ++n) {
    simulation->step();
    largest_angle = std::max(largest_angle, simulation->state().steering_angle);
  }
  ASSERT_EQ(simulation->actuator_status().end_stop_contact, 1) << "the 3 N·m command never brought the axle to the stop";
  EXPECT_LE(largest_angle, 0.5 + 1e-12);  // χ reached 4.95 rad without stops
  EXPECT_NEAR(simulation->state().steering_angle, 0.5, 1e-12);
  EXPECT_LT(std::abs(simulation->state().steering_rate), 1e-12);
  EXPECT_EQ(simulation->actuator_status().end_stop_events, 1u);
  // The balances close through the impact (its energy loss and impulse are booked, (S1)).
  const Diagnostics diagnostics = simulation->diagnostics();
  EXPECT_LT(std::abs(diagnostics.energy_balance_residual), 1e-9);
  EXPECT_LT(std::abs(diagnostics.p2_balance_residual), 1e-9);
}

TEST(EndStops, AnImpactKeepsP1AndLosesEnergy) {
  const Scene scene = driven_scene();
  const CartModel model(scene.cart);
  SteeringEndStopSettings settings;
  settings.angle = 0.5;
  for (double restitution : {0.0, 0.5, 1.0}) {
    settings.restitution = restitution;
    const SteeringEndStops stops(settings, model);
    CartState state = scene.initial_state;
    state.steering_angle = 0.5 + 1e-14;
    state.forward_speed = 2.0;
    state.steering_rate = 0.8;
    const double p1_before = model.momentum(state.steering_angle, Eigen::Vector2d(2.0, 0.8))(0);
    const double energy_before = model.energy(state);
    EXPECT_EQ(stops.impact(state), SteeringEndStops::Contact::kUpper);
    EXPECT_EQ(state.steering_angle, 0.5);
    EXPECT_NEAR(state.steering_rate, -restitution * 0.8, 1e-15);
    const double p1_after = model.momentum(0.5, Eigen::Vector2d(state.forward_speed, state.steering_rate))(0);
    EXPECT_NEAR(p1_after, p1_before, 1e-12 * std::abs(p1_before));  // (S1)
    const double energy_after = model.energy(state);
    if (restitution < 1.0) {
      EXPECT_LT(energy_after, energy_before);
    }
    EXPECT_NEAR(state.applied_work, energy_after - energy_before, 1e-15);  // booked for eq. (3.7)
  }
}

TEST(EndStops, TheAxleLeavesTheStopWhenTheTorqueReverses) {
  std::unique_ptr<Simulation> simulation(stopped_cart(0.0, 3.0));
  for (int n = 0; n < 300; ++n) simulation->step();
  ASSERT_EQ(simulation->actuator_status().end_stop_contact, 1);
  simulation->set_steering_command(-3.0);
  simulation->step();
  EXPECT_EQ(simulation->actuator_status().end_stop_contact, 0);
  EXPECT_LT(simulation->state().steering_angle, 0.5);
  double smallest_angle = 0.0;
  for (int n = 0; n < 600; ++n) {
    simulation->step();
    smallest_angle = std::min(smallest_angle, simulation->state().steering_angle);
  }
  EXPECT_GE(smallest_angle, -0.5 - 1e-12);
  EXPECT_EQ(simulation->actuator_status().end_stop_contact, -1);
}

TEST(EndStops, ABounceReversesTheRateByTheRestitution) {
  std::unique_ptr<Simulation> simulation(stopped_cart(0.5, 3.0));
  for (int n = 0; n < 500; ++n) {
    const double rate_before = simulation->state().steering_rate;
    const std::uint64_t events = simulation->actuator_status().end_stop_events;
    simulation->step();
    if (simulation->actuator_status().end_stop_events > events) {
      EXPECT_LT(simulation->state().steering_rate, 0.0);  // moving away from the stop after the bounce
      EXPECT_GT(rate_before, 0.0);
      break;
    }
  }
  EXPECT_EQ(simulation->actuator_status().end_stop_events, 1u);
  double largest_angle = 0.0;
  for (int n = 0; n < 1000; ++n) {
    simulation->step();
    largest_angle = std::max(largest_angle, std::abs(simulation->state().steering_angle));
  }
  EXPECT_LE(largest_angle, 0.5 + 1e-12);
  // The bounces die out (their flights shrink by e each) and the axle comes to rest on the stop.
  EXPECT_GT(simulation->actuator_status().end_stop_events, 2u);
  EXPECT_EQ(simulation->actuator_status().end_stop_contact, 1);
  EXPECT_LT(std::abs(simulation->diagnostics().energy_balance_residual), 1e-9);
}

TEST(ActuatedCart, TheReversibleStepControlIsRefusedByName) {
  Scene scene = driven_scene();
  scene.integrator.name = "birkhoff_gauss4";
  scene.integrator.step_control = StepControl::kReversible;
  scene.integrator.position_tolerance = 1e-6;
  scene.actuators.steering = lag(0.1);
  try {
    Simulation simulation(scene);
    ADD_FAILURE() << "the reversible control was accepted with an actuator";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("integrator.step_control"), std::string::npos) << error.what();
  }
}

TEST(EndStops, ARestartBeyondTheStopsIsRefused) {
  std::unique_ptr<Simulation> simulation(stopped_cart(0.0, 0.0));
  CartState beyond = simulation->state();
  beyond.steering_angle = 0.7;
  EXPECT_THROW(simulation->restart_from(beyond), std::invalid_argument);
  EXPECT_EQ(simulation->state().steering_angle, 0.0);
}

/// The shipped steering_actuator scene: the axle comes to rest on its stop, the shadow reference
/// follows the actuators and is restarted at the impact.
TEST(ShippedScene, SteeringActuatorRestsOnItsStopAndAgreesWithItsReference) {
  Simulation simulation(load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/steering_actuator.yaml"));
  double largest_angle = 0.0;
  while (!simulation.at_end()) {
    simulation.step_on_schedule();
    largest_angle = std::max(largest_angle, simulation.state().steering_angle);
  }
  const Simulation::ActuatorStatus status = simulation.actuator_status();
  EXPECT_EQ(status.end_stop_contact, 1);
  EXPECT_EQ(status.end_stop_events, 1u);
  EXPECT_NEAR(status.steering_applied, 2.0, 1e-12);  // saturated 3 → 2 N·m (the dead band acts below it)
  EXPECT_NEAR(status.drive_applied, 4.0, 1e-12);
  EXPECT_LE(largest_angle, 0.6 + 1e-12);
  const Diagnostics diagnostics = simulation.diagnostics();
  ASSERT_TRUE(diagnostics.has_reference);
  std::printf("steering_actuator: reference position error %.3e m, energy balance %.3e J\n",
              diagnostics.reference_position_error, diagnostics.energy_balance_residual);
  EXPECT_LT(diagnostics.reference_position_error, 1e-7);
  EXPECT_LT(std::abs(diagnostics.energy_balance_residual), 1e-9);
  EXPECT_EQ(actuator_summary(simulation),
            "steering motor applies 2 N·m (input 3 N·m); drive motor applies 4 N·m (input 6 N·m); end stops at "
            "+-0.6 rad: resting on the upper stop, end-stop events 1");
}

/// `driven.yaml` with `extra` appended (and `replace` → `with` applied), loaded from a temp file; the
/// SceneError's message, or "" when it loads.
std::string load_error(const std::string& extra, const std::string& replace = "", const std::string& with = "") {
  std::ifstream in(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/driven.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string scene = text.str();
  if (!replace.empty()) scene.replace(scene.find(replace), replace.size(), with);
  const std::string path = ::testing::TempDir() + "actuator_scene.yaml";
  std::ofstream(path) << scene << "\n" << extra;
  try {
    load_scene(path);
  } catch (const SceneError& error) {
    return error.what();
  }
  return "";
}

TEST(ActuatorScenes, BadSectionsAreRefusedByName) {
  EXPECT_EQ(load_error("steering_actuator: {time_constant: 0.1, dead_time: 0.02}\n"), "");
  EXPECT_NE(load_error("steering_actuator:\n").find("'steering_actuator': is empty"), std::string::npos);
  EXPECT_NE(load_error("drive_actuator: {time_constant: -1}\n").find("drive_actuator.time_constant"), std::string::npos);
  EXPECT_NE(load_error("drive_actuator: {rate_limit: 0}\n").find("drive_actuator.rate_limit"), std::string::npos);
  EXPECT_NE(load_error("steering_actuator: {lag: 0.1}\n").find("lag"), std::string::npos);
  EXPECT_NE(load_error("steering_end_stops: {angle: 1.6}\n").find("steering_end_stops.angle"), std::string::npos);
  EXPECT_NE(load_error("steering_end_stops: {restitution: 0.5}\n").find("angle"), std::string::npos);
  EXPECT_NE(load_error("steering_end_stops: {angle: 0.5, restitution: 1.5}\n").find("steering_end_stops.restitution"),
            std::string::npos);
  // An actuator needs its effect, with a piecewise-constant input.
  const std::string no_drive = load_error("drive_actuator: {time_constant: 0.1}\n", "  drive_torque:", "  unused_drive:");
  EXPECT_NE(no_drive.find("effect"), std::string::npos) << no_drive;
  const std::string cosine = load_error("steering_actuator: {time_constant: 0.1}\n",
                                        "    profile: command               # τ = the latest std_msgs/Float64 on steering_torque [N·m]\n    value: 0.0",
                                        "    profile: cosine\n    amplitude: 1.0\n    frequency: 0.5");
  EXPECT_NE(cosine.find("key 'steering_actuator'"), std::string::npos) << cosine;
  EXPECT_NE(cosine.find("piecewise-constant"), std::string::npos) << cosine;
  // The paper's special case has M11 = 0: no impact or holding reaction exists.
  std::ifstream paper_in(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/paper_special.yaml");
  std::stringstream paper_text;
  paper_text << paper_in.rdbuf();
  const std::string paper_path = ::testing::TempDir() + "paper_stops.yaml";
  std::ofstream(paper_path) << paper_text.str() << "\nsteering_end_stops: {angle: 1.5}\n";
  try {
    load_scene(paper_path);
    ADD_FAILURE() << "end stops accepted on the paper's special case";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("paper_special_case"), std::string::npos) << error.what();
  }
  // Stops the initial state already lies beyond.
  const std::string beyond = load_error("steering_end_stops: {angle: 0.3}\n", "  steering_angle: 0.0 ", "  steering_angle: 0.4 ");
  EXPECT_NE(beyond.find("initial_state.steering_angle"), std::string::npos) << beyond;
}

}  // namespace
}  // namespace birkhoff_cart
