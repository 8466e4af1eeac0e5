// cart_sim's progress line in fast mode (see cart_sim_node.h): a long run says how far it is.
#include <chrono>
#include <cmath>

#include "birkhoff_cart/ros/cart_sim_node.h"

namespace birkhoff_cart {

void CartSimNode::report_progress() {
  constexpr double kProgressPeriod = 1.0;  // at most one line per this much wall time [s]
  const WallClockPacing::Clock::time_point now = WallClockPacing::Clock::now();
  if (!last_progress_wall_) {  // the first call of the run: start counting
    last_progress_wall_ = run_start_wall_;
    last_progress_time_ = simulation_->scene().initial_state.time;
  }
  const double wall_elapsed = std::chrono::duration<double>(now - *last_progress_wall_).count();  // [s]
  if (wall_elapsed < kProgressPeriod) return;
  const double time = simulation_->state().time;
  const double start_time = simulation_->scene().initial_state.time;
  const double real_time_factor = (time - last_progress_time_) / wall_elapsed;
  if (std::isfinite(end_time_)) {
    ROS_INFO("cart_sim: t = %.3f s of %.3f s (%.1f %%), real-time factor %.1f", time, end_time_,
             100.0 * (time - start_time) / (end_time_ - start_time), real_time_factor);
  } else {
    ROS_INFO("cart_sim: t = %.3f s (until shutdown), real-time factor %.1f", time, real_time_factor);
  }
  last_progress_wall_ = now;
  last_progress_time_ = time;
}

}  // namespace birkhoff_cart
