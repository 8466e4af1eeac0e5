// An INDEPENDENT model of the cart for the tests: Lagrange's equations of the first kind in the
// eight coordinates q = (x, y, θ, χ, φ1, φ2, φ3, φ4) with multipliers for the six constraints of
// the paper's eq. (15) (wheel 2 with φ̇2: docs/derivation.md eq. (2.2)).
//
// It is built body by body from the rigid-body geometry of docs eq. (2.1) and shares NO formula
// with CartModel (it does not include cart_model.h and reads only CartParameters): no μ, μ1, ν,
// no quasi-velocities, no rim-speed coefficients. Each of the six bodies (rear body, two rear
// wheels, front axle, two front wheels) is a planar rigid body whose centre sits at
//     p(q) = B + R(ψ) ρ,      B = (x, y),  ψ = θ (rear parts) or θ + χ (front parts),
// with a constant offset ρ in its carrier's frame; the wheels also spin by φ_i about their axles.
//   T(q, q̇) = Σ_b ½ m_b |ṗ_b|² + ½ I_b ψ̇_b² + ½ J_b φ̇_b²,
//   M(q) q̈ + c(q, q̇) = f + A(q)ᵀ λ,     A(q) q̇ = 0,
// with M = Σ m JᵀJ + I ∇ψᵀ∇ψ + J ∇φᵀ∇φ, c = Σ m Jᵀ (J̇ q̇) (the d'Alembert form of Lagrange's
// equations for rigid bodies whose yaw and spin angles are linear in q), solved as the KKT system
//   [[M, Aᵀ], [A, 0]] [q̈; −λ] = [f − c; −Ȧ q̇].
// J̇ q̇ and Ȧ q̇ come from forward-mode AD (a Jet seeded with q̇); the analytic position Jacobian is
// itself checked against AD of the position in independent_model_test.cpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <unsupported/Eigen/AutoDiff>

#include "birkhoff_cart/core/physics/parameters.h"

