// The cart's two Birkhoffian representations (docs/birkhoffian.md §3) reproduce the core's
// Boltzmann–Hamel equations with every effect on, agree with each other, are invariant under the
// structure epoch, stay finite at late times, and convert to and from CartState losslessly.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "all_effects.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/integrators/birkhoff_symplectic.h"
#include "full_coordinate_model.h"

namespace birkhoff_cart {
namespace {

constexpr double kEquationTolerance = 1e-12;  // relative residual of ż [-]
constexpr double kConversionTolerance = 1e-14;  // relative round trip [-]

using birkhoff_cart_test::all_effect_specs;
using birkhoff_cart_test::typical_effect_spec;

class CartBirkhoffianTest : public ::testing::Test {
 protected:
  CartModel model{CartParameters{}};
  EffectSet effects = build_effects(all_effect_specs(), model);
  std::vector<CartState> states;

  void SetUp() override {
    std::mt19937 random(99);
    std::uniform_real_distribution<double> steering(-1.3, 1.3), speed(-4.0, 4.0), rate(-2.0, 2.0),
        angle(-3.0, 3.0), position(-20.0, 20.0), time(0.0, 30.0);
    for (int i = 0; i < 12; ++i) {
      CartState state;
      state.time = time(random);
      state.x = position(random);
      state.y = position(random);
      state.heading = angle(random);
      state.steering_angle = steering(random);
      state.wheel_spin_angle = {angle(random), angle(random), angle(random), angle(random)};
      state.arc_length = position(random);
      state.forward_speed = speed(random);
      state.steering_rate = rate(random);
      state.applied_work = position(random);
      state.steering_impulse = position(random);
      states.push_back(state);
    }
  }

