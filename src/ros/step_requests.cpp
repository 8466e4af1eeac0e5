// StepRequests (step_requests.h).
#include "birkhoff_cart/ros/step_requests.h"

#include <chrono>
#include <utility>

#include "birkhoff_cart/ros/cart_sim_parameters.h"

namespace birkhoff_cart {

StepRequests::StepRequests(ros::NodeHandle& private_node, Refusal refusal, std::function<void()> wake)
    : refusal_(std::move(refusal)), wake_(std::move(wake)) {
  ros::AdvertiseServiceOptions options = ros::AdvertiseServiceOptions::create<StepRun>(
      "step", [this](StepRun::Request& request, StepRun::Response& response) { return serve(request, response); },
      ros::VoidConstPtr(), &queue_);
  service_ = private_node.advertiseService(options);
  spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
  spinner_->start();
}

StepRequests::~StepRequests() {
  end(stepped_to_time_);
  spinner_->stop();
  service_.shutdown();
}

bool StepRequests::serve(StepRun::Request& request, StepRun::Response& response) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto refuse = [&response](const std::string& why) {
    response.success = false;
    response.steps_taken = 0;
    response.message = "~step refused: " + why;
    ROS_ERROR("cart_sim: %s", response.message.c_str());
    return true;
  };
  const std::string why = refusal_();
  if (!why.empty()) return refuse(why);
  if (request.steps == 0) return refuse("steps must be at least 1");
  if (request_open_) return refuse("another ~step call is being served");
  if (loop_over_) return refuse("the run has ended");
  request_open_ = true;
  steps_requested_ = request.steps;
  wake_();
  // The loop takes the steps on its own thread; wait for it (and not forever on a node going down).
  while (steps_requested_ > 0 && !loop_over_ && ros::ok()) {
    condition_.wait_for(lock, std::chrono::milliseconds(100));
  }
  const std::uint64_t remaining = steps_requested_.exchange(0);
  request_open_ = false;
  response.steps_taken = static_cast<std::uint32_t>(request.steps - remaining);
  response.time = stepped_to_time_;
  response.success = remaining == 0;
  response.message = (response.success ? "took " : "ran out after ") + std::to_string(response.steps_taken) +
                     " of " + std::to_string(request.steps) + " steps; t = " + format_seconds(stepped_to_time_) +
                     " s" + (response.success ? ", paused" : " (the run ended or a step failed)");
  if (!response.success) ROS_WARN("cart_sim: ~step %s", response.message.c_str());
  return true;
}

void StepRequests::count_step(double time) {
  if (steps_requested_.load(std::memory_order_relaxed) == 0) return;  // one load per step otherwise
  std::lock_guard<std::mutex> lock(mutex_);
  stepped_to_time_ = time;
  if (steps_requested_ > 0 && --steps_requested_ == 0) condition_.notify_all();
}

void StepRequests::end(double time) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    loop_over_ = true;
    stepped_to_time_ = time;
  }
  condition_.notify_all();
}

}  // namespace birkhoff_cart
