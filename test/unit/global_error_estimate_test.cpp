// The global error estimate of the adaptive control (richardson_shadow.h, docs/accuracy.md §4.5):
// within its range it follows the position error of B that the run delivers (against a reference
// independent of the judged run), it says when it is beyond its range, it leaves the run's steps and
// rows as they are while costing work, it is refused where it cannot follow a grid, and the CLI
// reports it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/richardson_shadow.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "run_end.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::scene_path;

/// `name` under `member`, the adaptive control at `tolerance` [m] with the estimate on or off,
/// rows at 10 Hz.
Scene estimated(const std::string& name, const std::string& member, double tolerance, bool estimate = true) {
  Scene scene = load_scene(scene_path(name));
  scene.integrator.name = member;
  scene.integrator.step_control = StepControl::kAdaptive;
  scene.integrator.position_tolerance = tolerance;
  scene.integrator.global_error_estimate = estimate;
  scene.output_rate = 10.0;
  scene.integrator.step_size = 0.1;
  scene.reference = ReferenceSettings{};
  return scene;
}

using birkhoff_cart_test::RunEnd;
RunEnd run(const Scene& scene) { return birkhoff_cart_test::run_to_end_time(scene); }

/// birkhoff_gauss8 at a fixed step of about `step` [s] over the whole run: on these scenes 2 ms and
/// 1 ms agree to ≤ 7.3e-13 m (paper_special; the others ≤ 1.3e-14 m), so errors from 1e-11 m on
/// are judged (scripts/python/global_error_estimate.py prints the spread).
CartState reference_end(const std::string& name, double step = 0.001) {
  Scene scene = load_scene(scene_path(name));
  scene.integrator.name = "birkhoff_gauss8";
  scene.integrator.step_control = StepControl::kFixed;
  const double steps = std::round(scene.duration / step);
  scene.integrator.step_size = scene.duration / steps;
  scene.output_rate = 1.0 / scene.duration;
  scene.reference = ReferenceSettings{};
  Simulation simulation(scene);
  while (!simulation.at_end()) simulation.step_on_schedule();
  return simulation.state();
}

double position_error(const CartState& a, const CartState& b) { return std::hypot(a.x - b.x, a.y - b.y); }

constexpr double kResolved = 1e-11;  ///< the smallest error reference_end() judges [m]

TEST(GlobalErrorEstimate, FollowsTheErrorWithinItsRange) {
  const std::vector<std::string> scenes = {"sine_steer_torque", "drive_rr_drag", "jackknife_whirl", "near_jackknife",
                                           "reverse_jackknife", "paper_special"};
  const std::vector<std::string> members = {"birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8"};
  int judged = 0;
  for (const std::string& name : scenes) {
    const CartState reference = reference_end(name);
    for (const std::string& member : members) {
      for (double tolerance : {1e-5, 1e-7, 1e-9}) {
        const RunEnd result = run(estimated(name, member, tolerance));
        const StepStatistics& statistics = result.statistics;
        const double error = position_error(result.end, reference);
        const bool in_range =
            global_error_estimate_in_range(statistics.global_error_paired_steps, statistics.global_error_stiffness);
        std::printf("[ measured ] %-18s %-16s tol %.0e m: error %.2e m, estimate %.2e m (%.2f), %llu pairs, h*rho %.2g%s\n",
                    name.c_str(), member.c_str(), tolerance, error, statistics.global_error_estimate,
                    statistics.global_error_estimate / error,
                    static_cast<unsigned long long>(statistics.global_error_paired_steps),
                    statistics.global_error_stiffness, in_range ? "" : " (beyond its range)");
        ASSERT_TRUE(std::isfinite(statistics.global_error_estimate)) << name << " " << member;
        EXPECT_EQ(statistics.global_error_estimate_time, result.end.time) << name << " " << member;
        if (!in_range || error < kResolved) continue;  // beyond its range, or below the reference's resolution
        ++judged;
        // 0.37 measured at the low end: gauss6 on the whirl at 1e-5 m, whose steps the control keeps
        // up to twice its aim (B.46) — long steps near the edge of the asymptotic range (A.6) assumes.
        EXPECT_GE(statistics.global_error_estimate, 0.3 * error) << name << " " << member << " at " << tolerance << " m";
        EXPECT_LE(statistics.global_error_estimate, 10.0 * error) << name << " " << member << " at " << tolerance << " m";
      }
    }
  }
  std::printf("[ measured ] %d of %zu runs judged (within the estimate's range, error >= %.0e m)\n", judged,
              scenes.size() * members.size() * 3, kResolved);
  EXPECT_GE(judged, 25);  // most of these runs are within the estimate's range and resolved
}

