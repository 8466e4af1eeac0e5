// Birkhoffian test systems with known solutions, modelling the concept of
// include/birkhoff_cart/core/integrators/birkhoffian_system.h (sign convention docs/birkhoffian.md eq. (B.1)):
//   K ż = ∇B + ∂R/∂t + Λ,   K_ij = ∂R_j/∂z_i − ∂R_i/∂z_j.
// Shared by the integrator tests (birkhoff and peers). The cart's Birkhoffian systems live in
// include/birkhoff_cart/core/physics/cart_birkhoffian.h.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

namespace birkhoff_cart {
namespace testing {

/// Damped oscillator m q̈ + γ m q̇ + k q = f(t) as a conformally symplectic Birkhoffian system
/// (docs/birkhoffian.md eq. (B.20)):
///   z = (q, p), R = e^{γt} (p, 0), B = e^{γt} (p²/2m + k q²/2), K = e^{γt} K₀, ∂R/∂t = γ e^{γt} (p, 0)
///   ⇒ q̇ = p/m, ṗ = −k q − γ p (+ f(t) when the forcing Λ = (−e^{γt} f(t), 0) is enabled),
/// f(t) = forcing_amplitude · cos(forcing_frequency · t). Darboux chart w = (q, e^{γt} p), in which
/// the Birkhoffian part is Hamiltonian with H_w = e^{−γt} P²/2m + e^{γt} k Q²/2.
/// Passive coordinate y = ∫ q dt (closed form: k ∫q dt = −m [q̇ + γ q], unforced).
struct DampedOscillator {
  static constexpr int kDimension = 2;
  static constexpr int kPassiveDimension = 1;
  template <class S>
  using Vector = Eigen::Matrix<S, 2, 1>;
  template <class S>
  using Matrix = Eigen::Matrix<S, 2, 2>;

  double mass = 1.0;                // m [kg]
  double stiffness = 4.0;           // k [N/m]
  double damping = 0.3;             // γ [1/s]
  double forcing_amplitude = 0.0;   // [N]
  double forcing_frequency = 1.3;   // [rad/s]
  bool forcing_enabled = false;

  bool non_birkhoffian_force_enabled() const { return forcing_enabled; }

  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& t) const {
    using std::exp;
    return Vector<S>(exp(damping * t) * z(1), S(0.0) * z(0));
  }
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& t) const {
    using std::exp;
    return exp(damping * t) * (z(1) * z(1) / (2.0 * mass) + stiffness * z(0) * z(0) / 2.0);
  }
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& /*z*/, const S& t) const {
    using std::exp;
    const S e = exp(damping * t);
    Matrix<S> k;
    k << S(0.0) * e, -e, e, S(0.0) * e;
    return k;
  }
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& t) const {
    using std::exp;
    const S e = exp(damping * t);
    return Vector<S>(e * stiffness * z(0), e * z(1) / mass);
  }
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const {
    using std::exp;
    return Vector<S>(damping * exp(damping * t) * z(1), S(0.0) * z(0));
  }
  template <class S>
  S forcing(const S& t) const {
    using std::cos;
    return forcing_amplitude * cos(forcing_frequency * t);
  }
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& t) const {
    using std::exp;
    if (!forcing_enabled) return Vector<S>(S(0.0) * z(0), S(0.0) * z(0));
    return Vector<S>(-exp(damping * t) * forcing(t), S(0.0) * z(0));
  }
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& t) const {
    using std::exp;
    return Vector<S>(z(0), exp(damping * t) * z(1));
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& t) const {
    using std::exp;
    return Vector<S>(w(0), exp(-damping * t) * w(1));
  }
  /// ẇ = (Q̇, Ṗ) = (e^{−γt} P/m, e^{γt} (−k Q + f(t))).
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& t) const {
    using std::exp;
    const S f = forcing_enabled ? forcing(t) : S(0.0) * t;
    return Vector<S>(exp(-damping * t) * w(1) / mass, exp(damping * t) * (-stiffness * w(0) + f));
  }
  template <class S>
  Eigen::Matrix<S, 1, 1> passive_rates(const Vector<S>& z, const S& /*t*/) const {
    return Eigen::Matrix<S, 1, 1>(z(0));
  }

  /// Exact unforced, underdamped (k/m > γ²/4) solution from (q0, p0, y0) at t0, evaluated at t.
  void exact(double t0, const Eigen::Vector2d& z0, double y0, double t, Eigen::Vector2d& z, double& y) const {
    const double omega_d = std::sqrt(stiffness / mass - damping * damping / 4.0);  // [rad/s]
    const double tau = t - t0;
    const double a = z0(0);
    const double b = (z0(1) / mass + damping * z0(0) / 2.0) / omega_d;
    const double decay = std::exp(-damping * tau / 2.0);
    const double co = std::cos(omega_d * tau), si = std::sin(omega_d * tau);
    z(0) = decay * (a * co + b * si);
    z(1) = mass * decay * ((-damping / 2.0 * a + omega_d * b) * co + (-damping / 2.0 * b - omega_d * a) * si);
    y = y0 - mass / stiffness * ((z(1) / mass + damping * z(0)) - (z0(1) / mass + damping * z0(0)));
  }
};

