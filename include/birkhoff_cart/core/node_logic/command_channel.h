// One commanded torque (steering_torque or drive_torque) between the subscriber and the core:
// zero-order hold, rejection of non-finite values, clamping to a limit and a watchdog that falls
// back to zero after a silence. ROS-free, so its rules are unit-tested without a master.
#pragma once

#include <cstdint>

namespace birkhoff_cart {

class CommandChannel {
 public:
  enum class Outcome { kAccepted, kClamped, kRejected };

  /// `initial_torque` [N·m] is held from the start; `max_torque` [N·m] > 0 is the clamp;
  /// `timeout` [s of scene time] ≥ 0 the watchdog's silence (0 disables it). Throws
  /// std::invalid_argument naming the bad value.
  CommandChannel(double initial_torque, double max_torque, double timeout, double start_time);

  /// A command received at scene time `time` [s]: NaN/Inf is rejected (the held value stays),
  /// |τ| > max is clamped to ±max, anything else is held as is.
  Outcome receive(double torque, double time);

  /// The watchdog at scene time `time` [s]: after `timeout` of silence a held non-zero torque falls
  /// to 0. Returns true exactly once per timeout (the caller warns then).
  bool check_watchdog(double time);

  /// Back to the initial torque and counters kept (a reset of the scene, not of the statistics).
  void restart(double start_time);

  /// New limits while running (dynamic_reconfigure): the clamp `max_torque` [N·m] > 0 applies to
  /// the commands received from now on (the held torque stays), the watchdog's `timeout` [s] ≥ 0
  /// counts from the last command. Throws std::invalid_argument naming a bad value; nothing changes then.
  void set_limits(double max_torque, double timeout);

  double torque() const { return torque_; }            ///< the held torque [N·m]
  double max_torque() const { return max_torque_; }    ///< [N·m]
  double timeout() const { return timeout_; }          ///< [s]
  std::uint64_t received() const { return received_; }
  std::uint64_t rejected() const { return rejected_; }
  std::uint64_t clamped() const { return clamped_; }
  std::uint64_t timeouts() const { return timeouts_; }

 private:
  double initial_torque_;    ///< [N·m]
  double max_torque_;        ///< [N·m]
  double timeout_;           ///< [s]
  double torque_;            ///< held [N·m]
  double last_command_time_; ///< scene time of the last accepted command (or the start) [s]
  bool watchdog_armed_;      ///< a non-zero torque is held and may time out
  std::uint64_t received_ = 0;
  std::uint64_t rejected_ = 0;
  std::uint64_t clamped_ = 0;
  std::uint64_t timeouts_ = 0;
};

}  // namespace birkhoff_cart
