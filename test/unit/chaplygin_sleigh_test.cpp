// The example system of docs/integrators.md, "Bring your own system": the Chaplygin sleigh
// (include/birkhoff_cart/core/examples/chaplygin_sleigh.h) models the Birkhoffian-system concept.
// Its structure (K, ∇B, ∂R/∂t, the chart) agrees with automatic differentiation in both forms; its
// closed-form motion (S.3) solves its equations (S.1); its closed-form Jacobian is AD's; the optional
// hooks change nothing but the cost (the same trajectory as the bare system to round-off); and a
// member run reaches the known asymptotics (v → V, the total turn πΩ/λ). The registry's members
// integrate it in the typed suites of integrator_contract_test (order against (S.3), energy over a
// long run, reversal) and k_symplectic_test (K-symplecticity, +h/−h symmetry).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/examples/chaplygin_sleigh.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "generated_docs.h"
#include "structure_checks.h"

namespace birkhoff_cart {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kJacobianTolerance = 1e-13;   // |J − J_AD| relative to max(1, |J_AD|) [-]
constexpr double kHookTolerance = 1e-13;       // hooked vs bare trajectory, relative [-]
constexpr double kRateTolerance = 1e-8;        // closed form's central difference vs the rates, relative [-]

ChaplyginSleighParameters sleigh_parameters(double conformal_rate) {
  ChaplyginSleighParameters parameters;
  parameters.conformal_rate = conformal_rate;
  parameters.structure_epoch = 0.5;
  return parameters;
}

/// The sleigh seen only through the concept's required members: none of the optional hooks.
struct BareSleigh {
  static constexpr int kDimension = ChaplyginSleigh::kDimension;
  static constexpr int kPassiveDimension = ChaplyginSleigh::kPassiveDimension;
  template <class S>
  using Vector = ChaplyginSleigh::Vector<S>;
  template <class S>
  using Matrix = ChaplyginSleigh::Matrix<S>;
  ChaplyginSleigh sleigh;

  bool non_birkhoffian_force_enabled() const { return sleigh.non_birkhoffian_force_enabled(); }
  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& t) const { return sleigh.birkhoff_functions(z, t); }
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& t) const { return sleigh.birkhoffian(z, t); }
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& z, const S& t) const { return sleigh.structure_matrix(z, t); }
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& t) const { return sleigh.birkhoffian_gradient(z, t); }
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const {
    return sleigh.birkhoff_functions_time_derivative(z, t);
  }
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& t) const { return sleigh.non_birkhoffian_force(z, t); }
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& t) const { return sleigh.to_darboux(z, t); }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& t) const { return sleigh.from_darboux(w, t); }
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& t) const { return sleigh.darboux_rates(w, t); }
  template <class S>
  ChaplyginSleigh::Passive<S> passive_rates(const Vector<S>& z, const S& t) const { return sleigh.passive_rates(z, t); }
};

/// Calls check(sleigh, z, t, label) at four random points (z, t) of each form of the sleigh (γ = 0
/// and 1), with and without the blade's reaction.
template <class Check>
void at_random_points_of_every_form(unsigned seed, Check check) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (double gamma : {0.0, 1.0}) {
    ChaplyginSleigh sleigh(sleigh_parameters(gamma));
    for (bool with_force : {true, false}) {
      sleigh.set_non_birkhoffian_force_enabled(with_force);
      for (int trial = 0; trial < 4; ++trial) {
        const Eigen::Vector4d z(3.0 * uniform(random), uniform(random), uniform(random), uniform(random));
        check(sleigh, z, uniform(random),
              "gamma " + std::to_string(gamma) + (with_force ? " with" : " without") + " the blade");
      }
    }
  }
}

TEST(ChaplyginSleigh, StructureMatchesAutomaticDifferentiationInBothForms) {
  at_random_points_of_every_form(11, [](const ChaplyginSleigh& sleigh, const Eigen::Vector4d& z, double t,
                                        const std::string& label) {
    birkhoff_cart_test::check_structure_against_ad(sleigh, z, t, label);
  });
}

