// CartModel's identities (docs/derivation.md): energy balance (3.7), ṗ2 = Q2 (3.8) and why the
// naive Lagrange equation in χ breaks it, workless Λ_nh (3.6)–(3.7), the canonical form (3.6)
// against Boltzmann–Hamel (3.4), the momentum map (3.5), the constraints (2.2) on reconstructed
// velocities (2.3)–(2.4), positive definiteness of M (3.3), the paper's special case (3.9), and
// T* (2.8) against the body-by-body kinetic energy of the independent full-coordinate model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "full_coordinate_model.h"

namespace birkhoff_cart {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRelativeTolerance = 1e-12;     // identities in double precision [-]
constexpr double kConstraintTolerance = 1e-14;   // residual per unit speed [m/s per (m/s)]
constexpr double kNaiveLagrangeMinimumError = 1e-3;  // how wrong the naive equation must be [N·m]

using Dual = Jet<1>;  // value and time derivative along the motion

/// A random state of the default cart's reduced variables and loads.
struct RandomReducedState {
  double steering_angle;     ///< χ [rad]
  Vector2<double> velocity;  ///< ω [m/s, rad/s]
  Vector2<double> force;     ///< Q [N, N·m]
};

class CartModelIdentities : public ::testing::Test {
 protected:
  RandomReducedState draw() {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    RandomReducedState state;
    state.steering_angle = 2.0 * kPi * unit(generator_);
    state.velocity = Vector2<double>(6.0 * unit(generator_), 3.0 * unit(generator_));
    state.force = Vector2<double>(200.0 * unit(generator_), 10.0 * unit(generator_));
    return state;
  }
  /// χ and ω as dual numbers whose derivative parts are χ̇ = ω2 and ω̇ from eq. (3.4).
  void along_motion(const RandomReducedState& state, Dual& chi, Vector2<Dual>& w) const {
    const Vector2<double> w_rate = model_.quasi_acceleration(state.steering_angle, state.velocity, state.force);
    chi = Dual(state.steering_angle, Eigen::Matrix<double, 1, 1>::Constant(state.velocity(1)));
    w(0) = Dual(state.velocity(0), Eigen::Matrix<double, 1, 1>::Constant(w_rate(0)));
    w(1) = Dual(state.velocity(1), Eigen::Matrix<double, 1, 1>::Constant(w_rate(1)));
  }

