// A torque actuator between a commanded torque and the torque the cart receives (the steering motor,
// the drive motor): dead band, saturation, dead time, first-order lag and rate limit
// (docs/actuators.md eqs. (A1)–(A5)). Its dynamics do not depend on the cart's state, so its response
// to an input held between two changes is known in closed form: the cart's integrators read the
// applied torque at any stage time of a step exactly (no splitting error), and the only loss of
// smoothness is at the kinks next_kink_after() reports, where the simulation ends a step
// (simulation.cpp). The state (time, applied torque, target, pending inputs) advances only when the
// simulation commits a step (advance_to).
#pragma once

#include <deque>
#include <limits>
#include <string>

namespace birkhoff_cart {

/// Settings of a torque actuator (scene sections steering_actuator / drive_actuator). The defaults
/// are an ideal actuator: every stage off.
struct TorqueActuatorSettings {
  double time_constant = 0.0;  ///< T of the first-order lag [s], ≥ 0 (0: no lag)
  double dead_time = 0.0;      ///< d, input to response [s], ≥ 0
  double rate_limit = std::numeric_limits<double>::infinity();    ///< R, |dτ/dt| ≤ R [N·m/s], > 0
  double torque_limit = std::numeric_limits<double>::infinity();  ///< τ_max, saturation [N·m], > 0
  double dead_band = 0.0;      ///< b: |u| ≤ b gives 0, larger inputs lose b (eq. (A1)) [N·m], ≥ 0
};

/// Throws std::invalid_argument naming `section`.key for a value out of its range (non-finite where
/// a number is needed, negative, a zero rate or torque limit).
void validate_torque_actuator(const std::string& section, const TorqueActuatorSettings& settings);

class TorqueActuator {
 public:
  /// An actuator at rest at `start_time` [s], its applied torque the shaped `initial_input` [N·m].
  TorqueActuator(const TorqueActuatorSettings& settings, double start_time, double initial_input);

  const TorqueActuatorSettings& settings() const { return settings_; }

  /// The input after dead band and saturation (eq. (A1)) [N·m].
  double shaped(double input) const;

  /// A new input `input` [N·m] arrives at `time` [s] (≥ the last input's time and ≥ time()); it takes
  /// effect at time + d. Throws std::invalid_argument for a non-finite input or a time out of order.
  void command(double time, double input);

  /// The applied torque τ(t) [N·m] at t ≥ time() given the inputs so far (eqs. (A2)–(A4)); a t
  /// below time() (an ulp of stage-time rounding) reads τ(time()).
  double output_at(double time) const;

  /// The first time > t [s] where τ is not smooth: an input taking effect, the end of a rate-limited
  /// ramp; +∞ when none is pending.
  double next_kink_after(double time) const;

  /// Commits the response up to `time` [s] (≥ time()): the state there, inputs due by then applied.
  void advance_to(double time);

  /// Moves the actuator's clock to `start_time` [s] without changing its torques (a teleport
  /// restart): pending inputs keep their remaining delay.
  void retime(double start_time);

  double time() const { return time_; }        ///< the committed time [s]
  double applied() const { return applied_; }  ///< τ at time() [N·m]
  double target() const { return target_; }    ///< the shaped input in effect at time() [N·m]
  /// The latest input as commanded, before shaping [N·m].
  double latest_input() const { return latest_input_; }
  /// Inputs commanded but not yet in effect (dead time) [-].
  std::size_t pending_inputs() const { return pending_.size(); }

 private:
  struct PendingInput {
    double effective_time;  ///< t + d [s]
    double target;          ///< shaped input [N·m]
  };
  /// τ at t ≥ t0 from τ0 at t0 with `target` held (eqs. (A2)–(A4)) [N·m].
  double hold_response(double t0, double applied0, double target, double t) const;
  /// The end of the rate-limited part of that response (t0 when there is none, +∞ never) [s].
  double ramp_end(double t0, double applied0, double target) const;

  TorqueActuatorSettings settings_;
  double time_;
  double applied_;
  double target_;
  double latest_input_;
  double latest_input_time_;
  std::deque<PendingInput> pending_;
};

}  // namespace birkhoff_cart