TEST(GlobalErrorEstimate, SaysWhenAStiffModeIsSteppedOver) {
  // The very stiff hinge's 400 rad/s swing: the grid steps over it (h·ρ(J) ≫ 1), where (A.6)'s
  // premise fails and the estimate under-states the error (docs/accuracy.md §4.5).
  const RunEnd result = run(estimated("very_stiff_hinge", "birkhoff_gauss8", 1e-7));
  EXPECT_GT(result.statistics.global_error_stiffness, 100.0);
  EXPECT_FALSE(global_error_estimate_in_range(result.statistics.global_error_paired_steps,
                                              result.statistics.global_error_stiffness));
}

TEST(GlobalErrorEstimate, SameStepsAndRowsMoreWork) {
  for (const char* name : {"sine_steer_torque", "stiff_hinge", "drive_rr_drag"}) {
    Simulation plain(estimated(name, "birkhoff_gauss6", 1e-7, false));
    Simulation shadowed(estimated(name, "birkhoff_gauss6", 1e-7, true));
    while (!plain.at_end()) {
      plain.step_on_schedule();
      shadowed.step_on_schedule();
      ASSERT_EQ(plain.state().x, shadowed.state().x) << name << " at t = " << plain.state().time;
      ASSERT_EQ(plain.state().y, shadowed.state().y) << name << " at t = " << plain.state().time;
      ASSERT_EQ(plain.state().steering_angle, shadowed.state().steering_angle) << name;
    }
    EXPECT_EQ(plain.statistics().internal_steps, shadowed.statistics().internal_steps) << name;
    EXPECT_EQ(plain.statistics().rejected_steps, shadowed.statistics().rejected_steps) << name;
    EXPECT_TRUE(std::isnan(plain.statistics().global_error_estimate)) << name;
    EXPECT_GT(shadowed.statistics().rhs_evaluations, plain.statistics().rhs_evaluations) << name;
    std::printf("[ measured ] %s: %llu rhs with the estimate, %llu without (%.2fx)\n", name,
                static_cast<unsigned long long>(shadowed.statistics().rhs_evaluations),
                static_cast<unsigned long long>(plain.statistics().rhs_evaluations),
                static_cast<double>(shadowed.statistics().rhs_evaluations) /
                    static_cast<double>(plain.statistics().rhs_evaluations));
  }
}

TEST(GlobalErrorEstimate, RefusedWhereThereIsNoGridToFollow) {
  Scene dopri = estimated("sine_steer_torque", "dopri5", 1e-6);
  dopri.integrator.birkhoffian_form = BirkhoffianForm::kAutonomous;
  try {
    Simulation simulation(dopri);
    FAIL() << "dopri5 with the estimate was taken";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("dopri5"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("global_error_estimate"), std::string::npos) << error.what();
  }
  Scene fixed = estimated("sine_steer_torque", "birkhoff_gauss8", 1e-6);
  fixed.integrator.step_control = StepControl::kFixed;  // as a caller's override would leave it (the node's ~step_control)
  fixed.integrator.step_size = 0.01;
  EXPECT_THROW(Simulation simulation(fixed), std::invalid_argument);
  const std::string text = birkhoff_cart_test::read_file(scene_path("sine_steer_torque"));
  try {  // the scene reader names dopri5 too (the Python module's load_scene reads scenes before any run)
    load_scene_text(birkhoff_cart_test::replaced_once(
                        text, "integrator:\n  name: birkhoff2 ",
                        "integrator:\n  step_control: adaptive\n  position_tolerance: 1.0e-6\n"
                        "  global_error_estimate: true\n  name: dopri5 "),
                    "dopri5_estimate.yaml");
    ADD_FAILURE() << "global_error_estimate with dopri5 was read";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("dopri5"), std::string::npos) << error.what();
  }
  for (const std::string control : {"fixed", "reversible"}) {
    const std::string integrator_block = "integrator:\n  step_control: " + control + "\n  global_error_estimate: true\n";
    std::string scene_text = birkhoff_cart_test::replaced_once(text, "integrator:\n", integrator_block);
    try {
      load_scene_text(scene_text, "estimate_without_adaptive.yaml");
      ADD_FAILURE() << "global_error_estimate under '" << control << "' was taken";
    } catch (const SceneError& error) {
      EXPECT_NE(std::string(error.what()).find("global_error_estimate"), std::string::npos) << error.what();
    }
  }
}

