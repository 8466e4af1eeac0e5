// cart_sim's inputs: the command topics and the ~reset and ~pause services (see cart_sim_node.h).
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>

namespace birkhoff_cart {

void CartSimNode::receive_command(CommandChannel& channel, const std::string& topic,
                                  const std_msgs::Float64& message) {
  const double time = simulation_->state().time;
  const CommandChannel::Outcome outcome = channel.receive(message.data, time);
  if (outcome == CommandChannel::Outcome::kRejected) {
    ROS_ERROR_THROTTLE(1.0, "cart_sim: rejected non-finite %s command (%g) at t = %.6g s (%lu rejected so far)",
                       topic.c_str(), message.data, time, static_cast<unsigned long>(channel.rejected()));
  } else if (outcome == CommandChannel::Outcome::kClamped) {
    ROS_WARN_THROTTLE(1.0, "cart_sim: %s command %g clamped to %g N m", topic.c_str(), message.data,
                      channel.torque());
  }
  if (steering_channel_ && &channel == &*steering_channel_) steering_answered_ = true;
  if (drive_channel_ && &channel == &*drive_channel_) drive_answered_ = true;
  if (parameters_.lockstep) {
    // Answers arrive over separate connections in any order; they are recorded at the barrier in
    // the order of the topics' names, so two identical runs record identical bags.
    lockstep_records_.emplace_back(topic, message);
    return;
  }
  if (recorder_ && !record_failure_) {
    try {
      recorder_->write(topic, ros_conversions::to_ros_time(std::max(time, 0.0)), message);
    } catch (const std::exception& failure) {
      record_failure_ = failure.what();
    }
  }
}

void CartSimNode::on_steering_torque(const std_msgs::Float64::ConstPtr& message) {
  if (!steering_channel_) {
    ROS_WARN_THROTTLE(5.0, "cart_sim: scene '%s' has no steering_torque effect with source 'command': "
                      "ignoring %s", simulation_->scene().name.c_str(), steering_subscriber_.getTopic().c_str());
    return;
  }
  receive_command(*steering_channel_, steering_subscriber_.getTopic(), *message);
  simulation_->set_steering_command(steering_channel_->torque());
}

void CartSimNode::on_drive_torque(const std_msgs::Float64::ConstPtr& message) {
  if (!drive_channel_) {
    ROS_WARN_THROTTLE(5.0, "cart_sim: scene '%s' has no drive_torque effect with source 'command': ignoring %s",
                      simulation_->scene().name.c_str(), drive_subscriber_.getTopic().c_str());
    return;
  }
  receive_command(*drive_channel_, drive_subscriber_.getTopic(), *message);
  simulation_->set_drive_command(drive_channel_->torque());
}

void CartSimNode::restart_commands(double time) {
  if (steering_channel_) {
    steering_channel_->restart(time);
    simulation_->set_steering_command(steering_channel_->torque());
  }
  if (drive_channel_) {
    drive_channel_->restart(time);
    simulation_->set_drive_command(drive_channel_->torque());
  }
}

bool CartSimNode::on_reset(std_srvs::Empty::Request& /*request*/, std_srvs::Empty::Response& /*response*/) {
  simulation_->reset();
  accuracy_guard_.reset();
  ++resets_;
  const double start_time = simulation_->state().time;
  restart_commands(start_time);
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
