// The Chaplygin sleigh as a Birkhoffian system: a worked example of bringing your own system to the
// integrators (docs/integrators.md, "Bring your own system"; the concept: birkhoffian_system.h).
//
// A rigid body on the plane rests on a knife edge at P, which cannot slide sideways. Its centre of
// mass C lies a distance a ahead of P along the blade (Chaplygin 1911; Neimark & Fufaev 1972, §III;
// Bloch 2003, §1.7). With v the speed of P along the blade and ω = θ̇ the turning rate as
// quasi-velocities, T* = ½ m v² + ½ J ω², J = I_C + m a², and the Boltzmann–Hamel equations are
//
//   m v̇ = m a ω²,   J ω̇ = −m a v ω                                            (S.1)
//
// (the blade's reaction does no work). In Birkhoffian variables z = (π1, θ, p1, p2): the arc length
// π1 travelled by P (a quasi-coordinate, π̇1 = v), the heading θ, and the momenta p = (m v, J ω);
// passive coordinates y = (x, y), the position of P: ẋ = v cos θ, ẏ = v sin θ.
//
// Two representations of the same motion, as for the cart (docs/birkhoffian.md §3), chosen by the
// conformal rate γ [1/s] (γ = 0: the autonomous canonical form; γ = 1: the seed paper's eᵗ form):
//
//   R = e^{γ(t−tₑ)} (p1, p2, 0, 0),  B = e^{γ(t−tₑ)} H̃,  H̃ = p1²/2m + p2²/2J = T*,
//   K = e^{γ(t−tₑ)} K₀,  ∂R/∂t = γ R,  Λ = e^{γ(t−tₑ)} (−(Λ_nh + γ p), 0, 0),
//   Λ_nh = (m a ω², −m a v ω)                                                  (S.2)
//
// so that K ż = ∇B + ∂R/∂t + Λ gives ṗ = Λ_nh, π̇1 = v, θ̇ = ω for every γ. Darboux chart:
// w = D(z, t) = (π1, θ, e^{γ(t−tₑ)} p1, e^{γ(t−tₑ)} p2), linear in z. With Λ off (the Birkhoffian
// part, for the K-symplecticity tests) the motion is the free body's, its momenta decaying as
// e^{−γ(t−tₑ)}.
//
// Invariants and closed form (all members are checked against them: test/unit/
// integrator_contract_test.cpp, k_symplectic_test.cpp, chaplygin_sleigh_test.cpp; under the step
// controls, system_step_controls_test.cpp): the energy
// E = T* is conserved (a quadratic invariant: Gauss collocation keeps it to round-off); with
// V = √(2E/m), Ω = √(2E/J), λ = m a V / J [1/s] and ω₀ ≠ 0,
//
//   v(t) = V tanh(λ(t − t*)),  ω(t) = ±Ω sech(λ(t − t*)),
//   θ(t) = θ* ± (Ω/λ) gd(λ(t − t*)),  π1(t) = π1* + (V/λ) ln cosh(λ(t − t*))        (S.3)
//
// (gd the Gudermannian, t* where v = 0): the sleigh turns through ±πΩ/λ in all and ends gliding
// straight at the speed V, ω → 0 like e^{−λt} (its known asymptotics).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <stdexcept>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

namespace birkhoff_cart {

/// Indices of z for the sleigh.
enum ChaplyginSleighIndex {
  kSleighArcLength = 0,        ///< π1: arc length travelled by the contact point P [m]
  kSleighHeading = 1,          ///< θ: heading of the blade [rad]
  kSleighForwardMomentum = 2,  ///< p1 = m v [kg·m/s]
  kSleighAngularMomentum = 3,  ///< p2 = J ω, the angular momentum about P [kg·m²/s]
};

/// The sleigh's constants.
struct ChaplyginSleighParameters {
  double mass = 2.0;                  ///< m [kg]
  double inertia_at_centre = 0.5;     ///< I_C, yaw inertia about the centre of mass C [kg·m²]
  double centre_offset = 0.3;         ///< a, distance of C ahead of P along the blade [m]
  double conformal_rate = 0.0;        ///< γ [1/s]: 0 the autonomous form, 1 the paper's eᵗ form
  double structure_epoch = 0.0;       ///< tₑ [s]: keeps e^{γ(t − tₑ)} of order 1 near the run's times

