// cart_sim's pacing: callbacks between steps and the wall-clock schedule of real-time mode (see cart_sim_node.h).
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>

#include <ros/callback_queue.h>

namespace birkhoff_cart {

void CartSimNode::process_callbacks(double wall_timeout) {
  ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(std::max(0.0, wall_timeout)));
}

void CartSimNode::pace() {
  if (effective_real_time_factor_ <= 0.0) {
    process_callbacks(0.0);
    return;
  }
  // Wall time at which the current scene time is due: anchor + (t − t_anchor)/factor.
  const double due_wall = (simulation_->state().time - pace_anchor_time_) / effective_real_time_factor_;
  while (true) {
    const double remaining = due_wall - (ros::WallTime::now() - pace_anchor_wall_).toSec();
    process_callbacks(std::min(remaining, 0.02));
    if (remaining <= 0.0 || paused_ || shutdown_signal_received() || !ros::ok()) break;
  }
}

}  // namespace birkhoff_cart