  CartParameters parameters_;
  CartModel model_{parameters_};
  std::mt19937 generator_{12345};
};

// dT*/dt = ω·Q (eq. (3.7)): the nonholonomic terms of eq. (3.4) do no work.
TEST_F(CartModelIdentities, EnergyRateEqualsPowerOfAppliedLoads) {
  for (int trial = 0; trial < 500; ++trial) {
    const RandomReducedState state = draw();
    Dual chi;
    Vector2<Dual> w;
    along_motion(state, chi, w);
    const double energy_rate = model_.kinetic_energy(chi, w).derivatives()(0);  // [W]
    const double power = state.velocity.dot(state.force);                        // [W]
    const double scale = state.velocity.cwiseAbs().dot(state.force.cwiseAbs()) + 1.0;
    EXPECT_NEAR(energy_rate, power, kRelativeTolerance * scale) << "trial " << trial;
  }
}

// ṗ2 = Q2 exactly (eq. (3.8)): p2 = I_f (θ̇ + χ̇) is the front axle's yaw momentum.
TEST_F(CartModelIdentities, SteeringMomentumRateEqualsSteeringTorque) {
  for (int trial = 0; trial < 500; ++trial) {
    const RandomReducedState state = draw();
    Dual chi;
    Vector2<Dual> w;
    along_motion(state, chi, w);
    const double momentum_rate = model_.momentum(chi, w)(1).derivatives()(0);  // ṗ2 [N·m]
    EXPECT_NEAR(momentum_rate, state.force(1), kRelativeTolerance * (std::abs(state.force(1)) + 100.0));
  }
}

// The naive Lagrange equation in χ, d/dt(∂T*/∂χ̇) − ∂T*/∂χ = Q2 (with d/dt(∂T*/∂ω1) = Q1), treats
// the quasi-velocity ω1 as if it were the rate of a true coordinate; its motion has
// ṗ2 = Q2 + ∂T*/∂χ ≠ Q2 (eq. (3.8)), so it is not the cart.
TEST_F(CartModelIdentities, NaiveLagrangeEquationInSteeringAngleViolatesSteeringMomentumBalance) {
  int clearly_violated = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const RandomReducedState state = draw();
    // Naive motion: M ω̇ = Q + (0, ∂T*/∂χ) − Ṁ ω, with Ṁ = (dM/dχ) ω2.
    const Dual chi_seed(state.steering_angle, Eigen::Matrix<double, 1, 1>::Constant(1.0));
    const Matrix2<Dual> mass_dual = model_.mass_matrix(chi_seed);
    Eigen::Matrix2d mass, mass_slope;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        mass(i, j) = mass_dual(i, j).value();
        mass_slope(i, j) = mass_dual(i, j).derivatives()(0);
      }
    const double steering_gradient =
        model_.kinetic_energy_steering_derivative(state.steering_angle, state.velocity);  // ∂T*/∂χ [J/rad]
    const Eigen::Vector2d naive_rate = mass.lu().solve(
        state.force + Eigen::Vector2d(0.0, steering_gradient) - mass_slope * state.velocity * state.velocity(1));
    Dual chi;
    Vector2<Dual> w;
    chi = Dual(state.steering_angle, Eigen::Matrix<double, 1, 1>::Constant(state.velocity(1)));
    w(0) = Dual(state.velocity(0), Eigen::Matrix<double, 1, 1>::Constant(naive_rate(0)));
    w(1) = Dual(state.velocity(1), Eigen::Matrix<double, 1, 1>::Constant(naive_rate(1)));
    const double naive_momentum_rate = model_.momentum(chi, w)(1).derivatives()(0);
    // Its defect is exactly ∂T*/∂χ ...
    EXPECT_NEAR(naive_momentum_rate - state.force(1), steering_gradient,
                kRelativeTolerance * (std::abs(state.force(1)) + 100.0));
    // ... which is not zero on general motion.
    if (std::abs(naive_momentum_rate - state.force(1)) > kNaiveLagrangeMinimumError) ++clearly_violated;
  }
  EXPECT_GT(clearly_violated, 150);
}

// ω·Λ_nh = 0 (eq. (3.7)), and Λ_nh is the force the rolling constraints exert: ṗ − ∂T*/∂q|_ω − Q
// of the independent full-coordinate model (p from its body-by-body kinetic energy, ṗ by a central
// difference along its motion). Workless alone would also hold for −Λ_nh or 0; the comparison
// with the full model fixes the sign and the size.
TEST_F(CartModelIdentities, NonholonomicForceIsWorklessAndIsTheRollingConstraintsForce) {
  constexpr double kFullModelTolerance = 1e-6;  // relative to the largest momentum-rate term [-]
  const full_model::FullCoordinateModel full(parameters_);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double largest_force = 0.0;
  for (int trial = 0; trial < 500; ++trial) {
    const RandomReducedState state = draw();
    const Vector2<double> force = model_.nonholonomic_force(state.steering_angle, state.velocity);
    const double scale = state.velocity.squaredNorm() * (1.0 + state.velocity.norm()) * 200.0;
    EXPECT_NEAR(state.velocity.dot(force), 0.0, kRelativeTolerance * scale);
    if (trial >= 50) continue;  // the full-model comparison costs ~10 KKT solves: 50 states suffice
    Eigen::Matrix<double, 8, 1> q;
    q << 3.0 * unit(generator_), 3.0 * unit(generator_), 3.0 * unit(generator_), state.steering_angle,
        unit(generator_), unit(generator_), unit(generator_), unit(generator_);
    const Eigen::Matrix<double, 8, 1> qd = full.admissible_velocity(q, state.velocity(0), state.velocity(1));
    full_model::AppliedLoads loads;  // Q = (T cos χ / r1, τ) (docs eqs. (4.1)–(4.2))
    loads.drive_torque = state.force(0) * parameters_.rear_wheel_radius;  // T [N·m]
    loads.steering_torque = state.force(1);
    const Vector2<double> applied(loads.drive_torque * std::cos(state.steering_angle) / parameters_.rear_wheel_radius,
                                  loads.steering_torque);
    const Eigen::Vector2d momentum_rate =
        full.reduced_momentum_rate(q, qd, full_model::FullCoordinateModel::applied_force(loads));
    const double steering_gradient =
        full.reduced_energy_steering_derivative(q, state.velocity(0), state.velocity(1));  // ∂T*/∂χ|_ω
    const Eigen::Vector2d full_force = momentum_rate - Eigen::Vector2d(0.0, steering_gradient) - applied;
    const double term_scale = 1.0 + momentum_rate.cwiseAbs().maxCoeff() + std::abs(steering_gradient) +
                              applied.cwiseAbs().maxCoeff();
    EXPECT_NEAR(force(0), full_force(0), kFullModelTolerance * term_scale) << "trial " << trial;
    EXPECT_NEAR(force(1), full_force(1), kFullModelTolerance * term_scale) << "trial " << trial;
    largest_force = std::max(largest_force, force.cwiseAbs().maxCoeff() / term_scale);
  }
  EXPECT_GT(largest_force, 0.1);  // the comparison saw Λ_nh of the size of the other terms
}

