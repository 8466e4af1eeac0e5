// The cmd_vel → (τ, T) law of cmd_vel_controller (see cmd_vel_controller.h for the equations).
#include "birkhoff_cart/core/node_logic/cmd_vel_controller.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace birkhoff_cart {
namespace {

void require(bool condition, const std::string& name, const std::string& rule, double value) {
  if (condition) return;
  std::ostringstream message;
  message << name << " must be " << rule << ", got " << value;
  throw std::invalid_argument(message.str());
}

bool finite_positive(double value) { return std::isfinite(value) && value > 0.0; }

// x moved toward `target` by at most `max_rise` up and `max_fall` down (both ≥ 0).
double slew(double x, double target, double max_rise, double max_fall) {
  return std::clamp(target, x - max_fall, x + max_rise);
}

}  // namespace

void validate(const CmdVelControllerSettings& s) {
  require(finite_positive(s.wheel_separation_h), "wheel_separation_h", "finite and > 0 m", s.wheel_separation_h);
  require(std::isfinite(s.cmd_vel_timeout) && s.cmd_vel_timeout >= 0.0, "cmd_vel_timeout",
          "finite and >= 0 s (0 = never)", s.cmd_vel_timeout);
  require(finite_positive(s.zero_speed), "zero_speed", "finite and > 0 m/s", s.zero_speed);
  require(std::isfinite(s.max_velocity) && s.max_velocity >= 0.0, "linear/x/max_velocity", "finite and >= 0 m/s",
          s.max_velocity);
  require(std::isfinite(s.min_velocity) && s.min_velocity <= 0.0, "linear/x/min_velocity",
          "finite and <= 0 m/s (the fastest reverse)", s.min_velocity);
  require(finite_positive(s.max_acceleration), "linear/x/max_acceleration", "finite and > 0 m/s^2",
          s.max_acceleration);
  require(std::isfinite(s.min_acceleration) && s.min_acceleration < 0.0, "linear/x/min_acceleration",
          "finite and < 0 m/s^2 (braking)", s.min_acceleration);
  require(std::isfinite(s.max_yaw_rate) && s.max_yaw_rate >= 0.0, "angular/z/max_velocity", "finite and >= 0 rad/s",
          s.max_yaw_rate);
  require(finite_positive(s.max_yaw_acceleration), "angular/z/max_acceleration", "finite and > 0 rad/s^2",
          s.max_yaw_acceleration);
  require(finite_positive(s.max_steering_angle) && s.max_steering_angle < 0.5 * M_PI, "steering/max_angle",
          "> 0 and < pi/2 rad", s.max_steering_angle);
  require(finite_positive(s.max_steering_rate), "steering/max_rate", "finite and > 0 rad/s", s.max_steering_rate);
  require(finite_positive(s.max_steering_torque), "steering/max_torque", "finite and > 0 N m",
          s.max_steering_torque);
  require(std::isfinite(s.steering_p) && s.steering_p > 0.0, "steering/p", "finite and > 0 N m/rad", s.steering_p);
  require(std::isfinite(s.steering_d) && s.steering_d >= 0.0, "steering/d", "finite and >= 0 N m s/rad",
          s.steering_d);
  require(finite_positive(s.max_drive_torque), "drive/max_torque", "finite and > 0 N m", s.max_drive_torque);
  require(std::isfinite(s.drive_ff) && s.drive_ff >= 0.0, "drive/ff", "finite and >= 0 N m/(m/s^2)", s.drive_ff);
  require(std::isfinite(s.drive_p) && s.drive_p > 0.0, "drive/p", "finite and > 0 N m/(m/s)", s.drive_p);
  require(std::isfinite(s.drive_i) && s.drive_i >= 0.0, "drive/i", "finite and >= 0 N m/m", s.drive_i);
  require(std::isfinite(s.drive_i_clamp) && s.drive_i_clamp >= 0.0, "drive/i_clamp", "finite and >= 0 N m",
          s.drive_i_clamp);
}

CmdVelController::CmdVelController(const CmdVelControllerSettings& settings) : settings_(settings) {
  validate(settings_);
}

void CmdVelController::set_settings(const CmdVelControllerSettings& settings) {
  validate(settings);
  if (settings.wheel_separation_h != settings_.wheel_separation_h) {
    throw std::invalid_argument("wheel_separation_h cannot change while running (it is the cart's geometry)");
  }
  settings_ = settings;
}

bool CmdVelController::set_command(double speed, double yaw_rate, double time) {
  if (!std::isfinite(speed) || !std::isfinite(yaw_rate) || !std::isfinite(time)) return false;
  commanded_speed_ = speed;
  commanded_yaw_rate_ = yaw_rate;
  command_time_ = time;
  has_command_ = true;
  return true;
}

