// The node's flagged callback queue (see signaling_callback_queue.h).
#include "birkhoff_cart/ros/signaling_callback_queue.h"

namespace birkhoff_cart {

void SignalingCallbackQueue::addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id) {
  ros::CallbackQueue::addCallback(callback, owner_id);
  {
    std::lock_guard<std::mutex> lock(wait_mutex_);
    pending_.store(true, std::memory_order_release);
  }
  wait_condition_.notify_one();
}

void SignalingCallbackQueue::call_pending() {
  // Cleared before the calls: a callback queued meanwhile sets the flag again and is not lost.
  pending_.store(false, std::memory_order_release);
  callAvailable(ros::WallDuration(0.0));
}

bool SignalingCallbackQueue::wait_until(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(wait_mutex_);
  wait_condition_.wait_until(lock, deadline, [this] { return pending_.load(std::memory_order_acquire); });
  return pending_.load(std::memory_order_acquire);
}

void SignalingCallbackQueue::wake() { wait_condition_.notify_all(); }

}  // namespace birkhoff_cart
