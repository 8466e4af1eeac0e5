// Reduced (Boltzmann–Hamel) dynamics of the cart in the quasi-velocities ω = (ω1, ω2), its
// canonical momentum form and the reconstruction of all coordinates. Equation numbers refer to
// docs/derivation.md. Functions are templates on the scalar so that forward-mode automatic
// differentiation (Eigen's AutoDiffScalar) can differentiate them exactly.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/parameters.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

template <class Scalar>
using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
template <class Scalar>
using Matrix2 = Eigen::Matrix<Scalar, 2, 2>;

/// Rates of the reconstructed coordinates, eqs. (2.3)–(2.4).
template <class Scalar>
struct CoordinateRates {
  Scalar x_rate;                           ///< ẋ [m/s]
  Scalar y_rate;                           ///< ẏ [m/s]
  Scalar heading_rate;                     ///< θ̇ [rad/s]
  std::array<Scalar, 4> wheel_spin_rate;   ///< φ̇1..φ̇4 [rad/s]
};

/// Which coefficients the model uses: a physical cart (validated, positive-definite mass
/// matrix) or the paper's special case μ = μ1 = 0, ν = 1, l = 1 (singular at χ = kπ).
enum class InertiaModel { kPhysical, kPaperSpecialCase };

/// The constant part of the simulation: parameters and reduced-inertia coefficients.
class CartModel {
 public:
  /// Validates `parameters`; for kPaperSpecialCase the wheelbase must be 1 m (eq. (3.9)).
  /// Throws std::invalid_argument with a message naming the offending parameter.
  explicit CartModel(const CartParameters& parameters,
                     InertiaModel inertia_model = InertiaModel::kPhysical);

  const CartParameters& parameters() const { return parameters_; }
  const ReducedInertia& inertia() const { return inertia_; }
  InertiaModel inertia_model() const { return inertia_model_; }

  /// M(χ) = [[μ + μ1 s², ν s], [ν s, l ν]], s = sin χ, so that T* = ½ ωᵀ M ω   (eq. (3.3)).
  template <class Scalar>
  Matrix2<Scalar> mass_matrix(const Scalar& steering_angle) const {
    using deterministic::sin;
    return mass_matrix_at(Scalar(sin(steering_angle)));
  }

  /// M(χ) from s = sin χ [-] (the right-hand sides compute sin χ and cos χ once per evaluation and
  /// hand them to the *_at functions: one sincos instead of three calls).
  template <class Scalar>
  Matrix2<Scalar> mass_matrix_at(const Scalar& s) const {
    Matrix2<Scalar> mass;
    mass(0, 0) = inertia_.mu + inertia_.mu1 * s * s;
    mass(0, 1) = inertia_.nu * s;
    mass(1, 0) = mass(0, 1);
    mass(1, 1) = Scalar(inertia_.wheelbase * inertia_.nu);
    return mass;
  }

  /// T* [J]   (eq. (2.8)).
  template <class Scalar>
  Scalar kinetic_energy(const Scalar& steering_angle, const Vector2<Scalar>& quasi_velocity) const {
    return Scalar(0.5) * quasi_velocity.dot(mass_matrix(steering_angle) * quasi_velocity);
  }

  /// p = ∂T*/∂ω = M(χ) ω   (eq. (3.5)): p1 [kg·m/s], p2 [kg·m²/s].
  template <class Scalar>
  Vector2<Scalar> momentum(const Scalar& steering_angle, const Vector2<Scalar>& quasi_velocity) const {
    return mass_matrix(steering_angle) * quasi_velocity;
  }

  /// ω = M(χ)⁻¹ p (closed-form 2×2 inverse; singular only in the paper's case at χ = kπ).
  template <class Scalar>
  Vector2<Scalar> quasi_velocity(const Scalar& steering_angle, const Vector2<Scalar>& momentum) const {
    return solve_mass(mass_matrix(steering_angle), momentum);
  }
  /// ω = M(χ)⁻¹ p from s = sin χ.
  template <class Scalar>
  Vector2<Scalar> quasi_velocity_at(const Scalar& s, const Vector2<Scalar>& momentum) const {
    return solve_mass(mass_matrix_at(s), momentum);
  }