namespace birkhoff_cart {
namespace full_model {

constexpr int kCoordinateCount = 8;  ///< q = (x, y, θ, χ, φ1..φ4)
constexpr int kConstraintCount = 6;  ///< paper eq. (15)

/// Index of each coordinate in q.
enum Coordinate : int {
  kX = 0,         ///< x of hinge B [m]
  kY = 1,         ///< y of hinge B [m]
  kHeading = 2,   ///< θ [rad]
  kSteering = 3,  ///< χ [rad]
  kSpin1 = 4,     ///< φ1 (rear left) [rad]; φ2, φ3, φ4 follow
};

template <class Scalar>
using Coordinates = Eigen::Matrix<Scalar, kCoordinateCount, 1>;
using Vector8 = Coordinates<double>;
using Matrix8 = Eigen::Matrix<double, kCoordinateCount, kCoordinateCount>;
using ConstraintMatrix = Eigen::Matrix<double, kConstraintCount, kCoordinateCount>;
/// One-direction dual number: its derivative part carries d/dt along q̇.
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;

/// One rigid body of the cart (docs eq. (2.1), DESIGN.md §4 modelling assumptions).
struct Body {
  double mass = 0.0;           ///< [kg]
  double yaw_inertia = 0.0;    ///< about the vertical axis through its centre [kg·m²]
  double spin_inertia = 0.0;   ///< about its own axle (wheels only) [kg·m²]
  int spin_coordinate = -1;    ///< index of φ_i in q, −1 for the rear body and front axle
  bool rides_front_axle = false;  ///< yaw ψ = θ + χ (front) or θ (rear)
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();  ///< ρ: centre in the carrier frame, from B [m]
};

/// Loads applied directly in the eight coordinates (not through any generalized-force formula).
struct AppliedLoads {
  double steering_torque = 0.0;  ///< τ: front axle on rear body, does work τ χ̇ [N·m]
  double drive_torque = 0.0;     ///< T: total motor torque on the rear axle, T/2 on each φ1, φ2 [N·m]
};

/// The six bodies, rear body first, wheels numbered as in the paper (1, 3 left; 2, 4 right).
inline std::array<Body, 6> cart_bodies(const CartParameters& p) {
  const double l = p.wheelbase;
  std::array<Body, 6> bodies;
  // Rear body: centre at A = B − l e (frame offset (−l, 0)), yaw θ.
  bodies[0] = {p.rear_body_mass, p.rear_body_yaw_inertia, 0.0, -1, false, {-l, 0.0}};
  // Rear wheels at A + a n (left, φ1) and A − a n (right, φ2).
  bodies[1] = {p.rear_wheel_mass, p.rear_wheel_yaw_inertia, p.rear_wheel_spin_inertia, kSpin1, false,
               {-l, p.rear_half_track}};
  bodies[2] = {p.rear_wheel_mass, p.rear_wheel_yaw_inertia, p.rear_wheel_spin_inertia, kSpin1 + 1, false,
               {-l, -p.rear_half_track}};
  // Front axle: centre at B, yaw θ + χ.
  bodies[3] = {p.front_axle_mass, p.front_axle_yaw_inertia, 0.0, -1, true, {0.0, 0.0}};
  // Front wheels at B + c g (left, φ3) and B − c g (right, φ4).
  bodies[4] = {p.front_wheel_mass, p.front_wheel_yaw_inertia, p.front_wheel_spin_inertia, kSpin1 + 2, true,
               {0.0, p.front_half_track}};
  bodies[5] = {p.front_wheel_mass, p.front_wheel_yaw_inertia, p.front_wheel_spin_inertia, kSpin1 + 3, true,
               {0.0, -p.front_half_track}};
  return bodies;
}

/// ψ_b(q): θ for rear parts, θ + χ for front parts [rad].
template <class Scalar>
Scalar yaw_angle(const Body& body, const Coordinates<Scalar>& q) {
  return body.rides_front_axle ? Scalar(q(kHeading) + q(kSteering)) : q(kHeading);
}

/// ∇ψ_b: the constant row ∂ψ_b/∂q.
inline Eigen::Matrix<double, 1, kCoordinateCount> yaw_gradient(const Body& body) {
  Eigen::Matrix<double, 1, kCoordinateCount> gradient = Eigen::Matrix<double, 1, kCoordinateCount>::Zero();
  gradient(kHeading) = 1.0;
  if (body.rides_front_axle) gradient(kSteering) = 1.0;
  return gradient;
}

/// p_b(q) = B + R(ψ) ρ [m].
template <class Scalar>
Eigen::Matrix<Scalar, 2, 1> centre_position(const Body& body, const Coordinates<Scalar>& q) {
  using std::cos;
  using std::sin;
  const Scalar psi = yaw_angle(body, q);
  Eigen::Matrix<Scalar, 2, 1> position;
  position(0) = q(kX) + cos(psi) * body.offset(0) - sin(psi) * body.offset(1);
  position(1) = q(kY) + sin(psi) * body.offset(0) + cos(psi) * body.offset(1);
  return position;
}

/// J_b(q) = ∂p_b/∂q (2×8): identity in (x, y), R'(ψ) ρ = R(ψ) [[0, −1], [1, 0]] ρ in each
/// coordinate that ψ depends on.
template <class Scalar>
Eigen::Matrix<Scalar, 2, kCoordinateCount> position_jacobian(const Body& body, const Coordinates<Scalar>& q) {
  using std::cos;
  using std::sin;
  const Scalar psi = yaw_angle(body, q);
  Eigen::Matrix<Scalar, 2, kCoordinateCount> jacobian;
  for (int row = 0; row < 2; ++row)
    for (int column = 0; column < kCoordinateCount; ++column) jacobian(row, column) = Scalar(0.0) * psi;
  jacobian(0, kX) = Scalar(1.0);
  jacobian(1, kY) = Scalar(1.0);
  Eigen::Matrix<Scalar, 2, 1> swing;  // ∂p/∂ψ [m/rad]
  swing(0) = -sin(psi) * body.offset(0) - cos(psi) * body.offset(1);
  swing(1) = cos(psi) * body.offset(0) - sin(psi) * body.offset(1);
  jacobian.col(kHeading) = swing;
  if (body.rides_front_axle) jacobian.col(kSteering) = swing;
  return jacobian;
}

/// A(q): the six constraints of the paper's eq. (15) as rows, A q̇ = 0 (docs eq. (2.2)):
///   B has no side slip; A has no side slip; wheels 1, 2 (with φ̇2, not the printed φ1) and 3, 4 roll.
template <class Scalar>
Eigen::Matrix<Scalar, kConstraintCount, kCoordinateCount> constraint_matrix(const CartParameters& p,
                                                                            const Coordinates<Scalar>& q) {
  using std::cos;
  using std::sin;
  const Scalar theta = q(kHeading);
  const Scalar front = q(kHeading) + q(kSteering);
  Eigen::Matrix<Scalar, kConstraintCount, kCoordinateCount> a;
  for (int row = 0; row < kConstraintCount; ++row)
    for (int column = 0; column < kCoordinateCount; ++column) a(row, column) = Scalar(0.0) * theta;
  // −ẋ sin(θ+χ) + ẏ cos(θ+χ) = 0
  a(0, kX) = -sin(front);
  a(0, kY) = cos(front);
  // −ẋ sin θ + ẏ cos θ − l θ̇ = 0
  a(1, kX) = -sin(theta);
  a(1, kY) = cos(theta);
  a(1, kHeading) = Scalar(-p.wheelbase);
  // ẋ cos θ + ẏ sin θ ∓ a θ̇ − r1 φ̇1,2 = 0
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    a(2 + side, kX) = cos(theta);
    a(2 + side, kY) = sin(theta);
    a(2 + side, kHeading) = Scalar(sign * p.rear_half_track);
    a(2 + side, kSpin1 + side) = Scalar(-p.rear_wheel_radius);
  }
  // ẋ cos(θ+χ) + ẏ sin(θ+χ) ∓ c (θ̇ + χ̇) − r2 φ̇3,4 = 0
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    a(4 + side, kX) = cos(front);
    a(4 + side, kY) = sin(front);
    a(4 + side, kHeading) = Scalar(sign * p.front_half_track);
    a(4 + side, kSteering) = Scalar(sign * p.front_half_track);
    a(4 + side, kSpin1 + 2 + side) = Scalar(-p.front_wheel_radius);
  }
  return a;
}