  /// J = I_C + m a², the yaw inertia about P [kg·m²].
  double inertia_at_contact() const { return inertia_at_centre + mass * centre_offset * centre_offset; }
};

/// The Chaplygin sleigh (S.1)–(S.2), a model of the Birkhoffian-system concept (birkhoffian_system.h)
/// with every optional hook the collocation members detect that it can use.
class ChaplyginSleigh {
 public:
  // --- required: dimensions ------------------------------------------------------------------
  static constexpr int kDimension = 4;         ///< z = (π1, θ, p1, p2)
  static constexpr int kPassiveDimension = 2;  ///< y = (x, y) of P [m]

  // --- optional hooks the collocation members detect (birkhoffian_system.h) --------------------
  /// No rate of w reads π1 or θ (ẇ depends on the momenta and t alone): the stage solve takes them
  /// out of the Newton block and their changes do not vote in its stop rule.
  static constexpr unsigned kCyclicMask = (1u << kSleighArcLength) | (1u << kSleighHeading);
  /// g(z, t) does not read y at all: one passive sweep is exact.
  static constexpr int kPassiveCouplingDepth = 0;
  /// D scales the momenta by e^{γ(t−tₑ)}: linear in z, so compensated summation's remainders map
  /// through it.
  static constexpr bool kDarbouxChartIsLinear = true;
  /// The heading θ is an angle (the rates are 2π-periodic in it): a step control carries it reduced
  /// to (−π, π] with its whole turns apart (system_traits.h, carried_point.h).
  static constexpr std::array<AngleCoordinate, 1> kAngleCoordinates{{{false, kSleighHeading}}};

  template <class S>
  using Vector = Eigen::Matrix<S, kDimension, 1>;
  template <class S>
  using Matrix = Eigen::Matrix<S, kDimension, kDimension>;
  template <class S>
  using Passive = Eigen::Matrix<S, kPassiveDimension, 1>;

  explicit ChaplyginSleigh(const ChaplyginSleighParameters& parameters = {}) : parameters_(parameters) {
    const ChaplyginSleighParameters& p = parameters;
    if (!(p.mass > 0.0) || !(p.inertia_at_centre > 0.0) || !std::isfinite(p.mass) || !std::isfinite(p.inertia_at_centre)) {
      throw std::invalid_argument("Chaplygin sleigh: mass and inertia_at_centre must be finite and > 0");
    }
    if (!std::isfinite(p.centre_offset) || !std::isfinite(p.conformal_rate) || !std::isfinite(p.structure_epoch)) {
      throw std::invalid_argument("Chaplygin sleigh: centre_offset, conformal_rate and structure_epoch must be finite");
    }
  }

  const ChaplyginSleighParameters& parameters() const { return parameters_; }

  /// Λ on (the sleigh) or off (its Birkhoffian part: the K-symplecticity tests).
  bool non_birkhoffian_force_enabled() const { return non_birkhoffian_force_enabled_; }
  void set_non_birkhoffian_force_enabled(bool enabled) { non_birkhoffian_force_enabled_ = enabled; }

  /// e^{γ(t − tₑ)} [-].
  template <class S>
  S conformal_factor(const S& t) const {
    using std::exp;
    return exp(parameters_.conformal_rate * (t - parameters_.structure_epoch));
  }

  /// ω = M⁻¹ p = (v [m/s], ω [rad/s]) of z.
  template <class S>
  Eigen::Matrix<S, 2, 1> quasi_velocity(const Vector<S>& z) const {
    return Eigen::Matrix<S, 2, 1>(z(kSleighForwardMomentum) / parameters_.mass, z(kSleighAngularMomentum) / inertia());
  }

