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

#include "birkhoff_cart/core/autodiff.h"
#include "birkhoff_cart/core/birkhoffian_system.h"
#include "birkhoff_cart/core/cart_birkhoffian.h"
#include "birkhoff_cart/core/effect_library.h"
#include "birkhoff_cart/core/integrators/newton.h"
#include "test_systems.h"

namespace birkhoff_cart {
namespace {

using testing::CubicChartOscillator;
using testing::DampedOscillator;

constexpr double kStructureTolerance = 1e-12;  // relative, Frobenius/max-norm [-]
constexpr double kChartTolerance = 1e-12;      // relative [-]

/// Jet of dimension N+1 over (z, t): z seeded with e_0..e_{N−1}, t with e_N.
template <int N>
struct ZtJets {
  Eigen::Matrix<Jet<N + 1>, N, 1> z;
  Jet<N + 1> t;
  ZtJets(const Eigen::Matrix<double, N, 1>& z_value, double t_value) {
    for (int i = 0; i < N; ++i) z(i) = Jet<N + 1>(z_value(i), N + 1, i);
    t = Jet<N + 1>(t_value, N + 1, N);
  }
};

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

/// Checks K_ij = ∂R_j/∂z_i − ∂R_i/∂z_j, ∇B, ∂R/∂t, the chart identity and the chart rates at (z, t).
template <class System>
void check_structure_against_ad(const System& system, const Eigen::Matrix<double, System::kDimension, 1>& z,
                                double t, const std::string& label) {
  constexpr int N = System::kDimension;
  SCOPED_TRACE(label);
  const ZtJets<N> jets(z, t);
  const auto r = system.birkhoff_functions(jets.z, jets.t);
  const auto b = system.birkhoffian(jets.z, jets.t);
  Eigen::Matrix<double, N, N> dr_dz;  // (i, j) = ∂R_j/∂z_i
  Eigen::Matrix<double, N, 1> dr_dt;
  for (int j = 0; j < N; ++j) {
    dr_dz.col(j) = r(j).derivatives().template head<N>();
    dr_dt(j) = r(j).derivatives()(N);
  }
  const Eigen::Matrix<double, N, N> k_ad = dr_dz - dr_dz.transpose();
  const Eigen::Matrix<double, N, N> k = system.structure_matrix(z, t);
  EXPECT_LE(relative_difference(k, k_ad), kStructureTolerance) << "K\n" << k << "\nAD\n" << k_ad;
  if constexpr (birkhoffian_system_detail::HasStructureMatrixInverse<System, double>::value) {
    const Eigen::Matrix<double, N, N> k_inverse = system.structure_matrix_inverse(z, t);  // analytic K⁻¹
    EXPECT_LE(relative_difference(k_inverse * k, Eigen::Matrix<double, N, N>::Identity()), kStructureTolerance);
  }
  const Eigen::Matrix<double, N, 1> gradient = system.birkhoffian_gradient(z, t);
  EXPECT_LE(relative_difference(gradient, b.derivatives().template head<N>()), kStructureTolerance)
      << gradient.transpose() << " vs AD " << b.derivatives().transpose();
  const Eigen::Matrix<double, N, 1> r_t = system.birkhoff_functions_time_derivative(z, t);
  EXPECT_LE((r_t - dr_dt).norm(), kStructureTolerance * std::max(1.0, dr_dt.norm()))
      << r_t.transpose() << " vs AD " << dr_dt.transpose();

  // Chart: D_zᵀ K₀ D_z = K, D⁻¹(D(z)) = z, ẇ = D_z ż + ∂_t D.
  const auto w_jet = system.to_darboux(jets.z, jets.t);
  Eigen::Matrix<double, N, N> d_z;
  Eigen::Matrix<double, N, 1> d_t, w;
  for (int i = 0; i < N; ++i) {
    w(i) = w_jet(i).value();
    d_z.row(i) = w_jet(i).derivatives().template head<N>().transpose();
    d_t(i) = w_jet(i).derivatives()(N);
  }
  const Eigen::Matrix<double, N, N> k0 = canonical_structure<N>();
  EXPECT_LE(relative_difference(d_z.transpose() * k0 * d_z, k), kChartTolerance);
  const Eigen::Matrix<double, N, 1> z_back = system.from_darboux(w, t);
  EXPECT_LE((z_back - z).norm(), kChartTolerance * std::max(1.0, z.norm()));
  const Eigen::Matrix<double, N, 1> z_rate = birkhoffian_rates(system, z, t);
  const Eigen::Matrix<double, N, 1> w_rate = system.darboux_rates(w, t);
  const Eigen::Matrix<double, N, 1> expected = d_z * z_rate + d_t;
  EXPECT_LE((w_rate - expected).norm(), kChartTolerance * std::max(1.0, expected.norm()))
      << w_rate.transpose() << " vs " << expected.transpose();
}

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
