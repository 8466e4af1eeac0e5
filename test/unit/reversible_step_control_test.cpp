// The reversible adaptive step (reversible_step_control.h, time_transformed_system.h,
// docs/birkhoffian.md §11): the grid map of the time-transformed member is time-reversible to
// round-off, its steps follow the step density, the energy of a long free run stays bounded, the grid
// does not depend on the output step, the error converges with the member's order in ε, a tolerance
// is met, and bad settings are refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/birkhoff_symplectic.h"
#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/integrators/reversible_step_control.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::scene_path;

/// Loads a scene from text (written to a file in the test's temporary directory).
Scene parse_scene(const std::string& text, const std::string& name) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << text;
  return load_scene(path);
}

Scene whirl() { return load_scene(scene_path("jackknife_whirl")); }

/// A member's grid on the free whirl, started at its initial state with fictive step ε (and
/// optionally a work limit): the setting of most tests below.
template <class Stepper>
struct WhirlGrid {
  using System = CartAutonomousBirkhoffian;
  using Transformed = TimeTransformedSystem<System>;
  using Grid = CarriedCartState<System, typename Stepper::template Memory<Transformed>, Transformed>;
  using Seed = CarriedCartState<System, NoStepMemory>;
  using Control = ReversibleStepControl<Stepper, System, Grid>;
  Scene scene = whirl();
  CartModel model{scene.cart};
  EffectSet effects;
  System system{model, effects};
  Transformed transformed{system, 0.0};
  Seed seed;
  StepStatistics statistics;
  std::unique_ptr<Control> control;

  explicit WhirlGrid(double epsilon, std::uint64_t work_limit = 1000000, const Stepper& stepper = Stepper()) {
    seed.start_from(system, scene.initial_state);
    ReversibleStepSettings settings;
    settings.fictive_step = epsilon;
    settings.max_steps_per_advance = work_limit;
    control = std::make_unique<Control>(stepper, settings);
    control->start(seed, 0.0);
  }
  double energy() const {
    const auto& point = control->grid().point;
    return system.hamiltonian(Eigen::Matrix<double, 4, 1>(point.z + point.z_remainder));
  }
};

/// Largest |a − b| / max(1, |b|) over z and y (time included) of two carried points [-].
template <class Point>
double relative_distance(const Point& a, const Point& b) {
  double distance = 0.0;
  for (int k = 0; k < a.z.size(); ++k) {
    const double target = b.z(k) + b.z_remainder(k);
    distance = std::max(distance, std::abs(a.z(k) + a.z_remainder(k) - target) / std::max(1.0, std::abs(target)));
  }
  for (int k = 0; k < a.y.size(); ++k) {
    const double target = b.y(k) + b.y_remainder(k);
    distance = std::max(distance, std::abs(a.y(k) + a.y_remainder(k) - target) / std::max(1.0, std::abs(target)));
  }
  return distance;
}

/// +ε for `steps` grid steps, then −ε as often: back at the start, time included, to round-off —
/// while the physical steps vary along the way.
template <class Stepper>
void expect_reversible(int steps, double epsilon) {
  WhirlGrid<Stepper> grid(epsilon);
  auto& control = *grid.control;
  const auto start = control.grid().point;
  double smallest = 1e300, largest = 0.0;
  for (int n = 0; n < steps; ++n) {
    const double h = control.grid_step(grid.transformed, epsilon, grid.statistics);
    smallest = std::min(smallest, h);
    largest = std::max(largest, h);
  }
  const double span = control.time();
  EXPECT_GT(span, 1.0);
  EXPECT_GT(largest / smallest, 2.0) << "the whirl's steps vary with the step density";
  for (int n = 0; n < steps; ++n) control.grid_step(grid.transformed, -epsilon, grid.statistics);
  // Measured: 1e-13 to 1e-12 after 2 × 200–400 steps. A controller that is not symmetric (hₙ from
  // zₙ alone) misses the start by its local error, ~1e-6 here.
  const double distance = relative_distance(control.grid().point, start);
  EXPECT_LT(distance, 1e-11) << Stepper::name() << ": round trip " << distance;
  EXPECT_NEAR(control.time(), 0.0, 1e-11 * span);
}

TEST(ReversibleStepControl, ForwardThenBackwardReturnsToTheStart) {
  expect_reversible<GaussCollocation<1>>(400, 0.05);
  expect_reversible<GaussCollocation<2>>(300, 0.2);
  expect_reversible<GaussCollocation<4>>(200, 0.5);
  expect_reversible<BirkhoffComposition<TripleJumpWeights>>(200, 0.1);
}

