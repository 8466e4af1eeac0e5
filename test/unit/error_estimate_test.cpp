// The per-step local error estimate ê (StepStatistics, error_estimate.h, docs/accuracy.md §1).
//
// On the paper's closed-form case (docs eq. (3.9)) one step from the exact state at t = 2 s is
// compared with the exact state at t + h. Every method that has an estimate must
//  - record a finite ê ≥ 0 on every step (every registered method);
//  - over-estimate its true local error (ê measures an embedded lower-order solution's error),
//    on the components the closed form gives (x, y, θ, χ, π1), with the same weights;
//  - for the fixed-step methods, shrink by 2^(p̂+1) when h halves (p̂ the embedded order: rk2's
//    Euler 1, rk4's Simpson-type 2, midpoint's Euler predictor 1): ê is an asymptotic estimate,
//    not noise. The ratio is asserted to ±25 %.
// The Birkhoffian members (endpoint quadrature, docs/birkhoffian.md eqs. (B.36)–(B.37)): birkhoff2's ê
// is its true local error within a factor 3 with order 3; the Gauss members' and the compositions' ê
// bounds the true error with slope s + 2 (Gauss) or 4 (compositions: the sub-steps' O(h³) error vectors,
// summed, cancel to O(h⁴) since Σγᵢ³ = 0); the
// estimate only observes (bit-for-bit trajectory with it on or off); a new command torque is not
// mistaken for the last step's end rate. The estimate-to-true ratios are printed; docs/accuracy.md §1's table
// is generated from these steps (generated_docs.h). The passive coordinates count absolutely, the
// Birkhoffian variables relatively above 1 SI unit (A.1).
#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/error_estimate.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/linear_mode_error.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/run/reference_solution.h"
#include "birkhoff_cart/core/run/run_summary.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "generated_docs.h"

