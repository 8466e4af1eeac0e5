// Accuracy on demand (adaptive_step_control.h, reversible_step_control.h, dopri5_cart_stepper.h;
// docs/birkhoffian.md §11–§12): a position tolerance drives every Birkhoffian member and dopri5 on
// every shipped scene, the delivered error lands within 2× of it under the adaptive control and 10× under
// the reversible one (for the Gauss members under the
// adaptive control also above 1/100 000 of it, with rejected attempts at most a tenth of the accepted
// steps but one) and the work falls as it loosens;
// every accepted step meets its error per unit step, a rejected or failed attempt never reaches the
// caller, steps land on the loads' kinks, a stiff hinge runs where fixed steps fail, the dense output
// matches the grid at its points and a tight run between them with the member's order, rows between
// grid points cost a few iterations each, and a run is deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/integrators/adaptive_step_control.h"
#include "birkhoff_cart/core/cart_binding/carried_state.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "run_end.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::scene_path;

Scene shipped(const std::string& name) { return load_scene(scene_path(name)); }

/// `scene` under `member` with `control` at `tolerance` [m] (dopri5 at fixed control: its own
/// tolerance [-]); one output step over the whole run.
Scene configured(Scene scene, const std::string& member, StepControl control, double tolerance) {
  scene.integrator.name = member;
  scene.integrator.step_control = control;
  scene.integrator.step_size = scene.duration;
  scene.integrator.local_error_estimate = true;
  if (control == StepControl::kFixed) {
    scene.integrator.tolerance = tolerance;
  } else {
    scene.integrator.position_tolerance = tolerance;
  }
  if (control == StepControl::kReversible || member == "dopri5") {
    scene.integrator.birkhoffian_form = BirkhoffianForm::kAutonomous;
  }
  scene.reference = ReferenceSettings{};
  return scene;
}

using birkhoff_cart_test::RunEnd;
RunEnd run(const Scene& scene) { return birkhoff_cart_test::run_to_end_time(scene); }

/// dopri5 over the whole run at 1e-13: resolves 1e-10 m on every shipped scene (against 1e-12: the
/// two agree to ≤ 3e-11 m, measured).
CartState reference_end(const Scene& scene) {
  Scene tight = configured(scene, "dopri5", StepControl::kFixed, 1e-13);
  Simulation simulation(tight);
  while (!simulation.at_end()) simulation.step_on_schedule();
  return simulation.state();
}

double position_error(const CartState& a, const CartState& b) { return std::hypot(a.x - b.x, a.y - b.y); }

/// Whether the scene's loads read the time (the reversible control refuses those).
bool time_dependent(const Scene& scene) {
  Simulation simulation(configured(scene, "birkhoff_gauss4", StepControl::kFixed, 0.0));
  return simulation.effects().depends_on_time();
}

/// Loose bounds on the Gauss members under the adaptive control (docs/accuracy.md §4.3 has the
/// measured figures): the delivered error not below tolerance / this [-], and rejected attempts at
/// most this share of the accepted steps [-].
constexpr double kOverdeliveryBound = 1e5;  // 1.7e-5 measured: gauss4 on very_stiff_hinge at 1e-3 m (20 s)
/// The delivered error at most this many times the tolerance under each control [-].
constexpr double kAdaptivePromise = 2.0;
constexpr double kReversiblePromise = 10.0;
constexpr double kRejectedShareBound = 0.10;
/// One rejection more: a run of fewer than ten steps cannot keep one below a tenth (paper_special,
/// gauss8: one rejected of 6 steps, where the motion stiffens towards the pole within a step) [-].
constexpr double kRejectedSlack = 1.0;
/// A run of at most this many internal steps is at the start's floor of work [-].
constexpr std::uint64_t kStartFloorSteps = 10;

