// cart_sim's ~events (see event_reports.h).
#include "birkhoff_cart/ros/event_reports.h"

#include <algorithm>
#include <utility>
#include <stdexcept>

#include <ros/console.h>

#include "birkhoff_cart/CartEvent.h"
#include "birkhoff_cart/ros/conversions.h"

namespace birkhoff_cart {

EventReports::EventReports(ros::NodeHandle& private_node, const std::vector<std::string>& texts,
                           Simulation& simulation, const std::string& frame_id)
    : simulation_(simulation), frame_id_(frame_id) {
  events_ = state_field_events(texts);
  if (events_.empty()) return;
  locator_.emplace(simulation_, events_);  // refuses here, by the core's reason
  published_.assign(events_.size(), 0);
  publisher_ = private_node.advertise<birkhoff_cart::CartEvent>("events", 100);
  if (simulation_.takes_own_steps()) {
    simulation_.observe_grid([this](const CartState& stepped_to) {
      if (locator_) locator_->step_to(stepped_to);
    });
  }
}

EventReports::~EventReports() {
  if (!events_.empty() && simulation_.takes_own_steps()) simulation_.observe_grid({});
}

void EventReports::restart() {
  if (events_.empty()) return;
  for (StateEvent& event : events_) {
    event.times.clear();
    event.states.clear();
  }
  published_.assign(events_.size(), 0);
  locator_.reset();
  try {
    locator_.emplace(simulation_, events_);
  } catch (const std::exception& error) {
    ROS_ERROR("cart_sim: ~events are off until the next restart: %s", error.what());
  }
}

bool EventReports::after_step(RunRecord* record) {
  if (!locator_) return false;
  if (!simulation_.takes_own_steps()) locator_->step_to(simulation_.state());
  // A member with its own steps may have found a crossing ahead of the run's time (its own step
  // reaches beyond the step of the schedule): it is published, and pauses, once the run gets there.
  const double now = simulation_.state().time;  // [s]
  std::vector<Occurrence> fresh;  // the crossings the run has reached and not yet published
  for (std::size_t i = 0; i < events_.size(); ++i) {
    const std::vector<double>& times = events_[i].times;
    for (; published_[i] < times.size() && times[published_[i]] <= now; ++published_[i]) {
      fresh.push_back({times[published_[i]], i, published_[i]});
    }
  }
  std::stable_sort(fresh.begin(), fresh.end(), [](const Occurrence& a, const Occurrence& b) { return a.time < b.time; });
  for (const Occurrence& occurrence : fresh) {
    const StateEvent& event = events_[occurrence.event];
    const CartState& state = event.states[occurrence.index];
    birkhoff_cart::CartEvent message;
    message.header.stamp = ros_conversions::to_ros_time(occurrence.time);
    message.header.frame_id = frame_id_;
    message.event = event.name;
    message.occurrence = static_cast<std::uint32_t>(occurrence.index + 1);
    message.terminal = event.terminal_after > 0;
    message.x = state.x;
    message.y = state.y;
    message.theta = state.heading;
    message.chi = state.steering_angle;
    message.omega1 = state.forward_speed;
    message.omega2 = state.steering_rate;
    publisher_.publish(message);
    if (record) record->write(publisher_.getTopic(), message.header.stamp, message);
    ROS_INFO("cart_sim: event %s", describe_occurrence(event, occurrence.index).c_str());
  }
  if (!locator_->stopped() || events_[locator_->stopping_event()].times.back() > now) return false;
  // A terminal event pauses the node; its next crossing pauses it again: the locator goes on from here.
  locator_->resume();
  return true;
}

}  // namespace birkhoff_cart
