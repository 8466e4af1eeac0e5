// The reduced Boltzmann–Hamel model (CartModel, docs eqs. (3.3)–(3.4), (2.3)–(2.4), (4.1)–(4.2))
// against an independent Lagrange-multiplier model in the eight coordinates built body by body
// (full_coordinate_model.h): same instantaneous accelerations, same trajectories over seconds of
// steering and drive torque, and a clear failure when μ1 is replaced by the paper's printed
// eq. (19) (docs eq. (2.12)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <random>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/effects/air_drag.h"
#include "birkhoff_cart/core/physics/effects/rolling_resistance.h"
#include "birkhoff_cart/core/physics/effects/steering_damping.h"
#include "birkhoff_cart/core/physics/effects/steering_stiffness.h"
#include "full_coordinate_model.h"
#include "generated_docs.h"

namespace birkhoff_cart {
namespace {

using full_model::AppliedLoads;
using full_model::FullCoordinateModel;
using full_model::Vector8;

constexpr double kPi = 3.14159265358979323846;
constexpr double kJacobianTolerance = 1e-13;        // [m/rad]
constexpr double kEnergyRelativeTolerance = 1e-13;  // [-]
constexpr double kAccelerationTolerance = 1e-11;    // relative to the largest term [-]
constexpr double kTrajectoryTolerance = 1e-9;       // [m], [rad], [m/s], [rad/s]
constexpr double kConstraintDriftTolerance = 1e-10; // [m/s]
constexpr double kPrintedMu1Disagreement = 1e-3;    // the typo must show at least this [m] or [rad]
constexpr double kStep = 2.5e-4;                    // RK4 step of both models [s]

/// Reduced state (x, y, θ, χ, φ1..φ4, ω1, ω2) [m, m, rad, rad, rad×4, m/s, rad/s].
using ReducedState = Eigen::Matrix<double, 10, 1>;
/// Full state (q, q̇).
using FullState = Eigen::Matrix<double, 16, 1>;

/// A time-varying load history, applied to both models.
struct LoadHistory {
  double steering_offset = 0.0;     ///< [N·m]
  double steering_amplitude = 0.0;  ///< [N·m]
  double steering_frequency = 0.0;  ///< [rad/s]
  double drive_mean = 0.0;          ///< [N·m]
  double drive_amplitude = 0.0;     ///< [N·m]
  double drive_frequency = 0.0;     ///< [rad/s]
  AppliedLoads at(double time) const {
    AppliedLoads loads;
    loads.steering_torque = steering_offset + steering_amplitude * std::sin(steering_frequency * time);
    loads.drive_torque = drive_mean + drive_amplitude * std::cos(drive_frequency * time);
    return loads;
  }
};

/// Q = (T cos χ / r1, τ): docs eqs. (4.2) (drive torque) and (4.1) (steering torque) [N, N·m].
Vector2<double> generalized_force(const CartParameters& p, const AppliedLoads& loads, double steering_angle) {
  return {loads.drive_torque * std::cos(steering_angle) / p.rear_wheel_radius, loads.steering_torque};
}

/// Boltzmann–Hamel eq. (3.4) for arbitrary coefficients: M(χ) ω̇ = Q − h. Used only to run the
/// model with the paper's printed μ1; the test ReducedRightHandSideMatchesCartModel shows it is
/// the same function as CartModel::quasi_acceleration.
Vector2<double> boltzmann_hamel_acceleration(const ReducedInertia& k, double chi, const Vector2<double>& w,
                                             const Vector2<double>& force) {
  const double s = std::sin(chi), c = std::cos(chi);
  Eigen::Matrix2d mass;
  mass << k.mu + k.mu1 * s * s, k.nu * s, k.nu * s, k.wheelbase * k.nu;
  const Eigen::Vector2d h(k.mu1 * s * c * w(0) * w(1), k.nu * c * w(0) * w(1));
  return mass.lu().solve(force - h);
}

/// μ1 as printed in the paper's eq. (19) (docs eq. (2.12)) [kg].
double paper_printed_mu1(const CartParameters& p) {
  const double l2 = p.wheelbase * p.wheelbase;
  const double c2 = p.front_half_track * p.front_half_track;
  return (p.rear_body_yaw_inertia + 2 * p.rear_wheel_mass * p.rear_half_track * p.rear_half_track +
          2 * p.rear_wheel_yaw_inertia + p.front_axle_yaw_inertia + 2 * p.front_wheel_mass * c2 +
          2 * p.front_wheel_yaw_inertia) /
             l2 -
         p.rear_body_mass - 2 * p.rear_wheel_mass +
         2 * p.front_wheel_spin_inertia / (p.front_wheel_radius * p.front_wheel_radius) * c2 / l2 -
         p.rear_wheel_spin_inertia / (p.rear_wheel_radius * p.rear_wheel_radius) * (1.0 - c2 / l2);
}

/// Further loads of the reduced model, Q(t, χ, ω) [N, N·m] (e.g. an EffectSet).
using ReducedLoads = std::function<Vector2<double>(double, double, const Vector2<double>&)>;
/// Further loads of the full model, f(q, q̇) in the eight coordinates [N, N·m].
using FullLoads = std::function<Vector8(const Vector8&, const Vector8&)>;

/// dy/dt of the reduced model: reconstruction eqs. (2.3)–(2.4), χ̇ = ω2, ω̇ from `acceleration`.
template <class Acceleration>
ReducedState reduced_rate(const CartModel& model, const LoadHistory& history, const ReducedLoads& extra,
                          const Acceleration& acceleration, double time, const ReducedState& y) {
  const Vector2<double> w(y(8), y(9));
  const CoordinateRates<double> rates = model.coordinate_rates(y(2), y(3), w);
  Vector2<double> force = generalized_force(model.parameters(), history.at(time), y(3));
  if (extra) force += extra(time, y(3), w);
  const Vector2<double> w_rate = acceleration(y(3), w, force);
  ReducedState rate;
  rate << rates.x_rate, rates.y_rate, rates.heading_rate, w(1), rates.wheel_spin_rate[0], rates.wheel_spin_rate[1],
      rates.wheel_spin_rate[2], rates.wheel_spin_rate[3], w_rate(0), w_rate(1);
  return rate;
}

FullState full_rate(const FullCoordinateModel& model, const LoadHistory& history, const FullLoads& extra,
                    double time, const FullState& y) {
  const Vector8 q = y.head<8>(), qd = y.tail<8>();
  Vector8 force = FullCoordinateModel::applied_force(history.at(time));
  if (extra) force += extra(q, qd);
  FullState rate;
  rate << qd, model.acceleration(q, qd, force);
  return rate;
}

/// What the two models are compared on: the 8 coordinates and (ω1, ω2).
Eigen::Matrix<double, 10, 1> observables_of_full(const FullState& y) {
  const Vector8 q = y.head<8>(), qd = y.tail<8>();
  Eigen::Matrix<double, 10, 1> observed;
  observed << q, FullCoordinateModel::front_axle_speed(q, qd), qd(full_model::kSteering);
  return observed;
}

struct Comparison {
  double max_difference = 0.0;            ///< max over time and observables [m, rad, m/s, rad/s]
  double max_constraint_residual = 0.0;   ///< of the full model's q̇ [m/s]
  double min_steering_angle = 0.0;        ///< [rad]
  double max_steering_angle = 0.0;        ///< [rad]
  double final_forward_speed = 0.0;       ///< [m/s]
};

/// Integrates both models from the same admissible state with RK4 (step kStep) and records the
/// largest disagreement.
template <class Acceleration>
Comparison compare_trajectories(const CartParameters& parameters, const Acceleration& reduced_acceleration,
                                const LoadHistory& history, const Vector8& q0, double forward_speed,
                                double steering_rate, double duration, const ReducedLoads& reduced_extra = {},
                                const FullLoads& full_extra = {}) {
  const CartModel model(parameters);
  const FullCoordinateModel full(parameters);
  FullState full_state;
  full_state << q0, full.admissible_velocity(q0, forward_speed, steering_rate);
  ReducedState reduced_state;
  reduced_state << q0, forward_speed, steering_rate;
  const auto reduced_rhs = [&](double t, const ReducedState& y) {
    return reduced_rate(model, history, reduced_extra, reduced_acceleration, t, y);
  };
  const auto full_rhs = [&](double t, const FullState& y) { return full_rate(full, history, full_extra, t, y); };
  Comparison result;
  result.min_steering_angle = result.max_steering_angle = q0(full_model::kSteering);
  const int steps = static_cast<int>(std::lround(duration / kStep));
  for (int k = 0; k < steps; ++k) {
    const double t = k * kStep;
    reduced_state = full_model::runge_kutta4_step(reduced_rhs, t, reduced_state, kStep);
    full_state = full_model::runge_kutta4_step(full_rhs, t, full_state, kStep);
    result.max_difference =
        std::max(result.max_difference, (observables_of_full(full_state) - reduced_state).cwiseAbs().maxCoeff());
    const Vector8 q = full_state.head<8>(), qd = full_state.tail<8>();
    result.max_constraint_residual =
        std::max(result.max_constraint_residual, (full.constraints(q) * qd).cwiseAbs().maxCoeff());
    result.min_steering_angle = std::min(result.min_steering_angle, reduced_state(3));
    result.max_steering_angle = std::max(result.max_steering_angle, reduced_state(3));
  }
  result.final_forward_speed = reduced_state(8);
  return result;
}

TEST(FullCoordinateModel, PositionJacobianMatchesAutomaticDifferentiation) {
  const FullCoordinateModel full{CartParameters{}};
  std::mt19937 generator(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int trial = 0; trial < 20; ++trial) {
    Vector8 q;
    for (int i = 0; i < 8; ++i) q(i) = angle(generator);
    full_model::Coordinates<Jet<8>> q_jet;
    for (int i = 0; i < 8; ++i) q_jet(i) = Jet<8>(q(i), Eigen::Matrix<double, 8, 1>::Unit(i));
    for (const full_model::Body& body : full.bodies()) {
      const Eigen::Matrix<Jet<8>, 2, 1> position = full_model::centre_position<Jet<8>>(body, q_jet);
      const Eigen::Matrix<double, 2, 8> jacobian = full_model::position_jacobian<double>(body, q);
      for (int row = 0; row < 2; ++row)
        for (int column = 0; column < 8; ++column)
          EXPECT_NEAR(jacobian(row, column), position(row).derivatives()(column), kJacobianTolerance);
    }
  }
}

TEST(FullCoordinateModel, MassMatrixReproducesBodyByBodyKineticEnergy) {
  const FullCoordinateModel full{CartParameters{}};
  std::mt19937 generator(11);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    Vector8 q, qd;
    for (int i = 0; i < 8; ++i) {
      q(i) = uniform(generator);
      qd(i) = uniform(generator);
    }
    const double energy = full.kinetic_energy(q, qd);
    EXPECT_NEAR(0.5 * qd.dot(full.mass_matrix(q) * qd), energy, kEnergyRelativeTolerance * energy);
  }
}

TEST(FullCoordinateModel, AdmissibleVelocitySatisfiesAllSixConstraints) {
  const FullCoordinateModel full{CartParameters{}};
  Vector8 q;
  q << 0.3, -0.2, 0.4, 1.1, 0.0, 0.0, 0.0, 0.0;
  const Vector8 qd = full.admissible_velocity(q, 1.7, -0.6);
  EXPECT_LT((full.constraints(q) * qd).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_NEAR(FullCoordinateModel::front_axle_speed(q, qd), 1.7, 1e-14);
  EXPECT_NEAR(qd(full_model::kSteering), -0.6, 1e-14);
}

TEST(ReducedModel, ReducedRightHandSideMatchesCartModel) {
  // The local eq. (3.4) used for the printed-μ1 run is the very function CartModel implements.
  const CartModel model{CartParameters{}};
  std::mt19937 generator(3);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double chi = uniform(generator);
    const Vector2<double> w(uniform(generator), uniform(generator));
    const Vector2<double> force(40 * uniform(generator), 5 * uniform(generator));
    const Vector2<double> expected = model.quasi_acceleration(chi, w, force);
    const Vector2<double> local = boltzmann_hamel_acceleration(model.inertia(), chi, w, force);
    EXPECT_NEAR(local(0), expected(0), 1e-12 * (1 + expected.norm()));
    EXPECT_NEAR(local(1), expected(1), 1e-12 * (1 + expected.norm()));
  }
}

// At random admissible states the full model's q̈, mapped to (ω̇1, ω̇2), is the reduced ω̇.
/// docs/derivation.md's table of the independent model states `measured` as the last figure of the
/// row that starts with `row` (two digits: 6 %; "4·10⁻¹⁵", one digit: 25 %).
void expect_the_derivation_table_states(const std::string& row, double measured, double tolerance = 0.06) {
  const std::string page = "docs/derivation.md";
  const std::size_t figures = birkhoff_cart_test::figures_after(page, "| " + row + " | ").size();
  ASSERT_GT(figures, 0u) << page << " has no row '" << row << "'";
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, "| " + row + " | ", figures - 1, measured, tolerance));
}

