// CommandInputs (command_inputs.h).
#include "birkhoff_cart/ros/command_inputs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace birkhoff_cart {

CommandInputs::CommandInputs(Simulation& simulation, const CartSimParameters& parameters, double start_time)
    : simulation_(simulation), parameters_(parameters) {
  if (simulation_.accepts_steering_command()) {
    steering_channel_.emplace(simulation_.steering_command(), parameters_.max_steering_torque,
                              parameters_.command_timeout, start_time);
  }
  if (simulation_.accepts_drive_command()) {
    drive_channel_.emplace(simulation_.drive_command(), parameters_.max_drive_torque, parameters_.command_timeout,
                           start_time);
  }
  // The lockstep barrier: the command topics named by ~lockstep_topics, by default every one the
  // scene takes commands on.
  if (!parameters_.lockstep) return;
  const auto wanted = [this](const std::string& topic) {
    if (!parameters_.lockstep_topics_given) return true;
    return std::find(parameters_.lockstep_topics.begin(), parameters_.lockstep_topics.end(), topic) !=
           parameters_.lockstep_topics.end();
  };
  expect_steering_ = wanted("steering_torque");
  expect_drive_ = wanted("drive_torque");
  if ((expect_steering_ && !steering_channel_) || (expect_drive_ && !drive_channel_)) {
    if (parameters_.lockstep_topics_given) {
      throw std::invalid_argument("~lockstep_topics names a command topic whose effect in scene " +
                                  parameters_.scene_path + " has no 'command' source");
    }
    expect_steering_ = expect_steering_ && steering_channel_.has_value();
    expect_drive_ = expect_drive_ && drive_channel_.has_value();
  }
}

void CommandInputs::subscribe(ros::NodeHandle& node, RecordCommand record) {
  record_ = std::move(record);
  // tcpNoDelay: a command is one small message; Nagle's algorithm would hold it back (lockstep
  // waits for it every publish instant).
  if (steering_channel_) {
    steering_subscriber_ = node.subscribe("steering_torque", 20, &CommandInputs::on_steering_torque, this,
                                          ros::TransportHints().tcpNoDelay());
  }
  if (drive_channel_) {
    drive_subscriber_ = node.subscribe("drive_torque", 20, &CommandInputs::on_drive_torque, this,
                                       ros::TransportHints().tcpNoDelay());
  }
}

void CommandInputs::receive(CommandChannel& channel, const std::string& topic, const std_msgs::Float64& message) {
  const double time = simulation_.state().time;
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
    lockstep_records_.emplace_back(topic, message);  // recorded at the barrier (end_barrier)
    return;
  }
  if (record_) record_(topic, std::max(time, 0.0), message);
}

void CommandInputs::on_steering_torque(const std_msgs::Float64::ConstPtr& message) {
  receive(*steering_channel_, steering_subscriber_.getTopic(), *message);
  simulation_.set_steering_command(steering_channel_->torque());
}

void CommandInputs::on_drive_torque(const std_msgs::Float64::ConstPtr& message) {
  receive(*drive_channel_, drive_subscriber_.getTopic(), *message);
  simulation_.set_drive_command(drive_channel_->torque());
}

void CommandInputs::restart(double time) {
  if (steering_channel_) {
    steering_channel_->restart(time);
    simulation_.set_steering_command(steering_channel_->torque());
  }
  if (drive_channel_) {
    drive_channel_->restart(time);
    simulation_.set_drive_command(drive_channel_->torque());
  }
}

void CommandInputs::apply_watchdogs() {
  const double time = simulation_.state().time;
  if (steering_channel_ && steering_channel_->check_watchdog(time)) {
    simulation_.set_steering_command(steering_channel_->torque());
    ROS_WARN("cart_sim: no steering_torque command for %g s at t = %.6g s: steering torque set to 0",
             steering_channel_->timeout(), time);
  }
  if (drive_channel_ && drive_channel_->check_watchdog(time)) {
    simulation_.set_drive_command(drive_channel_->torque());
    ROS_WARN("cart_sim: no drive_torque command for %g s at t = %.6g s: drive torque set to 0",
             drive_channel_->timeout(), time);
  }
}

void CommandInputs::set_limits(double max_steering_torque, double max_drive_torque, double timeout) {
  const auto require = [](bool ok, const std::string& what, double value) {
    if (!ok) throw std::invalid_argument(what + ", got " + format_seconds(value));
  };
  require(std::isfinite(max_steering_torque) && max_steering_torque > 0.0,
          "max_steering_torque must be finite and > 0 N m", max_steering_torque);
  require(std::isfinite(max_drive_torque) && max_drive_torque > 0.0, "max_drive_torque must be finite and > 0 N m",
          max_drive_torque);
  require(std::isfinite(timeout) && timeout >= 0.0, "command_timeout must be finite and >= 0 s", timeout);
  if (steering_channel_) steering_channel_->set_limits(max_steering_torque, timeout);
  if (drive_channel_) drive_channel_->set_limits(max_drive_torque, timeout);
}

bool CommandInputs::controllers_connected() const {
  return (!expect_steering_ || steering_subscriber_.getNumPublishers() > 0) &&
         (!expect_drive_ || drive_subscriber_.getNumPublishers() > 0);
}

bool CommandInputs::answered() const {
  return (!expect_steering_ || steering_answered_) && (!expect_drive_ || drive_answered_);
}

std::string CommandInputs::expected_topics() const {
  std::string topics = expect_steering_ ? steering_subscriber_.getTopic() : "";
  if (expect_steering_ && expect_drive_) topics += " and ";
  if (expect_drive_) topics += drive_subscriber_.getTopic();
  return topics;
}

std::string CommandInputs::unanswered_topics() const {
  const bool steering = expect_steering_ && !steering_answered_;
  const bool drive = expect_drive_ && !drive_answered_;
  return std::string(steering ? "steering_torque" : "") + (steering && drive ? " and " : "") +
         (drive ? "drive_torque" : "");
}

void CommandInputs::end_barrier(double time) {
  steering_answered_ = false;
  drive_answered_ = false;
  std::stable_sort(lockstep_records_.begin(), lockstep_records_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (record_) {
    for (const auto& [topic, message] : lockstep_records_) record_(topic, time, message);
  }
  lockstep_records_.clear();
}

std::uint64_t CommandInputs::rejected() const {
  return (steering_channel_ ? steering_channel_->rejected() : 0) + (drive_channel_ ? drive_channel_->rejected() : 0);
}

}  // namespace birkhoff_cart
