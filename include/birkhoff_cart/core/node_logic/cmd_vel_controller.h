// The control law of cmd_vel_controller, ROS-free so its rules are unit-tested without a master and
// its closed loop with a core Simulation runs in a plain gtest.
//
// cmd_vel (v*, r*) → steering and drive torques (τ, T) of the cart (docs/ros_interface.md, "Node
// cmd_vel_controller"). Kinematics of base_link (the rear-axle midpoint A, docs eq. (2.3)):
//   v_A = ω1 cos χ,   θ̇ = ω1 sin χ / l   ⇒   θ̇ = v_A tan χ / l,
// so the steering angle that turns at yaw rate r* at speed v* is  χ* = atan(r* l / v*)  (|χ*| < π/2,
// valid forward and in reverse). Each update:
//   1. limits on the command (ros_controllers' speed_limiter habit): v* and r* clamped to
//      [min_velocity, max_velocity], and their change per update to the acceleration limits;
//   2. before the first cmd_vel and after cmd_vel_timeout of silence the command is (0, 0): the
//      speed loop brakes to rest at linear/x/min_acceleration, the steering holds its angle;
//   3. χ* from the kinematics, clamped to ±steering.max_angle; at |v*| < zero_speed the cart cannot
//      turn (θ̇ = v_A tan χ / l = 0), so χ* keeps its last value instead of swinging to ±π/2;
//   4. a reference χ_ref that follows χ* at no more than steering.max_rate;
//   5. τ = k_p (χ_ref − χ) + k_d (χ̇_ref − χ̇), clamped to ±steering.max_torque  (PD on the hinge);
//   6. T = k_ff v̇_ref + k_p,v (v_ref − v_A) + k_i,v ∫(v_ref − v_A) dt, clamped to ±drive.max_torque,
//      the integral clamped to ±drive.i_clamp and frozen while v_ref ramps or T saturates: a
//      feed-forward of the reference's acceleration (k_ff = μ r1, the torque that accelerates the
//      straight-running cart at 1 m/s², eq. (3.4) at χ = 0 with Q1 = T / r1) and a PI loop.
// Time is whatever the caller stamps its feedback with (scene time for the node); it never reads
// a clock.
#pragma once

#include <cstdint>

namespace birkhoff_cart {

/// Every setting of the law, with its default (the node reads each from a private parameter of the
/// same name, docs/ros_interface.md). Limits follow ros_controllers' names (linear/x/..., angular/z/...).
struct CmdVelControllerSettings {
  double wheel_separation_h = 1.05;      ///< l: base_link (A) to the steering hinge B [m]
  double cmd_vel_timeout = 0.5;          ///< silence after which the command is (0, 0) [s]; 0 = never
  double zero_speed = 1e-3;              ///< |v*| below this counts as "stop" [m/s]
  // linear/x
  double max_velocity = 3.0;             ///< linear/x/max_velocity [m/s]
  double min_velocity = -1.0;            ///< linear/x/min_velocity [m/s] (≤ 0: reverse allowed down to it)
  double max_acceleration = 1.5;         ///< linear/x/max_acceleration: rise of v* [m/s²]
  double min_acceleration = -3.0;        ///< linear/x/min_acceleration: fall of v* (braking) [m/s²], < 0
  // angular/z
  double max_yaw_rate = 1.5;             ///< angular/z/max_velocity [rad/s] (also the bound of −r*)
  double max_yaw_acceleration = 3.0;     ///< angular/z/max_acceleration [rad/s²]
  // steering (the hinge χ)
  double max_steering_angle = 0.6;       ///< steering/max_angle [rad], < π/2
  double max_steering_rate = 1.5;        ///< steering/max_rate: slew of χ_ref [rad/s]
  double max_steering_torque = 50.0;     ///< steering/max_torque [N·m]
  double steering_p = 120.0;             ///< steering/p [N·m/rad]
  double steering_d = 30.0;              ///< steering/d [N·m·s/rad]
  // drive (total torque on the rear axle)
  double max_drive_torque = 150.0;       ///< drive/max_torque [N·m]
  double drive_ff = 23.5;                ///< drive/ff: μ r1 of the default cart (167.7 kg · 0.14 m) [N·m/(m/s²)]
  double drive_p = 150.0;                ///< drive/p [N·m/(m/s)]
  double drive_i = 50.0;                 ///< drive/i [N·m/m]
  double drive_i_clamp = 50.0;           ///< drive/i_clamp: bound of the integral term [N·m]
};

/// Throws std::invalid_argument naming the first setting that is out of range.
void validate(const CmdVelControllerSettings& settings);

/// The measured state the law needs, all at one instant.
struct CartFeedback {
  double time = 0.0;            ///< [s]
  double base_speed = 0.0;      ///< v_A: forward speed of base_link (odom twist.linear.x) [m/s]
  double steering_angle = 0.0;  ///< χ (joint_states steering_joint position) [rad]
  double steering_rate = 0.0;   ///< χ̇ = ω2 (joint_states steering_joint velocity) [rad/s]
};

/// The torques to publish.
struct ActuatorCommand {
  double steering_torque = 0.0;  ///< τ [N·m]
  double drive_torque = 0.0;     ///< T, total on the rear axle [N·m]
};

class CmdVelController {
 public:
  /// Throws std::invalid_argument for a bad setting (validate()).
  explicit CmdVelController(const CmdVelControllerSettings& settings);

