// SteeringEndStops: impact (S1), holding reaction (S2) and release test (S3) of docs/actuators.md §3.
#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace birkhoff_cart {

void validate_steering_end_stops(const std::string& section, const SteeringEndStopSettings& settings) {
  if (!(settings.angle > 0.0 && settings.angle < 0.5 * M_PI)) {
    std::ostringstream message;
    message << section << ".angle must be within (0, pi/2) [rad] (the stops sit at +-angle), got " << settings.angle;
    throw std::invalid_argument(message.str());
  }
  if (!(settings.restitution >= 0.0 && settings.restitution <= 1.0)) {
    std::ostringstream message;
    message << section << ".restitution must be within [0, 1], got " << settings.restitution;
    throw std::invalid_argument(message.str());
  }
}

SteeringEndStops::SteeringEndStops(const SteeringEndStopSettings& settings, const CartModel& model)
    : settings_(settings), model_(&model) {
  validate_steering_end_stops("steering_end_stops", settings);
}

void SteeringEndStops::add_reaction(const EffectInput& input, GeneralizedForce& total) const {
  if (contact_ == Contact::kNone) return;
  const ReducedInertia& inertia = model_->inertia();
  const double s = deterministic::sin(input.steering_angle);
  const double c = deterministic::cos(input.steering_angle);
  const double w1 = input.forward_speed;  // ω1 [m/s]
  const double w2 = input.steering_rate;  // ω2 [rad/s]
  const double m11 = inertia.mu + inertia.mu1 * s * s;  // [kg]
  const double q1 = total.force(0);                     // [N]
  const double h1 = inertia.mu1 * s * c * w1 * w2;      // [N]
  const double h2 = inertia.nu * c * w1 * w2;           // [N·m]
  const double g = q1 - h1;                             // M11 ω̇1 [N]
  // (S2) Q2 = ν s g / M11 + h2 makes the second row of M ω̇ = Q − h read ω̇2 = 0.
  const double held = inertia.nu * s * g / m11 + h2;  // [N·m]
  const double dg_dchi = total.jacobian(0, 0) - inertia.mu1 * (c * c - s * s) * w1 * w2;
  const double dg_dw1 = total.jacobian(0, 1) - inertia.mu1 * s * c * w2;
  const double dg_dw2 = total.jacobian(0, 2) - inertia.mu1 * s * c * w1;
  total.force(1) = held;
  total.jacobian(1, 0) = inertia.nu * c * g / m11 + inertia.nu * s * dg_dchi / m11 -
                         inertia.nu * s * g * (2.0 * inertia.mu1 * s * c) / (m11 * m11) - inertia.nu * s * w1 * w2;
  total.jacobian(1, 1) = inertia.nu * s * dg_dw1 / m11 + inertia.nu * c * w2;
  total.jacobian(1, 2) = inertia.nu * s * dg_dw2 / m11 + inertia.nu * c * w1;
}

double SteeringEndStops::reaction(const EffectInput& input, const GeneralizedForce& loads) const {
  SteeringEndStops holding = *this;
  if (holding.contact_ == Contact::kNone) holding.contact_ = Contact::kUpper;  // the formula is the same
  GeneralizedForce held = loads;
  holding.add_reaction(input, held);
  return held.force(1) - loads.force(1);
}

SteeringEndStops::Contact SteeringEndStops::impact(CartState& state, double restitution) const {
  const double energy_before = model_->energy(state);               // [J]
  const double momentum_before = model_->steering_momentum(state);  // p2 [kg·m²/s]
  const Contact side = state.steering_angle > 0.0 ? Contact::kUpper : Contact::kLower;
  state.steering_angle = side == Contact::kUpper ? settings_.angle : -settings_.angle;
  state.steering_angle_low = 0.0;
  const Matrix2<double> mass = model_->mass_matrix(state.steering_angle);
  const double rate_before = state.steering_rate;                // ω2⁻ [rad/s]
  const double rate_after = -restitution * rate_before;  // ω2⁺ [rad/s]
  // (S1) the stop's impulse acts on χ only: p1 = M11 ω1 + M12 ω2 is the same before and after.
  state.forward_speed += mass(0, 1) * (rate_before - rate_after) / mass(0, 0);
  state.steering_rate = rate_after;
  state.applied_work += model_->energy(state) - energy_before;
  state.steering_impulse += model_->steering_momentum(state) - momentum_before;
  return side;
}

void SteeringEndStops::hold_on_stop(CartState& state, Contact side) const {
  state.steering_angle = side == Contact::kUpper ? settings_.angle : -settings_.angle;
  state.steering_angle_low = 0.0;
}

}  // namespace birkhoff_cart