TEST(ReversibleStepControl, StepsFollowTheStepDensity) {
  // h·σ(z at the step's middle) ≈ ε (eq. (B.42)): the steps are short where the whirl turns fast.
  WhirlGrid<GaussCollocation<2>> grid(0.1);
  auto& control = *grid.control;
  double worst = 0.0;
  for (int n = 0; n < 500; ++n) {
    const double sigma_start = grid.system.step_density(Eigen::Matrix<double, 4, 1>(control.grid().point.z));
    const double h = control.grid_step(grid.transformed, 0.1, grid.statistics);
    const double sigma_end = grid.system.step_density(Eigen::Matrix<double, 4, 1>(control.grid().point.z));
    worst = std::max(worst, std::abs(h * std::sqrt(sigma_start * sigma_end) / 0.1 - 1.0));
  }
  EXPECT_LT(worst, 0.05);
  EXPECT_EQ(grid.statistics.internal_steps, 500u);
  EXPECT_GT(grid.statistics.internal_step_max / grid.statistics.internal_step_min, 2.0);
}

/// A whirl scene under reversible control with the given member, ε-tolerance and duration.
Scene reversible_whirl(const std::string& member, double tolerance, double duration, double output_step) {
  Scene scene = whirl();
  scene.integrator.name = member;
  scene.integrator.step_control = StepControl::kReversible;
  scene.integrator.position_tolerance = tolerance;
  scene.duration = duration;
  scene.integrator.step_size = output_step;
  return scene;
}

CartState run_to_end(const Scene& scene, StepStatistics* statistics = nullptr) {
  Simulation simulation(scene);
  while (!simulation.at_end()) simulation.step_on_schedule();
  if (statistics) *statistics = simulation.statistics();
  return simulation.state();
}

CartState reference_end(double duration) {
  Scene scene = whirl();
  scene.integrator.name = "birkhoff_gauss8";
  scene.integrator.step_size = 2e-3;
  scene.duration = duration;
  return run_to_end(scene);
}

TEST(ReversibleStepControl, TheGridDoesNotDependOnTheOutputStep) {
  const CartState every_10ms = run_to_end(reversible_whirl("birkhoff_gauss4", 1e-7, 4.0, 0.01));
  const CartState once = run_to_end(reversible_whirl("birkhoff_gauss4", 1e-7, 4.0, 4.0));
  EXPECT_EQ(every_10ms.x, once.x);
  EXPECT_EQ(every_10ms.y, once.y);
  EXPECT_EQ(every_10ms.steering_angle, once.steering_angle);
  EXPECT_EQ(every_10ms.forward_speed, once.forward_speed);
}

TEST(ReversibleStepControl, MeetsTheToleranceOnTheWhirl) {
  const CartState reference = reference_end(4.0);
  for (const std::string member : {"birkhoff2", "birkhoff_gauss4", "birkhoff_gauss8", "birkhoff4"}) {
    for (double tolerance : {1e-5, 1e-8}) {
      if (member == "birkhoff2" && tolerance < 1e-6) continue;  // order 2: ~1e6 steps
      StepStatistics statistics;
      const CartState end = run_to_end(reversible_whirl(member, tolerance, 4.0, 0.5), &statistics);
      const double error = std::hypot(end.x - reference.x, end.y - reference.y);
      EXPECT_LT(error, 10.0 * tolerance) << member << " at " << tolerance;
      EXPECT_GT(statistics.internal_steps, 0u);
    }
  }
}

TEST(ReversibleStepControl, EnergyStaysBoundedOverALongFreeRun) {
  // 1000 s of the free whirl at a large fixed ε: the energy error's largest value over the last
  // tenth is within 2× that over the first tenth (no drift: a linear drift would make it 10×; the
  // benchmark's 10 000 s run is in docs/results.md).
  WhirlGrid<GaussCollocation<2>> grid(0.3);
  auto& control = *grid.control;
  const double energy_start = grid.energy();
  const double horizon = 1000.0;
  double first = 0.0, last = 0.0;
  while (control.time() < horizon) {
    control.grid_step(grid.transformed, 0.3, grid.statistics);
    const double error = std::abs(grid.energy() - energy_start);
    if (control.time() < 0.1 * horizon) first = std::max(first, error);
    if (control.time() > 0.9 * horizon) last = std::max(last, error);
  }
  std::printf("[ measured ] gauss4 at eps = 0.3 rad over 1000 s: energy error %.3e J in the first tenth, %.3e J in "
              "the last, %llu steps\n",
              first, last, static_cast<unsigned long long>(grid.statistics.internal_steps));
  EXPECT_GT(first, 0.0);
  EXPECT_LE(last, 2.0 * first) << "first tenth " << first << " J, last tenth " << last << " J";
}

