// Simulation::take_step_with_events: a step of a scene with actuators or steering end stops
// (docs/actuators.md §4). The step [tₙ, tₙ₊₁] is cut into sub-steps that end
//   - at the actuators' kinks (an input taking effect after its dead time, the end of a rate-limited
//     ramp), so that every sub-step integrates a smooth torque and keeps the method's order;
//   - at end-stop events, located by the Illinois method on the sub-step length: an impact where
//     |χ| reaches χ_s (S1), a release where the holding reaction would have to pull (S3).
// The reference is stepped to each event and restarted from the simulation's state there. A step
// that throws leaves the state, the statistics and the contact as they were.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"
#include "birkhoff_cart/core/physics/actuators/torque_actuator.h"
#include "birkhoff_cart/core/run/reference_solution.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/physics/singular_steering.h"

namespace birkhoff_cart {
namespace {

/// Most end-stop events within one step before it is refused as chattering [-].
constexpr int kMaxEventsPerStep = 64;
/// A bounce whose flight 2|ω2⁺|/χ̈ would last less than this fraction of h ends the bouncing
/// sequence: the axle comes to rest on the stop (docs/actuators.md §3.2) [-].
constexpr double kSettlingFlightFraction = 1e-3;
/// Event location: |χ| − χ_s within this of 0 [rad].
constexpr double kImpactTolerance = 1e-13;
/// Event location: the bracket on the sub-step length shorter than this fraction of h [-].
constexpr double kEventTimeResolution = 1e-14;

using Contact = SteeringEndStops::Contact;

EffectInput effect_input(const CartState& state) {
  EffectInput input;
  input.time = state.time;
  input.steering_angle = state.steering_angle;
  input.forward_speed = state.forward_speed;
  input.steering_rate = state.steering_rate;
  return input;
}

}  // namespace

Simulation::ActuatorStatus Simulation::actuator_status() const {
  ActuatorStatus status;
  if (const auto& actuator = effects_.steering_actuator()) {
    status.steering_actuator = true;
    status.steering_input = actuator->latest_input();
    status.steering_applied = actuator->output_at(state_.time);
  }
  if (const auto& actuator = effects_.drive_actuator()) {
    status.drive_actuator = true;
    status.drive_input = actuator->latest_input();
    status.drive_applied = actuator->output_at(state_.time);
  }
  if (const auto& stops = effects_.end_stops()) {
    status.end_stops = true;
    status.end_stop_contact = stops->contact() == Contact::kUpper ? 1 : stops->contact() == Contact::kLower ? -1 : 0;
    status.end_stop_events = end_stop_events_;
  }
  return status;
}

void Simulation::take_step_with_events(double next_time) {
  TorqueActuator* const actuators[] = {effects_.steering_actuator().get(), effects_.drive_actuator().get()};
  SteeringEndStops* const stops = effects_.end_stops().get();
  const Contact contact_before = stops ? stops->contact() : Contact::kNone;
  const double h = next_time - state_.time;  // [s]

  CartState current = state_;
  StepStatistics statistics = statistics_;
  // The states right after each event and the contact from there on, for the reference.
  std::vector<std::pair<CartState, Contact>> events;
  auto record_event = [&](const CartState& state) { events.emplace_back(state, stops->contact()); };

  // One sub-step of the cart from `from` over `length` [s] (the contact mode as it stands).
  auto sub_step = [&](const CartState& from, double length, double end_time) {
    CartState next = from;
    check_singular_steering(model_, from, length);
    stepper_->step(next, length, statistics);  // throws StepError
    check_singular_steering(model_, from, length, &next);
    next.time = end_time;
    return next;
  };
  // Where g (≤ 0 at `from`, > 0 at `beyond`, `length` later) crosses 0: Illinois on the length.
  auto locate = [&](const CartState& from, double length, const CartState& beyond,
                    const std::function<double(const CartState&)>& g, double tolerance) {
    double a = 0.0, ga = g(from);
    double b = length, gb = g(beyond);
    CartState at_b = beyond;
    int retained = 0;  // which end stayed twice in a row (Illinois halving)
    for (int iteration = 0; iteration < 100 && b - a > kEventTimeResolution * h; ++iteration) {
      double s = b - gb * (b - a) / (gb - ga);
      if (!(s > a && s < b)) s = 0.5 * (a + b);
      const CartState trial = sub_step(from, s, from.time + s);
      const double gs = g(trial);
      if (gs > 0.0) {
        b = s, gb = gs, at_b = trial;
        if (retained == -1) ga *= 0.5;
        retained = -1;
      } else {
        a = s, ga = gs;
        if (retained == 1) gb *= 0.5;
        retained = 1;
      }
      if (std::abs(gs) <= tolerance) return trial;
    }
    return at_b;
  };

  try {
    while (current.time < next_time) {
      if (static_cast<int>(events.size()) > kMaxEventsPerStep) {
        std::ostringstream message;
        message << "more than " << kMaxEventsPerStep << " end-stop events within one step at t = " << current.time
                << " s (the steering axle chatters on a stop)";
        throw StepError(message.str());
      }
      // A resting axle leaves the stop at once when the loads now pull it away (a new command).
      if (stops && stops->contact() != Contact::kNone) {
        const GeneralizedForce loads = effects_.evaluate_loads(effect_input(current));
        if (stops->pulls(stops->contact(), stops->reaction(effect_input(current), loads))) {
          stops->set_contact(Contact::kNone);
          record_event(current);
        }
      }
      double end = next_time;
      for (TorqueActuator* actuator : actuators) {
        if (actuator) end = std::min(end, actuator->next_kink_after(current.time));
      }
      const Contact held = stops ? stops->contact() : Contact::kNone;  // the contact over this sub-step
      CartState next = sub_step(current, end - current.time, end);
      if (stops && stops->contact() == Contact::kNone && stops->penetration(next.steering_angle) > 0.0) {
        // (S1) impact: the instant where |χ| = χ_s, then the jump of ω.
        next = locate(current, end - current.time, next,
                      [&](const CartState& s) { return stops->penetration(s.steering_angle); }, kImpactTolerance);
        const Contact side = next.steering_angle > 0.0 ? Contact::kUpper : Contact::kLower;
        const GeneralizedForce loads = effects_.evaluate_loads(effect_input(next));
        const double acceleration =  // χ̈ = ω̇2 under the loads alone [rad/s²]
            model_.quasi_acceleration(next.steering_angle, Eigen::Vector2d(next.forward_speed, next.steering_rate),
                                      Eigen::Vector2d(loads.force))(1);
        const double into_stop = side == Contact::kUpper ? acceleration : -acceleration;  // [rad/s²]
        const double rebound = stops->settings().restitution * std::abs(next.steering_rate);  // |ω2⁺| [rad/s]
        const bool settles = rebound == 0.0 || (into_stop > 0.0 && 2.0 * rebound < kSettlingFlightFraction * h * into_stop);
        stops->impact(next, settles ? 0.0 : stops->settings().restitution);
        if (settles && !stops->pulls(side, stops->reaction(effect_input(next), effects_.evaluate_loads(effect_input(next))))) {
          stops->set_contact(side);
        }
        record_event(next);
      } else if (stops && stops->contact() != Contact::kNone) {
        // (S3) release: the instant where the holding reaction changes sign.
        const Contact side = stops->contact();
        auto pull = [&](const CartState& s) {
          const double reaction = stops->reaction(effect_input(s), effects_.evaluate_loads(effect_input(s)));
          return side == Contact::kUpper ? reaction : -reaction;  // > 0: the stop would pull
        };
        if (pull(next) > 0.0) {
          const double scale = std::abs(pull(current)) + std::abs(pull(next));  // [N·m]
          next = locate(current, end - current.time, next, pull, 1e-12 * scale);
          stops->set_contact(Contact::kNone);
          record_event(next);
        }
      }
      // (S2) a held axle does not move: χ stays on its stop exactly, whatever the step's round-off
      // (a state past the stop would be refused as a restart, e.g. a pose request, docs/actuators.md §3).
      if (held != Contact::kNone && stops->penetration(next.steering_angle) > 0.0) stops->hold_on_stop(next, held);
      current = next;
    }
    // The reference follows through the events: to each, restarted from the simulation's state there.
    // Each stretch with the contact it had.
    if (reference_) {
      const Contact contact_after = stops ? stops->contact() : Contact::kNone;
      if (stops) stops->set_contact(contact_before);
      for (const auto& [event, contact] : events) {
        reference_->step(event.time);
        reference_->restart_at(event);
        stops->set_contact(contact);
      }
      reference_->step(next_time);
      if (stops) stops->set_contact(contact_after);
    }
  } catch (...) {
    if (stops) stops->set_contact(contact_before);
    throw;
  }
  current.time = next_time;
  for (TorqueActuator* actuator : actuators) {
    if (actuator) actuator->advance_to(next_time);
  }
  end_stop_events_ += events.size();
  state_ = current;
  statistics_ = statistics;
  ++steps_taken_;
}

}  // namespace birkhoff_cart