/// The full-coordinate model: constant data only, every query is a pure function of (q, q̇).
class FullCoordinateModel {
 public:
  explicit FullCoordinateModel(const CartParameters& parameters)
      : parameters_(parameters), bodies_(cart_bodies(parameters)) {}

  const std::array<Body, 6>& bodies() const { return bodies_; }

  /// T = Σ_b ½ m |ṗ|² + ½ I ψ̇² + ½ J φ̇², summed body by body from the bodies' velocities [J].
  double kinetic_energy(const Vector8& q, const Vector8& qd) const {
    double energy = 0.0;
    for (const Body& body : bodies_) {
      const Eigen::Vector2d velocity = position_jacobian<double>(body, q) * qd;  // ṗ_b [m/s]
      const double yaw_rate = yaw_gradient(body).dot(qd);                        // ψ̇_b [rad/s]
      const double spin_rate = body.spin_coordinate >= 0 ? qd(body.spin_coordinate) : 0.0;  // φ̇_b [rad/s]
      energy += 0.5 * body.mass * velocity.squaredNorm() + 0.5 * body.yaw_inertia * yaw_rate * yaw_rate +
                0.5 * body.spin_inertia * spin_rate * spin_rate;
    }
    return energy;
  }

  /// M(q) = Σ_b m JᵀJ + I ∇ψᵀ∇ψ + J e_φ e_φᵀ  [kg, kg·m, kg·m² by block].
  Matrix8 mass_matrix(const Vector8& q) const {
    Matrix8 mass = Matrix8::Zero();
    for (const Body& body : bodies_) {
      const Eigen::Matrix<double, 2, kCoordinateCount> jacobian = position_jacobian<double>(body, q);
      const Eigen::Matrix<double, 1, kCoordinateCount> yaw = yaw_gradient(body);
      mass += body.mass * jacobian.transpose() * jacobian + body.yaw_inertia * yaw.transpose() * yaw;
      if (body.spin_coordinate >= 0) mass(body.spin_coordinate, body.spin_coordinate) += body.spin_inertia;
    }
    return mass;
  }

