// cart_sim's teleport (see cart_sim_node.h): a restart of the run from a new state at the current
// scene time, for ~set_state and initialpose (PoseRequests).
#include <cmath>
#include <sstream>

#include "birkhoff_cart/ros/cart_sim_node.h"

namespace birkhoff_cart {

bool CartSimNode::teleport(const CartState& target, const std::string& source, std::string& message) {
  if (simulation_->at_end()) {
    message = source + " refused: the run has ended at t = " + format_seconds(simulation_->state().time) + " s";
    ROS_ERROR("cart_sim: %s", message.c_str());
    return false;
  }
  try {
    simulation_->restart_from(target);
  } catch (const std::invalid_argument& error) {
    message = source + " refused: " + error.what() + "; the simulation goes on unchanged";
    ROS_ERROR("cart_sim: %s", message.c_str());
    return false;
  }
  accuracy_guard_.reset();
  ++resets_;  // a batch in progress stops: its publish instants belonged to the old start
  const double time = simulation_->state().time;
  commands_->restart(time);
  restart_schedule();
  const Eigen::Vector2d base = simulation_->model().rear_axle_midpoint(target);
  std::ostringstream text;
  text << source << ": teleported at t = " << format_seconds(time) << " s to base_link (" << base.x() << ", "
       << base.y() << ") m, heading " << target.heading << " rad, steering angle " << target.steering_angle
       << " rad, forward speed " << target.forward_speed << " m/s, steering rate " << target.steering_rate
       << " rad/s (a restart of the run from there" << (record_ ? "; the bag goes on)" : ")");
  message = text.str();
  ROS_INFO("cart_sim: %s", message.c_str());
  return true;
}

}  // namespace birkhoff_cart