TEST(GlobalErrorEstimate, TheCliReportsItAndRefusesItWithoutTheAdaptiveControl) {
  const std::string scratch = ::testing::TempDir() + "global_error_estimate_cli_";
  const std::string scene = "--scene '" + scene_path("sine_steer_torque") + "' --integrator birkhoff_gauss8 --output '" +
                            scratch + "rows.csv' --quiet";
  const birkhoff_cart_test::CliPrinted reported = birkhoff_cart_test::run_cart_simulate_printing(
      scene + " --step-control adaptive --position-tolerance 1e-7 --output-rate 10 --global-error-estimate", scratch);
  EXPECT_EQ(reported.exit_status, 0) << reported.standard_error;
  EXPECT_NE(reported.standard_output.find("global error estimate "), std::string::npos) << reported.standard_output;
  EXPECT_NE(reported.standard_output.find("within its range)"), std::string::npos) << reported.standard_output;
  // gauss8 on jackknife_whirl at 1e-7 m: its estimate, which over-states the error by up to 4× (q = 6
  // < p = 8: accuracy.md §4.5), reads 1.6e-7 m within its range: the summary says it is above the tolerance.
  const birkhoff_cart_test::CliPrinted missed = birkhoff_cart_test::run_cart_simulate_printing(
      "--scene '" + scene_path("jackknife_whirl") + "' --integrator birkhoff_gauss8 --output '" + scratch +
          "rows.csv' --quiet --step-control adaptive --position-tolerance 1e-7 --output-rate 10 --global-error-estimate",
      scratch);
  EXPECT_EQ(missed.exit_status, 0) << missed.standard_error;
  EXPECT_NE(missed.standard_output.find("within its range, above the tolerance"), std::string::npos)
      << missed.standard_output;
  // In the paper form the CLI also probes the chart's momentum drift at fixed steps; the estimate is the run's.
  const birkhoff_cart_test::CliPrinted paper = birkhoff_cart_test::run_cart_simulate_printing(
      "--scene '" + scene_path("paper_special") + "' --integrator birkhoff_gauss6 --birkhoffian-form paper --output '" +
          scratch + "rows.csv' --quiet --step-control adaptive --position-tolerance 1e-8 --global-error-estimate",
      scratch);
  EXPECT_EQ(paper.exit_status, 0) << paper.standard_error;
  EXPECT_NE(paper.standard_output.find("global error estimate "), std::string::npos) << paper.standard_output;
  const birkhoff_cart_test::CliPrinted fixed =
      birkhoff_cart_test::run_cart_simulate_printing(scene + " --step 0.01 --global-error-estimate", scratch);
  EXPECT_EQ(fixed.exit_status, 2);
  EXPECT_NE(fixed.standard_error.find("--global-error-estimate"), std::string::npos) << fixed.standard_error;
  const birkhoff_cart_test::CliPrinted valued = birkhoff_cart_test::run_cart_simulate_printing(
      scene + " --step-control adaptive --position-tolerance 1e-7 --global-error-estimate=yes", scratch);
  EXPECT_EQ(valued.exit_status, 2);
  EXPECT_NE(valued.standard_error.find("takes no value"), std::string::npos) << valued.standard_error;
  std::remove((scratch + "rows.csv").c_str());
}

}  // namespace
}  // namespace birkhoff_cart