namespace birkhoff_cart {
namespace {

constexpr double kStartTime = 2.0;         // t on the closed-form family, away from χ = kπ [s]
constexpr double kRatioSlack = 0.25;       // on ê(h)/ê(h/2) against 2^(p̂+1) [-]

struct OneStep {
  double estimate = std::numeric_limits<double>::quiet_NaN();  ///< ê [-]
  double true_error = 0.0;  ///< the same weighted norm of (x, y, θ, χ, π1) − exact [-]
  bool has_estimate = false;
};

/// The closed-form state at t = kStartTime on the family through the paper scene's start.
CartState exact_at(const Scene& scene, double time) {
  PaperAnalyticSolution solution;
  solution.initial = scene.initial_state;
  return solution.at(time);
}

double weighted(double value, double start) { return std::abs(value) / std::max(1.0, std::abs(start)); }

OneStep one_step(const std::string& integrator, double h) {
  Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/paper_special.yaml");
  const CartState start = exact_at(scene, kStartTime);
  scene.initial_state = start;
  scene.reference = ReferenceSettings{};
  scene.integrator.name = integrator;
  scene.integrator.step_size = h;
  scene.integrator.tolerance = 1e-9;  // dopri5
  Simulation simulation(scene);
  simulation.step();
  const CartState exact = exact_at(scene, kStartTime + h);
  const CartState& state = simulation.state();
  OneStep result;
  result.has_estimate = has_local_error_estimate(simulation.statistics());
  result.estimate = simulation.statistics().local_error_estimate_last_step;
  result.true_error = std::max({weighted(state.x - exact.x, start.x), weighted(state.y - exact.y, start.y),
                                weighted(state.heading - exact.heading, start.heading),
                                weighted(state.steering_angle - exact.steering_angle, start.steering_angle),
                                weighted(state.arc_length - exact.arc_length, start.arc_length)});
  return result;
}

struct Expectation {
  const char* integrator;
  int embedded_order;  ///< p̂; 0: adaptive (no fixed ratio)
};

class LocalErrorEstimate : public ::testing::TestWithParam<Expectation> {};

TEST_P(LocalErrorEstimate, OverEstimatesTheTrueLocalErrorAndShrinksWithItsOrder) {
  const Expectation expectation = GetParam();
  const double h = 0.02;  // [s]
  const OneStep coarse = one_step(expectation.integrator, h);
  const OneStep fine = one_step(expectation.integrator, h / 2);
  ASSERT_TRUE(coarse.has_estimate) << expectation.integrator << " records no local error estimate";
  ASSERT_TRUE(std::isfinite(coarse.estimate) && coarse.estimate >= 0.0) << coarse.estimate;
  ASSERT_TRUE(std::isfinite(fine.estimate) && fine.estimate >= 0.0) << fine.estimate;
  std::printf("%-9s h = %.3g s: ê = %.3e, true = %.3e (ê/true = %.3g); h/2: ê = %.3e, true = %.3e\n",
              expectation.integrator, h, coarse.estimate, coarse.true_error, coarse.estimate / coarse.true_error,
              fine.estimate, fine.true_error);
  EXPECT_GE(coarse.estimate, coarse.true_error);
  EXPECT_GE(fine.estimate, fine.true_error);
  if (expectation.embedded_order > 0) {
    const double expected_ratio = std::pow(2.0, expectation.embedded_order + 1);
    const double ratio = coarse.estimate / fine.estimate;
    EXPECT_NEAR(ratio, expected_ratio, kRatioSlack * expected_ratio) << expectation.integrator;
  }
}

INSTANTIATE_TEST_SUITE_P(NonBirkhoffianMethods, LocalErrorEstimate,
                         ::testing::Values(Expectation{"rk2", 1}, Expectation{"rk4", 2}, Expectation{"midpoint", 1},
                                           Expectation{"dopri5", 0}),
                         [](const ::testing::TestParamInfo<Expectation>& info) {
                           return std::string(info.param.integrator);
                         });

// The Birkhoffian members' endpoint-quadrature estimate (gauss_collocation.h, docs/birkhoffian.md
// eqs. (B.36)–(B.37)) on the same closed-form steps.
constexpr double kSlopeSlack = 0.4;       // on log2(ê(h)/ê(h/2)) against the estimate's order [-]
constexpr double kRoundOffFloor = 1e-13;  // true errors below this are round-off, not a local error [-]

/// log2(ê(h)/ê(h/2)) [-].
double estimate_slope(const std::string& integrator, double h) {
  return std::log2(one_step(integrator, h).estimate / one_step(integrator, h / 2).estimate);
}

TEST(BirkhoffianEstimate, Birkhoff2EstimateIsItsTrueLocalErrorWithinAFactorThreeAndOrderThree) {
  // Simpson on {0, ½, 1} against the midpoint rule: the classical O(h³) estimate of its own error.
  for (double h : {0.08, 0.04, 0.02, 0.01, 0.005}) {
    const OneStep step = one_step("birkhoff2", h);
    ASSERT_TRUE(step.has_estimate);
    const double ratio = step.estimate / step.true_error;
    std::printf("birkhoff2 h = %-6g s: ê = %.3e, true = %.3e, ê/true = %.3g\n", h, step.estimate, step.true_error, ratio);
    EXPECT_GE(ratio, 0.3) << h;
    EXPECT_LE(ratio, 3.0) << h;
  }
  for (double h : {0.04, 0.01}) EXPECT_NEAR(estimate_slope("birkhoff2", h), 3.0, kSlopeSlack) << h;
}

struct BoundExpectation {
  const char* integrator;
  int estimate_order;               ///< slope of ê: s + 2 for Gauss, 4 for the compositions (Σγᵢ³ = 0)
  std::vector<double> bound_steps;  ///< h [s] where the true error is above round-off
  double slope_step;                ///< h [s] of the slope measurement (ê above round-off at h/2)
};

class BirkhoffianBound : public ::testing::TestWithParam<BoundExpectation> {};

TEST_P(BirkhoffianBound, EstimateBoundsTheTrueLocalErrorWithItsOwnOrder) {
  const BoundExpectation expectation = GetParam();
  for (double h : expectation.bound_steps) {
    const OneStep step = one_step(expectation.integrator, h);
    ASSERT_TRUE(step.has_estimate) << expectation.integrator;
    ASSERT_GT(step.true_error, kRoundOffFloor) << expectation.integrator << " h = " << h << ": choose a larger step";
    std::printf("%-19s h = %-6g s: ê = %.3e, true = %.3e, ê/true = %.3g\n", expectation.integrator, h, step.estimate,
                step.true_error, step.estimate / step.true_error);
    EXPECT_GE(step.estimate, step.true_error) << expectation.integrator << " h = " << h;
  }
  const double slope = estimate_slope(expectation.integrator, expectation.slope_step);
  std::printf("%-19s log2(ê(h)/ê(h/2)) at h = %g s: %.3f (expected %d)\n", expectation.integrator,
              expectation.slope_step, slope, expectation.estimate_order);
  EXPECT_NEAR(slope, expectation.estimate_order, kSlopeSlack) << expectation.integrator;
}

INSTANTIATE_TEST_SUITE_P(
    GaussAndCompositions, BirkhoffianBound,
    ::testing::Values(BoundExpectation{"birkhoff_gauss4", 4, {0.16, 0.08, 0.04, 0.02, 0.01}, 0.04},
                      BoundExpectation{"birkhoff_gauss6", 5, {0.32, 0.16, 0.08}, 0.08},
                      BoundExpectation{"birkhoff_gauss8", 6, {0.32, 0.16}, 0.08},
                      BoundExpectation{"birkhoff4", 4, {0.16, 0.08, 0.04, 0.02, 0.01}, 0.02},
                      BoundExpectation{"birkhoff4_suzuki", 4, {0.16, 0.08, 0.04, 0.02, 0.01}, 0.02},
                      BoundExpectation{"birkhoff6_kahan_li", 4, {0.16, 0.08, 0.04}, 0.02},
                      BoundExpectation{"birkhoff8_kahan_li", 4, {0.32, 0.16}, 0.02}),
    [](const ::testing::TestParamInfo<BoundExpectation>& info) { return std::string(info.param.integrator); });

bool is_birkhoffian(const std::string& integrator) { return integrator.rfind("birkhoff", 0) == 0; }

/// `value` with `digits` digits after the point in the pages' exponent style: 1.7e-3, 9.1e4 [-].
std::string compact_exponent(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*e", digits, value);
  std::string out(text);
  const auto e = out.find('e');
  const bool negative = out[e + 1] == '-';
  std::string exponent = out.substr(e + 2);
  exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
  return out.substr(0, e) + "e" + (negative ? "-" : "") + exponent;
}

/// ê / true error as the page writes it: 2.1, 95, 477, 9.1e4 [-].
std::string ratio_as_written(double ratio) {
  char text[32];
  if (ratio < 10.0) {
    std::snprintf(text, sizeof text, "%.1f", ratio);
  } else if (ratio < 1000.0) {
    std::snprintf(text, sizeof text, "%.0f", ratio);
  } else {
    return compact_exponent(ratio, 1);
  }
  return text;
}

TEST(LocalErrorEstimate, TheAccuracyPagesTableIsWhatTheseStepsMeasure) {
  // docs/accuracy.md §1's table: one step of h and of h/2 from the exact state at t = 2 s, as the
  // tests above take them; the Gauss members of six and eight stages at a longer step, where their
  // true error is above round-off.
  struct Row {
    const char* integrator;
    double step;         ///< h [s]
    int expected_ratio;  ///< 2^(p̂+1) of ê(h)/ê(h/2); 0: adaptive, no fixed ratio
  };
  const Row rows[] = {{"rk2", 0.02, 4},
                      {"rk4", 0.02, 8},
                      {"midpoint", 0.02, 4},
                      {"dopri5", 0.02, 0},
                      {"birkhoff2", 0.02, 8},
                      {"birkhoff_gauss4", 0.02, 16},
                      {"birkhoff_gauss6", 0.08, 32},
                      {"birkhoff_gauss8", 0.16, 64},
                      {"birkhoff4", 0.02, 16},
                      {"birkhoff4_suzuki", 0.02, 16}};
  std::string table =
      "| method | h = 0.02 s: ê | true | ê / true | h = 0.01 s: ê | ê(h)/ê(h/2) (expected) |\n"
      "|---|---|---|---|---|---|\n";
  for (const Row& row : rows) {
    const OneStep coarse = one_step(row.integrator, row.step);
    const OneStep fine = one_step(row.integrator, row.step / 2);
    ASSERT_TRUE(coarse.has_estimate && fine.has_estimate) << row.integrator;
    char step_note[32] = "";
    if (row.step != 0.02) std::snprintf(step_note, sizeof step_note, " (h = %g s)", row.step);
    std::string halving = "– (adaptive)";
    if (row.expected_ratio > 0) {
      char text[48];
      std::snprintf(text, sizeof text, "%.1f (%d)", coarse.estimate / fine.estimate, row.expected_ratio);
      halving = text;
    }
    table += "| " + std::string(row.integrator) + (row.integrator == std::string("dopri5") ? " (tol 1e-9)" : "") +
             step_note + " | " + compact_exponent(coarse.estimate, 1) + " | " + compact_exponent(coarse.true_error, 1) +
             " | " + ratio_as_written(coarse.estimate / coarse.true_error) + " | " + compact_exponent(fine.estimate, 1) +
             " | " + halving + " |\n";
  }
  EXPECT_TRUE(birkhoff_cart_test::docs_part_is_current("docs/accuracy.md", "error_estimate_test", table));
}

/// `steps` steps of `scene` with the estimate on or off; the states after each step.
std::vector<CartState> trajectory(Scene scene, bool estimate, int steps, StepStatistics* statistics) {
  scene.integrator.local_error_estimate = estimate;
  Simulation simulation(scene);
  std::vector<CartState> states;
  for (int k = 0; k < steps; ++k) {
    simulation.step();
    states.push_back(simulation.state());
  }
  *statistics = simulation.statistics();
  return states;
}

TEST(BirkhoffianEstimate, OnlyObservesTheTrajectoryIsTheSameBitForBitWithItOnOrOff) {
  // The whirl (autonomous chart, angles reduced, first same as last) and the paper case (rep (a): a
  // new chart epoch every step). What the estimate costs, the evaluations a step with it on beyond
  // those with it off, is docs/birkhoffian.md §10.5's table (generated_docs.h); the differences are
  // the same on both stage-evaluation paths, the counts themselves are not.
  std::map<std::string, std::string> rows;  // member → its cells
  for (const char* scene_name : {"jackknife_whirl", "paper_special"}) {
    Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/" + scene_name + ".yaml");
    scene.reference = ReferenceSettings{};
    scene.integrator.step_size = 0.01;  // [s]
    for (const std::string& integrator : integrator_names()) {
      if (!is_birkhoffian(integrator)) continue;
      scene.integrator.name = integrator;
      StepStatistics with;
      StepStatistics without;
      const std::vector<CartState> on = trajectory(scene, true, 60, &with);
      const std::vector<CartState> off = trajectory(scene, false, 60, &without);
      for (std::size_t k = 0; k < on.size(); ++k) {
        ASSERT_EQ(std::memcmp(&on[k], &off[k], sizeof(CartState)), 0) << scene_name << " " << integrator << " step " << k;
      }
      EXPECT_EQ(with.steps_with_error_estimate, 60u) << integrator;
      EXPECT_FALSE(has_local_error_estimate(without)) << integrator;
      EXPECT_EQ(with.newton_iterations_total, without.newton_iterations_total) << integrator;
      EXPECT_GT(with.rhs_evaluations, without.rhs_evaluations) << integrator;
      std::printf("%-15s %-19s per step, estimate on / off: rhs %.3f / %.3f, passive %.3f / %.3f\n", scene_name,
                  integrator.c_str(), static_cast<double>(with.rhs_evaluations) / 60.0,
                  static_cast<double>(without.rhs_evaluations) / 60.0,
                  static_cast<double>(with.passive_evaluations) / 60.0,
                  static_cast<double>(without.passive_evaluations) / 60.0);
      char cells[64];
      std::snprintf(cells, sizeof cells, " %.2f / %.2f |",
                    static_cast<double>(with.rhs_evaluations - without.rhs_evaluations) / 60.0,
                    static_cast<double>(with.passive_evaluations - without.passive_evaluations) / 60.0);
      rows[integrator] += cells;
    }
  }
  std::string table = "| member | jackknife_whirl: extra rhs / passive evaluations a step | paper_special (paper form) |\n|---|---|---|\n";
  for (const std::string& integrator : integrator_names()) {
    if (rows.count(integrator) != 0) table += "| `" + integrator + "` |" + rows[integrator] + "\n";
  }
  EXPECT_TRUE(birkhoff_cart_test::docs_part_is_current("docs/birkhoffian.md", "error_estimate_test", table));
}

TEST(BirkhoffianEstimate, ANewCommandIsSeenAtTheStepStartNotTheLastStepsEndRate) {
  // First same as last must not carry F(w⁺) of the old torque into the step after a command.
  Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/driven.yaml");
  scene.integrator.name = "birkhoff_gauss4";
  scene.integrator.step_size = 0.01;  // [s]
  constexpr double kNewTorque = 5.0;  // [N·m]
  Simulation carried(scene);
  for (int k = 0; k < 20; ++k) carried.step();
  Scene restarted_scene = scene;
  restarted_scene.initial_state = carried.state();
  carried.set_steering_command(kNewTorque);
  carried.step();
  Simulation restarted(restarted_scene);  // no memory: F(w, tₖ) evaluated with the new torque
  restarted.set_steering_command(kNewTorque);
  restarted.step();
  const double carried_estimate = carried.statistics().local_error_estimate_last_step;
  const double restarted_estimate = restarted.statistics().local_error_estimate_last_step;
  std::printf("after a new command: ê carried = %.6e, restarted = %.6e\n", carried_estimate, restarted_estimate);
  EXPECT_NEAR(carried_estimate, restarted_estimate, 1e-6 * restarted_estimate);
}

TEST(LocalErrorEstimate, EveryRegisteredMethodRecordsAFiniteEstimateAndTheSummaryShowsIt) {
  for (const std::string& integrator : integrator_names()) {
    const OneStep result = one_step(integrator, 0.01);
    ASSERT_TRUE(result.has_estimate) << integrator;
    EXPECT_TRUE(std::isfinite(result.estimate) && result.estimate >= 0.0) << integrator << ": " << result.estimate;
    Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/free_coast.yaml");
    scene.integrator.name = integrator;
    Simulation simulation(scene);
    for (int k = 0; k < 5; ++k) simulation.step();
    const std::string summary = local_error_estimate_summary(simulation.statistics(), integrator);
    EXPECT_EQ(summary.find("none"), std::string::npos) << integrator << ": " << summary;
    // Once per step: a member's own steps where it takes them (dopri5's run), else the caller's.
    const std::uint64_t steps = simulation.statistics().internal_steps > 0 ? simulation.statistics().internal_steps : 5u;
    EXPECT_EQ(simulation.statistics().steps_with_error_estimate, steps) << integrator;
  }
}

TEST(LocalErrorEstimate, TurnedOffTheBirkhoffianMembersRecordNoneAndTheSummarySaysSo) {
  Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/free_coast.yaml");
  scene.integrator.name = "birkhoff8_kahan_li";
  scene.integrator.local_error_estimate = false;
  Simulation simulation(scene);
  simulation.step();
  EXPECT_FALSE(has_local_error_estimate(simulation.statistics()));
  EXPECT_NE(local_error_estimate_summary(simulation.statistics(), "birkhoff8_kahan_li").find("none"), std::string::npos);
}

TEST(LocalErrorEstimate, RecordKeepsLastLargestAndSumAndResetForgetsThem) {
  StepStatistics statistics;
  EXPECT_FALSE(has_local_error_estimate(statistics));
  EXPECT_TRUE(std::isnan(statistics.local_error_estimate_last_step));
  record_local_error_estimate(statistics, 2e-6);
  record_local_error_estimate(statistics, 1e-6);
  EXPECT_TRUE(has_local_error_estimate(statistics));
  EXPECT_EQ(statistics.local_error_estimate_last_step, 1e-6);
  EXPECT_EQ(statistics.local_error_estimate_max, 2e-6);
  EXPECT_DOUBLE_EQ(statistics.local_error_estimate_sum, 3e-6);
  EXPECT_EQ(statistics.steps_with_error_estimate, 2u);
  record_local_error_estimate(statistics, std::nan(""));
  EXPECT_TRUE(std::isnan(statistics.local_error_estimate_max));  // a NaN is never hidden by max()
  record_local_error_estimate(statistics, 1.0);
  EXPECT_TRUE(std::isnan(statistics.local_error_estimate_max));

  Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/free_coast.yaml");
  scene.integrator.name = "rk4";
  Simulation simulation(scene);
  simulation.step();
  simulation.step();
  EXPECT_EQ(simulation.statistics().steps_with_error_estimate, 2u);
  simulation.reset();
  EXPECT_FALSE(has_local_error_estimate(simulation.statistics()));
}

// ----------------------------------------------------------------------------------------------
// The linearised error (B.54): what the defect estimate cannot see.

/// The s-stage Gauss step's own error on ẇ = J w + c from a start rate F: h (ψ_s(hJ) − φ₁(hJ)) F, with
/// ψ_s from the collocation equations themselves (K = (I − h A ⊗ J)⁻¹ (1 ⊗ F), Δw = h Σ bᵢ Kᵢ) and φ₁
/// from Eigen's matrix exponential of the bordered matrix: independent of linear_mode_error's Padé sums.
template <int Stages>
Eigen::Vector4d linear_gauss_step_error(const Eigen::Matrix4d& jacobian, const Eigen::Vector4d& rate, double h) {
  const GaussLegendreTableau& tableau = gauss_legendre_tableau(Stages);
  Eigen::Matrix<double, 4 * Stages, 4 * Stages> system = Eigen::Matrix<double, 4 * Stages, 4 * Stages>::Identity();
  Eigen::Matrix<double, 4 * Stages, 1> right;
  for (int i = 0; i < Stages; ++i) {
    right.template segment<4>(4 * i) = rate;
    for (int j = 0; j < Stages; ++j) system.template block<4, 4>(4 * i, 4 * j) -= h * tableau.coefficients[i][j] * jacobian;
  }
  const Eigen::Matrix<double, 4 * Stages, 1> stages = system.partialPivLu().solve(right);
  Eigen::Vector4d collocation = Eigen::Vector4d::Zero();
  for (int i = 0; i < Stages; ++i) collocation += h * tableau.weights[i] * stages.template segment<4>(4 * i);
  Eigen::Matrix<double, 5, 5> bordered = Eigen::Matrix<double, 5, 5>::Zero();
  bordered.topLeftCorner<4, 4>() = h * jacobian;
  bordered.topRightCorner<4, 1>() = h * rate;
  const Eigen::Matrix<double, 5, 5> exact = bordered.exp();
  return collocation - exact.topRightCorner<4, 1>();
}

/// A stiff hinge's steering mode (400 rad/s, lightly damped) beside a slow one, coupled.
Eigen::Matrix4d stiff_and_slow_modes() {
  Eigen::Matrix4d jacobian;
  jacobian << 0.0, 1.0, 0.0, 0.0,
      -400.0 * 400.0, -5.0, 0.3, 0.0,
      0.0, 0.0, 0.0, 1.0,
      2.0, 0.0, -1.7, -0.2;
  return jacobian;
}

template <int Stages>
void expect_linear_mode_error_is_the_steps_error() {
  const Eigen::Matrix4d jacobian = stiff_and_slow_modes();
  const Eigen::Vector4d rate(0.7, -120.0, 0.4, -0.9);
  const double stiffness = 400.0;  // ρ(J) [1/s]
  // Smooth motion (h·ρ ≤ 0.4, where the step's error is above round-off): e_L is the step's error to
  // leading order, and of order 2s + 1.
  const std::vector<double> smooth = Stages == 4 ? std::vector<double>{0.2, 0.4} : std::vector<double>{0.1, 0.2, 0.4};
  for (double h_rho : smooth) {
    const double h = h_rho / stiffness;
    const Eigen::Vector4d estimated = linear_mode_error<Stages>(jacobian, rate, h, 0.0);
    const Eigen::Vector4d exact = linear_gauss_step_error<Stages>(jacobian, rate, h);
    std::printf("[ measured ] s = %d, h*rho = %.2g: |e_L| %.3e, |step error| %.3e\n", Stages, h_rho, estimated.norm(), exact.norm());
    EXPECT_NEAR(estimated.norm() / exact.norm(), 1.0, 0.05) << "s = " << Stages << ", h*rho = " << h_rho;
  }
  const double larger = Stages == 4 ? 0.4 : 0.1;  // h·ρ of the longer of two steps, the other half of it
  const double halved = linear_mode_error<Stages>(jacobian, rate, larger / stiffness, 0.0).norm() /
                        linear_mode_error<Stages>(jacobian, rate, 0.5 * larger / stiffness, 0.0).norm();
  std::printf("[ measured ] s = %d: e_L falls %.1fx when h halves (order %.2f)\n", Stages, halved, std::log2(halved));
  EXPECT_NEAR(std::log2(halved), 2 * Stages + 1, 0.4) << "s = " << Stages << ": the order of e_L";
  // A step over the mode (h·ρ ≫ 1): the error is the mode's own size, and e_L reads it within a few
  // times (R_s − R_{s+1} tends to twice the mode's share where the true step damps it).
  for (double h_rho : {10.0, 100.0, 1000.0}) {
    const double h = h_rho / stiffness;
    const double estimated = linear_mode_error<Stages>(jacobian, rate, h, 0.0).norm();
    const double exact = linear_gauss_step_error<Stages>(jacobian, rate, h).norm();
    std::printf("[ measured ] s = %d, h*rho = %.0f: |e_L| %.3e, |step error| %.3e\n", Stages, h_rho, estimated, exact);
    EXPECT_GE(estimated, 0.2 * exact) << "s = " << Stages << ", h*rho = " << h_rho;
    EXPECT_LE(estimated, 5.0 * exact) << "s = " << Stages << ", h*rho = " << h_rho;
  }
}

TEST(LinearModeError, IsTheGaussStepsOwnErrorOnLinearDynamicsWhereTheDefectReadsZero) {
  expect_linear_mode_error_is_the_steps_error<2>();
  expect_linear_mode_error_is_the_steps_error<3>();
  expect_linear_mode_error_is_the_steps_error<4>();
}

TEST(LinearModeError, IsNotComputedWhereItsLeadingTermCannotMatter) {
  const Eigen::Matrix4d jacobian = stiff_and_slow_modes();
  const Eigen::Vector4d rate(0.7, -120.0, 0.4, -0.9);
  const double h = 0.1 / 400.0;  // h·ρ = 0.1
  const Eigen::Vector4d full = linear_mode_error<4>(jacobian, rate, h, 0.0);
  ASSERT_GT(full.norm(), 0.0);
  // The leading term c_4 ‖(hJ)⁸ hF‖ bounds it here: a `negligible` above it returns exactly zero.
  EXPECT_TRUE(linear_mode_error<4>(jacobian, rate, h, 10.0 * full.cwiseAbs().maxCoeff()).isZero(0.0));
  EXPECT_TRUE(linear_mode_error<4>(jacobian, rate, h, 0.1 * full.cwiseAbs().maxCoeff()).isApprox(full));
}

// ê of (A.1) (accuracy.md §1): the Birkhoffian variables relatively above 1 SI unit, the passive
// coordinates absolutely whatever their size — the positions, the wheel angles, the loads' work W and
// impulse I2, which grow through a run (W reaches thousands of joules on a drive). Measured relatively,
// as odeint's norm, a 1 nJ step error in a W of 2000 J read as 5e-13 and a step control let it grow.
TEST(LocalErrorEstimate, ThePassiveCoordinatesCountAbsolutelyTheBirkhoffianRelativelyAboveOne) {
  using System = CartAutonomousBirkhoffian;
  StateVector<System, double> z_start;
  z_start << 30.0, 0.2, 300.0, 0.5;  // π1 [m], χ [rad], p1 [kg·m/s], p2 [kg·m²/s]
  PassiveVector<System, double> y_start;
  y_start << 1e4, -1e4, 3.0, 2000.0, 2000.0, 2100.0, 2100.0, 2000.0, 50.0;  // x, y, θ, φ1..φ4, W, I2
  const auto norm = [&](const StateVector<System, double>& z_error, const PassiveVector<System, double>& y_error) {
    return local_error_norm<System, double>(z_start, y_start, z_error, y_error);
  };
  const StateVector<System, double> no_z_error = StateVector<System, double>::Zero();
  const PassiveVector<System, double> no_y_error = PassiveVector<System, double>::Zero();
  for (int i = 0; i < System::kPassiveDimension; ++i) {
    PassiveVector<System, double> y_error = no_y_error;
    y_error(i) = -1e-9;
    EXPECT_EQ(norm(no_z_error, y_error), 1e-9) << "passive " << i;
  }
  StateVector<System, double> z_error = no_z_error;
  z_error(2) = 3e-7;  // on p1 = 300 kg·m/s: relative
  EXPECT_DOUBLE_EQ(norm(z_error, no_y_error), 1e-9);
  z_error(2) = 0.0;
  z_error(1) = 1e-9;  // on χ = 0.2 rad: absolute below 1
  EXPECT_EQ(norm(z_error, no_y_error), 1e-9);
  PassiveVector<System, double> y_error = no_y_error;
  y_error(0) = std::nan("");
  EXPECT_TRUE(std::isnan(norm(no_z_error, y_error)));
}

}  // namespace
}  // namespace birkhoff_cart
