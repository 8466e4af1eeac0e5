// cart_sim's reports: /diagnostics and the final summary (see cart_sim_node.h).
#include "birkhoff_cart/ros/cart_sim_node.h"

#include "birkhoff_cart/core/run_summary.h"
#include "birkhoff_cart/ros/accuracy_reporting.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace birkhoff_cart {
namespace {

/// The shortest decimal text that reads back as exactly `value` (t0 + T = 5.6960000000005, not 5.696).
std::string exact_text(double value) {
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace

void CartSimNode::produce_diagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const Diagnostics diagnostics = simulation_->diagnostics();
  const double real_time_factor = work_.real_time_factor(WallClockPacing::Clock::now());

  // One threshold system: the level is the accuracy guard's (ros_accuracy::report below), raised
  // by rejected commands and a failed step.
  unsigned char level = diagnostic_msgs::DiagnosticStatus::OK;
  std::string message;
  const std::uint64_t rejections = commands_->rejected();
  if (rejections > diagnostics_rejections_seen_) {
    level = std::max<unsigned char>(level, diagnostic_msgs::DiagnosticStatus::WARN);
    message += std::string(message.empty() ? "" : "; ") + "non-finite commands rejected";
    diagnostics_rejections_seen_ = rejections;
  }
  if (step_failure_) {
    level = diagnostic_msgs::DiagnosticStatus::ERROR;
    message = "step failed: " + *step_failure_;
  }
  status.summary(level, message.empty() ? "integration healthy" : message);
  ros_accuracy::report(status, accuracy_guard_, simulation_->statistics(), simulation_->integrator_name());
  status.add("scene", simulation_->scene().name);
  status.add("integrator", simulation_->integrator_name());
  status.add("step size [s]", simulation_->step_size());
  status.add("scene time [s]", simulation_->state().time);
  status.add("steps taken", simulation_->statistics().steps);
  status.add("paused", paused_);
  status.add("real-time factor [-]", real_time_factor);
  status.add("step cost [s]", work_.last_wall_time_per_step());
  status.add("energy T* [J]", diagnostics.energy);
  status.add("energy-balance residual [J]", diagnostics.energy_balance_residual);
  status.add("p2-balance residual [N m s]", diagnostics.p2_balance_residual);
  status.add("max constraint residual [m/s]", diagnostics.max_constraint_residual);
  if (diagnostics.has_reference) {
    status.add("reference position error [m]", diagnostics.reference_position_error);
    status.add("reference heading error [rad]", diagnostics.reference_heading_error);
    status.add("reference arc-length relative error [-]", diagnostics.reference_arc_length_relative_error);
  }
  const auto add_channel = [&status](const std::string& name, const std::optional<CommandChannel>& channel) {
    status.add(name + " commands received", channel ? channel->received() : 0);
    status.add(name + " commands rejected", channel ? channel->rejected() : 0);
    status.add(name + " commands clamped", channel ? channel->clamped() : 0);
    status.add(name + " command timeouts", channel ? channel->timeouts() : 0);
  };
  add_channel("steering_torque", commands_->steering());
  add_channel("drive_torque", commands_->drive());
  // The actuators' state (docs/actuators.md): what was commanded, what the cart receives.
  const Simulation::ActuatorStatus actuators = simulation_->actuator_status();
  if (actuators.steering_actuator) {
    status.add("steering actuator input [N m]", actuators.steering_input);
    status.add("steering actuator applied [N m]", actuators.steering_applied);
  }
  if (actuators.drive_actuator) {
    status.add("drive actuator input [N m]", actuators.drive_input);
    status.add("drive actuator applied [N m]", actuators.drive_applied);
  }
  if (actuators.end_stops) {
    status.add("steering end stop contact", actuators.end_stop_contact == 0 ? std::string("free")
                                            : actuators.end_stop_contact > 0 ? std::string("upper")
                                                                             : std::string("lower"));
    status.add("steering end stop events", actuators.end_stop_events);
  }
}

void CartSimNode::write_summary(const std::string& outcome) {
  const CartState& state = simulation_->state();
  const Diagnostics diagnostics = simulation_->diagnostics();
  const Eigen::Vector2d rear_axle_midpoint = simulation_->model().rear_axle_midpoint(state);
  // One clock reading for the wall time and the real-time factor, so the summary's numbers agree
  // with each other (two readings drifted apart by more than 1e-3 of a short run under load).
  const WallClockPacing::Clock::time_point now = WallClockPacing::Clock::now();
  const double wall_time = work_.wall_time(now);  // [s]
  std::ostringstream text;
  text << std::setprecision(9);
  text << "cart_sim summary: " << outcome << ". Scene '" << simulation_->scene().name << "', integrator "
       << simulation_->integrator_name() << ", h = " << simulation_->step_size() << " s, final t = " << exact_text(state.time)
       << " s. Final pose of base_link (rear-axle midpoint A): x = " << rear_axle_midpoint.x()
       << " m, y = " << rear_axle_midpoint.y() << " m, theta = " << state.heading
       << " rad. Energy T* = " << diagnostics.energy << " J, energy-balance residual = "
       << diagnostics.energy_balance_residual << " J, p2-balance residual = " << diagnostics.p2_balance_residual
       << " N m s, max constraint residual = " << diagnostics.max_constraint_residual << " m/s";
  if (diagnostics.has_reference) {
    text << ", reference position error = " << diagnostics.reference_position_error << " m";
  }
  text << ". Steps: " << work_.steps() << " (" << simulation_->statistics().newton_iterations_total
       << " Newton iterations since the last start), wall time " << wall_time << " s (stepping "
       << work_.stepping_wall_time() << " s, paused " << work_.paused_wall_time()
       << " s), real-time factor " << work_.real_time_factor(now)
       << ". Published instants: " << work_.published_instants() << "."
       << ros_accuracy::summary_sentence(accuracy_guard_, simulation_->statistics(), simulation_->integrator_name());
  const std::string control = step_control_summary(simulation_->scene().integrator, simulation_->statistics());
  if (!control.empty()) text << " Step size: the output step h; " << control << ".";
  if (parameters_.lockstep) text << " Lockstep timeouts: " << lockstep_timeouts_ << ".";
  if (odometry_sensor_ && odometry_sensor_->estimate().time == state.time) {  // read at the last instant
    text << " " << odometry_drift_line(*odometry_sensor_, state, simulation_->model()) << ".";
  }
  if (record_) {
    text << " Bag: " << record_->bag().current_path() << (record_->failure() ? " (unfinished; " : " (");
    bool first = true;
    for (const auto& [topic, count] : record_->bag().message_counts()) {
      text << (first ? "" : ", ") << topic << ": " << count;
      first = false;
    }
    text << ").";
  } else {
    text << " No bag recorded.";
  }
  ROS_INFO("%s", text.str().c_str());
  if (!parameters_.summary_path.empty()) {
    std::ofstream file(parameters_.summary_path);
    file << text.str() << "\n";
    if (!file) ROS_ERROR("cart_sim: cannot write the summary to %s", parameters_.summary_path.c_str());
  }
}

}  // namespace birkhoff_cart