/// p of the cubic chart P = p + p³/3: the real root of p³ + 3p − 3P = 0 (Cardano, u − 1/u with
/// u = ∛(3|P|/2 + √(9P²/4 + 1)), free of cancellation in the sum), polished by Newton in double and
/// lifted to S by one Newton step so AD jets carry dp/dP = 1/(1 + p²) exactly.
template <class S>
S cubic_chart_inverse(const S& chart_momentum) {
  const double big_p = value_of(chart_momentum);
  const double u = std::cbrt(1.5 * std::abs(big_p) + std::sqrt(2.25 * big_p * big_p + 1.0));
  double p = std::copysign(u - 1.0 / u, big_p);
  for (int i = 0; i < 3; ++i) p -= (p + p * p * p / 3.0 - big_p) / (1.0 + p * p);
  // p ← p − (p + p³/3 − P)/(1 + p²) in S: value unchanged to round-off, derivative exact.
  return S(p) - (S(p + p * p * p / 3.0) - chart_momentum) / (1.0 + p * p);
}

/// A Birkhoffian system with a z-dependent structure matrix (docs eq. (B.21)):
///   z = (q, p), R = (p + p³/3, 0) ⇒ K = (1 + p²) K₀;  B = P²/2m + k Q²/2 with the chart
///   w = (Q, P) = (q, p + p³/3), in which the system is a harmonic oscillator: Q̇ = P/m, Ṗ = −k Q,
///   i.e. q̇ = P(p)/m, ṗ = −k q/(1 + p²). Exact solution through the chart. No passive coordinates.
struct CubicChartOscillator {
  static constexpr int kDimension = 2;
  static constexpr int kPassiveDimension = 0;
  template <class S>
  using Vector = Eigen::Matrix<S, 2, 1>;
  template <class S>
  using Matrix = Eigen::Matrix<S, 2, 2>;

  double mass = 1.5;       // m [kg]
  double stiffness = 2.0;  // k [N/m]

  bool non_birkhoffian_force_enabled() const { return false; }