TEST(ChaplyginSleigh, TheRatesAreTheBoltzmannHamelEquations) {
  // ż = K⁻¹(∇B + ∂R/∂t + Λ) is (S.1) in both forms: π̇1 = v, θ̇ = ω, m v̇ = m a ω², J ω̇ = −m a v ω.
  for (double gamma : {0.0, 1.0}) {
    const ChaplyginSleigh sleigh(sleigh_parameters(gamma));
    const ChaplyginSleighParameters& p = sleigh.parameters();
    const double v = 0.7, omega = -1.3;  // [m/s], [rad/s]
    const Eigen::Vector4d z = sleigh.state(0.2, 0.4, v, omega);
    const Eigen::Vector4d rate = birkhoffian_rates(sleigh, z, 0.9);
    EXPECT_NEAR(rate(kSleighArcLength), v, 1e-14);
    EXPECT_NEAR(rate(kSleighHeading), omega, 1e-14);
    EXPECT_NEAR(rate(kSleighForwardMomentum), p.mass * p.centre_offset * omega * omega, 1e-14);
    EXPECT_NEAR(rate(kSleighAngularMomentum), -p.mass * p.centre_offset * v * omega, 1e-14);
    // The blade does no work: dE/dt = ω·ṗ = 0.
    EXPECT_NEAR(v * rate(kSleighForwardMomentum) + omega * rate(kSleighAngularMomentum), 0.0, 1e-14);
  }
}

TEST(ChaplyginSleigh, ClosedFormSolvesTheEquationsAndHasTheKnownAsymptotics) {
  const ChaplyginSleigh sleigh;
  const Eigen::Vector4d z0 = sleigh.state(0.0, 0.3, -0.4, 2.0);  // backing up while turning
  const ChaplyginSleighMotion motion(sleigh, z0, 1.0);
  EXPECT_LE((motion.at(1.0, sleigh) - z0).cwiseAbs().maxCoeff(), 1e-14);
  constexpr double kDifferenceStep = 1e-5;  // [s]
  for (double t : {1.0, 1.7, 3.2, 6.0}) {
    const Eigen::Vector4d difference =
        (motion.at(t + kDifferenceStep, sleigh) - motion.at(t - kDifferenceStep, sleigh)) / (2.0 * kDifferenceStep);
    const Eigen::Vector4d rate = birkhoffian_rates(sleigh, motion.at(t, sleigh), t);
    EXPECT_LE((difference - rate).cwiseAbs().maxCoeff(), kRateTolerance * std::max(1.0, rate.cwiseAbs().maxCoeff()))
        << "t = " << t << ": " << difference.transpose() << " vs " << rate.transpose();
    EXPECT_NEAR(sleigh.hamiltonian(Eigen::Vector4d(motion.at(t, sleigh))), sleigh.hamiltonian(z0), 1e-13);
  }
  // Long after: v → V = √(2E/m), ω → 0, the heading turned by the remaining turn, ≤ πΩ/λ in all.
  const Eigen::Vector4d late = motion.at(200.0, sleigh);
  EXPECT_NEAR(late(kSleighForwardMomentum) / sleigh.parameters().mass, motion.final_speed(), 1e-12);
  EXPECT_LE(std::abs(late(kSleighAngularMomentum)), 1e-12);
  EXPECT_NEAR(late(kSleighHeading) - z0(kSleighHeading), motion.remaining_turn(), 1e-12);
  EXPECT_GT(motion.remaining_turn(), 0.5 * kPi * motion.peak_turning_rate() / motion.decay_rate());
  EXPECT_LT(motion.remaining_turn(), kPi * motion.peak_turning_rate() / motion.decay_rate());
}