TEST(ToleranceProportionality, EveryShippedSceneEveryControl) {
  const std::vector<std::string> scenes = {"const_steer_torque", "default",      "drive_rr_drag",  "driven",
                                           "free_coast",         "jackknife_whirl", "near_jackknife", "noisy_odometry",
                                           "paper_special",      "reverse_jackknife", "sine_steer_torque", "stiff_hinge",
                                           "very_stiff_hinge"};
  struct Setting {
    std::string member;
    StepControl control;
  };
  const std::vector<Setting> settings = {{"birkhoff_gauss6", StepControl::kAdaptive},
                                         {"birkhoff_gauss4", StepControl::kAdaptive},
                                         {"birkhoff_gauss8", StepControl::kAdaptive},
                                         {"birkhoff_gauss8", StepControl::kReversible},
                                         {"dopri5", StepControl::kAdaptive}};
  const std::vector<double> tolerances = {1e-3, 1e-5, 1e-7};  // [m]
  for (const std::string& name : scenes) {
    Scene scene = shipped(name);
    scene.duration = std::min(scene.duration, 20.0);
    const CartState reference = reference_end(scene);
    for (const Setting& setting : settings) {
      // Refused (tested below, and in tolerance_requests_test): loads that vary in time, the paper's case.
      if (setting.control == StepControl::kReversible && (time_dependent(scene) || scene.paper_special_case)) continue;
      std::vector<double> work;
      double loosest_error = 0.0;
      std::uint64_t loosest_steps = 0;  // internal steps at the loosest tolerance [-]
      for (double tolerance : tolerances) {
        const RunEnd result = run(configured(scene, setting.member, setting.control, tolerance));
        const double error = position_error(result.end, reference);
        std::printf("[ measured ] %-18s %-16s %-10s tol %.0e m: error %.2e m, %llu rhs, %llu rejected of %llu\n",
                    name.c_str(), setting.member.c_str(), to_string(setting.control), tolerance, error,
                    static_cast<unsigned long long>(result.statistics.rhs_evaluations),
                    static_cast<unsigned long long>(result.statistics.rejected_steps),
                    static_cast<unsigned long long>(result.statistics.internal_steps));
        // The adaptive control's promise is 2× (accuracy.md §4.3: worst measured 1.4×, gauss6 on
        // stiff_hinge at 1e-7 m); the reversible control's 10× (0.29× measured, gauss8 on
        // reverse_jackknife at 1e-5 m: its ε cap sets the steps on these short runs).
        const double promise = setting.control == StepControl::kAdaptive ? kAdaptivePromise : kReversiblePromise;
        EXPECT_LE(error, promise * tolerance + 1e-10) << name << " " << setting.member << " at " << tolerance << " m";
        if (setting.control == StepControl::kAdaptive && setting.member != "dopri5") {
          // The Gauss members aim at the tolerance (eq. (B.53)), not orders below it — except where
          // the motion is exact at any step (driven: a straight coast), and judged only where the
          // reference resolves tolerance / kOverdeliveryBound (1e-10 m).
          if (name != "driven" && tolerance / kOverdeliveryBound >= 1e-10) {
            EXPECT_GE(error, tolerance / kOverdeliveryBound) << name << " " << setting.member << " at " << tolerance << " m";
          }
          // The controller does not thrash: rejected attempts at most a tenth of the accepted steps
          // (issue goal), but for one.
          EXPECT_LE(static_cast<double>(result.statistics.rejected_steps),
                    kRejectedShareBound * static_cast<double>(result.statistics.internal_steps) + kRejectedSlack)
              << name << " " << setting.member << " at " << tolerance << " m";
        }
        work.push_back(static_cast<double>(result.statistics.rhs_evaluations));
        if (work.size() == 1) {
          loosest_error = error;
          loosest_steps = result.statistics.internal_steps;
        }
      }
      // The work falls as the tolerance loosens — but where the loosest tolerance's run already
      // meets the tightest (straight coasting is exact for every method), and for the reversible
      // control on these runs of seconds: its fictive step is capped at 0.6 rad and its calibration
      // costs ~20 grid steps, a floor these short runs reach at every tolerance (on the 1000 s whirl
      // its work falls 2.9× from 1e-7 to 1e-3 m: docs/results.md).
      // An eighth-order member whose error follows the tolerance needs (10⁴)^{1/8} = 3.2× fewer steps
      // at 1e-3 m than at 1e-7 m, before the start's floor of steps: 0.7 for it (accuracy.md §4.1).
      // A loosest run of at most kStartFloorSteps steps is at that floor (const_steer_torque, gauss6:
      // 5 steps and 97 rhs at 1e-3 m, 14 and 169 at 1e-7 m; paper_special, dopri5: 10 and 26 steps).
      const double falls_to = setting.member == "birkhoff_gauss8" ? 0.7 : 0.5;
      if (loosest_error > tolerances.back() && setting.control != StepControl::kReversible &&
          loosest_steps > kStartFloorSteps) {
        EXPECT_LE(work.front(), falls_to * work.back()) << name << " " << setting.member << ": the work at 1e-3 m against 1e-7 m";
      }
    }
  }
}

