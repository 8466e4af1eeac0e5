// The cart's Boltzmann–Hamel dynamics as Birkhoffian systems (docs/birkhoffian.md §3), in the
// variables z = (π1, χ, p1, p2) (state.h BirkhoffianIndex) with passive coordinates
// y = (x, y, θ, φ1..φ4, W, I2) (state.h PassiveIndex). Two representations of the same motion:
//
//  (b) CartAutonomousBirkhoffian: R = (p1, p2, 0, 0), K = K₀, B = H̃ = ½ pᵀ M(χ)⁻¹ p, ∂R/∂t = 0,
//      Λ = (−(Λ_nh + Q), 0, 0)                                               (eqs. (B.6)–(B.8))
//      Darboux chart: the identity.
//  (a) CartPaperBirkhoffian (the paper's form, eqs. (9)–(11), (24)–(25)):
//      R = e^{t−tₑ} (p1, p2, 0, 0), K = e^{t−tₑ} K₀, B = e^{t−tₑ} H̃, ∂R/∂t = e^{t−tₑ} (p, 0),
//      Λ = e^{t−tₑ} (−(Λ_nh + Q) − p, 0, 0)                                   (eqs. (B.9)–(B.11))
//      Darboux chart: w = (π1, χ, e^{t−tₑ} p1, e^{t−tₑ} p2). The structure epoch tₑ is set by
//      begin_step(t) (tₑ = t) so that e^{t−tₑ} stays O(1) for runs of any length.
//
// Both reproduce ṗ = ∂T*/∂q|_ω + Λ_nh + Q, q̇ = ω = M⁻¹ p (derivation eq. (3.6)); with
// non_birkhoffian_force disabled they are their Birkhoffian parts (Λ = 0, no applied loads):
// (b) the Hamiltonian flow of H̃, (a) the conformally symplectic ṗ = −∂H̃/∂q − p.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/state.h"
#include "birkhoff_cart/core/integrators/vector_math.h"

namespace birkhoff_cart {

/// 0 of the scalar type of `like` (an AD jet with an empty derivative part for jets).
template <class S>
S cart_birkhoffian_zero(const S& like) {
  return S(0.0) * like;
}

/// A point of the cart in Birkhoffian variables.
struct CartBirkhoffianPoint {
  Eigen::Matrix<double, kBirkhoffianSize, 1> z;  ///< (π1 [m], χ [rad], p1 [kg·m/s], p2 [kg·m²/s])
  Eigen::Matrix<double, kPassiveSize, 1> y;      ///< (x [m], y [m], θ [rad], φ1..φ4 [rad], W [J], I2 [N·m·s])
};

/// What both representations share: the model, the loads, conversions and the passive rates.
class CartBirkhoffianBase {
 public:
  static constexpr int kDimension = kBirkhoffianSize;
  static constexpr int kPassiveDimension = kPassiveSize;
  /// No rate reads the arc length π1 (it is cyclic): implicit solves need not converge it.
  static constexpr unsigned kCyclicMask = 1u << kArcLengthIndex;
  /// g reads y only through θ, and θ̇ depends on z alone: two passive sweeps are exact.
  static constexpr int kPassiveCouplingDepth = 1;
  /// Both charts are linear in z (identity; diagonal scaling of p): remainders map through them.
  static constexpr bool kDarbouxChartIsLinear = true;
  /// χ (angle 0) and θ (angle 1) are angles: a carried point keeps them reduced to (−π, π] with their
  /// whole turns apart (carried_point.h).
  static constexpr std::array<AngleCoordinate, 2> kAngleCoordinates{
      {{false, kSteeringAngleIndex}, {true, kHeadingIndex}}};
  static constexpr std::size_t kSteeringAngle = 0;  ///< χ's place in kAngleCoordinates
  static constexpr std::size_t kHeadingAngle = 1;   ///< θ's place in kAngleCoordinates
  template <class S>
  using Vector = Eigen::Matrix<S, kDimension, 1>;
  template <class S>
  using Matrix = Eigen::Matrix<S, kDimension, kDimension>;
  template <class S>
  using Passive = Eigen::Matrix<S, kPassiveDimension, 1>;

  /// `model` and `effects` must outlive the system.
  CartBirkhoffianBase(const CartModel& model, const EffectSet& effects) : model_(&model), effects_(&effects) {}