  /// H̃ = p1²/2m + p2²/2J = T* [J]: the energy, conserved by the sleigh.
  template <class S>
  S hamiltonian(const Vector<S>& z) const {
    const Eigen::Matrix<S, 2, 1> omega = quasi_velocity(z);
    return S(0.5) * (z(kSleighForwardMomentum) * omega(0) + z(kSleighAngularMomentum) * omega(1));
  }

  /// Λ_nh = ṗ = (m a ω² [N], −m a v ω [N·m]) at momenta p (S.1): the blade's reaction.
  template <class S>
  Eigen::Matrix<S, 2, 1> nonholonomic_force(const S& p1, const S& p2) const {
    const double m = parameters_.mass, a = parameters_.centre_offset, j = inertia();
    return Eigen::Matrix<S, 2, 1>(m * a * (p2 / j) * (p2 / j), -a * (p1 / j) * p2);
  }

  // --- required: the Birkhoffian structure (S.2) -----------------------------------------------
  /// R = e^{γ(t−tₑ)} (p1, p2, 0, 0) [kg·m/s, kg·m²/s].
  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& t) const {
    const S e = conformal_factor(t);
    return Vector<S>(e * z(kSleighForwardMomentum), e * z(kSleighAngularMomentum), S(0.0) * e, S(0.0) * e);
  }
  /// B = e^{γ(t−tₑ)} H̃ [J].
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& t) const {
    return conformal_factor(t) * hamiltonian(z);
  }
  /// K = e^{γ(t−tₑ)} K₀.
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& /*z*/, const S& t) const {
    return canonical_structure<kDimension>().template cast<S>() * conformal_factor(t);
  }
  /// K⁻¹ = −e^{−γ(t−tₑ)} K₀ (K₀² = −I): optional, saves the LU of birkhoffian_rates.
  template <class S>
  Matrix<S> structure_matrix_inverse(const Vector<S>& /*z*/, const S& t) const {
    return canonical_structure<kDimension>().template cast<S>() * (-1.0 / conformal_factor(t));
  }
  /// ∇B = e^{γ(t−tₑ)} (0, 0, v, ω).
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& t) const {
    const S e = conformal_factor(t);
    const Eigen::Matrix<S, 2, 1> omega = quasi_velocity(z);
    return Vector<S>(S(0.0) * e, S(0.0) * e, e * omega(0), e * omega(1));
  }
  /// ∂R/∂t = γ R.
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const {
    return birkhoff_functions(z, t) * S(parameters_.conformal_rate);
  }
  /// Λ = e^{γ(t−tₑ)} (−(Λ_nh + γ p), 0, 0); zero when disabled.
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& t) const {
    const S e = conformal_factor(t);
    Vector<S> force = Vector<S>::Constant(S(0.0) * e);
    if (!non_birkhoffian_force_enabled_) return force;
    const Eigen::Matrix<S, 2, 1> reaction = nonholonomic_force(z(kSleighForwardMomentum), z(kSleighAngularMomentum));
    const double gamma = parameters_.conformal_rate;
    force(kSleighArcLength) = -e * (reaction(0) + gamma * z(kSleighForwardMomentum));
    force(kSleighHeading) = -e * (reaction(1) + gamma * z(kSleighAngularMomentum));
    return force;
  }

  // --- required: the Darboux chart and the rates in it ----------------------------------------
  /// w = D(z, t) = (π1, θ, e^{γ(t−tₑ)} p1, e^{γ(t−tₑ)} p2).
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& t) const {
    const S e = conformal_factor(t);
    Vector<S> w = z;
    w(kSleighForwardMomentum) *= e;
    w(kSleighAngularMomentum) *= e;
    return w;
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& t) const {
    const S inverse = S(1.0) / conformal_factor(t);
    Vector<S> z = w;
    z(kSleighForwardMomentum) *= inverse;
    z(kSleighAngularMomentum) *= inverse;
    return z;
  }
  /// ẇ = D_z ż + ∂_t D = (v, ω, e^{γ(t−tₑ)} (ṗ + γ p)): with Λ, ṗ = Λ_nh; without, ṗ = −γ p and the
  /// momentum rates in the chart vanish.
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& t) const {
    const S e = conformal_factor(t);
    const Vector<S> z = from_darboux(w, t);
    const Eigen::Matrix<S, 2, 1> omega = quasi_velocity(z);
    Vector<S> rate;
    rate(kSleighArcLength) = omega(0);
    rate(kSleighHeading) = omega(1);
    if (non_birkhoffian_force_enabled_) {
      const Eigen::Matrix<S, 2, 1> reaction = nonholonomic_force(z(kSleighForwardMomentum), z(kSleighAngularMomentum));
      const double gamma = parameters_.conformal_rate;
      rate(kSleighForwardMomentum) = e * (reaction(0) + gamma * z(kSleighForwardMomentum));
      rate(kSleighAngularMomentum) = e * (reaction(1) + gamma * z(kSleighAngularMomentum));
    } else {
      rate(kSleighForwardMomentum) = S(0.0) * e;
      rate(kSleighAngularMomentum) = S(0.0) * e;
    }
    return rate;
  }

  // --- optional hook: J = ∂ẇ/∂w in closed form (else the members differentiate ẇ by AD) ---------
  /// With e = e^{γ(t−tₑ)}, W = (π1, θ, P1, P2), P = e p:
  ///   ẇ = (P1/(e m), P2/(e J), m a P2²/(e J²) + γ P1, −a P1 P2/(e J) + γ P2)   (Λ on).
  /// The π1 and θ columns are zero (kCyclicMask).
  Matrix<double> darboux_jacobian(const Vector<double>& w, double t) const {
    const double e = conformal_factor(t);
    const double m = parameters_.mass, a = parameters_.centre_offset, j = inertia();
    const double gamma = parameters_.conformal_rate;
    Matrix<double> jacobian = Matrix<double>::Zero();
    jacobian(kSleighArcLength, kSleighForwardMomentum) = 1.0 / (e * m);
    jacobian(kSleighHeading, kSleighAngularMomentum) = 1.0 / (e * j);
    if (non_birkhoffian_force_enabled_) {
      const double p1 = w(kSleighForwardMomentum), p2 = w(kSleighAngularMomentum);  // P1, P2 (chart momenta)
      jacobian(kSleighForwardMomentum, kSleighForwardMomentum) = gamma;
      jacobian(kSleighForwardMomentum, kSleighAngularMomentum) = 2.0 * m * a * p2 / (e * j * j);
      jacobian(kSleighAngularMomentum, kSleighForwardMomentum) = -a * p2 / (e * j);
      jacobian(kSleighAngularMomentum, kSleighAngularMomentum) = -a * p1 / (e * j) + gamma;
    }
    return jacobian;
  }

  // --- required: the passive coordinates ------------------------------------------------------
  /// g(z, t) = (ẋ, ẏ) = v (cos θ, sin θ) [m/s]: reads z only (kPassiveCouplingDepth = 0).
  template <class S>
  Passive<S> passive_rates(const Vector<S>& z, const S& /*t*/) const {
    using std::cos;
    using std::sin;
    const S v = z(kSleighForwardMomentum) / parameters_.mass;
    return Passive<S>(v * cos(z(kSleighHeading)), v * sin(z(kSleighHeading)));
  }

  /// z of the sleigh at speed v [m/s] and turning rate ω [rad/s] (p = (m v, J ω)).
  Vector<double> state(double arc_length, double heading, double speed, double turning_rate) const {
    return Vector<double>(arc_length, heading, parameters_.mass * speed, inertia() * turning_rate);
  }

 private:
  double inertia() const { return parameters_.inertia_at_contact(); }

  ChaplyginSleighParameters parameters_;
  bool non_birkhoffian_force_enabled_ = true;
};