  /// c(q, q̇) = Σ_b m J_bᵀ (J̇_b q̇): the velocity terms of Lagrange's equations [N, N·m].
  /// J̇ q̇ = d/dt (J(q) q̇) at fixed q̇, by a dual number seeded with q̇.
  Vector8 velocity_terms(const Vector8& q, const Vector8& qd) const {
    const Coordinates<Dual> q_dual = seeded(q, qd);
    Vector8 terms = Vector8::Zero();
    for (const Body& body : bodies_) {
      const Eigen::Matrix<Dual, 2, kCoordinateCount> jacobian = position_jacobian<Dual>(body, q_dual);
      Eigen::Vector2d convective;  // J̇ q̇ [m/s²]
      for (int row = 0; row < 2; ++row) {
        Dual velocity = Dual(0.0);
        for (int column = 0; column < kCoordinateCount; ++column) velocity += jacobian(row, column) * qd(column);
        convective(row) = velocity.derivatives()(0);
      }
      terms += body.mass * position_jacobian<double>(body, q).transpose() * convective;
    }
    return terms;
  }

  ConstraintMatrix constraints(const Vector8& q) const { return constraint_matrix<double>(parameters_, q); }

  /// Ȧ q̇ [m/s²], by a dual number seeded with q̇.
  Eigen::Matrix<double, kConstraintCount, 1> constraint_velocity_terms(const Vector8& q, const Vector8& qd) const {
    const Eigen::Matrix<Dual, kConstraintCount, kCoordinateCount> a =
        constraint_matrix<Dual>(parameters_, seeded(q, qd));
    Eigen::Matrix<double, kConstraintCount, 1> terms;
    for (int row = 0; row < kConstraintCount; ++row) {
      Dual rate = Dual(0.0);
      for (int column = 0; column < kCoordinateCount; ++column) rate += a(row, column) * qd(column);
      terms(row) = rate.derivatives()(0);
    }
    return terms;
  }

  /// f: the applied loads as generalized forces in q (power f·q̇ = τ χ̇ + T/2 (φ̇1 + φ̇2)).
  static Vector8 applied_force(const AppliedLoads& loads) {
    Vector8 force = Vector8::Zero();
    force(kSteering) = loads.steering_torque;
    force(kSpin1) = 0.5 * loads.drive_torque;
    force(kSpin1 + 1) = 0.5 * loads.drive_torque;
    return force;
  }

  /// q̈ from the KKT system [[M, Aᵀ], [A, 0]] [q̈; −λ] = [f − c; −Ȧ q̇]; λ (constraint forces
  /// [N, N·m]) is written to `multipliers` when given.
  Vector8 acceleration(const Vector8& q, const Vector8& qd, const AppliedLoads& loads,
                       Eigen::Matrix<double, kConstraintCount, 1>* multipliers = nullptr) const {
    return acceleration(q, qd, applied_force(loads), multipliers);
  }

  /// The same for any generalized force f in the eight coordinates [N, N·m].
  Vector8 acceleration(const Vector8& q, const Vector8& qd, const Vector8& force,
                       Eigen::Matrix<double, kConstraintCount, 1>* multipliers = nullptr) const {
    constexpr int kSize = kCoordinateCount + kConstraintCount;
    Eigen::Matrix<double, kSize, kSize> kkt = Eigen::Matrix<double, kSize, kSize>::Zero();
    const ConstraintMatrix a = constraints(q);
    kkt.topLeftCorner<kCoordinateCount, kCoordinateCount>() = mass_matrix(q);
    kkt.topRightCorner<kCoordinateCount, kConstraintCount>() = a.transpose();
    kkt.bottomLeftCorner<kConstraintCount, kCoordinateCount>() = a;
    Eigen::Matrix<double, kSize, 1> right;
    right.head<kCoordinateCount>() = force - velocity_terms(q, qd);
    right.tail<kConstraintCount>() = -constraint_velocity_terms(q, qd);
    const Eigen::Matrix<double, kSize, 1> solution = kkt.fullPivLu().solve(right);
    if (multipliers != nullptr) *multipliers = -solution.tail<kConstraintCount>();
    return solution.head<kCoordinateCount>();
  }

  /// The admissible q̇ (A q̇ = 0) whose B moves at `forward_speed` [m/s] along the front axle
  /// heading and whose steering angle turns at `steering_rate` [rad/s]: an 8×8 linear solve.
  Vector8 admissible_velocity(const Vector8& q, double forward_speed, double steering_rate) const {
    Matrix8 system = Matrix8::Zero();
    Vector8 right = Vector8::Zero();
    system.topRows<kConstraintCount>() = constraints(q);
    const double front = q(kHeading) + q(kSteering);
    system(6, kX) = std::cos(front);  // speed of B along (cos(θ+χ), sin(θ+χ))
    system(6, kY) = std::sin(front);
    right(6) = forward_speed;
    system(7, kSteering) = 1.0;  // χ̇
    right(7) = steering_rate;
    return system.fullPivLu().solve(right);
  }