  const CartModel& model() const { return *model_; }
  /// Are the rates 2π-periodic in χ (no enabled load that grows with χ)?
  bool periodic_in_steering_angle() const { return effects_->periodic_in_steering_angle(); }
  /// The rates are 2π-periodic in θ always, and in χ unless a load grows with it (a steering spring).
  bool angle_is_periodic(std::size_t angle) const { return angle != kSteeringAngle || periodic_in_steering_angle(); }
  bool non_birkhoffian_force_enabled() const { return non_birkhoffian_force_enabled_; }
  /// Do the rates change with t at a fixed state (an enabled time profile)?
  bool depends_on_time() const { return non_birkhoffian_force_enabled_ && effects_->depends_on_time(); }
  /// Disabled: Λ = 0 and no applied loads (the Birkhoffian part; K-symplecticity tests).
  void set_non_birkhoffian_force_enabled(bool enabled) { non_birkhoffian_force_enabled_ = enabled; }

  /// (z, y) of a cart state: p = M(χ) ω (eq. (3.5)).
  CartBirkhoffianPoint to_birkhoffian(const CartState& state) const;
  /// The cart state of (z, y) at time t [s]: ω = M(χ)⁻¹ p.
  CartState to_cart_state(const Vector<double>& z, const Passive<double>& y, double t) const;

  /// ω = M(χ)⁻¹ p [m/s, rad/s].
  template <class S>
  Vector2<S> quasi_velocity(const Vector<S>& z) const {
    return model_->quasi_velocity(z(kSteeringAngleIndex),
                                  Vector2<S>(z(kForwardMomentumIndex), z(kSteeringMomentumIndex)));
  }
  /// The same from s = sin χ.
  template <class S>
  Vector2<S> quasi_velocity_at(const S& s, const Vector<S>& z) const {
    return model_->quasi_velocity_at(s, Vector2<S>(z(kForwardMomentumIndex), z(kSteeringMomentumIndex)));
  }

  /// sin χ and cos χ [-]: every rate below computes them once per evaluation (one sincos).
  template <class S>
  struct SteeringTrig {
    S s;
    S c;
  };
  template <class S>
  static SteeringTrig<S> steering_trig(const S& steering_angle) {
    using deterministic::cos;
    using deterministic::sin;
    return {sin(steering_angle), cos(steering_angle)};
  }


  /// Q = (Q1 [N], Q2 [N·m]) of the enabled loads at χ [rad] and ω = M(χ)⁻¹ p [m/s, rad/s] (the
  /// caller's, so that one evaluation of the right-hand side solves M ω = p once); zero when the
  /// non-Birkhoffian force is disabled.
  /// `trig`: sin χ and cos χ where the caller has computed them (double only), so that the loads do
  /// not compute them again (EffectInput; the same bits).
  template <class S>
  Vector2<S> generalized_force(const S& steering_angle, const Vector2<S>& omega, const S& t,
                               const SteeringTrig<S>* trig = nullptr) const {
    if (!non_birkhoffian_force_enabled_) return Vector2<S>(S(0.0) * omega(0), S(0.0) * omega(0));
    if constexpr (std::is_same_v<S, double>) {
      if (trig != nullptr) return effects_->generalized_force(t, steering_angle, omega, trig->s, trig->c);
    }
    return effects_->generalized_force(value_of(t), steering_angle, omega);
  }

  /// ω̇ = M⁻¹ (ṗ − (dM/dχ) ω2 ω) [m/s², rad/s²] at (z, t): the quasi-accelerations (eq. (3.6) with
  /// ṗ from momentum_rate; dM/dχ = [[2 μ1 s c, ν c], [ν c, 0]] from eq. (3.3)).
  template <class S>
  Vector2<S> quasi_acceleration(const Vector<S>& z, const S& t) const {
    using deterministic::cos;
    using deterministic::sin;
    const S& chi = z(kSteeringAngleIndex);
    const Vector2<S> omega = quasi_velocity(z);
    const Vector2<S> p_rate = momentum_rate(chi, omega, t);
    const S s = sin(chi);
    const S c = cos(chi);
    const ReducedInertia& inertia = model_->inertia();
    const S m00 = S(2.0 * inertia.mu1) * s * c;
    const S m01 = S(inertia.nu) * c;
    const Vector2<S> mass_rate_omega(omega(1) * (m00 * omega(0) + m01 * omega(1)), omega(1) * m01 * omega(0));
    return model_->quasi_velocity(chi, Vector2<S>(p_rate - mass_rate_omega));
  }

