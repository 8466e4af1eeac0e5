// cart_sim's lockstep barrier (docs/ros_interface.md, "Running modes"): before the first step it
// waits until every expected command topic has a publisher and joint_states a subscriber; after
// each publish instant, until every expected topic has answered or ~lockstep_timeout [s of wall
// time] has passed. In lockstep the node's callbacks run only here, so a closed loop through
// another node is the same on every run. Part of CartSimNode.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

#include "birkhoff_cart/ros/command_inputs.h"
#include "birkhoff_cart/ros/instant_publisher.h"
#include "birkhoff_cart/ros/signaling_callback_queue.h"

namespace birkhoff_cart {

class LockstepBarrier {
 public:
  /// `timeout`: ~lockstep_timeout [s of wall time]; `stop_requested`: the node is stopping;
  /// `paused`: ~pause (a paused run does not wait for answers). All outlive the barrier.
  LockstepBarrier(SignalingCallbackQueue& queue, CommandInputs& commands, const InstantPublisher& publisher,
                  double timeout, std::function<bool()> stop_requested, const std::atomic<bool>& paused);

  /// Before the first step: waits until every expected command topic has a publisher and
  /// joint_states a subscriber (a state published before would be lost and its barrier time out).
  void wait_for_controllers();
  /// After publishing instant `time` [s]: runs the callbacks queued since the last barrier, then
  /// waits for every expected command topic (or the timeout, counted), and records the answers at `time`.
  void wait_for_commands(double time);

  /// Lockstep instants that went on without every answer.
  const std::uint64_t& timeouts() const { return timeouts_; }

 private:
  SignalingCallbackQueue& queue_;
  CommandInputs& commands_;
  const InstantPublisher& publisher_;
  double timeout_;  ///< [s of wall time]
  std::function<bool()> stop_requested_;
  const std::atomic<bool>& paused_;
  std::uint64_t timeouts_ = 0;
};

}  // namespace birkhoff_cart