  /// Speed of B along the front axle heading, (ẋ, ẏ)·(cos(θ+χ), sin(θ+χ)) [m/s].
  static double front_axle_speed(const Vector8& q, const Vector8& qd) {
    const double front = q(kHeading) + q(kSteering);
    return qd(kX) * std::cos(front) + qd(kY) * std::sin(front);
  }

  /// The momenta conjugate to the two quasi-velocities, computed from the body-by-body kinetic
  /// energy alone: q̇ = ω1 v1(q) + ω2 v2(q) on the constraint manifold, so
  ///   p_i = ∂T*/∂ω_i = q̇ᵀ M(q) v_i(q),   v_i = admissible_velocity(q, e_i)   [kg·m/s, kg·m²/s].
  /// (Any q̇, admissible or not, is projected this way; along the motion it is admissible.)
  Eigen::Vector2d reduced_momentum(const Vector8& q, const Vector8& qd) const {
    const Matrix8 mass = mass_matrix(q);
    return {qd.dot(mass * admissible_velocity(q, 1.0, 0.0)), qd.dot(mass * admissible_velocity(q, 0.0, 1.0))};
  }

  /// ṗ along the full model's motion under the generalized force f [N, N·m in q]: central
  /// difference of reduced_momentum over ±ε [s] with q(±ε), q̇(±ε) from their Taylor series
  /// (error O(ε²); ε = 1e-5 s gives ~1e-9 relative).
  Eigen::Vector2d reduced_momentum_rate(const Vector8& q, const Vector8& qd, const Vector8& force,
                                        double epsilon = 1e-5) const {
    const Vector8 qdd = acceleration(q, qd, force);
    const Vector8 q_later = q + epsilon * qd + 0.5 * epsilon * epsilon * qdd;
    const Vector8 q_earlier = q - epsilon * qd + 0.5 * epsilon * epsilon * qdd;
    return (reduced_momentum(q_later, qd + epsilon * qdd) - reduced_momentum(q_earlier, qd - epsilon * qdd)) /
           (2.0 * epsilon);
  }

  /// ∂T*/∂χ at constant ω, T*(χ, ω) = T(q, ω1 v1 + ω2 v2), by a central difference in χ [J/rad].
  double reduced_energy_steering_derivative(const Vector8& q, double forward_speed, double steering_rate,
                                            double epsilon = 1e-6) const {
    Vector8 q_plus = q, q_minus = q;
    q_plus(kSteering) += epsilon;
    q_minus(kSteering) -= epsilon;
    return (kinetic_energy(q_plus, admissible_velocity(q_plus, forward_speed, steering_rate)) -
            kinetic_energy(q_minus, admissible_velocity(q_minus, forward_speed, steering_rate))) /
           (2.0 * epsilon);
  }

 private:
  static Coordinates<Dual> seeded(const Vector8& q, const Vector8& qd) {
    Coordinates<Dual> q_dual;
    for (int i = 0; i < kCoordinateCount; ++i)
      q_dual(i) = Dual(q(i), Eigen::Matrix<double, 1, 1>::Constant(qd(i)));
    return q_dual;
  }

  CartParameters parameters_;
  std::array<Body, 6> bodies_;
};

/// Classical fixed-step RK4 for the tests: y⁽ᵏ⁺¹⁾ ← y⁽ᵏ⁾ + h/6 (k1 + 2 k2 + 2 k3 + k4).
template <class State, class Rate>
State runge_kutta4_step(const Rate& rate, double time, const State& state, double step) {
  const State k1 = rate(time, state);
  const State k2 = rate(time + 0.5 * step, State(state + 0.5 * step * k1));
  const State k3 = rate(time + 0.5 * step, State(state + 0.5 * step * k2));
  const State k4 = rate(time + step, State(state + step * k3));
  return state + (step / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

}  // namespace full_model
}  // namespace birkhoff_cart