  /// The step density of the reversible step control's time transformation
  /// (time_transformed_system.h, docs/birkhoffian.md §11.2, eq. (B.44)) [1/s]:
  ///   σ = √(ω2² + θ̇² + σ₀²),   θ̇ = ω1 sin χ / l (eq. (2.3)),   σ₀ = 1 s⁻¹,
  /// how fast the front axle turns against the body and the body against the ground: on the
  /// jackknife whirl χ turns at up to 5 rad/s near the jackknife and 0.8 rad/s elsewhere, so the
  /// steps shrink there. σ₀ bounds the steps where the cart neither turns nor steers. A function of
  /// z alone, even in p (the reversal p ↦ −p leaves it unchanged).
  template <class S>
  S step_density(const Vector<S>& z) const {
    using deterministic::sin;
    return step_density_at(S(sin(z(kSteeringAngleIndex))), z);
  }
  /// The same from s = sin χ.
  template <class S>
  S step_density_at(const S& s, const Vector<S>& z) const {
    using std::sqrt;
    constexpr double kDensityFloor = 1.0;  // σ₀ [1/s]
    const Vector2<S> omega = quasi_velocity_at(s, z);
    const S heading_rate = omega(0) * s / model_->parameters().wheelbase;
    return sqrt(omega(1) * omega(1) + heading_rate * heading_rate + S(kDensityFloor * kDensityFloor));
  }
  /// σ at the s stages of a collocation step, sin χ from one sin_cos_lanes call (vector_math.h); bit
  /// for bit step_density stage by stage (the reversible control divides every stage's rates by it).
  template <std::size_t Count>
  void step_density_stages(const std::array<Vector<double>, Count>& z, std::array<double, Count>& densities) const {
    const StageSteeringTrig<Count> steering = stage_steering_trig(z);
    for (std::size_t j = 0; j < Count; ++j) densities[j] = step_density_at(steering.sines[j], z[j]);
  }

  /// H̃ = ½ pᵀ M(χ)⁻¹ p = T* [J].
  template <class S>
  S hamiltonian(const Vector<S>& z) const {
    const Vector2<S> omega = quasi_velocity(z);
    return S(0.5) * (z(kForwardMomentumIndex) * omega(0) + z(kSteeringMomentumIndex) * omega(1));
  }

  /// ∇H̃ = (0, ∂H̃/∂χ|_p, ω1, ω2) with ∂H̃/∂χ|_p = −∂T*/∂χ|_ω (eq. (B.5)).
  template <class S>
  Vector<S> hamiltonian_gradient(const Vector<S>& z) const {
    const Vector2<S> omega = quasi_velocity(z);
    Vector<S> gradient;
    gradient(kArcLengthIndex) = S(0.0) * omega(0);
    gradient(kSteeringAngleIndex) = -model_->kinetic_energy_steering_derivative(z(kSteeringAngleIndex), omega);
    gradient(kForwardMomentumIndex) = omega(0);
    gradient(kSteeringMomentumIndex) = omega(1);
    return gradient;
  }

  /// The physical momentum rate ṗ = ∂T*/∂q|_ω + Λ_nh + Q (eq. (3.6)) [N, N·m] at χ [rad] and
  /// ω = M(χ)⁻¹ p [m/s, rad/s].
  template <class S>
  Vector2<S> momentum_rate(const S& chi, const Vector2<S>& omega, const S& t) const {
    return model_->momentum_rate(chi, omega, generalized_force(chi, omega, t));
  }

  /// The rates of the passive coordinates that g reads, each of which depends on z alone: θ̇ =
  /// ω1 sin χ / l (eq. (2.3)), the other entries zero. The first of a collocation's
  /// kPassiveCouplingDepth + 1 passive sweeps needs only these (gauss_collocation.h); they equal the
  /// θ̇ of passive_rates bit for bit.
  template <class S>
  Passive<S> passive_coupling_rates(const Vector<S>& z, const S& /*t*/) const {
    const SteeringTrig<S> trig = steering_trig(z(kSteeringAngleIndex));
    Passive<S> rate = Passive<S>::Constant(cart_birkhoffian_zero(z(kSteeringAngleIndex)));
    rate(kHeadingIndex) = model_->heading_rate_at(trig.s, quasi_velocity_at(trig.s, z));
    return rate;
  }