// ṗ = ∂T*/∂q|_ω + Λ_nh + Q (eq. (3.6)) describes the same motion as M ω̇ + h = Q (eq. (3.4)):
// q = (π1, χ), T* does not depend on π1, ∂T*/∂χ by AD at fixed ω.
TEST_F(CartModelIdentities, CanonicalFormAgreesWithBoltzmannHamel) {
  for (int trial = 0; trial < 500; ++trial) {
    const RandomReducedState state = draw();
    Dual chi;
    Vector2<Dual> w;
    along_motion(state, chi, w);
    const Vector2<Dual> momentum = model_.momentum(chi, w);
    const Eigen::Vector2d momentum_rate(momentum(0).derivatives()(0), momentum(1).derivatives()(0));
    const Dual chi_seed(state.steering_angle, Eigen::Matrix<double, 1, 1>::Constant(1.0));
    const Vector2<Dual> w_fixed(Dual(state.velocity(0), Eigen::Matrix<double, 1, 1>::Zero()),
                                Dual(state.velocity(1), Eigen::Matrix<double, 1, 1>::Zero()));
    const double steering_gradient = model_.kinetic_energy(chi_seed, w_fixed).derivatives()(0);
    EXPECT_NEAR(steering_gradient, model_.kinetic_energy_steering_derivative(state.steering_angle, state.velocity),
                kRelativeTolerance * (1.0 + state.velocity.squaredNorm() * 200.0));
    const Eigen::Vector2d canonical = Eigen::Vector2d(0.0, steering_gradient) +
                                      model_.nonholonomic_force(state.steering_angle, state.velocity) + state.force;
    const double scale = 1.0 + state.force.cwiseAbs().maxCoeff() + state.velocity.squaredNorm() * 200.0;
    EXPECT_NEAR(momentum_rate(0), canonical(0), kRelativeTolerance * scale);
    EXPECT_NEAR(momentum_rate(1), canonical(1), kRelativeTolerance * scale);
    EXPECT_NEAR(canonical(1), state.force(1), kRelativeTolerance * scale);  // ṗ2 = Q2
  }
}

// p = M ω and ω = M⁻¹ p are inverse maps (eq. (3.5)).
TEST_F(CartModelIdentities, MomentumAndQuasiVelocityRoundTrip) {
  for (int trial = 0; trial < 500; ++trial) {
    const RandomReducedState state = draw();
    const Vector2<double> momentum = model_.momentum(state.steering_angle, state.velocity);
    const Vector2<double> back = model_.quasi_velocity(state.steering_angle, momentum);
    EXPECT_NEAR(back(0), state.velocity(0), kRelativeTolerance * (1.0 + state.velocity.norm()));
    EXPECT_NEAR(back(1), state.velocity(1), kRelativeTolerance * (1.0 + state.velocity.norm()));
  }
}

