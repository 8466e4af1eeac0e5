// cart_sim's ~step service (docs/ros_interface.md, "~step"): a paused run advances N steps of its
// schedule, exactly as the unpaused run would. The service is served on a queue and two threads of
// its own: one call blocks until the run loop has taken its steps, while the other thread answers a
// concurrent call at once (refused). The loop asks open() whether steps are requested, reports
// each step with count_step(), a pause, reset or teleport with cancel() (the open request is
// answered at once with the steps taken) and its end with end(). A request is bounded: at most
// kMaxSteps steps. Every answer, a refusal too, carries the current scene time. Part of CartSimNode.
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
#include "birkhoff_cart/ros/cart_sim_parameters.h"

namespace birkhoff_cart {

class StepRequests {
 public:
  /// The most steps one call may ask for [-]: a bound on how long a call runs and how much it
  /// publishes and records (larger runs: unpause, or call again).
  static constexpr std::uint32_t kMaxSteps = 100000;

  /// Why a ~step request is refused now ("" when it is not): the node's own conditions (lockstep,
  /// following /clock, not paused). Called on the service's threads.
  using Refusal = std::function<std::string()>;
  /// The refusal of cart_sim in the mode of `parameters`: ~lockstep and ~follow_clock pace the run
  /// themselves; otherwise it must be `paused` first. Both outlive the refusal.
  static Refusal node_refusal(const CartSimParameters& parameters, const std::atomic<bool>& paused);

  /// Advertises ~step on `private_node` with a queue and two threads of its own; `wake` wakes the
  /// run loop when steps are requested; `time` [s]: the scene time at the start.
  StepRequests(ros::NodeHandle& private_node, Refusal refusal, std::function<void()> wake, double time);
  ~StepRequests();

  /// A request has steps not yet taken.
  bool open() const { return steps_requested_.load(std::memory_order_relaxed) > 0; }
  /// After each step of the run, at scene time `time` [s]: counts it against an open request and
  /// answers the call when its last step is taken.
  void count_step(double time);
  /// The run moved to scene time `time` [s] by `reason` (~pause, ~reset, a teleport): an open
  /// request takes no further step and is answered now, naming `reason`; later answers give `time`.
  void cancel(const std::string& reason, double time);
  /// The run loop has ended at scene time `time` [s] (`shutdown`: stopped by a shutdown, not at the
  /// run's end or a failed step): an open request returns with the steps taken, naming which.
  void end(double time, bool shutdown = false);

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
  std::atomic<double> time_;    ///< the scene time after the last step or move [s]
  bool request_open_ = false;   ///< guarded by mutex_
  bool loop_over_ = false;      ///< guarded by mutex_
  bool shut_down_ = false;      ///< the loop ended by a shutdown; guarded by mutex_
  std::uint64_t steps_taken_ = 0;  ///< of the open request; guarded by mutex_
  std::string cancelled_by_;       ///< why the open request was cancelled ("" if not); guarded by mutex_
};

}  // namespace birkhoff_cart
