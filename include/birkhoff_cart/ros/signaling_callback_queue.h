// The node's callback queue: roscpp's queue plus a flag and a condition set by the transport when a
// callback (a command, a service call) is queued. The time loop checks the flag per step (one
// atomic load) instead of polling the queue, and real-time mode sleeps on the condition until a
// deadline, so it wakes only when a step batch is due or a message has arrived.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

#include <ros/callback_queue.h>

namespace birkhoff_cart {

class SignalingCallbackQueue : public ros::CallbackQueue {
 public:
  /// roscpp's transport threads call this for every message or service request of the node.
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id = 0) override;

  /// True when a callback was queued since the last call_pending() (a relaxed hint, one load).
  bool pending() const { return pending_.load(std::memory_order_acquire); }
  /// Runs every queued callback in this thread.
  void call_pending();
  /// Sleeps until a callback is queued or `deadline` (steady clock) passes; true when a callback
  /// is pending. Returns at once when one is already pending.
  bool wait_until(std::chrono::steady_clock::time_point deadline);
  /// Wakes a wait_until() now (e.g. on shutdown).
  void wake();

 private:
  std::atomic<bool> pending_{false};
  std::mutex wait_mutex_;
  std::condition_variable wait_condition_;
};

}  // namespace birkhoff_cart
