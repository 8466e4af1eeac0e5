#include "birkhoff_cart/core/physics/cart_birkhoffian.h"

#include "birkhoff_cart/core/integrators/angle_reduction.h"

namespace birkhoff_cart {

CartBirkhoffianPoint CartBirkhoffianBase::to_birkhoffian(const CartState& state) const {
  const Vector2<double> momentum =
      model_->momentum(reduced_angle(state.steering_angle, state.steering_angle_low),
                       Vector2<double>(state.forward_speed, state.steering_rate));  // p = M ω (M is 2π-periodic in χ)
  CartBirkhoffianPoint point;
  point.z(kArcLengthIndex) = state.arc_length;
  point.z(kSteeringAngleIndex) = state.steering_angle;  // the low part is the caller's to carry
  point.z(kForwardMomentumIndex) = momentum(0);
  point.z(kSteeringMomentumIndex) = momentum(1);
  point.y(kXIndex) = state.x;
  point.y(kYIndex) = state.y;
  point.y(kHeadingIndex) = state.heading;
  for (int wheel = 0; wheel < 4; ++wheel) point.y(kWheel1Index + wheel) = state.wheel_spin_angle[wheel];
  point.y(kAppliedWorkIndex) = state.applied_work;
  point.y(kSteeringImpulseIndex) = state.steering_impulse;
  return point;
}

CartState CartBirkhoffianBase::to_cart_state(const Vector<double>& z, const Passive<double>& y, double t) const {
  const Vector2<double> omega = quasi_velocity(z);  // ω = M(χ)⁻¹ p
  CartState state;
  state.time = t;
  state.x = y(kXIndex);
  state.y = y(kYIndex);
  state.heading = y(kHeadingIndex);
  state.steering_angle = z(kSteeringAngleIndex);
  for (int wheel = 0; wheel < 4; ++wheel) state.wheel_spin_angle[wheel] = y(kWheel1Index + wheel);
  state.arc_length = z(kArcLengthIndex);
  state.forward_speed = omega(0);
  state.steering_rate = omega(1);
  state.applied_work = y(kAppliedWorkIndex);
  state.steering_impulse = y(kSteeringImpulseIndex);
  return state;
}

}  // namespace birkhoff_cart