TEST(AdaptiveStepControl, EveryAcceptedStepMeetsItsErrorPerUnitStep) {
  // The control on drive_rr_drag (forced, dissipative): each accepted step's ê ≤ A·τh (B.46), and
  // the stage solve stopped short of round-off (fewer iterations than at κ = 0).
  const Scene scene = shipped("drive_rr_drag");
  const CartModel model(scene.cart);
  const EffectSet effects = build_effects(scene.effects, model, scene.actuators, 0.0);
  CartAutonomousBirkhoffian system(model, effects);
  using Stepper = GaussCollocation<3>;
  using Carried = CarriedCartState<CartAutonomousBirkhoffian, Stepper::Memory<CartAutonomousBirkhoffian>>;
  auto iterations_with = [&](double stage_fraction, bool check) {
    AdaptiveStepSettings settings;
    settings.error_per_unit_step = 1e-8;  // [1/s]
    settings.stage_change_fraction = stage_fraction;
    AdaptiveStepControl<Stepper, CartAutonomousBirkhoffian, Carried> control(Stepper(), settings);
    Carried seed;
    seed.start_from(system, scene.initial_state);
    control.start(seed, 0.0, 1e-3);
    StepStatistics statistics;
    while (control.time() < scene.duration) {
      const double h = control.step(system, scene.duration, statistics);
      if (check) {
        EXPECT_LE(statistics.local_error_estimate_last_step, settings.acceptance_ratio * settings.error_per_unit_step * h)
            << "at t = " << control.time();
      }
    }
    EXPECT_EQ(control.time(), scene.duration) << "the last step lands on the limit";
    return statistics;
  };
  const StepStatistics loose = iterations_with(0.01, true);
  const StepStatistics exact = iterations_with(0.0, false);
  std::printf("[ measured ] gauss6 on drive_rr_drag at 1e-8 /s: %llu steps, %llu rejected, %.2f iterations a step "
              "(%.2f converged to round-off)\n",
              static_cast<unsigned long long>(loose.internal_steps), static_cast<unsigned long long>(loose.rejected_steps),
              static_cast<double>(loose.newton_iterations_total) / loose.internal_steps,
              static_cast<double>(exact.newton_iterations_total) / exact.internal_steps);
  EXPECT_GT(loose.internal_steps, 10u);
  EXPECT_LT(loose.newton_iterations_total, exact.newton_iterations_total);
}

