// A torque as a function of time (a scene's steering_torque / drive_torque profile), or the command
// source the ROS node writes. Plain data; evaluated in src/core/physics/effects/torque_profile.cpp.
#pragma once

namespace birkhoff_cart {

/// A time profile of a torque, or the command source (written by the ROS node).
struct TorqueProfile {
  enum class Kind {
    kConstant,         ///< value
    kCosine,           ///< amplitude·cos(2π frequency t + phase)
    kStep,             ///< initial for t < step_time, final after
    kRamp,             ///< initial → final linearly over [start_time, end_time]
    kSmoothSwitchOff,  ///< initial · ½(1 − tanh((t − switch_off_time)/width))
    kCommand,          ///< the latest command (zero-order hold), initial value `value`
  };
  Kind kind = Kind::kConstant;
  double value = 0.0;            ///< constant / initial command [N·m]
  double amplitude = 0.0;        ///< [N·m]
  double frequency = 0.0;        ///< [Hz]
  double phase = 0.0;            ///< [rad]
  double initial = 0.0;          ///< [N·m]
  double final = 0.0;            ///< [N·m]
  double step_time = 0.0;        ///< [s]
  double start_time = 0.0;       ///< [s]
  double end_time = 0.0;         ///< [s]
  double switch_off_time = 0.0;  ///< [s]
  double width = 1.0;            ///< [s]

  /// The first time > t [s] where the profile is not smooth (a step, a ramp's corners); +∞ if none.
  double next_kink_after(double t) const;

  /// The torque at time t [N·m] (for kCommand: `value`; the effect reads its command input).
  double at(double time) const;
};

}  // namespace birkhoff_cart