TEST(IndependentModel, InstantaneousAccelerationsAgreeAtRandomStates) {
  const CartParameters parameters;
  const CartModel model(parameters);
  const FullCoordinateModel full(parameters);
  std::mt19937 generator(2024);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    Vector8 q;
    for (int i = 0; i < 8; ++i) q(i) = 4.0 * uniform(generator);
    const double forward_speed = 5.0 * uniform(generator), steering_rate = 3.0 * uniform(generator);
    const Vector8 qd = full.admissible_velocity(q, forward_speed, steering_rate);
    AppliedLoads loads;
    loads.steering_torque = 10.0 * uniform(generator);
    loads.drive_torque = 50.0 * uniform(generator);
    const Vector8 qdd = full.acceleration(q, qd, loads);
    const double front = q(2) + q(3), front_rate = qd(2) + qd(3);
    // ω̇1 = d/dt[ẋ cos(θ+χ) + ẏ sin(θ+χ)],  ω̇2 = χ̈.
    const double full_w1_rate = qdd(0) * std::cos(front) + qdd(1) * std::sin(front) +
                                front_rate * (-qd(0) * std::sin(front) + qd(1) * std::cos(front));
    const Vector2<double> w(forward_speed, steering_rate);
    const Vector2<double> reduced =
        model.quasi_acceleration(q(3), w, generalized_force(parameters, loads, q(3)));
    const double scale = 1.0 + reduced.cwiseAbs().maxCoeff();
    worst = std::max(worst, std::max(std::abs(full_w1_rate - reduced(0)), std::abs(qdd(3) - reduced(1))) / scale);
    EXPECT_NEAR(full_w1_rate, reduced(0), kAccelerationTolerance * scale) << "trial " << trial;
    EXPECT_NEAR(qdd(3), reduced(1), kAccelerationTolerance * scale) << "trial " << trial;
  }
  std::cout << "[ measured ] max relative |ω̇_full − ω̇_reduced| over 200 random states: " << worst << "\n";
  expect_the_derivation_table_states("ω̇ at 200 random states (relative)", worst, 0.25);
}