/// The sleigh in its autonomous form (γ = 0): its Darboux chart is the identity, which the reversible
/// step control's time transformation needs (time_transformed_system.h). Nothing else differs.
class AutonomousChaplyginSleigh : public ChaplyginSleigh {
 public:
  static constexpr bool kDarbouxChartIsIdentity = true;
  explicit AutonomousChaplyginSleigh(const ChaplyginSleighParameters& parameters = {}) : ChaplyginSleigh(parameters) {
    if (parameters.conformal_rate != 0.0) {
      throw std::invalid_argument("AutonomousChaplyginSleigh: conformal_rate must be 0 (the identity chart)");
    }
  }
};

/// The closed-form motion (S.3) of the sleigh from z₀ at t₀ (centre_offset a > 0): z at any t.
class ChaplyginSleighMotion {
 public:
  ChaplyginSleighMotion(const ChaplyginSleigh& sleigh, const Eigen::Vector4d& z0, double t0)
      : z0_(z0), t0_(t0), turning_sign_(z0(kSleighAngularMomentum) >= 0.0 ? 1.0 : -1.0) {
    const ChaplyginSleighParameters& p = sleigh.parameters();
    if (!(p.centre_offset > 0.0)) throw std::invalid_argument("ChaplyginSleighMotion: needs centre_offset > 0");
    const double energy = sleigh.hamiltonian(Eigen::Vector4d(z0));  // E [J]
    final_speed_ = std::sqrt(2.0 * energy / p.mass);
    peak_turning_rate_ = std::sqrt(2.0 * energy / p.inertia_at_contact());
    rate_ = p.mass * p.centre_offset * final_speed_ / p.inertia_at_contact();
    straight_ = z0(kSleighAngularMomentum) == 0.0;
    speed0_ = z0(kSleighForwardMomentum) / p.mass;
    phase0_ = straight_ ? 0.0 : std::atanh(speed0_ / final_speed_);  // λ(t₀ − t*)
  }

