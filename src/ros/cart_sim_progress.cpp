// cart_sim's progress line in fast mode (see cart_sim_node.h): a long run says how far it is.
#include <cmath>
#include <optional>

#include "birkhoff_cart/ros/cart_sim_node.h"

namespace birkhoff_cart {

void CartSimNode::report_progress() {
  const std::optional<double> real_time_factor = work_.progress(WallClockPacing::Clock::now(), simulation_->state().time);
  if (!real_time_factor) return;
  const double time = simulation_->state().time;
  const double start_time = simulation_->scene().initial_state.time;
  if (std::isfinite(end_time_)) {
    ROS_INFO("cart_sim: t = %.3f s of %.3f s (%.1f %%), real-time factor %.1f", time, end_time_,
             100.0 * (time - start_time) / (end_time_ - start_time), *real_time_factor);
  } else {
    ROS_INFO("cart_sim: t = %.3f s (until shutdown), real-time factor %.1f", time, *real_time_factor);
  }
}

}  // namespace birkhoff_cart
