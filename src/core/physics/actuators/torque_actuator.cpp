// TorqueActuator: the closed-form response of docs/actuators.md eqs. (A1)–(A5).
#include "birkhoff_cart/core/physics/actuators/torque_actuator.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace birkhoff_cart {
namespace {

[[noreturn]] void refuse(const std::string& section, const std::string& key, const std::string& rule, double value) {
  std::ostringstream message;
  message << section << "." << key << " must be " << rule << ", got " << value;
  throw std::invalid_argument(message.str());
}

double sign_of(double value) { return value > 0.0 ? 1.0 : -1.0; }

}  // namespace

void validate_torque_actuator(const std::string& section, const TorqueActuatorSettings& settings) {
  if (!(std::isfinite(settings.time_constant) && settings.time_constant >= 0.0)) {
    refuse(section, "time_constant", "finite and >= 0 [s]", settings.time_constant);
  }
  if (!(std::isfinite(settings.dead_time) && settings.dead_time >= 0.0)) {
    refuse(section, "dead_time", "finite and >= 0 [s]", settings.dead_time);
  }
  if (!(settings.rate_limit > 0.0)) refuse(section, "rate_limit", "> 0 [N·m/s]", settings.rate_limit);
  if (!(settings.torque_limit > 0.0)) refuse(section, "torque_limit", "> 0 [N·m]", settings.torque_limit);
  if (!(std::isfinite(settings.dead_band) && settings.dead_band >= 0.0)) {
    refuse(section, "dead_band", "finite and >= 0 [N·m]", settings.dead_band);
  }
}

TorqueActuator::TorqueActuator(const TorqueActuatorSettings& settings, double start_time, double initial_input)
    : settings_(settings),
      time_(start_time),
      applied_(0.0),
      target_(0.0),
      latest_input_(initial_input),
      latest_input_time_(start_time) {
  validate_torque_actuator("actuator", settings);
  if (!std::isfinite(initial_input)) {
    throw std::invalid_argument("actuator: initial input must be a finite torque [N·m]");
  }
  target_ = shaped(initial_input);
  applied_ = target_;  // at rest
}

double TorqueActuator::shaped(double input) const {
  // (A1) u = sat(sign(u_c) · max(|u_c| − b, 0)), sat clamps to ±τ_max.
  const double outside_band = std::max(std::abs(input) - settings_.dead_band, 0.0);  // [N·m]
  return sign_of(input) * std::min(outside_band, settings_.torque_limit);
}

void TorqueActuator::command(double time, double input) {
  if (!std::isfinite(input)) {
    std::ostringstream message;
    message << "actuator input must be a finite torque [N·m], got " << input;
    throw std::invalid_argument(message.str());
  }
  if (!(time >= latest_input_time_ && time >= time_)) {
    std::ostringstream message;
    message.precision(17);
    message << "actuator input at t = " << time << " s arrives before the last one (t = "
            << std::max(latest_input_time_, time_) << " s)";
    throw std::invalid_argument(message.str());
  }
  latest_input_ = input;
  latest_input_time_ = time;
  const double target = shaped(input);                      // [N·m]
  const double effective_time = time + settings_.dead_time;  // (A5) [s]
  if (effective_time <= time_) {  // no dead time and no later input pending: in effect now
    target_ = target;
    return;
  }
  const double last_target = pending_.empty() ? target_ : pending_.back().target;
  if (!pending_.empty() && pending_.back().effective_time == effective_time) {
    pending_.back().target = target;  // a second input at the same instant replaces the first
  } else if (target != last_target) {
    pending_.push_back({effective_time, target});
  }
}

double TorqueActuator::hold_response(double t0, double applied0, double target, double t) const {
  const double error = target - applied0;  // [N·m]
  if (error == 0.0) return target;
  const double elapsed = std::max(t - t0, 0.0);  // [s]
  const double lag = settings_.time_constant;    // T [s]
  const double rate = settings_.rate_limit;      // R [N·m/s]
  const double direction = sign_of(error);
  if (lag == 0.0) {
    // (A3) without lag: a ramp at R onto the target (a jump when R = ∞).
    if (std::isinf(rate)) return target;
    return elapsed * rate >= std::abs(error) ? target : applied0 + direction * rate * elapsed;
  }
  if (std::abs(error) > rate * lag) {
    // (A4) the lag would exceed R: ramp at R until |target − τ| = R T, then the lag from there.
    const double ramp = (std::abs(error) - rate * lag) / rate;  // duration [s]
    if (elapsed <= ramp) return applied0 + direction * rate * elapsed;
    return target - direction * rate * lag * deterministic::exp(-(elapsed - ramp) / lag);
  }
  // (A2) first-order lag: τ = u − (u − τ0) e^{−(t − t0)/T}.
  return target - error * deterministic::exp(-elapsed / lag);
}

double TorqueActuator::ramp_end(double t0, double applied0, double target) const {
  const double error = std::abs(target - applied0);  // [N·m]
  const double lag = settings_.time_constant;
  const double rate = settings_.rate_limit;
  if (error == 0.0 || std::isinf(rate)) return t0;
  if (lag == 0.0) return t0 + error / rate;
  return error > rate * lag ? t0 + (error - rate * lag) / rate : t0;
}

double TorqueActuator::output_at(double time) const {
  double t0 = time_;
  double applied = applied_;
  double target = target_;
  for (const PendingInput& input : pending_) {
    if (input.effective_time > time) break;
    applied = hold_response(t0, applied, target, input.effective_time);
    t0 = input.effective_time;
    target = input.target;
  }
  return hold_response(t0, applied, target, time);
}

double TorqueActuator::next_kink_after(double time) const {
  double t0 = time_;
  double applied = applied_;
  double target = target_;
  for (const PendingInput& input : pending_) {
    const double end = ramp_end(t0, applied, target);
    if (end > time && end < input.effective_time) return end;
    if (input.effective_time > time) return input.effective_time;
    applied = hold_response(t0, applied, target, input.effective_time);
    t0 = input.effective_time;
    target = input.target;
  }
  const double end = ramp_end(t0, applied, target);
  return end > time ? end : std::numeric_limits<double>::infinity();
}

void TorqueActuator::advance_to(double time) {
  while (!pending_.empty() && pending_.front().effective_time <= time) {
    applied_ = hold_response(time_, applied_, target_, pending_.front().effective_time);
    time_ = pending_.front().effective_time;
    target_ = pending_.front().target;
    pending_.pop_front();
  }
  applied_ = hold_response(time_, applied_, target_, time);
  time_ = std::max(time_, time);
}

void TorqueActuator::retime(double start_time) {
  const double shift = start_time - time_;  // [s]
  for (PendingInput& input : pending_) input.effective_time += shift;
  latest_input_time_ = std::max(latest_input_time_ + shift, start_time);
  time_ = start_time;
}

}  // namespace birkhoff_cart
