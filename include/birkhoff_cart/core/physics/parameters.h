// Physical parameters of the four-wheel steered cart and the coefficients of its reduced kinetic
// energy T* (docs/derivation.md, eqs. (2.8)–(2.11)).
#pragma once

#include <string>

namespace birkhoff_cart {

/// The 15 physical parameters of the cart (paper §4, DESIGN.md §4) plus gravity. SI units.
/// Defaults are the project's default cart.
struct CartParameters {
  double wheelbase = 1.05;                 ///< l: distance from rear-axle midpoint A to hinge B [m]
  double rear_half_track = 0.55;           ///< a: rear wheel centre to A, along the rear axle [m]
  double front_half_track = 0.5;           ///< c: front wheel centre to B, along the front axle [m]
  double rear_wheel_radius = 0.14;         ///< r1 [m]
  double front_wheel_radius = 0.13;        ///< r2 [m]
  double rear_body_mass = 140.0;           ///< M1: rear body without wheels, centre of mass at A [kg]
  double rear_body_yaw_inertia = 30.0;     ///< Θ1: about the vertical axis through A [kg·m²]
  double front_axle_mass = 12.0;           ///< M2: front axle without wheels, centre at B [kg]
  double front_axle_yaw_inertia = 1.0;     ///< Θ2: about the vertical axis through B [kg·m²]
  double rear_wheel_mass = 3.0;            ///< m1: each rear wheel [kg]
  double rear_wheel_spin_inertia = 0.03;   ///< J1: about its axle [kg·m²]
  double rear_wheel_yaw_inertia = 0.025;   ///< J1': about the vertical diameter [kg·m²]
  double front_wheel_mass = 2.2;           ///< m3: each front wheel [kg]
  double front_wheel_spin_inertia = 0.019; ///< J3: about its axle [kg·m²]
  double front_wheel_yaw_inertia = 0.013;  ///< J3': about the vertical diameter [kg·m²]
  double gravity = 9.81;                   ///< g: only the rolling-resistance loads use it [m/s²]

  /// Throws std::invalid_argument naming the first parameter that is not finite and > 0.
  void validate() const;
};

/// Coefficients of T* = ½[(μ + μ1 sin²χ) ω1² + l ν ω2² + 2 ν ω1 ω2 sin χ]   (docs eq. (2.8)).
struct ReducedInertia {
  double mu = 0.0;         ///< μ  [kg]
  double mu1 = 0.0;        ///< μ1 [kg]   (negative for most real carts: see docs eq. (2.10))
  double nu = 0.0;         ///< ν  [kg·m]
  double wheelbase = 1.0;  ///< l  [m]

  /// The paper's special case (its eq. (20)): μ = μ1 = 0, ν = 1, l = 1. Its mass matrix is
  /// singular at χ = kπ and indefinite elsewhere.
  static ReducedInertia paper_special_case();

  /// min over χ of det M(χ) = (μ + μ1 s²) l ν − ν² s², s = sin χ (docs eq. (3.3)) [kg²·m²].
  /// det M is affine in s², so the minimum is at s² = 0 or s² = 1.
  double smallest_mass_matrix_determinant() const;

  /// Throws std::invalid_argument unless M(χ) is positive definite for every χ (l ν > 0 and
  /// det M > 0): the paper's special case fails this and is admitted only when declared.
  void validate_positive_definite() const;
};

/// μ, μ1, ν of a physical cart, body by body (docs eqs. (2.9)–(2.11)). Validates `parameters`.
ReducedInertia reduced_inertia(const CartParameters& parameters);

}  // namespace birkhoff_cart