  /// ẏ = g(z, y, t) = (ẋ, ẏ, θ̇, φ̇1..φ̇4, ω·Q, Q2) (eqs. (2.3)–(2.4), (3.7)). Reads only the heading
  /// θ = y(kHeadingIndex) of y (ẋ, ẏ need it), and θ̇ depends on z alone: g is triangular in y.
  template <class S>
  Passive<S> passive_rates(const Vector<S>& z, const Passive<S>& y, const S& t) const {
    const SteeringTrig<S> trig = steering_trig(z(kSteeringAngleIndex));
    const Vector2<S> omega = quasi_velocity_at(trig.s, z);
    const CoordinateRates<S> rates =
        model_->coordinate_rates_at(y(kHeadingIndex), z(kSteeringAngleIndex), trig.s, trig.c, omega);
    return passive_rates_from(omega, rates, generalized_force(z(kSteeringAngleIndex), omega, t, &trig));
  }

  /// The stages' steering angles χ [rad] with their sines and cosines [-], from one sin_cos_lanes call
  /// (vector_math.h): the same bits as deterministic::sin and cos angle by angle.
  template <std::size_t Count>
  struct StageSteeringTrig {
    std::array<double, Count> angles;
    std::array<double, Count> sines;
    std::array<double, Count> cosines;
  };
  template <std::size_t Count>
  static StageSteeringTrig<Count> stage_steering_trig(const std::array<Vector<double>, Count>& z) {
    static_assert(Count <= kMaxVectorLanes, "one vector call takes at most kMaxVectorLanes angles");
    StageSteeringTrig<Count> trig;
    for (std::size_t j = 0; j < Count; ++j) trig.angles[j] = z[j](kSteeringAngleIndex);
    sin_cos_lanes(trig.angles.data(), static_cast<int>(Count), trig.sines.data(), trig.cosines.data());
    return trig;
  }

  /// g at the s stages of a collocation step (passive_quadrature.h): the sines and cosines of the
  /// steering angles and of the front axle's headings θ + χ from one sin_cos_lanes call each
  /// (vector_math.h), the rest as passive_rates; bit for bit passive_rates stage by stage.
  template <std::size_t Count>
  void passive_rates_stages(const std::array<Vector<double>, Count>& z, const std::array<Passive<double>, Count>& y,
                            const std::array<double, Count>& t, std::array<Passive<double>, Count>& rates) const {
    const StageSteeringTrig<Count> steering = stage_steering_trig(z);
    double front_headings[Count];
    double front_sines[Count];
    double front_cosines[Count];
    for (std::size_t j = 0; j < Count; ++j) {
      front_headings[j] = y[j](kHeadingIndex) + steering.angles[j];  // θ + χ, as coordinate_rates_at forms it
    }
    sin_cos_lanes(front_headings, static_cast<int>(Count), front_sines, front_cosines);
    for (std::size_t j = 0; j < Count; ++j) {
      const Vector2<double> omega = quasi_velocity_at(steering.sines[j], z[j]);
      const CoordinateRates<double> coordinate_rates = model_->coordinate_rates_from(
          steering.sines[j], steering.cosines[j], front_sines[j], front_cosines[j], omega);
      const SteeringTrig<double> trig{steering.sines[j], steering.cosines[j]};
      rates[j] = passive_rates_from(omega, coordinate_rates, generalized_force(steering.angles[j], omega, t[j], &trig));
    }
  }

  /// passive_coupling_rates at the s stages, sin χ from one sin_cos_lanes call; bit for bit
  /// passive_coupling_rates stage by stage.
  template <std::size_t Count>
  void passive_coupling_rates_stages(const std::array<Vector<double>, Count>& z, const std::array<double, Count>& /*t*/,
                                     std::array<Passive<double>, Count>& rates) const {
    const StageSteeringTrig<Count> steering = stage_steering_trig(z);
    for (std::size_t j = 0; j < Count; ++j) {
      rates[j] = Passive<double>::Constant(cart_birkhoffian_zero(steering.angles[j]));
      rates[j](kHeadingIndex) = model_->heading_rate_at(steering.sines[j], quasi_velocity_at(steering.sines[j], z[j]));
    }
  }