  /// Nonholonomic (gyroscopic) force of the canonical form (eq. (3.6)):
  ///   ṗ = ∂T*/∂q|_ω + Λ_nh + Q, with  Λ_nh = ( μ1 s c ω1 ω2 + ν c ω2²,  −μ1 s c ω1² − ν c ω1 ω2 ).
  /// Together with ∂T*/∂χ = μ1 s c ω1² + ν c ω1 ω2 it gives ṗ1 = Q1 + μ1 s c ω1 ω2 + ν c ω2² and
  /// ṗ2 = Q2. It is workless: ω·Λ_nh = 0 (eq. (3.7)).
  template <class Scalar>
  Vector2<Scalar> nonholonomic_force(const Scalar& steering_angle,
                                     const Vector2<Scalar>& quasi_velocity) const {
    using deterministic::cos;
    using deterministic::sin;
    const Scalar s = sin(steering_angle);
    const Scalar c = cos(steering_angle);
    return nonholonomic_force_at(s, c, quasi_velocity);
  }

  /// ∂T*/∂χ at constant ω = μ1 s c ω1² + ν c ω1 ω2 [J/rad] (= −∂H̃/∂χ at constant p).
  template <class Scalar>
  Scalar kinetic_energy_steering_derivative(const Scalar& steering_angle,
                                            const Vector2<Scalar>& quasi_velocity) const {
    using deterministic::cos;
    using deterministic::sin;
    return kinetic_energy_steering_derivative_at(Scalar(sin(steering_angle)), Scalar(cos(steering_angle)),
                                                 quasi_velocity);
  }

  /// ṗ = ∂T*/∂q|_ω + Λ_nh + Q summed in closed form (eq. (3.6)): the χ-row of ∂T*/∂q|_ω cancels
  /// that of Λ_nh, so ṗ1 = Q1 + μ1 s c ω1 ω2 + ν c ω2² [N] and ṗ2 = Q2 [N·m] exactly (eq. (3.8)).
  /// One sin/cos of χ instead of one in each of nonholonomic_force and
  /// kinetic_energy_steering_derivative, and no cancellation in ṗ2.
  template <class Scalar>
  Vector2<Scalar> momentum_rate(const Scalar& steering_angle, const Vector2<Scalar>& quasi_velocity,
                                const Vector2<Scalar>& generalized_force) const {
    using deterministic::cos;
    using deterministic::sin;
    return momentum_rate_at(Scalar(sin(steering_angle)), Scalar(cos(steering_angle)), quasi_velocity,
                            generalized_force);
  }
  /// ṗ of eq. (3.8) from s = sin χ, c = cos χ.
  template <class Scalar>
  Vector2<Scalar> momentum_rate_at(const Scalar& s, const Scalar& c, const Vector2<Scalar>& quasi_velocity,
                                   const Vector2<Scalar>& generalized_force) const {
    Vector2<Scalar> rate;
    rate(0) = nonholonomic_force_at(s, c, quasi_velocity)(0) + generalized_force(0);  // Λ_nh,1 + Q1
    rate(1) = generalized_force(1);
    return rate;
  }

  /// Boltzmann–Hamel equations solved for ω̇ (eq. (3.4)):
  ///   M(χ) ω̇ = Q − h(χ, ω),   h = (μ1 s c ω1 ω2,  ν c ω1 ω2).
  template <class Scalar>
  Vector2<Scalar> quasi_acceleration(const Scalar& steering_angle, const Vector2<Scalar>& quasi_velocity,
                                     const Vector2<Scalar>& generalized_force) const {
    using deterministic::cos;
    using deterministic::sin;
    const Scalar s = sin(steering_angle);
    const Scalar c = cos(steering_angle);
    const Scalar coupling = quasi_velocity(0) * quasi_velocity(1) * c;
    Vector2<Scalar> right_hand_side;
    right_hand_side(0) = generalized_force(0) - inertia_.mu1 * s * coupling;
    right_hand_side(1) = generalized_force(1) - inertia_.nu * coupling;
    return solve_mass(mass_matrix(steering_angle), right_hand_side);
  }

