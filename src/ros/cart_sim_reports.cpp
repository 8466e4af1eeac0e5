// CartSimReports (cart_sim_reports.h).
#include "birkhoff_cart/ros/cart_sim_reports.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

#include <diagnostic_msgs/DiagnosticArray.h>

#include "birkhoff_cart/core/run/accuracy_floors.h"
#include "birkhoff_cart/core/run/run_summary.h"
#include "birkhoff_cart/ros/accuracy_reporting.h"

namespace birkhoff_cart {
namespace {

/// The shortest decimal text that reads back as exactly `value` (t0 + T = 5.6960000000005, not 5.696).
std::string exact_text(double value) {
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace

CartSimReports::CartSimReports(const RunView& run, ros::NodeHandle& node, ros::NodeHandle& private_node)
    : run_(run), updater_(node, private_node) {
  updater_.setHardwareID("birkhoff_cart/" + run_.simulation.scene().name);
  updater_.add("simulation", this, &CartSimReports::produce_diagnostics);
  diagnostics_listeners_ = node.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 1);
}

void CartSimReports::log_start() const {
  const StepControl control = run_.simulation.scene().integrator.step_control;
  const std::string step_control = control == StepControl::kFixed
                                       ? ""
                                       : std::string(" (") + to_string(control) + " step control for " +
                                             format_seconds(run_.simulation.scene().integrator.position_tolerance) +
                                             " m; h is the output step)";
  ROS_INFO("cart_sim: scene '%s' (%s), integrator %s, h = %g s%s, %s mode%s, publish %g Hz, end t = %s s, frames %s -> "
           "%s, %s%s%s",
           run_.simulation.scene().name.c_str(), run_.parameters.scene_path.c_str(), run_.simulation.integrator_name().c_str(),
           run_.simulation.step_size(), step_control.c_str(), run_.parameters.fast ? "fast" : "real-time", run_.parameters.lockstep ? ", lockstep" : "",
           run_.parameters.publish_rate, format_seconds(run_.timeline.end_time()).c_str(), run_.parameters.frames.odom.c_str(),
           run_.parameters.frames.base_link.c_str(),
           run_.parameters.publish_clock ? "publishing /clock"
                                     : (run_.parameters.follow_clock ? "following /clock" : "not publishing /clock"),
           run_.record ? ", recording to " : "", run_.record ? run_.record->bag().path().c_str() : "");
}

void CartSimReports::publish_diagnostics() {
  // Without a subscriber roscpp drops the status, so it is not built (some 30 µs: forty values
  // turned into text, once per ~diagnostic_period). The rejections it would have reported count as
  // reported, so every status that is sent says what it said before.
  if (!diagnostics_listened()) {
    rejections_seen_ = run_.commands.rejected();
    return;
  }
  updater_.force_update();
}

void CartSimReports::produce_diagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const Diagnostics diagnostics = run_.simulation.diagnostics();
  const double real_time_factor = run_.work.real_time_factor(RunWorkMeter::Clock::now());