 protected:
  /// g from ω = M⁻¹p, the coordinate rates and the loads Q = (Q1 [N], Q2 [N·m]) at (z, t): the
  /// work rate ω·Q [W] and the impulse rate Q2.
  template <class S>
  Passive<S> passive_rates_from(const Vector2<S>& omega, const CoordinateRates<S>& rates,
                                const Vector2<S>& force) const {
    Passive<S> rate;
    rate(kXIndex) = rates.x_rate;
    rate(kYIndex) = rates.y_rate;
    rate(kHeadingIndex) = rates.heading_rate;
    for (int wheel = 0; wheel < 4; ++wheel) rate(kWheel1Index + wheel) = rates.wheel_spin_rate[wheel];
    rate(kAppliedWorkIndex) = omega.dot(force);
    rate(kSteeringImpulseIndex) = force(1);
    return rate;
  }

 protected:
  const CartModel* model_;
  const EffectSet* effects_;
  bool non_birkhoffian_force_enabled_ = true;
};

namespace cart_birkhoffian_detail {
template <class S>
S zero_like(const S& s) {
  return S(0.0) * s;
}
}  // namespace cart_birkhoffian_detail

/// ẇ of a form (CRTP: Form::darboux_rates_at(w, t, sin/cos of χ)) at one point, and at the s
/// stages of a collocation step at once.
template <class Form>
class CartStageRates {
 public:
  template <class S>
  using Vector = CartBirkhoffianBase::Vector<S>;

  /// ẇ(w, t).
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& t) const {
    return form().darboux_rates_at(w, t, CartBirkhoffianBase::steering_trig(w(kSteeringAngleIndex)));
  }
  /// ẇ at the stages w[j], times t[j] (gauss_collocation.h): sin χ, cos χ of all of them from one
  /// sin_cos_lanes call (vector_math.h), the rest as darboux_rates. On the scalar path bit-identical
  /// to darboux_rates point by point.
  template <std::size_t Count>
  void darboux_rates_stages(const std::array<Vector<double>, Count>& w, const std::array<double, Count>& t,
                            std::array<Vector<double>, Count>& rates) const {
    const auto steering = CartBirkhoffianBase::stage_steering_trig(w);
    for (std::size_t j = 0; j < Count; ++j) {
      rates[j] = form().darboux_rates_at(
          w[j], t[j], CartBirkhoffianBase::SteeringTrig<double>{steering.sines[j], steering.cosines[j]});
    }
  }

 private:
  const Form& form() const { return static_cast<const Form&>(*this); }
};

/// Representation (b): autonomous canonical form, K = K₀ (eqs. (B.6)–(B.8)).
class CartAutonomousBirkhoffian : public CartBirkhoffianBase, public CartStageRates<CartAutonomousBirkhoffian> {
 public:
  using CartBirkhoffianBase::CartBirkhoffianBase;
  using CartBirkhoffianBase::Vector;

  /// w = z: the chart's rates are ż, so a step's F(w⁺) serves as the rate of its end point (dense
  /// output, system_traits.h).
  static constexpr bool kDarbouxChartIsIdentity = true;

  /// No structure epoch: K = K₀ does not depend on time.
  void begin_step(double /*t*/) {}