  /// V = √(2E/m): the speed it ends gliding at [m/s].
  double final_speed() const { return final_speed_; }
  /// Ω = √(2E/J): the turning rate where v = 0 [rad/s].
  double peak_turning_rate() const { return peak_turning_rate_; }
  /// λ = m a V / J: the rate at which ω dies away [1/s].
  double decay_rate() const { return rate_; }
  /// The heading turned through from t₀ to t → ∞ [rad].
  double remaining_turn() const {
    return straight_ ? 0.0 : turning_sign_ * peak_turning_rate_ / rate_ * (0.5 * kPi - gudermannian(phase0_));
  }

  /// z at time t [s].
  Eigen::Vector4d at(double t, const ChaplyginSleigh& sleigh) const {
    const ChaplyginSleighParameters& p = sleigh.parameters();
    if (straight_) {
      return Eigen::Vector4d(z0_(kSleighArcLength) + speed0_ * (t - t0_), z0_(kSleighHeading), z0_(kSleighForwardMomentum), 0.0);
    }
    const double phase = phase0_ + rate_ * (t - t0_);  // λ(t − t*)
    const double speed = final_speed_ * std::tanh(phase);
    const double turning = turning_sign_ * peak_turning_rate_ / std::cosh(phase);
    const double heading = z0_(kSleighHeading) +
                           turning_sign_ * peak_turning_rate_ / rate_ * (gudermannian(phase) - gudermannian(phase0_));
    const double arc = z0_(kSleighArcLength) + final_speed_ / rate_ * (log_cosh(phase) - log_cosh(phase0_));
    return Eigen::Vector4d(arc, heading, p.mass * speed, p.inertia_at_contact() * turning);
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;
  static double gudermannian(double x) { return std::atan(std::sinh(x)); }
  /// ln cosh x without overflow: |x| + ln((1 + e^{−2|x|})/2).
  static double log_cosh(double x) {
    const double ax = std::abs(x);
    return ax + std::log1p(std::exp(-2.0 * ax)) - std::log(2.0);
  }

  Eigen::Vector4d z0_;
  double t0_;
  double turning_sign_;
  double final_speed_ = 0.0, peak_turning_rate_ = 0.0, rate_ = 0.0, speed0_ = 0.0, phase0_ = 0.0;
  bool straight_ = false;
};

}  // namespace birkhoff_cart