TEST(AdaptiveStepControl, AStiffHingeRunsWhereFixedStepsFail) {
  // very_stiff_hinge: k_s = 2e5 N·m/rad, 20 s. At a fixed h = 0.05 s gauss4's stage solve settles on a
  // spurious root and the run fails (or ends far off); the adaptive control meets the tolerance, with
  // rejected attempts that never reach the caller: every state it hands out or passes on its grid is
  // finite and near the reference's scale.
  const Scene scene = shipped("very_stiff_hinge");
  const CartState reference = reference_end(scene);
  Scene fixed = configured(scene, "birkhoff_gauss4", StepControl::kFixed, 0.0);
  fixed.integrator.step_size = 0.05;
  bool fixed_failed = false;
  try {
    Simulation simulation(fixed);
    while (!simulation.at_end()) simulation.step_on_schedule();
    fixed_failed = position_error(simulation.state(), reference) > 1.0;
  } catch (const StepError&) {
    fixed_failed = true;
  }
  EXPECT_TRUE(fixed_failed) << "gauss4 at h = 0.05 s ran the very stiff hinge";
  // Every output row (100 Hz) against dopri5 at 1e-13 at the same instant: a row from a rejected
  // attempt would be off by far more than the tolerance.
  Scene tight = configured(scene, "dopri5", StepControl::kFixed, 1e-13);
  tight.integrator.step_size = 0.01;
  for (const std::string member : {"birkhoff_gauss4", "birkhoff_gauss8"}) {
    Scene adaptive = configured(scene, member, StepControl::kAdaptive, 1e-6);
    adaptive.integrator.step_size = 0.01;
    Simulation simulation(adaptive);
    Simulation lockstep_reference(tight);
    double largest = 0.0;
    double worst_row = 0.0;   // [m]
    double worst_grid = 0.0;  // [m]
    Scene tight_own_steps = tight;
    tight_own_steps.integrator.step_size = tight.duration;
    Simulation grid_reference(tight_own_steps);  // dopri5 at 1e-13 to each grid instant
    simulation.observe_grid([&](const CartState& grid) {
      largest = std::max(largest, std::abs(grid.x) + std::abs(grid.y));
      if (grid.time > grid_reference.state().time) grid_reference.advance_output_to(grid.time);
      if (grid.time == grid_reference.state().time) {
        worst_grid = std::max(worst_grid, position_error(grid, grid_reference.state()));
      }
    });
    while (!simulation.at_end()) {
      simulation.step_on_schedule();
      lockstep_reference.step_on_schedule();
      const CartState& out = simulation.state();
      ASSERT_TRUE(std::isfinite(out.x) && std::isfinite(out.y) && std::isfinite(out.forward_speed));
      ASSERT_EQ(out.time, lockstep_reference.state().time);
      largest = std::max(largest, std::abs(out.x) + std::abs(out.y));
      worst_row = std::max(worst_row, position_error(out, lockstep_reference.state()));
    }
    const double error = position_error(simulation.state(), reference);
    std::printf("[ measured ] very_stiff_hinge %s adaptive at 1e-6 m: error %.2e m (worst of %llu rows %.2e m, of the grid "
                "%.2e m), %llu steps, %llu rejected\n",
                member.c_str(), error, static_cast<unsigned long long>(simulation.statistics().steps), worst_row, worst_grid,
                static_cast<unsigned long long>(simulation.statistics().internal_steps),
                static_cast<unsigned long long>(simulation.statistics().rejected_steps));
    EXPECT_LE(error, 1e-5) << member;
    // The control aims at the tolerance (eq. (B.53)): a grid state may reach twice it; the rows between
    // steps carry the dense output's error on top (docs/accuracy.md §4).
    EXPECT_LE(worst_row, 2e-5) << member << ": an output row off by more than 20x the tolerance";
    EXPECT_LE(worst_grid, 2e-6) << member << ": a grid state off by more than twice the tolerance";
    EXPECT_GT(simulation.statistics().rejected_steps, 0u) << member << ": the start is stiff enough to reject";
    EXPECT_LT(largest, 2.0 * (std::abs(reference.x) + std::abs(reference.y)) + 1.0) << member;
  }
}

TEST(AdaptiveStepControl, AStiffModeIsNotSteppedOverWhileItRings) {
  // very_stiff_hinge's steering mode (400 rad/s) rings for seconds after the start. The collocation
  // defect (B.37) vanishes on linear dynamics and cannot see it: without the linearised error (B.55)
  // the steps jumped over it at t ≈ 2.4 s while it still rang (h·ρ(J) 8 → 165) and the end position
  // was off by 14× the tolerance at 1e-9 m (gauss8), 12× (gauss6), 1.9× and 1.5× at 1e-7 m.
  const Scene scene = shipped("very_stiff_hinge");
  const CartState reference = reference_end(scene);
  for (const std::string member : {"birkhoff_gauss6", "birkhoff_gauss8"}) {
    for (double tolerance : {1e-7, 1e-9}) {
      const RunEnd result = run(configured(scene, member, StepControl::kAdaptive, tolerance));
      const double error = position_error(result.end, reference);
      std::printf("[ measured ] very_stiff_hinge %s adaptive at %.0e m: error %.2e m (%.3g of it), %llu steps, %llu rejected\n",
                  member.c_str(), tolerance, error, error / tolerance,
                  static_cast<unsigned long long>(result.statistics.internal_steps),
                  static_cast<unsigned long long>(result.statistics.rejected_steps));
      EXPECT_LE(error, 2.0 * tolerance) << member << " at " << tolerance << " m";
    }
  }
}