/// CartModel's reduced accelerations ω̇ (docs eq. (3.4)) in the form compare_trajectories takes.
auto cart_model_acceleration(const CartModel& model) {
  return [&model](double chi, const Vector2<double>& w, const Vector2<double>& force) {
    return model.quasi_acceleration(chi, w, force);
  };
}

/// Steering and drive torques of the steering-and-drive run, shared by the agreement test and the
/// refutation of the paper's printed μ1 so that both integrate the same motion.
LoadHistory steering_and_drive_history() {
  LoadHistory history;
  history.steering_offset = 0.5;     // [N·m]
  history.steering_amplitude = 6.0;  // [N·m]
  history.steering_frequency = 1.7;  // [rad/s]
  history.drive_mean = 25.0;         // [N·m]
  history.drive_amplitude = 15.0;    // [N·m]
  history.drive_frequency = 0.9;     // [rad/s]
  return history;
}

/// Start configuration q0 = (x, y, θ, χ, φ1..φ4) [m, m, rad, rad, rad ×4] of the steering-and-drive
/// run.
Vector8 steering_and_drive_start() {
  Vector8 q0;
  q0 << 0.3, -0.2, 0.4, 0.25, 0.1, -0.2, 0.3, 0.05;
  return q0;
}

TEST(IndependentModel, TrajectoriesAgreeUnderSteeringAndDriveTorque) {
  const CartParameters parameters;
  const CartModel model(parameters);
  const LoadHistory history = steering_and_drive_history();
  const Vector8 q0 = steering_and_drive_start();
  const Comparison result =
      compare_trajectories(parameters, cart_model_acceleration(model), history, q0, 1.2, 0.4, 5.0);
  std::cout << "[ measured ] 5 s, steering + drive torque: max disagreement " << result.max_difference
            << ", full-model constraint drift " << result.max_constraint_residual << " m/s, χ in ["
            << result.min_steering_angle << ", " << result.max_steering_angle << "] rad, final ω1 "
            << result.final_forward_speed << " m/s\n";
  expect_the_derivation_table_states("steering + drive torque, χ ∈ [0.25, 0.91] rad", result.max_difference);
  EXPECT_LT(result.max_difference, kTrajectoryTolerance);
  EXPECT_LT(result.max_constraint_residual, kConstraintDriftTolerance);
  EXPECT_GT(result.final_forward_speed, 2.0);  // the drive torque really drove the cart
}

