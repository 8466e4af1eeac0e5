// cart_sim's ~reset and ~pause services (see cart_sim_node.h).
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>

namespace birkhoff_cart {

bool CartSimNode::on_reset(std_srvs::Empty::Request& /*request*/, std_srvs::Empty::Response& /*response*/) {
  simulation_->reset();
  accuracy_guard_.reset();
  ++resets_;
  const double start_time = simulation_->state().time;
  commands_->restart(start_time);
  restart_schedule();
  // Each run gets its own bag: one bag across a reset would hold overlapping times of two runs,
  // which playback interleaves.
  if (record_) record_->next_run();
  ROS_INFO("cart_sim: reset to the scene's initial state at t = %.6g s%s%s", start_time,
           record_ && !record_->failure() ? ", recording to " : "",
           record_ && !record_->failure() ? record_->bag().path().c_str() : "");
  return true;
}

bool CartSimNode::on_pause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
  paused_ = request.data;
  response.success = true;
  response.message = std::string(paused_ ? "paused" : "running") + " at t = " +
                     format_seconds(simulation_->state().time) + " s";
  ROS_INFO("cart_sim: %s", response.message.c_str());
  return true;
}

}  // namespace birkhoff_cart