TEST(AdaptiveStepControl, StepsLandOnTheLoadsKinks) {
  // The default scene's drive ramp has corners at 1 s and 4 s: the grid lands on each.
  Scene scene = configured(shipped("default"), "birkhoff_gauss6", StepControl::kAdaptive, 1e-6);
  scene.duration = 8.0;
  Simulation simulation(scene);
  std::vector<double> grid_times;
  simulation.observe_grid([&](const CartState& grid) { grid_times.push_back(grid.time); });
  simulation.advance_output_to(simulation.end_time());
  for (double t = 0.0;;) {
    const double kink = simulation.effects().next_kink_after(t);
    if (!(kink < scene.duration)) break;
    EXPECT_NE(std::find(grid_times.begin(), grid_times.end(), kink), grid_times.end()) << "kink at " << kink << " s";
    t = kink;
  }
  EXPECT_EQ(grid_times.back(), scene.duration) << "the grid lands on the run's end";
}

TEST(DenseOutput, MatchesTheGridAtItsPointsAndATightRunBetween) {
  // The whirl under the adaptive control: outputs every 10 ms come from the Hermite dense output;
  // at grid instants they are the grid's states, between them within a few tolerances of a tight
  // run at the same instants; halving the tolerance shrinks the output error with the grid's.
  Scene scene = configured(shipped("jackknife_whirl"), "birkhoff_gauss8", StepControl::kAdaptive, 1e-8);
  scene.integrator.step_size = 0.01;
  Simulation simulation(scene);
  std::vector<CartState> grid;
  simulation.observe_grid([&](const CartState& state) { grid.push_back(state); });
  Scene tight = configured(shipped("jackknife_whirl"), "dopri5", StepControl::kFixed, 1e-13);
  tight.integrator.step_size = 0.01;
  Simulation reference(tight);
  double worst = 0.0;
  int matched = 0;
  while (!simulation.at_end()) {
    simulation.step_on_schedule();
    reference.step_on_schedule();
    worst = std::max(worst, position_error(simulation.state(), reference.state()));
    for (const CartState& point : grid) {
      if (point.time == simulation.state().time) {
        EXPECT_EQ(point.x, simulation.state().x);
        EXPECT_EQ(point.forward_speed, simulation.state().forward_speed);
        ++matched;
      }
    }
  }
  std::printf("[ measured ] dense output of gauss8 adaptive at 1e-8 m, every 10 ms over 4 s: worst %.2e m against "
              "dopri5 at 1e-13, %zu grid points\n",
              worst, grid.size());
  EXPECT_GE(matched, 1) << "the run's end is a grid point";
  EXPECT_LT(worst, 1e-7);
  EXPECT_GT(grid.size(), 5u);
  EXPECT_LT(grid.size(), 400u) << "far fewer grid steps than outputs";
}

/// Rows every `output_step` [s] through step_on_schedule: the worst position error of B against
/// dopri5 at 1e-13 at the same instants [m], and the run's work.
struct RowsRun {
  double worst = 0.0;                 ///< position [m]
  double worst_steering_angle = 0.0;  ///< [rad]
  double worst_speed = 0.0;           ///< the larger of ω1's [m/s] and ω2's [rad/s]
  std::size_t rows = 0;
  StepStatistics statistics;
};
RowsRun run_rows(Scene scene, double output_step) {
  scene.integrator.step_size = output_step;
  Scene tight = configured(scene, "dopri5", StepControl::kFixed, 1e-13);
  tight.integrator.step_size = output_step;
  Simulation simulation(scene);
  Simulation reference(tight);
  RowsRun rows;
  while (!simulation.at_end()) {
    simulation.step_on_schedule();
    reference.step_on_schedule();
    const CartState& row = simulation.state();
    const CartState& exact = reference.state();
    rows.worst = std::max(rows.worst, position_error(row, exact));
    rows.worst_steering_angle = std::max(rows.worst_steering_angle, std::abs(row.steering_angle - exact.steering_angle));
    rows.worst_speed = std::max({rows.worst_speed, std::abs(row.forward_speed - exact.forward_speed),
                                 std::abs(row.steering_rate - exact.steering_rate)});
    ++rows.rows;
  }
  rows.statistics = simulation.statistics();
  return rows;
}