TEST(ChaplyginSleigh, ClosedFormJacobianIsAutomaticDifferentiationOfTheRates) {
  at_random_points_of_every_form(3, [](const ChaplyginSleigh& sleigh, const Eigen::Vector4d& w, double t,
                                       const std::string& label) {
    Eigen::Matrix<Jet<4>, 4, 1> w_jet;
    for (int k = 0; k < 4; ++k) w_jet(k) = Jet<4>(w(k), 4, k);
    const Eigen::Matrix<Jet<4>, 4, 1> rate = sleigh.darboux_rates(w_jet, Jet<4>(t));
    Eigen::Matrix4d ad;
    for (int k = 0; k < 4; ++k) ad.row(k) = rate(k).derivatives().transpose();
    const Eigen::Matrix4d closed = sleigh.darboux_jacobian(w, t);
    EXPECT_LE((closed - ad).cwiseAbs().maxCoeff(), kJacobianTolerance * std::max(1.0, ad.cwiseAbs().maxCoeff()))
        << label << "\n" << closed << "\nAD\n" << ad;
    // The columns kCyclicMask names are zero.
    EXPECT_TRUE(closed.col(kSleighArcLength).isZero(0.0)) << label;
    EXPECT_TRUE(closed.col(kSleighHeading).isZero(0.0)) << label;
  });
}

TEST(ChaplyginSleigh, TheOptionalHooksChangeNothingButTheCost) {
  // gauss4 (fresh memory each step, as the generic step() runs) on the sleigh with its hooks and on
  // the same sleigh through the required members only (AD Jacobian, no cyclic coordinates, passive
  // sweeps until settled): the same trajectory to round-off, in both forms.
  for (double gamma : {0.0, 1.0}) {
    const ChaplyginSleigh sleigh(sleigh_parameters(gamma));
    const BareSleigh bare{sleigh};
    const GaussCollocation<2> gauss4;
    Eigen::Vector4d z_hooked = sleigh.state(0.0, 0.3, 0.5, 1.5), z_bare = z_hooked;
    Eigen::Vector2d y_hooked(0.1, -0.2), y_bare = y_hooked;
    StepStatistics hooked_statistics, bare_statistics;
    constexpr double kStep = 0.05;  // [s]
    for (int k = 0; k < 100; ++k) {
      gauss4.step(sleigh, z_hooked, y_hooked, k * kStep, kStep, hooked_statistics);
      gauss4.step(bare, z_bare, y_bare, k * kStep, kStep, bare_statistics);
    }
    const double difference = std::max((z_hooked - z_bare).cwiseAbs().maxCoeff(), (y_hooked - y_bare).cwiseAbs().maxCoeff());
    std::printf("[ measured ] gamma %g: hooked vs bare sleigh %.3e; passive evaluations %llu vs %llu\n", gamma,
                difference, static_cast<unsigned long long>(hooked_statistics.passive_evaluations),
                static_cast<unsigned long long>(bare_statistics.passive_evaluations));
    EXPECT_LE(difference, kHookTolerance * std::max(1.0, z_hooked.cwiseAbs().maxCoeff()));
    // kPassiveCouplingDepth = 0: one sweep of the two stages a step (plus the estimate's end rate).
    EXPECT_LT(hooked_statistics.passive_evaluations, bare_statistics.passive_evaluations);
  }
}