void CmdVelController::restart(const CartFeedback& feedback) {
  // A command from before a jump back in time counts as received now, so it still times out.
  command_time_ = std::min(command_time_, feedback.time);
  timed_out_ = false;
  started_ = true;
  last_time_ = feedback.time;
  speed_reference_ = 0.0;
  yaw_rate_reference_ = 0.0;
  steering_target_ = feedback.steering_angle;
  steering_reference_ = feedback.steering_angle;
  steering_reference_rate_ = 0.0;
  speed_reference_rate_ = 0.0;
  speed_integral_ = 0.0;
  last_output_ = ActuatorCommand{};
}

ActuatorCommand CmdVelController::update(const CartFeedback& feedback) {
  const CmdVelControllerSettings& s = settings_;
  if (started_ && feedback.time < last_time_) started_ = false;  // time went back: a simulator reset
  if (!started_) {
    // The first feedback (or the first after a reset): start from the cart as it is, v_ref at its speed, so that the speed
    // limits, not a step, take a rolling cart to the commanded speed.
    restart(feedback);
    speed_reference_ = std::clamp(feedback.base_speed, s.min_velocity, s.max_velocity);
  } else if (feedback.time <= last_time_) {
    return last_output_;  // a repeated instant changes nothing
  }
  const double dt = feedback.time - last_time_;  // [s]; 0 on the first update
  last_time_ = feedback.time;

  // 2. The command in force: (0, 0) before the first cmd_vel and after cmd_vel_timeout of silence
  //    (the speed loop then brakes to rest at linear/x/min_acceleration).
  double speed_command = has_command_ ? commanded_speed_ : 0.0;
  double yaw_rate_command = has_command_ ? commanded_yaw_rate_ : 0.0;
  const bool silent = has_command_ && s.cmd_vel_timeout > 0.0 && feedback.time - command_time_ > s.cmd_vel_timeout;
  if (silent) {
    speed_command = 0.0;
    yaw_rate_command = 0.0;
    if (!timed_out_) ++timeouts_;
  }
  timed_out_ = silent;

  // 1. Limits: value, then change per update (a slew on v_ref and r_ref).
  speed_command = std::clamp(speed_command, s.min_velocity, s.max_velocity);
  yaw_rate_command = std::clamp(yaw_rate_command, -s.max_yaw_rate, s.max_yaw_rate);
  const double previous_speed_reference = speed_reference_;
  speed_reference_ = slew(speed_reference_, speed_command, s.max_acceleration * dt, -s.min_acceleration * dt);
  speed_reference_rate_ = dt > 0.0 ? (speed_reference_ - previous_speed_reference) / dt : 0.0;
  yaw_rate_reference_ = slew(yaw_rate_reference_, yaw_rate_command, s.max_yaw_acceleration * dt,
                             s.max_yaw_acceleration * dt);

  // 3. χ* = atan(r l / v) (θ̇ = v_A tan χ / l); held at zero speed, where no χ turns the cart, and
  //    while braking after a timeout.
  if (!silent && std::abs(speed_reference_) >= s.zero_speed) {
    steering_target_ = std::atan(yaw_rate_reference_ * s.wheel_separation_h / speed_reference_);
  }
  steering_target_ = std::clamp(steering_target_, -s.max_steering_angle, s.max_steering_angle);

  // 4. χ_ref follows χ* at ≤ max_rate; its rate χ̇_ref feeds the D term.
  const double previous_reference = steering_reference_;
  steering_reference_ = slew(steering_reference_, steering_target_, s.max_steering_rate * dt,
                             s.max_steering_rate * dt);
  steering_reference_rate_ = dt > 0.0 ? (steering_reference_ - previous_reference) / dt : 0.0;

  ActuatorCommand output;
  // 5. τ = k_p (χ_ref − χ) + k_d (χ̇_ref − χ̇)  [N·m]
  output.steering_torque = s.steering_p * (steering_reference_ - feedback.steering_angle) +
                           s.steering_d * (steering_reference_rate_ - feedback.steering_rate);
  output.steering_torque = std::clamp(output.steering_torque, -s.max_steering_torque, s.max_steering_torque);

  // 6. T = k_ff v̇_ref + k_p,v e + k_i,v ∫e dt, e = v_ref − v_A [m/s]. The integral is for a steady
  //    load (rolling resistance, drag): it grows only while v_ref is steady (a ramp's tracking lag
  //    would wind it up and leave a slow creep after the ramp) and T is not saturated.
  const double speed_error = speed_reference_ - feedback.base_speed;
  const double proportional = s.drive_ff * speed_reference_rate_ + s.drive_p * speed_error;
  const double candidate_integral =
      std::clamp(speed_integral_ + s.drive_i * speed_error * dt, -s.drive_i_clamp, s.drive_i_clamp);
  const double unclamped = proportional + candidate_integral;
  const bool reference_steady = speed_reference_rate_ == 0.0;
  if ((reference_steady && std::abs(unclamped) <= s.max_drive_torque) ||
      std::abs(candidate_integral) < std::abs(speed_integral_)) {
    speed_integral_ = candidate_integral;
  }
  output.drive_torque = std::clamp(proportional + speed_integral_, -s.max_drive_torque, s.max_drive_torque);
  last_output_ = output;
  return output;
}

}  // namespace birkhoff_cart