  /// ż expected from the core: π̇1 = ω1, χ̇ = ω2, ṗ = d/dt(M ω) = M ω̇ + (∂M/∂χ) χ̇ ω with
  /// ω̇ = CartModel::quasi_acceleration (Boltzmann–Hamel, eq. (3.4)).
  Eigen::Vector4d boltzmann_hamel_rates(const CartState& state) const {
    const Vector2<double> omega(state.forward_speed, state.steering_rate);
    const double chi = state.steering_angle;
    EffectInput input{state.time, chi, omega(0), omega(1)};
    const Vector2<double> force = effects.evaluate(input).force;
    const Vector2<double> acceleration = model.quasi_acceleration(chi, omega, force);
    const ReducedInertia& inertia = model.inertia();
    Matrix2<double> mass_derivative;  // ∂M/∂χ
    mass_derivative << 2.0 * inertia.mu1 * std::sin(chi) * std::cos(chi), inertia.nu * std::cos(chi),
        inertia.nu * std::cos(chi), 0.0;
    const Vector2<double> momentum_rate = model.mass_matrix(chi) * acceleration + mass_derivative * omega * omega(1);
    return Eigen::Vector4d(omega(0), omega(1), momentum_rate(0), momentum_rate(1));
  }
};

template <class System>
Eigen::Vector4d rates_of(System& system, const CartState& state) {
  system.begin_step(state.time - 0.37);  // any epoch
  return birkhoffian_rates(system, system.to_birkhoffian(state).z, state.time);
}

TEST_F(CartBirkhoffianTest, BothRepresentationsReproduceTheBoltzmannHamelEquations) {
  CartAutonomousBirkhoffian autonomous(model, effects);
  CartPaperBirkhoffian paper(model, effects);
  for (const CartState& state : states) {
    const Eigen::Vector4d expected = boltzmann_hamel_rates(state);
    const double scale = expected.cwiseAbs().maxCoeff();
    const Eigen::Vector4d rate_a = rates_of(paper, state);
    const Eigen::Vector4d rate_b = rates_of(autonomous, state);
    EXPECT_LE((rate_a - expected).cwiseAbs().maxCoeff(), kEquationTolerance * scale)
        << "(a) " << rate_a.transpose() << "\ncore " << expected.transpose();
    EXPECT_LE((rate_b - expected).cwiseAbs().maxCoeff(), kEquationTolerance * scale)
        << "(b) " << rate_b.transpose() << "\ncore " << expected.transpose();
    // The chart's analytic rates are the same motion: ẇ = D_z ż + ∂_t D (checked generally in
    // birkhoffian_system_test); here (b)'s identity chart gives ż directly.
    const Eigen::Vector4d z = autonomous.to_birkhoffian(state).z;
    EXPECT_LE((autonomous.darboux_rates(z, state.time) - expected).cwiseAbs().maxCoeff(), kEquationTolerance * scale);
  }
}

TEST_F(CartBirkhoffianTest, MomentumRatesAreThoseOfTheIndependentModel) {
  // ṗ of both representations against the independent full-coordinate model: p = ∂T*/∂ω from its
  // body-by-body kinetic energy, ṗ by a central difference along its motion under a steering
  // torque τ and a drive torque T. The law ṗ2 = Q2 = τ (eq. (3.8)) is checked on the full model
  // itself, where nothing builds it in; ṗ1 checks the sign and size of Λ_nh + Q.
  constexpr double kFullModelTolerance = 1e-6;  // relative to the largest momentum rate [-]
  const full_model::FullCoordinateModel full(model.parameters());
  const EffectSpec drive = typical_effect_spec("drive_torque");
  const EffectSet torques_only = build_effects({typical_effect_spec("steering_torque"), drive}, model);
  CartAutonomousBirkhoffian autonomous(model, torques_only);
  CartPaperBirkhoffian paper(model, torques_only);
  for (const CartState& state : states) {
    Eigen::Matrix<double, 8, 1> q;
    q << state.x, state.y, state.heading, state.steering_angle, state.wheel_spin_angle[0],
        state.wheel_spin_angle[1], state.wheel_spin_angle[2], state.wheel_spin_angle[3];
    const Eigen::Matrix<double, 8, 1> qd = full.admissible_velocity(q, state.forward_speed, state.steering_rate);
    EffectInput input{state.time, state.steering_angle, state.forward_speed, state.steering_rate};
    const Vector2<double> load = torques_only.evaluate(input).force;  // Q [N, N·m]
    full_model::AppliedLoads loads;
    loads.steering_torque = load(1);                                                        // τ = Q2
    loads.drive_torque = drive.profile.value;                                               // T [N·m] (constant)
    const Eigen::Vector2d full_rate =
        full.reduced_momentum_rate(q, qd, full_model::FullCoordinateModel::applied_force(loads));
    const double scale = 1.0 + full_rate.cwiseAbs().maxCoeff();
    EXPECT_NEAR(full_rate(1), loads.steering_torque, kFullModelTolerance * scale) << "full model: ṗ2 = τ";
    const Eigen::Vector4d rate_b = rates_of(autonomous, state);
    const Eigen::Vector4d rate_a = rates_of(paper, state);
    for (int row = 0; row < 2; ++row) {
      EXPECT_NEAR(rate_b(kForwardMomentumIndex + row), full_rate(row), kFullModelTolerance * scale) << "(b) row " << row;
      EXPECT_NEAR(rate_a(kForwardMomentumIndex + row), full_rate(row), kFullModelTolerance * scale) << "(a) row " << row;
    }
  }
}

TEST_F(CartBirkhoffianTest, BirkhoffianPartsAreHamiltonianAndConformallyHamiltonian) {
  // Λ disabled: (b) ṗ = −∂H̃/∂q, (a) ṗ = −∂H̃/∂q − p (the spurious damping the paper's ∂R/∂t adds).
  CartAutonomousBirkhoffian autonomous(model, effects);
  CartPaperBirkhoffian paper(model, effects);
  autonomous.set_non_birkhoffian_force_enabled(false);
  paper.set_non_birkhoffian_force_enabled(false);
  for (const CartState& state : states) {
    const Eigen::Vector4d z = autonomous.to_birkhoffian(state).z;
    const Eigen::Vector4d gradient = autonomous.hamiltonian_gradient(z);
    const Eigen::Vector4d rate_b = rates_of(autonomous, state);
    const Eigen::Vector4d rate_a = rates_of(paper, state);
    const double scale = std::max(1.0, gradient.cwiseAbs().maxCoeff() + z.cwiseAbs().maxCoeff());
    EXPECT_NEAR(rate_b(kForwardMomentumIndex), -gradient(kArcLengthIndex), kEquationTolerance * scale);
    EXPECT_NEAR(rate_b(kSteeringMomentumIndex), -gradient(kSteeringAngleIndex), kEquationTolerance * scale);
    EXPECT_NEAR(rate_a(kForwardMomentumIndex), -gradient(kArcLengthIndex) - z(kForwardMomentumIndex),
                kEquationTolerance * scale);
    EXPECT_NEAR(rate_a(kSteeringMomentumIndex), -gradient(kSteeringAngleIndex) - z(kSteeringMomentumIndex),
                kEquationTolerance * scale);
    EXPECT_NEAR(rate_a(kArcLengthIndex), state.forward_speed, kEquationTolerance * scale);
    EXPECT_NEAR(rate_b(kSteeringAngleIndex), state.steering_rate, kEquationTolerance * scale);
  }
}

TEST_F(CartBirkhoffianTest, StructureEpochDoesNotChangeTheMotion) {
  CartPaperBirkhoffian paper(model, effects);
  for (const CartState& state : states) {
    const Eigen::Vector4d z = paper.to_birkhoffian(state).z;
    paper.begin_step(0.0);
    const Eigen::Vector4d rate_0 = birkhoffian_rates(paper, z, state.time);
    paper.begin_step(state.time);
    const Eigen::Vector4d rate_now = birkhoffian_rates(paper, z, state.time);
    paper.begin_step(state.time + 3.0);
    const Eigen::Vector4d rate_later = birkhoffian_rates(paper, z, state.time);
    const double scale = rate_now.cwiseAbs().maxCoeff();
    EXPECT_LE((rate_0 - rate_now).cwiseAbs().maxCoeff(), kEquationTolerance * scale);
    EXPECT_LE((rate_later - rate_now).cwiseAbs().maxCoeff(), kEquationTolerance * scale);
  }
  // A whole birkhoff2 step too: epoch tₑ = t vs tₑ = t − 2 s.
  const CartState& state = states.front();
  CartBirkhoffianPoint start = paper.to_birkhoffian(state);
  StepStatistics statistics;
  Eigen::Vector4d z1 = start.z, z2 = start.z;
  Eigen::Matrix<double, 9, 1> y1 = start.y, y2 = start.y;
  paper.begin_step(state.time);
  BirkhoffSymplectic2{}.step(paper, z1, y1, state.time, 0.01, statistics);
  paper.begin_step(state.time - 2.0);
  BirkhoffSymplectic2{}.step(paper, z2, y2, state.time, 0.01, statistics);
  EXPECT_LE((z1 - z2).cwiseAbs().maxCoeff(), 1e-13 * z1.cwiseAbs().maxCoeff());
  EXPECT_LE((y1 - y2).cwiseAbs().maxCoeff(), 1e-13 * y1.cwiseAbs().maxCoeff());
}

TEST_F(CartBirkhoffianTest, PaperFormStaysFiniteAtLateTimes) {
  // e^{t} overflows double near t = 709 s; with the epoch at the step start it never appears.
  CartPaperBirkhoffian paper(model, effects);
  CartAutonomousBirkhoffian autonomous(model, effects);
  CartState state = states.front();
  state.time = 5000.0;  // [s]
  paper.begin_step(state.time);
  CartBirkhoffianPoint point = paper.to_birkhoffian(state);
  const Eigen::Vector4d rate = birkhoffian_rates(paper, point.z, state.time);
  EXPECT_TRUE(rate.allFinite()) << rate.transpose();
  EXPECT_TRUE(paper.structure_matrix(point.z, state.time).allFinite());
  StepStatistics statistics;
  for (int step = 0; step < 10; ++step) {
    const double t = 5000.0 + 0.01 * step;
    paper.begin_step(t);
    BirkhoffSymplectic4{}.step(paper, point.z, point.y, t, 0.01, statistics);
  }
  EXPECT_TRUE(point.z.allFinite() && point.y.allFinite()) << point.z.transpose();
  // Same motion as (b) from the same start, to integration accuracy of the same symmetric scheme.
  CartBirkhoffianPoint reference = autonomous.to_birkhoffian(state);
  for (int step = 0; step < 10; ++step) {
    BirkhoffSymplectic4{}.step(autonomous, reference.z, reference.y, 5000.0 + 0.01 * step, 0.01, statistics);
  }
  EXPECT_LE((point.z - reference.z).cwiseAbs().maxCoeff(), 1e-8 * reference.z.cwiseAbs().maxCoeff());
}

TEST_F(CartBirkhoffianTest, ConversionsRoundTrip) {
  const CartAutonomousBirkhoffian autonomous(model, effects);
  for (const CartState& state : states) {
    const CartBirkhoffianPoint point = autonomous.to_birkhoffian(state);
    EXPECT_NEAR(point.z(kForwardMomentumIndex),
                model.momentum(state.steering_angle, Vector2<double>(state.forward_speed, state.steering_rate))(0),
                1e-15 * std::abs(point.z(kForwardMomentumIndex)) + 1e-15);
    EXPECT_DOUBLE_EQ(point.z(kSteeringMomentumIndex), model.steering_momentum(state));
    const CartState back = autonomous.to_cart_state(point.z, point.y, state.time);
    EXPECT_EQ(back.time, state.time);
    EXPECT_EQ(back.x, state.x);
    EXPECT_EQ(back.y, state.y);
    EXPECT_EQ(back.heading, state.heading);
    EXPECT_EQ(back.steering_angle, state.steering_angle);
    EXPECT_EQ(back.arc_length, state.arc_length);
    EXPECT_EQ(back.wheel_spin_angle, state.wheel_spin_angle);
    EXPECT_EQ(back.applied_work, state.applied_work);
    EXPECT_EQ(back.steering_impulse, state.steering_impulse);
    EXPECT_NEAR(back.forward_speed, state.forward_speed, kConversionTolerance * std::max(1.0, std::abs(state.forward_speed)));
    EXPECT_NEAR(back.steering_rate, state.steering_rate, kConversionTolerance * std::max(1.0, std::abs(state.steering_rate)));
  }
}

TEST_F(CartBirkhoffianTest, PassiveRatesAreTheReconstructionAndTheBalances) {
  const CartPaperBirkhoffian paper(model, effects);
  for (const CartState& state : states) {
    const CartBirkhoffianPoint point = paper.to_birkhoffian(state);
    const Eigen::Matrix<double, 9, 1> rate = paper.passive_rates(point.z, point.y, state.time);
    const Vector2<double> omega(state.forward_speed, state.steering_rate);
    const CoordinateRates<double> expected = model.coordinate_rates(state.heading, state.steering_angle, omega);
    EffectInput input{state.time, state.steering_angle, omega(0), omega(1)};
    const Vector2<double> force = effects.evaluate(input).force;
    constexpr double kRateTolerance = 1e-13;  // [-], relative
    EXPECT_NEAR(rate(kXIndex), expected.x_rate, kRateTolerance * 10);
    EXPECT_NEAR(rate(kYIndex), expected.y_rate, kRateTolerance * 10);
    EXPECT_NEAR(rate(kHeadingIndex), expected.heading_rate, kRateTolerance * 10);
    for (int wheel = 0; wheel < 4; ++wheel) {
      EXPECT_NEAR(rate(kWheel1Index + wheel), expected.wheel_spin_rate[wheel], kRateTolerance * 100);
    }
    EXPECT_NEAR(rate(kAppliedWorkIndex), omega.dot(force), kRateTolerance * std::max(1.0, std::abs(omega.dot(force))));
    EXPECT_NEAR(rate(kSteeringImpulseIndex), force(1), kRateTolerance * std::max(1.0, std::abs(force(1))));
  }
}

TEST_F(CartBirkhoffianTest, EnergyBalanceHoldsAlongTheRates) {
  // dT*/dt = ω·Q (eq. (3.7)): the nonholonomic force is workless in both representations.
  CartAutonomousBirkhoffian autonomous(model, effects);
  for (const CartState& state : states) {
    const CartBirkhoffianPoint point = autonomous.to_birkhoffian(state);
    const Eigen::Vector4d rate = birkhoffian_rates(autonomous, point.z, state.time);
    const Eigen::Vector4d gradient = autonomous.hamiltonian_gradient(point.z);
    const double energy_rate = gradient.dot(rate);  // dH̃/dt along ż
    const double power = autonomous.passive_rates(point.z, point.y, state.time)(kAppliedWorkIndex);
    EXPECT_NEAR(energy_rate, power, 1e-12 * std::max(1.0, std::abs(power)));
  }
}

}  // namespace
}  // namespace birkhoff_cart