  /// R = (p1, p2, 0, 0).
  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& /*t*/) const {
    Vector<S> r;
    r << z(kForwardMomentumIndex), z(kSteeringMomentumIndex), cart_birkhoffian_detail::zero_like(z(0)),
        cart_birkhoffian_detail::zero_like(z(0));
    return r;
  }
  /// B = H̃ [J].
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& /*t*/) const {
    return hamiltonian(z);
  }
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& /*z*/, const S& /*t*/) const {
    return canonical_structure<kDimension>().template cast<S>();
  }
  /// K⁻¹ = K₀⁻¹ = −K₀ (K₀² = −I).
  template <class S>
  Matrix<S> structure_matrix_inverse(const Vector<S>& /*z*/, const S& /*t*/) const {
    return (-canonical_structure<kDimension>()).template cast<S>();
  }
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& /*t*/) const {
    return hamiltonian_gradient(z);
  }
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& /*t*/) const {
    return Vector<S>::Constant(cart_birkhoffian_detail::zero_like(z(0)));
  }
  /// Λ = (−(Λ_nh + Q), 0, 0) (eq. (B.7)).
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& t) const {
    Vector<S> force = Vector<S>::Constant(cart_birkhoffian_detail::zero_like(z(0)));
    if (!non_birkhoffian_force_enabled_) return force;
    const Vector2<S> omega = quasi_velocity(z);
    const S& chi = z(kSteeringAngleIndex);
    const Vector2<S> load = model_->nonholonomic_force(chi, omega) + generalized_force(chi, omega, t);
    force(kArcLengthIndex) = -load(0);
    force(kSteeringAngleIndex) = -load(1);
    return force;
  }
  /// Identity chart.
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& /*t*/) const {
    return z;
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& /*t*/) const {
    return w;
  }
  /// ẇ = ż = (ω, ṗ) with ṗ = ∂T*/∂q|_ω + Λ_nh + Q (enabled) or −∂H̃/∂q (Birkhoffian part), with
  /// sin χ, cos χ given (darboux_rates and darboux_rates_stages: CartStageRates).
  template <class S>
  Vector<S> darboux_rates_at(const Vector<S>& w, const S& t, const SteeringTrig<S>& trig) const {
    const S& chi = w(kSteeringAngleIndex);
    const Vector2<S> omega = quasi_velocity_at(trig.s, w);
    Vector<S> rate;
    rate(kArcLengthIndex) = omega(0);
    rate(kSteeringAngleIndex) = omega(1);
    if (non_birkhoffian_force_enabled_) {
      const Vector2<S> p_rate = model_->momentum_rate_at(trig.s, trig.c, omega, generalized_force(chi, omega, t, &trig));
      rate(kForwardMomentumIndex) = p_rate(0);
      rate(kSteeringMomentumIndex) = p_rate(1);
    } else {
      rate(kForwardMomentumIndex) = cart_birkhoffian_detail::zero_like(omega(0));
      rate(kSteeringMomentumIndex) = model_->kinetic_energy_steering_derivative_at(trig.s, trig.c, omega);
    }
    return rate;
  }

  /// ẇ and g at one point (w = z: the identity chart), from one sin χ and cos χ, one ω = M⁻¹p and
  /// one evaluation of the loads, which darboux_rates and passive_rates would each compute: the
  /// local error estimate's rates at a step's end (collocation_error_estimate.h). Bit for bit the
  /// two of them.
  void darboux_and_passive_rates(const Vector<double>& w, const Passive<double>& y, double t, Vector<double>& rate,
                                 Passive<double>& passive) const {
    const double chi = w(kSteeringAngleIndex);
    const SteeringTrig<double> trig = steering_trig(chi);
    const Vector2<double> omega = quasi_velocity_at(trig.s, w);
    const Vector2<double> force = generalized_force(chi, omega, t, &trig);  // zero when the force is disabled
    // ẇ as darboux_rates_at writes it (which stays as it is: the stage solve's hot path, inlined).
    rate(kArcLengthIndex) = omega(0);
    rate(kSteeringAngleIndex) = omega(1);
    if (non_birkhoffian_force_enabled_) {
      const Vector2<double> p_rate = model_->momentum_rate_at(trig.s, trig.c, omega, force);
      rate(kForwardMomentumIndex) = p_rate(0);
      rate(kSteeringMomentumIndex) = p_rate(1);
    } else {
      rate(kForwardMomentumIndex) = cart_birkhoffian_detail::zero_like(omega(0));
      rate(kSteeringMomentumIndex) = model_->kinetic_energy_steering_derivative_at(trig.s, trig.c, omega);
    }
    passive = passive_rates_from(omega, model_->coordinate_rates_at(y(kHeadingIndex), chi, trig.s, trig.c, omega), force);
  }

  /// J = ∂ẇ/∂w [rows: rates of (π1, χ, p1, p2); columns: (π1, χ, p1, p2)] in closed form, for the
  /// implicit members' Newton matrices (gauss_collocation.h; test/unit/cart_jacobian_test.cpp checks it
  /// against automatic differentiation of darboux_rates). With ω = M⁻¹p (eq. (3.5)):
  ///   ∂ω/∂p = M⁻¹,  ∂ω/∂χ = −M⁻¹ (dM/dχ) ω,  dM/dχ = [[2 μ1 s c, ν c], [ν c, 0]]   (eq. (3.3));
  ///   ṗ = (Λ1 + Q1, Q2), Λ1 = μ1 s c ω1 ω2 + ν c ω2²                                   (eq. (3.8)),
  ///   ∂ṗ/∂w = ∂ṗ/∂χ|_ω e_χᵀ + ∂ṗ/∂ω ∂ω/∂w, with ∂Q/∂(χ, ω) from the effects.
  /// The π1 column is zero: no rate reads the arc length.
  Matrix<double> darboux_jacobian(const Vector<double>& w, double t) const {
    const double chi = w(kSteeringAngleIndex);
    const SteeringTrig<double> trig = steering_trig(chi);
    const double s = trig.s;
    const double c = trig.c;
    const ReducedInertia& inertia = model_->inertia();
    const Matrix2<double> mass = model_->mass_matrix_at(s);
    const double determinant = mass(0, 0) * mass(1, 1) - mass(0, 1) * mass(1, 0);
    Matrix2<double> mass_inverse;
    mass_inverse << mass(1, 1) / determinant, -mass(0, 1) / determinant, -mass(1, 0) / determinant,
        mass(0, 0) / determinant;
    const Vector2<double> omega = mass_inverse * Vector2<double>(w(kForwardMomentumIndex), w(kSteeringMomentumIndex));
    Matrix2<double> mass_rate;  // dM/dχ
    mass_rate << 2.0 * inertia.mu1 * s * c, inertia.nu * c, inertia.nu * c, 0.0;
    // ∂ω/∂(χ, p1, p2): columns χ, p1, p2
    Eigen::Matrix<double, 2, 3> omega_partials;
    omega_partials.col(0) = -mass_inverse * (mass_rate * omega);
    omega_partials.rightCols<2>() = mass_inverse;
    // ṗ's partials at fixed ω (χ) and in ω
    Eigen::Matrix<double, 2, 1> p_rate_chi;
    Matrix2<double> p_rate_omega;
    const double w1 = omega(0);
    const double w2 = omega(1);
    if (non_birkhoffian_force_enabled_) {
      const GeneralizedForce load = effects_->force_and_jacobian(t, chi, omega, s, c);
      p_rate_chi << inertia.mu1 * (c * c - s * s) * w1 * w2 - inertia.nu * s * w2 * w2 + load.jacobian(0, 0),
          load.jacobian(1, 0);
      p_rate_omega << inertia.mu1 * s * c * w2 + load.jacobian(0, 1),
          inertia.mu1 * s * c * w1 + 2.0 * inertia.nu * c * w2 + load.jacobian(0, 2), load.jacobian(1, 1),
          load.jacobian(1, 2);
    } else {  // ṗ = (0, ∂T*/∂χ|_ω), ∂T*/∂χ = μ1 s c ω1² + ν c ω1 ω2
      p_rate_chi << 0.0, inertia.mu1 * (c * c - s * s) * w1 * w1 - inertia.nu * s * w1 * w2;
      p_rate_omega << 0.0, 0.0, 2.0 * inertia.mu1 * s * c * w1 + inertia.nu * c * w2, inertia.nu * c * w1;
    }
    Eigen::Matrix<double, 2, 3> p_rate_partials = p_rate_omega * omega_partials;
    p_rate_partials.col(0) += p_rate_chi;
    Matrix<double> jacobian = Matrix<double>::Zero();
    jacobian.block<2, 3>(kArcLengthIndex, kSteeringAngleIndex) = omega_partials;
    jacobian.block<2, 3>(kForwardMomentumIndex, kSteeringAngleIndex) = p_rate_partials;
    return jacobian;
  }
};