// Eqs. (2.3)–(2.4) produce velocities that satisfy all six constraints of eq. (2.2).
TEST_F(CartModelIdentities, ReconstructedVelocitiesSatisfyAllSixConstraints) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    CartState state;
    state.x = 50.0 * unit(generator_);
    state.y = 50.0 * unit(generator_);
    state.heading = 10.0 * unit(generator_);
    state.steering_angle = 10.0 * unit(generator_);
    for (double& spin : state.wheel_spin_angle) spin = 100.0 * unit(generator_);
    state.forward_speed = 6.0 * unit(generator_);
    state.steering_rate = 3.0 * unit(generator_);
    const double speed_scale = 1.0 + std::abs(state.forward_speed) + std::abs(state.steering_rate);
    EXPECT_LE(model_.max_constraint_residual(state), kConstraintTolerance * speed_scale) << "trial " << trial;
    // The residuals can fail: a sideways slip of B shows in the first constraint.
    Eigen::Matrix<double, 8, 1> q;
    q << state.x, state.y, state.heading, state.steering_angle, state.wheel_spin_angle[0],
        state.wheel_spin_angle[1], state.wheel_spin_angle[2], state.wheel_spin_angle[3];
    Eigen::Matrix<double, 8, 1> slipping = model_.coordinate_velocities(state);
    const double front = state.heading + state.steering_angle;
    slipping(0) += -0.1 * std::sin(front);
    slipping(1) += 0.1 * std::cos(front);
    EXPECT_NEAR(CartModel::constraint_residuals(parameters_, q, slipping)(0), 0.1, 1e-12);
  }
}

// The paper prints r1 φ̇1 in the fourth constraint of eq. (15); with it a turning cart would need
// φ̇1 = (v − a θ̇)/r1 and φ̇1 = (v + a θ̇)/r1 at once. The model uses φ̇2 (docs eq. (2.2)).
TEST_F(CartModelIdentities, PrintedFourthConstraintWithPhi1CannotHoldWhileTurning) {
  CartState state;
  state.steering_angle = 0.3;
  state.forward_speed = 2.0;
  const Eigen::Matrix<double, 8, 1> v = model_.coordinate_velocities(state);
  const double along_rear = v(0) * std::cos(state.heading) + v(1) * std::sin(state.heading);
  const double printed_residual = along_rear + parameters_.rear_half_track * v(2) - parameters_.rear_wheel_radius * v(4);
  EXPECT_NEAR(printed_residual, 2.0 * parameters_.rear_half_track * v(2), 1e-14);
  EXPECT_GT(std::abs(printed_residual), 0.1);
  EXPECT_LE(model_.max_constraint_residual(state), kConstraintTolerance * 3.0);
}

// μ1 < 0 for the default cart, yet M(χ) is positive definite for every χ (eq. (3.3)):
// μ + μ1 s² = m_r c² + m_f + (I_r + I_f) s²/l² > 0 and det M = I_f (m_r c² + m_f + I_r s²/l²) > 0.
TEST_F(CartModelIdentities, MassMatrixPositiveDefiniteAlthoughMu1IsNegative) {
  const CartParameters& p = parameters_;
  const double l = p.wheelbase;
  const double rear_mass = p.rear_body_mass + 2 * p.rear_wheel_mass +
                           2 * p.rear_wheel_spin_inertia / std::pow(p.rear_wheel_radius, 2);  // m_r [kg]
  const double front_mass = p.front_axle_mass + 2 * p.front_wheel_mass +
                            2 * p.front_wheel_spin_inertia / std::pow(p.front_wheel_radius, 2);  // m_f [kg]
  const double rear_yaw = p.rear_body_yaw_inertia + 2 * p.rear_wheel_mass * std::pow(p.rear_half_track, 2) +
                          2 * p.rear_wheel_yaw_inertia +
                          2 * p.rear_wheel_spin_inertia * std::pow(p.rear_half_track / p.rear_wheel_radius, 2);
  const double front_yaw = p.front_axle_yaw_inertia + 2 * p.front_wheel_mass * std::pow(p.front_half_track, 2) +
                           2 * p.front_wheel_yaw_inertia +
                           2 * p.front_wheel_spin_inertia * std::pow(p.front_half_track / p.front_wheel_radius, 2);
  EXPECT_LT(model_.inertia().mu1, 0.0);
  for (int k = 0; k <= 720; ++k) {
    const double chi = -kPi + k * kPi / 360.0;
    const double s = std::sin(chi), c = std::cos(chi);
    const Matrix2<double> mass = model_.mass_matrix(chi);
    const double body_sum = rear_mass * c * c + front_mass + (rear_yaw + front_yaw) * s * s / (l * l);
    EXPECT_NEAR(mass(0, 0), body_sum, kRelativeTolerance * body_sum);
    // det M = (m_r c² + m_f + I_r s²/l²) I_f: the coupling ν² s² cancels the I_f s²/l² part of M11 l ν.
    const double determinant = mass.determinant();
    const double expected = (rear_mass * c * c + front_mass + rear_yaw * s * s / (l * l)) * front_yaw;
    EXPECT_NEAR(determinant, expected, kRelativeTolerance * expected);
    EXPECT_GT(mass(0, 0), 0.0);
    EXPECT_GT(determinant, 0.0);
  }
}

