// cart_sim's ~step service (docs/ros_interface.md, "~step"): a paused run advances N steps of its
// schedule, exactly as the unpaused run would. The service is served on a thread of its own (its
// call blocks until the run loop has taken the steps); the loop asks open() whether steps are
// requested, reports each step with count_step() and its end with end(). Part of CartSimNode.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/spinner.h>

#include "birkhoff_cart/StepRun.h"

namespace birkhoff_cart {

class StepRequests {
 public:
  /// Why a ~step request is refused now ("" when it is not): the node's own conditions (lockstep,
  /// following /clock, not paused). Called on the service's thread.
  using Refusal = std::function<std::string()>;

  /// Advertises ~step on `private_node` with a queue and a thread of its own; `wake` wakes the run
  /// loop when steps are requested.
  StepRequests(ros::NodeHandle& private_node, Refusal refusal, std::function<void()> wake);
  ~StepRequests();

  /// A request is open: it has steps not yet taken.
  bool open() const { return steps_requested_ > 0; }
  /// After each step of the run, at scene time `time` [s]: counts it against an open request and
  /// answers the call when its last step is taken.
  void count_step(double time);
  /// The run loop has ended at scene time `time` [s]: an open request returns with the steps taken.
  void end(double time);

 private:
  bool serve(StepRun::Request& request, StepRun::Response& response);

  Refusal refusal_;
  std::function<void()> wake_;
  ros::CallbackQueue queue_;  ///< ~step alone: its call blocks until the loop has taken the steps
  ros::ServiceServer service_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
  std::mutex mutex_;
  std::condition_variable condition_;
  std::atomic<std::uint64_t> steps_requested_{0};  ///< steps of the open request not yet taken
  bool request_open_ = false;   ///< guarded by mutex_
  bool loop_over_ = false;      ///< guarded by mutex_
  double stepped_to_time_ = 0;  ///< scene time after the last requested step [s]; guarded by mutex_
};

}  // namespace birkhoff_cart