TEST(SideSteps, RowsAtAHundredHertzCostAFewIterationsEachAndMeetTheTolerance) {
  // gauss8's long steps leave rows between grid points to side steps where the Hermite output's own
  // estimate (on the whole state) exceeds the tolerance (birkhoffian.md §12.3). Under the adaptive
  // control each starts from the grid step's stage points with its J and stops at κτ_a·h (B.49'), a
  // hundredth of the aim: measured 6.7 and 2.8 evaluations per extra row (the dense output serves
  // the rest), where stopping at the grid's κτh took 8.9 on the drive and an explicit start
  // converged to round-off 23.3 and 9.8. Under the reversible control (grid in the fictive time)
  // each starts explicitly, with its own J, but stops at κτh: 13.0, against 17.4.
  struct Case {
    const char* scene;
    StepControl control;
    double tolerance;      // [m]
    double per_row_bound;  // rhs evaluations per extra row [-]
  };
  for (const Case& c : {Case{"drive_rr_drag", StepControl::kAdaptive, 1e-6, 8.0},
                        Case{"free_coast", StepControl::kAdaptive, 1e-3, 5.0},
                        Case{"jackknife_whirl", StepControl::kReversible, 1e-6, 14.5}}) {
    const Scene scene = configured(shipped(c.scene), "birkhoff_gauss8", c.control, c.tolerance);
    const RowsRun sparse = run_rows(scene, 1.0);
    const RowsRun dense = run_rows(scene, 0.01);
    const double per_row = static_cast<double>(dense.statistics.rhs_evaluations - sparse.statistics.rhs_evaluations) /
                           static_cast<double>(dense.rows - sparse.rows);
    const char* control = c.control == StepControl::kAdaptive ? "adaptive" : "reversible";
    std::printf("[ measured ] %s, gauss8 %s at %g m: %llu rhs at rows of 1 Hz, %llu at 100 Hz (%.1f per extra "
                "row), worst row %.2e m\n",
                c.scene, control, c.tolerance, static_cast<unsigned long long>(sparse.statistics.rhs_evaluations),
                static_cast<unsigned long long>(dense.statistics.rhs_evaluations), per_row, dense.worst);
    EXPECT_EQ(dense.statistics.internal_steps, sparse.statistics.internal_steps) << c.scene << ": the grid is the rows'";
    EXPECT_LE(per_row, c.per_row_bound) << c.scene << " " << control;
    EXPECT_LE(dense.worst, 10.0 * c.tolerance) << c.scene << " " << control;
  }
}