TEST(IndependentModel, TrajectoriesAgreeWhileSteeringSwingsThroughRightAngles) {
  const CartParameters parameters;
  const CartModel model(parameters);
  LoadHistory history;
  history.steering_amplitude = 16.0;
  history.steering_frequency = 1.3;
  history.drive_mean = 10.0;
  history.drive_amplitude = 20.0;
  history.drive_frequency = 2.1;
  Vector8 q0;
  q0 << -1.0, 2.0, -0.7, 0.0, 0.0, 0.0, 0.0, 0.0;
  const Comparison result =
      compare_trajectories(parameters, cart_model_acceleration(model), history, q0, 0.8, -4.6, 5.0);
  expect_the_derivation_table_states("steering swinging through ±π/2 (χ ∈ [−1.86, 5.52] rad)", result.max_difference);
  std::cout << "[ measured ] 5 s, χ through ±π/2: max disagreement " << result.max_difference
            << ", full-model constraint drift " << result.max_constraint_residual << " m/s, χ in ["
            << result.min_steering_angle << ", " << result.max_steering_angle << "] rad\n";
  EXPECT_LT(result.min_steering_angle, -kPi / 2);
  EXPECT_GT(result.max_steering_angle, kPi / 2);
  EXPECT_LT(result.max_difference, kTrajectoryTolerance);
  EXPECT_LT(result.max_constraint_residual, kConstraintDriftTolerance);
}


