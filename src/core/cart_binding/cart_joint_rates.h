// The cart's joint rates d(z, y)/dt in the autonomous form as one array, for Boost.Odeint's steppers
// (the shadow reference, shadow_reference.cpp; the dopri5 member's run, dopri5_cart_stepper.h).
// Private to the core library.
#pragma once

#include <array>
#include <cstdint>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/cart_model.h"

namespace birkhoff_cart {

/// The joint state (z, y) of the autonomous Birkhoffian form, as odeint sees it.
using Joint = std::array<double, kBirkhoffianSize + kPassiveSize>;

/// (ż, ẏ) for odeint: ż = K₀⁻¹(∇H̃ + Λ) = (ω, ṗ) with ṗ = ∂T*/∂q|_ω + Λ_nh + Q (CartModel::momentum_rate,
/// eq. (3.6)) and ẏ = g(z, y, t) (CartBirkhoffianBase::passive_rates), from ONE evaluation of
/// ω = M(χ)⁻¹ p and of the loads Q. birkhoffian_rates() and passive_coordinate_rates() would each
/// evaluate both again (the loads were a third of the shadow's cost); the rates are the same up to
/// round-off.
struct JointRates {
  const CartAutonomousBirkhoffian* system;
  const CartModel* model;
  std::uint64_t* evaluations = nullptr;  ///< counted when given
  void operator()(const Joint& state, Joint& rate, double time) const {
    if (evaluations != nullptr) ++*evaluations;
    StateVector<CartAutonomousBirkhoffian, double> z;
    for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = state[i];
    const double chi = z(kSteeringAngleIndex);
    const Vector2<double> omega = system->quasi_velocity(z);                 // ω = M(χ)⁻¹ p
    const Vector2<double> force = system->generalized_force(chi, omega, time);  // Q
    const Vector2<double> momentum_rate = model->momentum_rate(chi, omega, force);
    rate[kArcLengthIndex] = omega(0);
    rate[kSteeringAngleIndex] = omega(1);
    rate[kForwardMomentumIndex] = momentum_rate(0);
    rate[kSteeringMomentumIndex] = momentum_rate(1);
    const CoordinateRates<double> rates =
        model->coordinate_rates(state[kBirkhoffianSize + kHeadingIndex], chi, omega);
    double* passive = rate.data() + kBirkhoffianSize;
    passive[kXIndex] = rates.x_rate;
    passive[kYIndex] = rates.y_rate;
    passive[kHeadingIndex] = rates.heading_rate;
    for (int wheel = 0; wheel < 4; ++wheel) passive[kWheel1Index + wheel] = rates.wheel_spin_rate[wheel];
    passive[kAppliedWorkIndex] = omega.dot(force);
    passive[kSteeringImpulseIndex] = force(1);
  }
};


/// The joint state of a Birkhoffian point, and back.
inline Joint joint_of(const CartBirkhoffianPoint& point) {
  Joint x;
  for (int i = 0; i < kBirkhoffianSize; ++i) x[i] = point.z(i);
  for (int i = 0; i < kPassiveSize; ++i) x[kBirkhoffianSize + i] = point.y(i);
  return x;
}
inline CartState cart_state_of(const CartAutonomousBirkhoffian& system, const Joint& x, double time) {
  StateVector<CartAutonomousBirkhoffian, double> z;
  PassiveVector<CartAutonomousBirkhoffian, double> y;
  for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x[i];
  for (int i = 0; i < kPassiveSize; ++i) y(i) = x[kBirkhoffianSize + i];
  return system.to_cart_state(z, y, time);
}

}  // namespace birkhoff_cart
