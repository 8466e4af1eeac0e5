// cart_sim's publish instant (see cart_sim_node.h): the accuracy guard judged, then the state
// published and recorded (InstantPublisher), and /diagnostics when it is due.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include "birkhoff_cart/core/node_logic/instant_schedule.h"

namespace birkhoff_cart {

void CartSimNode::publish_instant() {
  const double wall_time_per_step = work_.end_period();  // [s]
  const OdometryEstimate* estimate = odometry_sensor_ ? &odometry_sensor_->read(simulation_->state()) : nullptr;
  // The accuracy guard is judged here, once per instant, before the messages are filled from it.
  const Diagnostics diagnostics = simulation_->diagnostics();
  accuracy_guard_.check(simulation_->state().time, diagnostics, simulation_->statistics());
  publisher_->publish(*simulation_, diagnostics, accuracy_guard_, wall_time_per_step, estimate,
                      record_ ? &*record_ : nullptr);
  if (pass_due_instants(simulation_->scene().initial_state.time, parameters_.diagnostic_period, simulation_->state().time,
                        0.5 * simulation_->step_size(), next_diagnostic_index_)) {
    reports_->publish_diagnostics();
  }
}

}  // namespace birkhoff_cart