// The dissipative effects (docs eqs. (4.3)–(4.6)) as the core's EffectSet computes Q, against the
// same loads applied body by body in the eight coordinates: a torque −c_rr N_i r_i tanh(r_i φ̇_i/v_eps)
// on each wheel's φ_i, the drag force −k|v_A|v_A at A through A's position Jacobian, and hinge
// torques −b χ̇ and −k_s χ on the χ coordinate.
TEST(IndependentModel, TrajectoriesAgreeWithRollingResistanceAirDragAndHingeSpringDamper) {
  const CartParameters p;
  const CartModel model(p);
  constexpr double kRolling = 0.015;        // c_rr [-]
  constexpr double kSpeedEpsilon = 0.05;    // v_eps [m/s]
  constexpr double kDrag = 0.3;             // k [N·s²/m²]
  constexpr double kDamping = 2.0;          // b [N·m·s/rad]
  constexpr double kStiffness = 40.0;       // k_s [N·m/rad]
  EffectSet effects;
  effects.add(std::make_unique<RollingResistance>(model, kRolling, kSpeedEpsilon));
  effects.add(std::make_unique<AirDrag>(kDrag));
  effects.add(std::make_unique<SteeringDamping>(kDamping));
  effects.add(std::make_unique<SteeringStiffness>(kStiffness));
  const ReducedLoads reduced_effects = [&](double t, double chi, const Vector2<double>& w) {
    EffectInput input;
    input.time = t;
    input.steering_angle = chi;
    input.forward_speed = w(0);
    input.steering_rate = w(1);
    return Vector2<double>(effects.evaluate(input).force);
  };
  const FullCoordinateModel full(p);
  const double rear_load = (0.5 * p.rear_body_mass + p.rear_wheel_mass) * p.gravity;    // N1, N2 [N]
  const double front_load = (0.5 * p.front_axle_mass + p.front_wheel_mass) * p.gravity;  // N3, N4 [N]
  const FullLoads full_effects = [&](const Vector8& q, const Vector8& qd) {
    Vector8 force = Vector8::Zero();
    for (int wheel = 0; wheel < 4; ++wheel) {
      const double radius = wheel < 2 ? p.rear_wheel_radius : p.front_wheel_radius;
      const double load = wheel < 2 ? rear_load : front_load;
      const double spin_rate = qd(full_model::kSpin1 + wheel);
      force(full_model::kSpin1 + wheel) += -kRolling * load * radius * std::tanh(radius * spin_rate / kSpeedEpsilon);
    }
    const full_model::Body& rear_body = full.bodies()[0];  // centre at A
    const Eigen::Matrix<double, 2, 8> jacobian = full_model::position_jacobian<double>(rear_body, q);
    const Eigen::Vector2d velocity = jacobian * qd;  // v_A [m/s]
    force += jacobian.transpose() * (-kDrag * velocity.norm() * velocity);
    force(full_model::kSteering) += -kDamping * qd(full_model::kSteering) - kStiffness * q(full_model::kSteering);
    return force;
  };
  LoadHistory history;
  history.steering_amplitude = 8.0;
  history.steering_frequency = 1.1;
  history.drive_mean = 30.0;
  history.drive_amplitude = 20.0;
  history.drive_frequency = 0.8;
  Vector8 q0;
  q0 << 0.0, 0.0, 0.2, -0.3, 0.0, 0.0, 0.0, 0.0;
  const Comparison result = compare_trajectories(p, cart_model_acceleration(model), history, q0, 2.0, 0.5, 5.0,
                                                 reduced_effects, full_effects);
  expect_the_derivation_table_states("rolling resistance, air drag, hinge damper and spring (4.3)–(4.6) from the core's "
                                     "`EffectSet` vs. the same loads applied per wheel / at A / on χ in q",
                                     result.max_difference);
  std::cout << "[ measured ] 5 s, all dissipative effects: max disagreement " << result.max_difference
            << ", χ in [" << result.min_steering_angle << ", " << result.max_steering_angle << "] rad, final ω1 "
            << result.final_forward_speed << " m/s\n";
  EXPECT_LT(result.max_difference, kTrajectoryTolerance);
  EXPECT_LT(result.max_constraint_residual, kConstraintDriftTolerance);
}