TEST(ChaplyginSleigh, CarriedStepsFollowTheSameTrajectory) {
  // The carried path of a Birkhoffian member (docs/integrators.md, "Bring your own system"):
  // advance_compensated with the point and the member's Memory carried from step to step (starting
  // values from the last steps' stages, the Jacobian kept while it contracts, compensated summation)
  // against step() from scratch each time: the same trajectory to round-off. (On this 4-dimensional
  // system a fresh Jacobian every step is cheap, and the fresh path takes fewer evaluations.)
  const ChaplyginSleigh sleigh;
  const GaussCollocation<3> gauss6;
  Eigen::Vector4d z = sleigh.state(0.0, 0.3, -0.4, 2.0);
  Eigen::Vector2d y = Eigen::Vector2d::Zero();
  CompensatedPoint<ChaplyginSleigh> point;
  point.z = z;
  point.y = y;
  GaussCollocation<3>::Memory<ChaplyginSleigh> memory;
  StepStatistics fresh_statistics, carried_statistics;
  constexpr double kStep = 0.05;  // [s]
  for (int k = 0; k < 400; ++k) {
    gauss6.step(sleigh, z, y, k * kStep, kStep, fresh_statistics);
    gauss6.advance_compensated(sleigh, point, memory, k * kStep, kStep, carried_statistics);
  }
  const double difference = std::max((point.z - z).cwiseAbs().maxCoeff(), (point.y - y).cwiseAbs().maxCoeff());
  std::printf("[ measured ] gauss6 over 20 s: carried vs fresh %.3e; iterations %llu vs %llu, rhs evaluations %llu vs %llu\n", difference,
              static_cast<unsigned long long>(carried_statistics.newton_iterations_total),
              static_cast<unsigned long long>(fresh_statistics.newton_iterations_total),
              static_cast<unsigned long long>(carried_statistics.rhs_evaluations),
              static_cast<unsigned long long>(fresh_statistics.rhs_evaluations));
  EXPECT_LE(difference, 1e-12 * std::max(1.0, z.cwiseAbs().maxCoeff()));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees("docs/integrators.md",
                                                     "on the sleigh it gives the same trajectory to ", 0, difference, 0.25));
}

TEST(ChaplyginSleigh, AMemberRunReachesTheKnownAsymptotics) {
  // birkhoff_gauss4 at h = 0.05 s over 60 s from a sleigh turning at 2 rad/s from rest (v = 0: the
  // middle of its motion (S.3)): it ends gliding straight at V = √(2E/m), having turned through
  // half its total turn, (π/2) Ω/λ.
  const ChaplyginSleigh sleigh;
  const Eigen::Vector4d z0 = sleigh.state(0.0, 0.0, 0.0, 2.0);
  const ChaplyginSleighMotion motion(sleigh, z0, 0.0);
  const GaussCollocation<2> gauss4;
  Eigen::Vector4d z = z0;
  Eigen::Vector2d y = Eigen::Vector2d::Zero();
  StepStatistics statistics;
  constexpr double kStep = 0.05;  // [s]
  for (int k = 0; k < 1200; ++k) gauss4.step(sleigh, z, y, k * kStep, kStep, statistics);
  const double speed = z(kSleighForwardMomentum) / sleigh.parameters().mass;
  std::printf("[ measured ] after 60 s: v = %.15f m/s (V = %.15f), turned %.15f rad (pi Omega/(2 lambda) = %.15f)\n",
              speed, motion.final_speed(), z(kSleighHeading), 0.5 * kPi * motion.peak_turning_rate() / motion.decay_rate());
  EXPECT_NEAR(speed, motion.final_speed(), 1e-9);
  EXPECT_NEAR(motion.remaining_turn(), 0.5 * kPi * motion.peak_turning_rate() / motion.decay_rate(), 1e-14);
  EXPECT_NEAR(z(kSleighHeading), motion.remaining_turn(), 1e-6);
  EXPECT_LE(std::abs(z(kSleighAngularMomentum)), 1e-9);
  // docs/integrators.md quotes this run: in the example's comment and in the sleigh table.
  const std::string page = "docs/integrators.md";
  const std::vector<double> stated_speed = birkhoff_cart_test::figures_after(page, "// 60 s later: v = p1/m = ");
  ASSERT_FALSE(stated_speed.empty()) << page << " no longer states the sleigh's speed after 60 s";
  EXPECT_NEAR(stated_speed.front(), speed, 1e-14) << page << " states v = " << stated_speed.front();
  EXPECT_TRUE(birkhoff_cart_test::page_bound_holds(page, "ends gliding at V to ", 0, std::abs(speed - motion.final_speed())));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, "turns through (π/2) Ω/λ to ", 0,
                                                     std::abs(z(kSleighHeading) - motion.remaining_turn()), 0.25));
}

}  // namespace
}  // namespace birkhoff_cart