TEST(SideSteps, RowsMeetTheToleranceInSpeedsAndAnglesNotInPositionOnly) {
  // A row's dense output is judged on the whole state (the position in metres, z and the angles in
  // ê's weights; grid_dense_output.h), not on the position alone, which passed rows far off:
  //  - after a start the held points crowd at t = 0 (the first steps grow 100× each), and 1 ms into
  //    drive_rr_drag at 1e-5 m the interpolant gave ω1 = −97.9 m/s at a position still near zero (the
  //    energy guard then stopped the run);
  //  - reverse_jackknife at 1e-6 m with rows at 100 Hz ended rows 8.6e-6 m off (now 1.95e-6 m);
  //  - stiff_hinge at 1e-3 m: χ 2.6e-2 rad off (now 3.6e-4 rad).
  Scene start = configured(shipped("drive_rr_drag"), "birkhoff_gauss8", StepControl::kAdaptive, 1e-5);
  start.duration = 0.005;
  const RowsRun ramp = run_rows(start, 0.001);
  EXPECT_LE(ramp.worst_speed, 1e-5) << "rows after the start ramp";
  EXPECT_LE(ramp.worst, 1e-5);
  const RowsRun reverse =
      run_rows(configured(shipped("reverse_jackknife"), "birkhoff_gauss8", StepControl::kAdaptive, 1e-6), 0.01);
  EXPECT_LE(reverse.worst, 4e-6);
  const RowsRun stiff = run_rows(configured(shipped("stiff_hinge"), "birkhoff_gauss8", StepControl::kAdaptive, 1e-3), 0.01);
  EXPECT_LE(stiff.worst_steering_angle, 1e-3);
  std::printf("[ measured ] worst rows: drive_rr_drag start %.2e m/s, %.2e m; reverse_jackknife %.2e m; stiff_hinge "
              "%.2e rad\n",
              ramp.worst_speed, ramp.worst, reverse.worst, stiff.worst_steering_angle);
}

TEST(AdaptiveStepControl, ARunIsDeterministicAndResetRepeatsIt) {
  const Scene scene = configured(shipped("sine_steer_torque"), "birkhoff_gauss6", StepControl::kAdaptive, 1e-6);
  Simulation simulation(scene);
  simulation.advance_output_to(simulation.end_time());
  const CartState first = simulation.state();
  simulation.reset();
  simulation.advance_output_to(simulation.end_time());
  EXPECT_EQ(simulation.state().x, first.x);
  EXPECT_EQ(simulation.state().steering_angle, first.steering_angle);
  const RunEnd again = run(scene);
  EXPECT_EQ(again.end.x, first.x);
  EXPECT_EQ(again.end.y, first.y);
}

TEST(AdaptiveStepControl, BadSettingsAreRefusedByName) {
  Scene scene = configured(shipped("sine_steer_torque"), "rk4", StepControl::kAdaptive, 1e-6);
  try {
    Simulation simulation(scene);
    FAIL() << "rk4 under the adaptive control was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'adaptive' is for"), std::string::npos) << error.what();
  }
  Scene zero = configured(shipped("sine_steer_torque"), "birkhoff_gauss4", StepControl::kAdaptive, 0.0);
  EXPECT_THROW(Simulation simulation(zero), std::invalid_argument);
  Scene actuated = configured(shipped("steering_actuator"), "birkhoff_gauss4", StepControl::kAdaptive, 1e-6);
  try {
    Simulation simulation(actuated);
    FAIL() << "actuators under the adaptive control were accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("adaptive cannot go with"), std::string::npos) << error.what();
  }
  Simulation fixed(configured(shipped("sine_steer_torque"), "birkhoff_gauss4", StepControl::kFixed, 0.0));
  EXPECT_THROW(fixed.advance_output_to(1.0), std::logic_error) << "a fixed-step run has no output between its steps";
  // The control's own settings (adaptive_step_control.h), each refused with its name.
  using Control = AdaptiveStepControl<GaussCollocation<3>, CartAutonomousBirkhoffian,
                                      CarriedCartState<CartAutonomousBirkhoffian, GaussCollocation<3>::Memory<CartAutonomousBirkhoffian>>>;
  auto refusal = [](AdaptiveStepSettings settings) -> std::string {
    try {
      Control control(GaussCollocation<3>(), settings);
    } catch (const std::invalid_argument& error) {
      return error.what();
    }
    return "accepted";
  };
  AdaptiveStepSettings below_aim;
  below_aim.acceptance_ratio = 0.5;
  EXPECT_NE(refusal(below_aim).find("acceptance ratio"), std::string::npos) << refusal(below_aim);
  AdaptiveStepSettings no_margin;
  no_margin.start_exponent_margin = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(refusal(no_margin).find("exponent margin"), std::string::npos) << refusal(no_margin);
  AdaptiveStepSettings no_aim;
  no_aim.error_per_unit_step = -1.0;
  EXPECT_NE(refusal(no_aim).find("error per unit step"), std::string::npos) << refusal(no_aim);
}

}  // namespace
}  // namespace birkhoff_cart
