// Zero-order hold, rejection, clamping and watchdog of one commanded torque (see command_channel.h).
#include "birkhoff_cart/core/node_logic/command_channel.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace birkhoff_cart {

namespace {

void check_limits(double max_torque, double timeout) {
  if (!std::isfinite(max_torque) || max_torque <= 0.0) {
    throw std::invalid_argument("maximum torque must be finite and > 0 N m, got " + std::to_string(max_torque));
  }
  if (!std::isfinite(timeout) || timeout < 0.0) {
    throw std::invalid_argument("command timeout must be finite and >= 0 s, got " + std::to_string(timeout));
  }
}

}  // namespace

CommandChannel::CommandChannel(double initial_torque, double max_torque, double timeout, double start_time)
    : initial_torque_(initial_torque), max_torque_(max_torque), timeout_(timeout) {
  check_limits(max_torque, timeout);
  if (!std::isfinite(initial_torque)) {
    throw std::invalid_argument("initial commanded torque must be finite");
  }
  restart(start_time);
}

CommandChannel::Outcome CommandChannel::receive(double torque, double time) {
  ++received_;
  if (!std::isfinite(torque)) {
    ++rejected_;
    return Outcome::kRejected;
  }
  Outcome outcome = Outcome::kAccepted;
  if (std::abs(torque) > max_torque_) {
    torque = std::copysign(max_torque_, torque);
    ++clamped_;
    outcome = Outcome::kClamped;
  }
  torque_ = torque;
  last_command_time_ = time;
  watchdog_armed_ = torque_ != 0.0;
  return outcome;
}

bool CommandChannel::check_watchdog(double time) {
  if (timeout_ == 0.0 || !watchdog_armed_ || time - last_command_time_ <= timeout_) return false;
  torque_ = 0.0;
  watchdog_armed_ = false;
  ++timeouts_;
  return true;
}

void CommandChannel::restart(double start_time) {
  torque_ = initial_torque_;
  last_command_time_ = start_time;
  watchdog_armed_ = torque_ != 0.0;
}

void CommandChannel::set_limits(double max_torque, double timeout) {
  check_limits(max_torque, timeout);
  max_torque_ = max_torque;
  timeout_ = timeout;
}

}  // namespace birkhoff_cart
