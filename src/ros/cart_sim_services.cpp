// cart_sim's ~reset and ~pause services and the bag of each run (see cart_sim_node.h).
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
  if (recorder_ && !record_failure_) {
    try {
      recorder_->close();
      ROS_INFO("cart_sim: run %lu recorded to %s", static_cast<unsigned long>(run_index_), recorder_->path().c_str());
      open_record(parameters_.bag_path);
    } catch (const std::exception& failure) {
      record_failure_ = std::string("at ~reset: ") + failure.what();
    }
  }
  ROS_INFO("cart_sim: reset to the scene's initial state at t = %.6g s%s%s", start_time,
           recorder_ && !record_failure_ ? ", recording to " : "",
           recorder_ && !record_failure_ ? recorder_->path().c_str() : "");
  return true;
}

void CartSimNode::open_record(const std::string& path) {
  ++run_index_;
  world_transform_recorded_ = false;
  recorder_ = std::make_unique<BagRecorder>(run_bag_path(path, run_index_),
                                            BagRecorder::parse_compression(parameters_.bag_compression),
                                            parameters_.min_free_disk_space);
  if (!recorder_->earlier_bag_kept_as().empty()) {
    ROS_WARN("cart_sim: %s already held a bag: kept it as %s (a record never overwrites one)",
             recorder_->path().c_str(), recorder_->earlier_bag_kept_as().c_str());
  }
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