// The paper's special case (eq. (3.9)): μ = μ1 = 0, ν = l = 1, Q = 0, from t0 = π/2 with
// π1 = 1, ω1 = 1, ω2 = 1, χ = π/2: χ = t, ω1 = 1/sin t, π1 = 1 + ln tan(t/2) on (0, π).
TEST(PaperSpecialCase, AnalyticSolutionSatisfiesTheReducedEquations) {
  CartParameters parameters;
  parameters.wheelbase = 1.0;
  const CartModel model(parameters, InertiaModel::kPaperSpecialCase);
  EXPECT_DOUBLE_EQ(model.inertia().mu, 0.0);
  EXPECT_DOUBLE_EQ(model.inertia().mu1, 0.0);
  EXPECT_DOUBLE_EQ(model.inertia().nu, 1.0);
  for (const double t : {0.3, 0.9, kPi / 2, 2.0, 2.7, 3.0}) {
    const double s = std::sin(t), c = std::cos(t);
    const double w1 = 1.0 / s, w2 = 1.0;
    const double w1_rate = -c / (s * s), w2_rate = 0.0;
    // Residual of the paper's eq. (20) with the analytic solution.
    EXPECT_NEAR(w2_rate * s, 0.0, 1e-15);
    EXPECT_NEAR(1.0 * w2_rate + w1_rate * s + w1 * w2 * c, 0.0, 1e-13 * (1.0 + std::abs(w1_rate)));
    // CartModel's eq. (3.4) gives the same accelerations.
    const Vector2<double> rate = model.quasi_acceleration(t, Vector2<double>(w1, w2), Vector2<double>(0.0, 0.0));
    EXPECT_NEAR(rate(0), w1_rate, 1e-13 * (1.0 + std::abs(w1_rate))) << "t = " << t;
    EXPECT_NEAR(rate(1), w2_rate, 1e-13 * (1.0 + std::abs(w1_rate))) << "t = " << t;
    // π̇1 = ω1 for π1 = 1 + ln tan(t/2).
    const Dual time(t, Eigen::Matrix<double, 1, 1>::Constant(1.0));
    using std::log;
    using std::tan;
    const Dual arc_length = 1.0 + log(tan(time / 2.0));
    EXPECT_NEAR(arc_length.derivatives()(0), w1, 1e-13 * w1);
  }
  // The initial conditions of eq. (3.9).
  EXPECT_NEAR(1.0 + std::log(std::tan(kPi / 4)), 1.0, 1e-15);
  // det M = −sin²χ: singular at χ = kπ, where ω1 = 1/sin t blows up.
  EXPECT_NEAR(model.mass_matrix(kPi / 2).determinant(), -1.0, 1e-15);
  EXPECT_NEAR(model.mass_matrix(kPi).determinant(), 0.0, 1e-15);
}

TEST(PaperSpecialCase, RequiresUnitWheelbase) {
  EXPECT_THROW(CartModel(CartParameters{}, InertiaModel::kPaperSpecialCase), std::invalid_argument);
}

// T* (eq. (2.8)) equals the body-by-body kinetic energy of the independent model (eq. (2.6)).
TEST_F(CartModelIdentities, ReducedKineticEnergyEqualsBodyByBodySum) {
  const full_model::FullCoordinateModel full(parameters_);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    CartState state;
    state.x = 20.0 * unit(generator_);
    state.y = 20.0 * unit(generator_);
    state.heading = 5.0 * unit(generator_);
    state.steering_angle = 5.0 * unit(generator_);
    for (double& spin : state.wheel_spin_angle) spin = 30.0 * unit(generator_);
    state.forward_speed = 6.0 * unit(generator_);
    state.steering_rate = 3.0 * unit(generator_);
    Eigen::Matrix<double, 8, 1> q;
    q << state.x, state.y, state.heading, state.steering_angle, state.wheel_spin_angle[0],
        state.wheel_spin_angle[1], state.wheel_spin_angle[2], state.wheel_spin_angle[3];
    const double body_sum = full.kinetic_energy(q, model_.coordinate_velocities(state));
    EXPECT_NEAR(model_.energy(state), body_sum, kRelativeTolerance * (1.0 + body_sum)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace birkhoff_cart