  /// Rim speed coefficients of the four wheels, r_i φ̇_i = d1_i ω1 + d2_i ω2   (eq. (2.4)):
  ///   d1 = (cos χ − a s/l, cos χ + a s/l, 1 − c s/l, 1 + c s/l),  d2 = (0, 0, −c, c).
  template <class Scalar>
  void rim_speed_coefficients(const Scalar& steering_angle, std::array<Scalar, 4>& d1,
                              std::array<double, 4>& d2) const {
    using deterministic::cos;
    using deterministic::sin;
    rim_speed_coefficients_at(Scalar(sin(steering_angle)), Scalar(cos(steering_angle)), d1, d2);
  }
  /// The same from s = sin χ, c = cos χ.
  template <class Scalar>
  void rim_speed_coefficients_at(const Scalar& s, const Scalar& c, std::array<Scalar, 4>& d1,
                                 std::array<double, 4>& d2) const {
    const double l = parameters_.wheelbase;
    const double a = parameters_.rear_half_track;
    const double cf = parameters_.front_half_track;
    d1 = {c - a * s / l, c + a * s / l, Scalar(1.0) - cf * s / l, Scalar(1.0) + cf * s / l};
    d2 = {0.0, 0.0, -cf, cf};
  }

  /// Wheel radius of wheel i (0-based: 0, 1 rear; 2, 3 front) [m].
  double wheel_radius(int wheel) const {
    return wheel < 2 ? parameters_.rear_wheel_radius : parameters_.front_wheel_radius;
  }

  /// Kinematic reconstruction (eqs. (2.3)–(2.4)):
  ///   ẋ = ω1 cos(θ+χ), ẏ = ω1 sin(θ+χ), θ̇ = ω1 sin χ / l, r_i φ̇_i = d1_i ω1 + d2_i ω2.
  template <class Scalar>
  CoordinateRates<Scalar> coordinate_rates(const Scalar& heading, const Scalar& steering_angle,
                                           const Vector2<Scalar>& quasi_velocity) const {
    using deterministic::cos;
    using deterministic::sin;
    return coordinate_rates_at(heading, steering_angle, Scalar(sin(steering_angle)), Scalar(cos(steering_angle)),
                               quasi_velocity);
  }
  /// The same from s = sin χ, c = cos χ.
  template <class Scalar>
  CoordinateRates<Scalar> coordinate_rates_at(const Scalar& heading, const Scalar& steering_angle, const Scalar& s,
                                              const Scalar& c, const Vector2<Scalar>& quasi_velocity) const {
    using deterministic::cos;
    using deterministic::sin;
    const Scalar front_heading = heading + steering_angle;
    return coordinate_rates_from(s, c, Scalar(sin(front_heading)), Scalar(cos(front_heading)), quasi_velocity);
  }
  /// The same from s = sin χ, c = cos χ and the sine and cosine of the front axle's heading θ + χ.
  template <class Scalar>
  CoordinateRates<Scalar> coordinate_rates_from(const Scalar& s, const Scalar& c, const Scalar& front_sin,
                                                const Scalar& front_cos, const Vector2<Scalar>& quasi_velocity) const {
    CoordinateRates<Scalar> rates;
    rates.x_rate = quasi_velocity(0) * front_cos;
    rates.y_rate = quasi_velocity(0) * front_sin;
    rates.heading_rate = heading_rate_at(s, quasi_velocity);
    std::array<Scalar, 4> d1;
    std::array<double, 4> d2;
    rim_speed_coefficients_at(s, c, d1, d2);
    for (int wheel = 0; wheel < 4; ++wheel) {
      rates.wheel_spin_rate[wheel] =
          (d1[wheel] * quasi_velocity(0) + d2[wheel] * quasi_velocity(1)) / wheel_radius(wheel);
    }
    return rates;
  }