/// Representation (a): the paper's time-dependent form, K = e^{t−tₑ} K₀ (eqs. (B.9)–(B.11)).
class CartPaperBirkhoffian : public CartBirkhoffianBase, public CartStageRates<CartPaperBirkhoffian> {
 public:
  using CartBirkhoffianBase::CartBirkhoffianBase;
  using CartBirkhoffianBase::Vector;

  /// Sets the structure epoch tₑ = t [s]: a constant factor e^{−tₑ} on R and B leaves Birkhoff's
  /// equations unchanged and keeps e^{t−tₑ} = O(1) (no overflow at t ≈ 709 s).
  void begin_step(double t) { structure_epoch_ = t; }
  double structure_epoch() const { return structure_epoch_; }

  /// e^{t−tₑ} [-].
  template <class S>
  S conformal_factor(const S& t) const {
    using deterministic::exp;
    const S since_epoch = t - structure_epoch_;  // [s]
    return exp(since_epoch);
  }
  /// R = e^{t−tₑ} (p1, p2, 0, 0).
  template <class S>
  Vector<S> birkhoff_functions(const Vector<S>& z, const S& t) const {
    const S e = conformal_factor(t);
    Vector<S> r;
    r << e * z(kForwardMomentumIndex), e * z(kSteeringMomentumIndex), cart_birkhoffian_detail::zero_like(e),
        cart_birkhoffian_detail::zero_like(e);
    return r;
  }
  /// B = e^{t−tₑ} H̃.
  template <class S>
  S birkhoffian(const Vector<S>& z, const S& t) const {
    return conformal_factor(t) * hamiltonian(z);
  }
  /// K = e^{t−tₑ} K₀.
  template <class S>
  Matrix<S> structure_matrix(const Vector<S>& /*z*/, const S& t) const {
    return canonical_structure<kDimension>().template cast<S>() * conformal_factor(t);
  }
  /// K⁻¹ = −e^{−(t−tₑ)} K₀.
  template <class S>
  Matrix<S> structure_matrix_inverse(const Vector<S>& /*z*/, const S& t) const {
    return canonical_structure<kDimension>().template cast<S>() * (-1.0 / conformal_factor(t));
  }
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& z, const S& t) const {
    return hamiltonian_gradient(z) * conformal_factor(t);
  }
  /// ∂R/∂t = e^{t−tₑ} (p1, p2, 0, 0).
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& z, const S& t) const {
    return birkhoff_functions(z, t);
  }
  /// Λ = e^{t−tₑ} (−(Λ_nh + Q) − p, 0, 0) (eq. (B.10)); zero when disabled.
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& z, const S& t) const {
    Vector<S> force = Vector<S>::Constant(cart_birkhoffian_detail::zero_like(z(0)));
    if (!non_birkhoffian_force_enabled_) return force;
    const S e = conformal_factor(t);
    const Vector2<S> omega = quasi_velocity(z);
    const S& chi = z(kSteeringAngleIndex);
    const Vector2<S> load = model_->nonholonomic_force(chi, omega) + generalized_force(chi, omega, t);
    force(kArcLengthIndex) = -e * (load(0) + z(kForwardMomentumIndex));
    force(kSteeringAngleIndex) = -e * (load(1) + z(kSteeringMomentumIndex));
    return force;
  }
  /// w = D(z, t) = (π1, χ, e^{t−tₑ} p1, e^{t−tₑ} p2) (eq. (B.11)).
  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& t) const {
    const S e = conformal_factor(t);
    Vector<S> w = z;
    w(kForwardMomentumIndex) *= e;
    w(kSteeringMomentumIndex) *= e;
    return w;
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& t) const {
    const S inverse = 1.0 / conformal_factor(t);
    Vector<S> z = w;
    z(kForwardMomentumIndex) *= inverse;
    z(kSteeringMomentumIndex) *= inverse;
    return z;
  }
  /// ẇ = D_z ż + ∂_t D = (ω, e^{t−tₑ} (ṗ + p)): with Λ, ṗ + p = ∂T*/∂q|_ω + Λ_nh + Q + p; without,
  /// ṗ = −∂H̃/∂q − p, so ẇ_p = e^{t−tₑ} ∂T*/∂q|_ω (Hamiltonian in the chart with H_w = e^{t−tₑ} H̃).
  /// With sin χ, cos χ given (χ is the same in z and w; darboux_rates: CartStageRates).
  template <class S>
  Vector<S> darboux_rates_at(const Vector<S>& w, const S& t, const SteeringTrig<S>& trig) const {
    const S e = conformal_factor(t);
    const Vector<S> z = from_darboux(w, t);
    const S& chi = z(kSteeringAngleIndex);
    const Vector2<S> omega = quasi_velocity_at(trig.s, z);
    Vector<S> rate;
    rate(kArcLengthIndex) = omega(0);
    rate(kSteeringAngleIndex) = omega(1);
    if (non_birkhoffian_force_enabled_) {
      const Vector2<S> p_rate = model_->momentum_rate_at(trig.s, trig.c, omega, generalized_force(chi, omega, t, &trig));
      rate(kForwardMomentumIndex) = e * (p_rate(0) + z(kForwardMomentumIndex));
      rate(kSteeringMomentumIndex) = e * (p_rate(1) + z(kSteeringMomentumIndex));
    } else {
      rate(kForwardMomentumIndex) = cart_birkhoffian_detail::zero_like(e);
      rate(kSteeringMomentumIndex) = e * model_->kinetic_energy_steering_derivative_at(trig.s, trig.c, omega);
    }
    return rate;
  }

 private:
  double structure_epoch_ = 0.0;  ///< tₑ [s]
};

}  // namespace birkhoff_cart
