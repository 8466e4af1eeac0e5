// StepRequests (step_requests.h).
#include "birkhoff_cart/ros/step_requests.h"

#include <chrono>
#include <utility>

#include "birkhoff_cart/ros/cart_sim_parameters.h"

namespace birkhoff_cart {
namespace {

/// Threads serving ~step: one blocked in a call while the loop steps, one to refuse a second call.
constexpr std::uint32_t kServiceThreads = 2;

}  // namespace

StepRequests::StepRequests(ros::NodeHandle& private_node, Refusal refusal, std::function<void()> wake, double time)
    : refusal_(std::move(refusal)), wake_(std::move(wake)), time_(time) {
  ros::AdvertiseServiceOptions options = ros::AdvertiseServiceOptions::create<StepRun>(
      "step", [this](StepRun::Request& request, StepRun::Response& response) { return serve(request, response); },
      ros::VoidConstPtr(), &queue_);
  service_ = private_node.advertiseService(options);
  spinner_ = std::make_unique<ros::AsyncSpinner>(kServiceThreads, &queue_);
  spinner_->start();
}

StepRequests::~StepRequests() {
  end(time_, true);  // the node goes away
  spinner_->stop();
  service_.shutdown();
}

bool StepRequests::serve(StepRun::Request& request, StepRun::Response& response) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto refuse = [this, &response](const std::string& why) {
    response.success = false;
    response.steps_taken = 0;
    response.time = time_;
    response.message = "~step refused: " + why + "; t = " + format_seconds(response.time) + " s";
    ROS_ERROR("cart_sim: %s", response.message.c_str());
    return true;
  };
  if (request_open_) return refuse("another ~step call is being served");
  if (loop_over_) return refuse("the run has ended");
  const std::string why = refusal_();
  if (!why.empty()) return refuse(why);
  if (request.steps == 0) return refuse("steps must be at least 1");
  if (request.steps > kMaxSteps) {
    return refuse("steps " + std::to_string(request.steps) + " is more than the " + std::to_string(kMaxSteps) +
                  " one call may take (call again, or unpause the run)");
  }
  request_open_ = true;
  steps_taken_ = 0;
  cancelled_by_.clear();
  steps_requested_ = request.steps;
  wake_();
  // The loop takes the steps on its own thread; wait for it (and not forever on a node going down).
  while (steps_requested_ > 0 && !loop_over_ && ros::ok()) {
    condition_.wait_for(lock, std::chrono::milliseconds(100));
  }
  steps_requested_ = 0;
  request_open_ = false;
  response.steps_taken = static_cast<std::uint32_t>(steps_taken_);
  response.time = time_;
  response.success = steps_taken_ == request.steps;
  const std::string count = std::to_string(response.steps_taken) + " of " + std::to_string(request.steps) + " steps";
  const std::string at = "; t = " + format_seconds(response.time) + " s";
  if (response.success) {
    response.message = "took " + count + at + ", paused";
  } else if (!cancelled_by_.empty() || shut_down_) {
    response.message = "cancelled by " + (shut_down_ ? std::string("shutdown") : cancelled_by_) + " after " + count + at;
  } else {
    response.message = "ran out after " + count + at + " (the run ended or a step failed)";
  }
  if (!response.success) ROS_WARN("cart_sim: ~step %s", response.message.c_str());
  return true;
}

void StepRequests::count_step(double time) {
  time_.store(time, std::memory_order_relaxed);
  if (steps_requested_.load(std::memory_order_relaxed) == 0) return;  // one load per step otherwise
  std::lock_guard<std::mutex> lock(mutex_);
  if (steps_requested_ == 0) return;
  ++steps_taken_;
  if (--steps_requested_ == 0) condition_.notify_all();
}

void StepRequests::cancel(const std::string& reason, double time) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    time_ = time;
    if (steps_requested_ == 0) return;
    steps_requested_ = 0;
    cancelled_by_ = reason;
  }
  condition_.notify_all();
}

void StepRequests::end(double time, bool shutdown) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    loop_over_ = true;
    shut_down_ = shutdown;
    time_ = time;
  }
  condition_.notify_all();
}

StepRequests::Refusal StepRequests::node_refusal(const CartSimParameters& parameters, const std::atomic<bool>& paused) {
  return [&parameters, &paused]() -> std::string {
    if (parameters.lockstep) return "~lockstep is on: the controllers' answers pace the run";
    if (parameters.follow_clock) return "~follow_clock is on: the leader's /clock paces the run";
    if (!paused) return "the run is not paused (call ~pause with data: true first)";
    return "";
  };
}

}  // namespace birkhoff_cart