  // One threshold system: the level is the accuracy guard's (ros_accuracy::report below), raised
  // by rejected commands and a failed step.
  unsigned char level = diagnostic_msgs::DiagnosticStatus::OK;
  std::string message;
  const std::uint64_t rejections = run_.commands.rejected();
  if (rejections > rejections_seen_) {
    level = std::max<unsigned char>(level, diagnostic_msgs::DiagnosticStatus::WARN);
    message += std::string(message.empty() ? "" : "; ") + "non-finite commands rejected";
    rejections_seen_ = rejections;
  }
  if (run_.step_failure) {
    level = diagnostic_msgs::DiagnosticStatus::ERROR;
    message = "step failed: " + *run_.step_failure;
  }
  status.summary(level, message.empty() ? "integration healthy" : message);
  ros_accuracy::report(status, run_.guard, run_.simulation.statistics(), run_.simulation.integrator_name());
  status.add("scene", run_.simulation.scene().name);
  status.add("integrator", run_.simulation.integrator_name());
  status.add("step size [s]", run_.simulation.step_size());
  status.add("scene time [s]", run_.simulation.state().time);
  status.add("steps taken", run_.simulation.statistics().steps);
  status.add("paused", run_.paused);
  status.add("real-time factor [-]", real_time_factor);
  status.add("step cost [s]", run_.work.last_wall_time_per_step());
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
  add_channel("steering_torque", run_.commands.steering());
  add_channel("drive_torque", run_.commands.drive());
  // The actuators' state (docs/actuators.md): what was commanded, what the cart receives.
  const Simulation::ActuatorStatus actuators = run_.simulation.actuator_status();
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

void CartSimReports::report_progress() {
  const std::optional<double> real_time_factor = run_.work.progress(RunWorkMeter::Clock::now(), run_.simulation.state().time);
  if (!real_time_factor) return;
  const double time = run_.simulation.state().time;
  const double start_time = run_.simulation.scene().initial_state.time;
  const double end_time = run_.timeline.end_time();
  if (std::isfinite(end_time)) {
    ROS_INFO("cart_sim: t = %.3f s of %.3f s (%.1f %%), real-time factor %.1f", time, end_time,
             100.0 * (time - start_time) / (end_time - start_time), *real_time_factor);
  } else {
    ROS_INFO("cart_sim: t = %.3f s (until shutdown), real-time factor %.1f", time, *real_time_factor);
  }
}


std::string CartSimReports::report_stop(const std::string& outcome,
                                        const std::optional<std::string>& internal_error) {
  std::string result = outcome;
  const double time = run_.simulation.state().time;  // [s]
  if (run_.step_failure) {
    ROS_ERROR("cart_sim: step failed at t = %.9g s: %s", time, run_.step_failure->c_str());
    result = "step failure: " + *run_.step_failure;
    publish_diagnostics();
  }
  if (internal_error) {
    ROS_FATAL("cart_sim: stopped at t = %.9g s by an unexpected error: %s", time, internal_error->c_str());
    result = "internal error: " + *internal_error;
  }
  return result;
}

void CartSimReports::write_summary(const std::string& outcome) {
  const CartState& state = run_.simulation.state();
  const Diagnostics diagnostics = run_.simulation.diagnostics();
  const Eigen::Vector2d rear_axle_midpoint = run_.simulation.model().rear_axle_midpoint(state);
  // One clock reading for the wall time and the real-time factor, so the summary's numbers agree
  // with each other (two readings drifted apart by more than 1e-3 of a short run under load).
  const RunWorkMeter::Clock::time_point now = RunWorkMeter::Clock::now();
  const double wall_time = run_.work.wall_time(now);  // [s]
  std::ostringstream text;
  text << std::setprecision(9);
  text << "cart_sim summary: " << outcome << ". Scene '" << run_.simulation.scene().name << "', integrator "
       << run_.simulation.integrator_name() << ", h = " << run_.simulation.step_size() << " s, final t = " << exact_text(state.time)
       << " s. Final pose of base_link (rear-axle midpoint A): x = " << rear_axle_midpoint.x()
       << " m, y = " << rear_axle_midpoint.y() << " m, theta = " << state.heading
       << " rad. Energy T* = " << diagnostics.energy << " J, energy-balance residual = "
       << diagnostics.energy_balance_residual << " J, p2-balance residual = " << diagnostics.p2_balance_residual
       << " N m s, max constraint residual = " << diagnostics.max_constraint_residual << " m/s";
  if (diagnostics.has_reference) {
    text << ", reference position error = " << diagnostics.reference_position_error << " m";
    // A reference judges only errors ≥ 10× its own (docs/accuracy.md §4.4).
    const double resolution = shadow_reference_resolution(run_.simulation.scene());  // [m]; 0: not estimated
    if (resolution > 0.0 && !(diagnostics.reference_position_error >= 10.0 * resolution)) {
      text << " (not resolved: the shadow reference is itself off by up to ~" << resolution
           << " m, so it judges errors above ~" << 10.0 * resolution << " m only)";
    }
  }
  text << ". Steps: " << run_.work.steps() << " (" << run_.simulation.statistics().newton_iterations_total
       << " Newton iterations since the last start), wall time " << wall_time << " s (stepping "
       << run_.work.stepping_wall_time() << " s, paused " << run_.work.paused_wall_time()
       << " s), real-time factor " << run_.work.real_time_factor(now)
       << ". Published instants: " << run_.work.published_instants() << "."
       << ros_accuracy::summary_sentence(run_.guard, run_.simulation.statistics(), run_.simulation.integrator_name());
  const std::string control = step_control_summary(run_.simulation.scene().integrator, run_.simulation.statistics());
  if (!control.empty()) {
    const bool fixed = run_.simulation.scene().integrator.step_control == StepControl::kFixed;
    text << (fixed ? " " : " Step size: the output step h; ") << control << ".";
  }
  if (run_.parameters.lockstep) text << " Lockstep timeouts: " << run_.lockstep_timeouts << ".";
  if (run_.odometry_sensor && run_.odometry_sensor->estimate().time == state.time) {  // read at the last instant
    text << " " << odometry_drift_line(*run_.odometry_sensor, state, run_.simulation.model()) << ".";
  }
  if (run_.record) {
    text << " Bag: " << run_.record->bag().current_path() << (run_.record->failure() ? " (unfinished; " : " (");
    bool first = true;
    for (const auto& [topic, count] : run_.record->bag().message_counts()) {
      text << (first ? "" : ", ") << topic << ": " << count;
      first = false;
    }
    text << ").";
  } else {
    text << " No bag recorded.";
  }
  ROS_INFO("%s", text.str().c_str());
  if (!run_.parameters.summary_path.empty()) {
    std::ofstream file(run_.parameters.summary_path);
    file << text.str() << "\n";
    if (!file) ROS_ERROR("cart_sim: cannot write the summary to %s", run_.parameters.summary_path.c_str());
  }
}

}  // namespace birkhoff_cart