// The same comparison with μ1 from the paper's printed eq. (19): the independent model refutes it.
TEST(IndependentModel, PaperPrintedMu1IsRefutedByTheFullModel) {
  const CartParameters parameters;
  const CartModel model(parameters);
  ReducedInertia printed = model.inertia();
  printed.mu1 = paper_printed_mu1(parameters);
  std::cout << "[ measured ] μ1 correct " << model.inertia().mu1 << " kg, printed " << printed.mu1 << " kg\n";
  ASSERT_GT(std::abs(printed.mu1 - model.inertia().mu1), 0.5);
  const LoadHistory history = steering_and_drive_history();
  const Vector8 q0 = steering_and_drive_start();
  const auto printed_acceleration = [&](double chi, const Vector2<double>& w, const Vector2<double>& force) {
    return boltzmann_hamel_acceleration(printed, chi, w, force);
  };
  const Comparison result = compare_trajectories(parameters, printed_acceleration, history, q0, 1.2, 0.4, 5.0);
  std::cout << "[ measured ] 5 s with the printed μ1: max disagreement " << result.max_difference << "\n";
  expect_the_derivation_table_states("as the first trajectory, with the printed μ1 of eq. (19)", result.max_difference);
  EXPECT_GT(result.max_difference, kPrintedMu1Disagreement);
}

}  // namespace
}  // namespace birkhoff_cart