  template <class S>
  static S chart_momentum(const S& p) {
    return p + p * p * p / 3.0;
  }
  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>(chart_momentum(z(1)), S(0.0) * z(0));
  }
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& /*t*/) const {
    const S big_p = chart_momentum(z(1));
    return big_p * big_p / (2.0 * mass) + stiffness * z(0) * z(0) / 2.0;
  }
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& z, const S& /*t*/) const {
    const S g = 1.0 + z(1) * z(1);
    Matrix<S> k;
    k << S(0.0) * g, -g, g, S(0.0) * g;
    return k;
  }
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>(stiffness * z(0), chart_momentum(z(1)) / mass * (1.0 + z(1) * z(1)));
  }
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>(S(0.0) * z(0), S(0.0) * z(0));
  }
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>(S(0.0) * z(0), S(0.0) * z(0));
  }
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>(z(0), chart_momentum(z(1)));
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& /*t*/) const {
    return Vector<S>(w(0), cubic_chart_inverse(w(1)));
  }
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& /*t*/) const {
    return Vector<S>(w(1) / mass, -stiffness * w(0));
  }
  template <class S>
  Eigen::Matrix<S, 0, 1> passive_rates(const Vector<S>& /*z*/, const S& /*t*/) const {
    return Eigen::Matrix<S, 0, 1>();
  }

  /// Exact solution from z0 at t0, evaluated at t.
  Eigen::Vector2d exact(double t0, const Eigen::Vector2d& z0, double t) const {
    const double omega = std::sqrt(stiffness / mass);  // [rad/s]
    const double tau = t - t0;
    const double q0 = z0(0), big_p0 = chart_momentum(z0(1));
    const double q = q0 * std::cos(omega * tau) + big_p0 / (mass * omega) * std::sin(omega * tau);
    const double big_p = -mass * omega * q0 * std::sin(omega * tau) + big_p0 * std::cos(omega * tau);
    return Eigen::Vector2d(q, cubic_chart_inverse(big_p));
  }
};

/// A Birkhoffian system whose Darboux chart is nonlinear in z AND depends on t (docs eq. (B.22)):
///   z = (q, p), R = (e^{γt} P(p), 0) with P(p) = p + p³/3 ⇒ K = e^{γt} (1 + p²) K₀,
///   B = e^{γt} (P²/2m + k q²/2), ∂R/∂t = γ e^{γt} (P, 0)
///   ⇒ q̇ = P/m, Ṗ = (1 + p²) ṗ = −k q − γ P: a damped oscillator in (q, P).
/// Chart w = (Q, W) = (q, e^{γt} P(p)), in which it is Hamiltonian with
/// H_w = e^{−γt} W²/2m + e^{γt} k Q²/2. Neither the identity chart (midpoint in z) nor any method
/// that is symplectic only for constant or only for z-independent K preserves K(z, t) here.
struct CubicDampedOscillator {
  static constexpr int kDimension = 2;
  static constexpr int kPassiveDimension = 0;
  template <class S>
  using Vector = Eigen::Matrix<S, 2, 1>;
  template <class S>
  using Matrix = Eigen::Matrix<S, 2, 2>;

  double mass = 1.5;       // m [kg]
  double stiffness = 2.0;  // k [N/m]
  double damping = 0.3;    // γ [1/s]

  bool non_birkhoffian_force_enabled() const { return false; }

  template <class S>
  static S chart_momentum(const S& p) {
    return p + p * p * p / 3.0;
  }
  template <class S>
  S growth(const S& t) const {
    using std::exp;
    return exp(damping * t);
  }
  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& t) const {
    return Vector<S>(growth(t) * chart_momentum(z(1)), S(0.0) * z(0));
  }
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& t) const {
    const S big_p = chart_momentum(z(1));
    return growth(t) * (big_p * big_p / (2.0 * mass) + stiffness * z(0) * z(0) / 2.0);
  }
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& z, const S& t) const {
    const S g = growth(t) * (1.0 + z(1) * z(1));
    Matrix<S> k;
    k << S(0.0) * g, -g, g, S(0.0) * g;
    return k;
  }
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& t) const {
    return growth(t) * Vector<S>(stiffness * z(0), chart_momentum(z(1)) / mass * (1.0 + z(1) * z(1)));
  }
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const {
    return Vector<S>(damping * growth(t) * chart_momentum(z(1)), S(0.0) * z(0));
  }
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>(S(0.0) * z(0), S(0.0) * z(0));
  }
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& t) const {
    return Vector<S>(z(0), growth(t) * chart_momentum(z(1)));
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& t) const {
    return Vector<S>(w(0), cubic_chart_inverse(S(w(1) / growth(t))));
  }
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& t) const {
    return Vector<S>(w(1) / (growth(t) * mass), -growth(t) * stiffness * w(0));
  }
  template <class S>
  Eigen::Matrix<S, 0, 1> passive_rates(const Vector<S>& /*z*/, const S& /*t*/) const {
    return Eigen::Matrix<S, 0, 1>();
  }
};

}  // namespace testing
}  // namespace birkhoff_cart
