// The Birkhoffian-system concept (docs/birkhoffian.md §1–§2) on the test systems and the cart:
// the analytic K, ∇B, ∂R/∂t agree with automatic differentiation of R and B; the Darboux chart
// satisfies D_zᵀ K₀ D_z = K and ẇ = D_z ż + ∂_t D; and the Newton solver (integrators/newton.h)
// converges to round-off, differentiates through its root, and fails loudly.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/integrators/newton.h"
#include "structure_checks.h"
#include "test_systems.h"

namespace birkhoff_cart {
namespace {

using testing::CubicChartOscillator;
using testing::DampedOscillator;

using birkhoff_cart_test::check_structure_against_ad;

TEST(TestSystems, DampedOscillatorStructureMatchesAutomaticDifferentiation) {
  DampedOscillator oscillator;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (bool forced : {false, true}) {
    oscillator.forcing_enabled = forced;
    oscillator.forcing_amplitude = 0.7;
    for (int trial = 0; trial < 5; ++trial) {
      check_structure_against_ad(oscillator, Eigen::Vector2d(uniform(random), uniform(random)), 3.0 * uniform(random),
                                 "damped oscillator, forced " + std::to_string(forced));
    }
  }
}

TEST(TestSystems, DampedOscillatorRatesAreTheDampedOscillatorEquations) {
  DampedOscillator oscillator;
  oscillator.forcing_enabled = true;
  oscillator.forcing_amplitude = 0.7;
  const Eigen::Vector2d z(0.4, -1.1);
  const double t = 0.8;
  const Eigen::Vector2d rate = birkhoffian_rates(oscillator, z, t);
  EXPECT_NEAR(rate(0), z(1) / oscillator.mass, 1e-14);
  EXPECT_NEAR(rate(1), -oscillator.stiffness * z(0) - oscillator.damping * z(1) + oscillator.forcing(t), 1e-14);
}

TEST(TestSystems, DampedOscillatorExactSolutionSolvesTheEquations) {
  const DampedOscillator oscillator;
  const Eigen::Vector2d z0(0.9, 0.2);
  const double t0 = 0.3, t = 1.7, dt = 1e-5;  // [s]
  Eigen::Vector2d z_plus, z_minus, z_now;
  double y_plus, y_minus, y_now;
  oscillator.exact(t0, z0, 0.0, t + dt, z_plus, y_plus);
  oscillator.exact(t0, z0, 0.0, t - dt, z_minus, y_minus);
  oscillator.exact(t0, z0, 0.0, t, z_now, y_now);
  const Eigen::Vector2d rate = birkhoffian_rates(oscillator, z_now, t);
  constexpr double kCentralDifferenceTolerance = 1e-8;  // O(dt²) [-]
  EXPECT_NEAR((z_plus(0) - z_minus(0)) / (2 * dt), rate(0), kCentralDifferenceTolerance);
  EXPECT_NEAR((z_plus(1) - z_minus(1)) / (2 * dt), rate(1), kCentralDifferenceTolerance);
  EXPECT_NEAR((y_plus - y_minus) / (2 * dt), z_now(0), kCentralDifferenceTolerance);
}

TEST(TestSystems, CubicChartOscillatorStructureMatchesAutomaticDifferentiation) {
  const CubicChartOscillator system;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  for (int trial = 0; trial < 8; ++trial) {
    check_structure_against_ad(system, Eigen::Vector2d(uniform(random), uniform(random)), uniform(random),
                               "cubic chart oscillator");
  }
}

TEST(TestSystems, CubicChartInverseIsAccurateOverManyDecades) {
  for (double big_p : {-1e8, -3e3, -2.5, -1e-3, -1e-12, 0.0, 1e-15, 1e-6, 0.7, 40.0, 1e10}) {
    const double p = testing::cubic_chart_inverse(big_p);
    EXPECT_LE(std::abs(CubicChartOscillator::chart_momentum(p) - big_p), 4e-16 * std::max(std::abs(big_p), 1e-300))
        << "P = " << big_p;
  }
}

TEST(TestSystems, CubicChartExactSolutionSolvesTheEquations) {
  const CubicChartOscillator system;
  const Eigen::Vector2d z0(0.5, 1.2);
  const double t0 = 0.0, t = 2.3, dt = 1e-5;  // [s]
  const Eigen::Vector2d rate = birkhoffian_rates(system, system.exact(t0, z0, t), t);
  const Eigen::Vector2d difference = (system.exact(t0, z0, t + dt) - system.exact(t0, z0, t - dt)) / (2 * dt);
  EXPECT_LE((difference - rate).norm(), 1e-8);
}

TEST(CartSystems, StructureAndChartMatchAutomaticDifferentiation) {
  // Both representations, with loads on (Λ ≠ 0) and off, on the physical cart and the paper's case.
  std::vector<EffectSpec> specs(3);
  specs[0].name = "steering_torque";
  specs[0].profile.kind = TorqueProfile::Kind::kCosine;
  specs[0].profile.amplitude = 2.0;  // [N·m]
  specs[0].profile.frequency = 0.5;  // [Hz]
  specs[1].name = "air_drag";
  specs[1].coefficients = {{"coefficient", 0.4}};
  specs[2].name = "steering_damping";
  specs[2].coefficients = {{"coefficient", 1.5}};
  CartParameters paper_parameters;
  paper_parameters.wheelbase = 1.0;
  for (const CartModel& model : {CartModel(CartParameters{}), CartModel(paper_parameters, InertiaModel::kPaperSpecialCase)}) {
    const EffectSet effects = build_effects(specs, model);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> uniform(-1.2, 1.2);
    for (bool enabled : {true, false}) {
      CartAutonomousBirkhoffian autonomous(model, effects);
      CartPaperBirkhoffian paper(model, effects);
      autonomous.set_non_birkhoffian_force_enabled(enabled);
      paper.set_non_birkhoffian_force_enabled(enabled);
      for (int trial = 0; trial < 4; ++trial) {
        const Eigen::Vector4d z(10.0 * uniform(random), uniform(random), 5.0 * uniform(random), uniform(random));
        const double t = 4.0 + uniform(random);
        paper.begin_step(t - 0.3 * uniform(random));
        const std::string label = std::string(model.inertia_model() == InertiaModel::kPhysical ? "physical" : "paper") +
                                  (enabled ? ", loads on" : ", Birkhoffian part");
        check_structure_against_ad(autonomous, z, t, "cart (b), " + label);
        check_structure_against_ad(paper, z, t, "cart (a), " + label);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Newton's method

/// F(x) = (x0² + x1² − 4, x0 − x1 − a) with a parameter a (a double or a jet).
template <class S>
auto circle_line_factory(const S& a) {
  return [a](auto cast) {
    return [a, cast](const auto& x) {
      using T = typename std::decay_t<decltype(x)>::Scalar;
      const T offset = cast.template scalar<T>(a);
      Eigen::Matrix<T, 2, 1> f;
      f(0) = x(0) * x(0) + x(1) * x(1) - 4.0;
      f(1) = x(0) - x(1) - offset;
      return f;
    };
  };
}

TEST(Newton, ConvergesToRoundOffAndCountsIterations) {
  Eigen::Vector2d x(2.0, 0.5);
  StepStatistics statistics;
  const int iterations = solve_newton<2>(circle_line_factory(0.5), x, NewtonSettings{}, 0.0, statistics);
  EXPECT_NEAR(x(0) * x(0) + x(1) * x(1), 4.0, 1e-15 * 4.0);
  EXPECT_NEAR(x(0) - x(1), 0.5, 1e-15);
  EXPECT_GE(iterations, 3);
  EXPECT_LE(iterations, 10);
  EXPECT_EQ(statistics.newton_iterations_total, static_cast<std::uint64_t>(iterations));
  EXPECT_GE(statistics.rhs_evaluations, statistics.newton_iterations_total);
}

TEST(Newton, JetRootCarriesTheImplicitFunctionDerivative) {
  // Root x(a) of the circle–line system; dx/da by the implicit function theorem:
  // J dx/da = −∂F/∂a = (0, 1).
  using J1 = Jet<1>;
  const J1 a(0.5, 1, 0);
  Eigen::Matrix<J1, 2, 1> x;
  x << J1(2.0), J1(0.5);
  StepStatistics statistics;
  solve_newton<2>(circle_line_factory(a), x, NewtonSettings{}, 0.0, statistics);
  const double x0 = x(0).value(), x1 = x(1).value();
  Eigen::Matrix2d jacobian;
  jacobian << 2 * x0, 2 * x1, 1.0, -1.0;
  const Eigen::Vector2d expected = jacobian.inverse() * Eigen::Vector2d(0.0, 1.0);
  EXPECT_NEAR(x(0).derivatives()(0), expected(0), 1e-14);
  EXPECT_NEAR(x(1).derivatives()(0), expected(1), 1e-14);
  EXPECT_NEAR(x0 - x1, 0.5, 1e-15);
}

TEST(Newton, NoRootThrowsStepErrorNamingTimeAndResidual) {
  // The line x0 − x1 = 5 misses the circle of radius 2: Newton wanders and must give up.
  Eigen::Vector2d x(2.0, 0.5);
  StepStatistics statistics;
  NewtonSettings settings;
  settings.max_iterations = 25;
  try {
    solve_newton<2>(circle_line_factory(5.0), x, settings, 12.5, statistics);
    FAIL() << "expected StepError";
  } catch (const StepError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("t = 12.5"), std::string::npos) << message;
    EXPECT_NE(message.find("residual"), std::string::npos) << message;
  }
}

TEST(Newton, NonFiniteResidualThrowsStepError) {
  const auto factory = [](auto cast) {
    return [cast](const auto& x) {
      using std::log;
      using T = typename std::decay_t<decltype(x)>::Scalar;
      Eigen::Matrix<T, 1, 1> f;
      f(0) = log(x(0)) + 1.0;  // NaN for x ≤ 0
      return f;
    };
  };
  Eigen::Matrix<double, 1, 1> x(-1.0);
  StepStatistics statistics;
  EXPECT_THROW(solve_newton<1>(factory, x, NewtonSettings{}, 1.0, statistics), StepError);
}

}  // namespace
}  // namespace birkhoff_cart
