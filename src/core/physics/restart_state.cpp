// check_restart_state (restart_state.h).
#include "birkhoff_cart/core/physics/restart_state.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/physics/singular_steering.h"

namespace birkhoff_cart {
namespace {

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument("restart state: " + what); }

std::string text(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}

void require_within(const char* name, double value, double largest, const char* unit, const char* why) {
  if (std::abs(value) > largest) {
    refuse(std::string(name) + " " + text(value) + " " + unit + " is beyond +-" + text(largest) + " " + unit + " (" +
           why + ")");
  }
}

}  // namespace

void check_restart_state(const CartModel& model, const EffectSet& effects, const CartState& state, double step_size) {
  const CartState& s = state;
  const double fields[] = {s.time, s.x, s.y, s.heading, s.steering_angle, s.arc_length, s.forward_speed,
                           s.steering_rate, s.wheel_spin_angle[0], s.wheel_spin_angle[1], s.wheel_spin_angle[2],
                           s.wheel_spin_angle[3]};
  const char* names[] = {"time", "x", "y", "heading", "steering_angle", "arc_length", "forward_speed",
                         "steering_rate", "wheel_spin_angle[0]", "wheel_spin_angle[1]", "wheel_spin_angle[2]",
                         "wheel_spin_angle[3]"};
  for (std::size_t i = 0; i < sizeof(fields) / sizeof(fields[0]); ++i) {
    if (!std::isfinite(fields[i])) refuse(std::string(names[i]) + " must be finite, got " + text(fields[i]));
  }
  const char* resolution = "a double there cannot resolve one step's motion";
  require_within("x", s.x, kLargestRestartPosition, "m", resolution);
  require_within("y", s.y, kLargestRestartPosition, "m", resolution);
  require_within("heading", s.heading, kLargestRestartAngle, "rad", resolution);
  require_within("steering_angle", s.steering_angle, kLargestRestartAngle, "rad", resolution);
  // One step of h turns χ by about ω2 h, moves the hinge by about ω1 h and turns the body by at
  // most |ω1| h / l (θ̇ = ω1 sin χ / l).
  const double wheelbase = model.parameters().wheelbase;  // [m]
  const std::string remedy = "; a smaller ~step_size allows more";
  require_within("steering_rate", s.steering_rate, kLargestStepFraction / step_size, "rad/s",
                 ("in one step of h = " + text(step_size) + " s the front axle would turn by more than " +
                  text(kLargestStepFraction) + " rad" + remedy).c_str());
  require_within("forward_speed", s.forward_speed, kLargestStepFraction * wheelbase / step_size, "m/s",
                 ("in one step of h = " + text(step_size) + " s the hinge would travel more than " +
                  text(kLargestStepFraction) + " of the wheelbase " + text(wheelbase) + " m" + remedy).c_str());
  const double energy = model.energy(state);  // [J]
  if (!std::isfinite(energy)) refuse("its kinetic energy T* is " + text(energy) + " J, not finite");
  try {
    check_singular_steering(model, state, step_size);
  } catch (const StepError& error) {
    refuse(error.what());
  }
  if (const auto& stops = effects.end_stops()) {
    if (stops->penetration(state.steering_angle) > 0.0) {
      refuse("steering_angle " + text(state.steering_angle) + " rad lies beyond the end stops at +-" +
             text(stops->settings().angle) + " rad");
    }
  }
}

}  // namespace birkhoff_cart