TEST(ReversibleStepControl, ErrorConvergesWithTheMembersOrderInEpsilon) {
  // Fixed ε (no calibration): the position error at the grid's first point past 4 s against the
  // reference at that time falls like ε^p.
  double previous = 0.0;
  for (double epsilon : {0.2, 0.1, 0.05}) {
    WhirlGrid<GaussCollocation<2>> grid(epsilon);
    auto& control = *grid.control;
    control.advance_past(grid.transformed, 4.0, grid.statistics, [] { return true; });
    Scene scene = whirl();
    scene.integrator.name = "birkhoff_gauss8";
    scene.integrator.step_size = control.time() / 4000.0;
    scene.duration = control.time();
    Simulation reference(scene);
    while (!reference.at_end()) reference.step_on_schedule();
    const auto& point = control.grid().point;
    const double error = std::hypot(point.y(kXIndex) + point.y_remainder(kXIndex) - reference.state().x,
                                    point.y(kYIndex) + point.y_remainder(kYIndex) - reference.state().y);
    if (previous > 0.0) {
      const double order = std::log2(previous / error);
      EXPECT_NEAR(order, 4.0, 0.5) << "ε = " << epsilon << ": errors " << previous << " m, " << error << " m";
    }
    previous = error;
  }
}

TEST(ReversibleStepControl, BadSettingsAreRefusedByName) {
  Scene scene = whirl();
  scene.integrator.name = "rk4";
  scene.integrator.step_control = StepControl::kReversible;
  try {
    Simulation simulation(scene);
    FAIL() << "rk4 under reversible control was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("symmetric Birkhoffian"), std::string::npos) << error.what();
  }
  const std::string text = birkhoff_cart_test::read_file(scene_path("jackknife_whirl"));
  const std::string rk4 = birkhoff_cart_test::replaced_once(
      birkhoff_cart_test::replaced_once(text, "name: birkhoff2", "name: rk4"), "birkhoffian_form: autonomous",
      "birkhoffian_form: autonomous\n  step_control: reversible");
  try {
    parse_scene(rk4, "bad.yaml");
    FAIL() << "the scene reader accepted rk4 with step_control: reversible";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("integrator.step_control"), std::string::npos) << error.what();
  }
  const std::string horizon = birkhoff_cart_test::replaced_once(text, "birkhoffian_form: autonomous",
                                                               "birkhoffian_form: autonomous\n  tolerance_horizon: 10");
  EXPECT_THROW(parse_scene(horizon, "bad.yaml"), SceneError) << "tolerance_horizon without reversible control";
  // One meaning per key: the reversible control's position error is `position_tolerance` [m], never
  // dopri5's `tolerance` [-] (which the shipped scenes carry); each is required or refused by name.
  const std::string reversible = birkhoff_cart_test::replaced_once(
      text, "birkhoffian_form: autonomous", "birkhoffian_form: autonomous\n  step_control: reversible");
  try {
    parse_scene(reversible, "bad.yaml");
    FAIL() << "step_control: reversible without position_tolerance was accepted";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("integrator.position_tolerance"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("integrator.tolerance is dopri5's"), std::string::npos) << error.what();
  }
  const Scene accepted = parse_scene(
      birkhoff_cart_test::replaced_once(reversible, "step_control: reversible",
                                        "step_control: reversible\n  position_tolerance: 1.0e-6"),
      "good.yaml");
  EXPECT_EQ(accepted.integrator.position_tolerance, 1e-6);
  EXPECT_EQ(accepted.integrator.tolerance, 1e-10) << "dopri5's tolerance keeps its own meaning";
  const std::string fixed = birkhoff_cart_test::replaced_once(text, "birkhoffian_form: autonomous",
                                                             "birkhoffian_form: autonomous\n  position_tolerance: 1e-6");
  try {
    parse_scene(fixed, "bad.yaml");
    FAIL() << "position_tolerance at fixed steps was accepted";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("integrator.position_tolerance"), std::string::npos) << error.what();
  }
  // A tolerance out of the member's reach is refused when the simulation is built (CLI exit 3,
  // node start-up error), not at its first step.
  try {
    Simulation tight(reversible_whirl("birkhoff2", 2e-12, 4.0, 0.5));  // above the floor of 1.8e-12 m
    FAIL() << "a tolerance out of birkhoff2's reach was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("out of reach"), std::string::npos) << error.what();
  }
  // The time transformation reads the loads at one time: a torque profile is refused by name, as
  // is the paper's form (its chart moves with time).
  Scene forced = load_scene(scene_path("sine_steer_torque"));
  forced.integrator.name = "birkhoff_gauss4";
  forced.integrator.step_control = StepControl::kReversible;
  forced.integrator.position_tolerance = 1e-6;
  try {
    Simulation simulation(forced);
    FAIL() << "a torque profile under the reversible control was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("use step_control 'adaptive'"), std::string::npos) << error.what();
  }
  Scene paper = reversible_whirl("birkhoff_gauss4", 1e-6, 4.0, 0.5);
  paper.integrator.birkhoffian_form = BirkhoffianForm::kPaper;
  try {
    Simulation simulation(paper);
    FAIL() << "the paper form under the reversible control was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("birkhoffian_form 'autonomous'"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace birkhoff_cart

namespace birkhoff_cart {
namespace {

TEST(ReversibleStepControl, AWorkLimitStopsARunThatWouldTakeTooManySteps) {
  WhirlGrid<GaussCollocation<2>> grid(0.01, 100);  // 4 s of the whirl need ~1300 steps at ε = 0.01
  try {
    grid.control->advance_past(grid.transformed, 4.0, grid.statistics, [] { return true; });
    FAIL() << "the work limit did not stop the run";
  } catch (const StepError& error) {
    EXPECT_NE(std::string(error.what()).find("more than 100 internal steps"), std::string::npos) << error.what();
  }
}

TEST(ReversibleStepControl, TheCliAsksForAPositionTolerance) {
  // The shipped scenes' `tolerance` (1e-10) is dopri5's local tolerance [-]: it never stands in
  // for the position error [m], and --tolerance is refused with this control.
  const std::string csv = testing::TempDir() + "reversible_cli.csv";
  const auto without = birkhoff_cart_test::run_cart_simulate(
      "--scene " + scene_path("jackknife_whirl") + " --step-control reversible --quiet --output " + csv,
      testing::TempDir() + "reversible_cli.err");
  EXPECT_EQ(without.exit_status, 2);
  EXPECT_NE(without.standard_error.find("needs --position-tolerance"), std::string::npos) << without.standard_error;
  const auto dopri5s = birkhoff_cart_test::run_cart_simulate(
      "--scene " + scene_path("jackknife_whirl") + " --step-control reversible --tolerance 1e-5 --quiet --output " + csv,
      testing::TempDir() + "reversible_cli.err");
  EXPECT_EQ(dopri5s.exit_status, 2);
  EXPECT_NE(dopri5s.standard_error.find("--tolerance is dopri5's local tolerance"), std::string::npos)
      << dopri5s.standard_error;
  const auto fixed = birkhoff_cart_test::run_cart_simulate(
      "--scene " + scene_path("jackknife_whirl") + " --position-tolerance 1e-5 --quiet --output " + csv,
      testing::TempDir() + "reversible_cli.err");
  EXPECT_EQ(fixed.exit_status, 2);
  EXPECT_NE(fixed.standard_error.find("--position-tolerance is the position error [m] for --step-control adaptive or "
                                      "reversible"),
            std::string::npos)
      << fixed.standard_error;
  const std::string summary = testing::TempDir() + "reversible_cli.out";
  const std::string command = "'" + birkhoff_cart_test::cart_simulate_path() + "' --scene " +
                              scene_path("jackknife_whirl") +
                              " --step-control reversible --position-tolerance 1e-5 --duration 1 --quiet --output " + csv + " > " +
                              summary;
  EXPECT_EQ(std::system(command.c_str()), 0);
  const std::string text = birkhoff_cart_test::read_file(summary);
  EXPECT_NE(text.find("reversible step control: position tolerance 1e-05 m"), std::string::npos) << text;
  EXPECT_NE(text.find("output step = "), std::string::npos) << text;
  std::remove(summary.c_str());
  std::remove(csv.c_str());
}

}  // namespace
}  // namespace birkhoff_cart