  /// A cmd_vel received at `time` [s]: v* = linear.x [m/s], r* = angular.z [rad/s]. Returns false
  /// (and keeps the previous command) for a non-finite value.
  bool set_command(double speed, double yaw_rate, double time);

  /// One control update on the feedback. A repeated time returns the last output unchanged; an
  /// earlier time (the simulator was reset) restarts the law from that feedback, keeping the command.
  ActuatorCommand update(const CartFeedback& feedback);

  /// References from the feedback (χ_ref = χ, v_ref = 0), integral 0; the received command stays.
  void restart(const CartFeedback& feedback);

  const CmdVelControllerSettings& settings() const { return settings_; }
  /// New limits, gains and timeout while running (dynamic_reconfigure); the command, references
  /// and integral carry on. Throws std::invalid_argument (validate()) and keeps the old settings
  /// for a bad set, or for a new wheel_separation_h: the cart's geometry is not a tuning knob.
  void set_settings(const CmdVelControllerSettings& settings);
  bool timed_out() const { return timed_out_; }             ///< the last update ran on the (0, 0) fallback
  std::uint64_t timeouts() const { return timeouts_; }      ///< times the command fell to (0, 0)
  double speed_reference() const { return speed_reference_; }           ///< v_ref after limits [m/s]
  double yaw_rate_reference() const { return yaw_rate_reference_; }     ///< r_ref after limits [rad/s]
  double steering_target() const { return steering_target_; }           ///< χ* [rad]
  double steering_reference() const { return steering_reference_; }     ///< χ_ref (rate-limited χ*) [rad]

 private:
  CmdVelControllerSettings settings_;
  double commanded_speed_ = 0.0;       ///< v* as received [m/s]
  double commanded_yaw_rate_ = 0.0;    ///< r* as received [rad/s]
  double command_time_ = 0.0;          ///< when it was received [s]
  bool has_command_ = false;
  bool timed_out_ = false;
  std::uint64_t timeouts_ = 0;

  bool started_ = false;               ///< update() has seen a feedback
  double last_time_ = 0.0;             ///< time of the last update [s]
  double speed_reference_ = 0.0;       ///< v_ref [m/s]
  double yaw_rate_reference_ = 0.0;    ///< r_ref [rad/s]
  double steering_target_ = 0.0;       ///< χ* [rad]
  double steering_reference_ = 0.0;    ///< χ_ref [rad]
  double steering_reference_rate_ = 0.0;  ///< χ̇_ref [rad/s]
  double speed_reference_rate_ = 0.0;  ///< v̇_ref [m/s²]
  double speed_integral_ = 0.0;        ///< k_i,v ∫(v_ref − v_A) dt [N·m]
  ActuatorCommand last_output_;
};

}  // namespace birkhoff_cart