  /// θ̇ = ω1 sin χ / l [rad/s] (eq. (2.3)) from s = sin χ.
  template <class Scalar>
  Scalar heading_rate_at(const Scalar& s, const Vector2<Scalar>& quasi_velocity) const {
    return quasi_velocity(0) * s / parameters_.wheelbase;
  }

  /// ∂T*/∂χ at constant ω from s = sin χ, c = cos χ: −Λ_nh,2 exactly (negation is exact in
  /// floating point).
  template <class Scalar>
  Scalar kinetic_energy_steering_derivative_at(const Scalar& s, const Scalar& c,
                                               const Vector2<Scalar>& quasi_velocity) const {
    return -nonholonomic_force_at(s, c, quasi_velocity)(1);
  }

  /// T* of a state [J].
  double energy(const CartState& state) const;
  /// p2 = ∂T*/∂ω2 = l ν ω2 + ν ω1 sin χ of a state [kg·m²/s]   (eq. (3.5)).
  double steering_momentum(const CartState& state) const;
  /// Rear-axle midpoint A = B − l (cos θ, sin θ) [m] (the REP-105 base_link origin).
  Eigen::Vector2d rear_axle_midpoint(const CartState& state) const;

  /// The six constraint residuals (paper eq. (15), wheel 2 uses φ̇2) of a configuration q and
  /// velocity q̇ in the 8 coordinates (x, y, θ, χ, φ1..φ4) [m/s]. Zero on admissible motion.
  static Eigen::Matrix<double, 6, 1> constraint_residuals(const CartParameters& parameters,
                                                          const Eigen::Matrix<double, 8, 1>& coordinates,
                                                          const Eigen::Matrix<double, 8, 1>& velocities);
  /// The velocities q̇ of a state, from eqs. (2.3)–(2.4).
  Eigen::Matrix<double, 8, 1> coordinate_velocities(const CartState& state) const;
  /// Largest |residual| of the state's own q̇ (a consistency diagnostic) [m/s].
  double max_constraint_residual(const CartState& state) const;

 private:
  /// Λ_nh of eq. (3.6) from s = sin χ, c = cos χ (computed once by the caller):
  ///   ( μ1 s c ω1 ω2 + ν c ω2²,  −μ1 s c ω1² − ν c ω1 ω2 ).
  template <class Scalar>
  Vector2<Scalar> nonholonomic_force_at(const Scalar& s, const Scalar& c, const Vector2<Scalar>& quasi_velocity) const {
    const Scalar& w1 = quasi_velocity(0);
    const Scalar& w2 = quasi_velocity(1);
    Vector2<Scalar> force;
    force(0) = inertia_.mu1 * s * c * w1 * w2 + inertia_.nu * c * w2 * w2;
    force(1) = -inertia_.mu1 * s * c * w1 * w1 - inertia_.nu * c * w1 * w2;
    return force;
  }

  /// M⁻¹ b by the closed-form 2×2 inverse (Cramer's rule).
  template <class Scalar>
  static Vector2<Scalar> solve_mass(const Matrix2<Scalar>& mass, const Vector2<Scalar>& b) {
    const Scalar determinant = mass(0, 0) * mass(1, 1) - mass(0, 1) * mass(1, 0);
    Vector2<Scalar> solution;
    solution(0) = (mass(1, 1) * b(0) - mass(0, 1) * b(1)) / determinant;
    solution(1) = (mass(0, 0) * b(1) - mass(1, 0) * b(0)) / determinant;
    return solution;
  }

  CartParameters parameters_;
  ReducedInertia inertia_;
  InertiaModel inertia_model_;
};

}  // namespace birkhoff_cart
