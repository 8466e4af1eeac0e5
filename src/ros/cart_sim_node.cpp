// cart_sim's construction and time loop (see cart_sim_node.h). It never computes physics: the
// state, the diagnostics and the rates all come from the core.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <cmath>
#include <limits>

#include <rosgraph_msgs/Clock.h>

#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/ros/accuracy_reporting.h"
#include "birkhoff_cart/ros/instant_schedule.h"

namespace birkhoff_cart {

CartSimNode::CartSimNode(ros::NodeHandle node, ros::NodeHandle private_node)
    : node_(node), private_node_(private_node) {
  try {
    parameters_ = load_parameters(private_node_);
  } catch (const std::exception& error) {
    throw NodeStartupError(std::string("bad parameter: ") + error.what());
  }
  Scene scene;
  try {
    scene = load_scene(parameters_.scene_path);
  } catch (const std::exception& error) {
    throw NodeStartupError(std::string("cannot load scene: ") + error.what());
  }
  if (!parameters_.integrator.empty()) scene.integrator.name = parameters_.integrator;
  if (parameters_.step_size > 0.0) scene.integrator.step_size = parameters_.step_size;
  try {
    simulation_ = std::make_unique<Simulation>(scene);
  } catch (const std::exception& error) {
    throw NodeStartupError("cannot build the simulation of " + parameters_.scene_path + ": " + error.what());
  }
  try {
    accuracy_guard_ = AccuracyGuard(ros_accuracy::load_requirements(private_node_, scene.accuracy));
  } catch (const std::exception& error) {
    throw NodeStartupError(std::string("bad parameter: ") + error.what());
  }

  const double start_time = simulation_->state().time;
  // Scene time t is ROS time t, and ROS time cannot be negative: refuse here, not at the first
  // /clock (which would end the run in std::terminate with the bag left unfinished).
  if (!(start_time >= 0.0)) {
    throw NodeStartupError("scene " + parameters_.scene_path + " starts at t = " + format_seconds(start_time) +
                           " s: cart_sim publishes scene time as ROS time, which must be >= 0");
  }
  if (parameters_.duration < 0.0) {
    end_time_ = simulation_->end_time();
  } else if (parameters_.duration == 0.0 || std::isinf(parameters_.duration)) {
    end_time_ = std::numeric_limits<double>::infinity();
  } else {
    end_time_ = start_time + parameters_.duration;
  }
  publish_period_ = 1.0 / parameters_.publish_rate;
  effective_real_time_factor_ = parameters_.real_time_factor;
  if (!parameters_.fast && effective_real_time_factor_ == 0.0) effective_real_time_factor_ = 1.0;

  if (simulation_->accepts_steering_command()) {
    steering_channel_.emplace(simulation_->steering_command(), parameters_.max_steering_torque,
                              parameters_.command_timeout, start_time);
  }
  if (simulation_->accepts_drive_command()) {
    drive_channel_.emplace(simulation_->drive_command(), parameters_.max_drive_torque, parameters_.command_timeout,
                           start_time);
  }

  // The record comes first: a node that cannot keep its record does not run at all.
  if (!parameters_.bag_path.empty()) {
    try {
      recorder_ = std::make_unique<BagRecorder>(parameters_.bag_path,
                                                BagRecorder::parse_compression(parameters_.bag_compression),
                                                parameters_.min_free_disk_space);
    } catch (const std::exception& error) {
      throw NodeStartupError(std::string("cannot record (~bag_path): ") + error.what());
    }
  }

  odometry_publisher_ = node_.advertise<nav_msgs::Odometry>("odom", 50);
  joint_state_publisher_ = node_.advertise<sensor_msgs::JointState>("joint_states", 50);
  integration_error_publisher_ = private_node_.advertise<IntegrationError>("integration_error", 50);
  if (parameters_.publish_clock) clock_publisher_ = node_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  if (parameters_.publish_tf) transform_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  // Subscriptions exist for every scene, so a command for an effect without a command source is
  // counted and reported instead of vanishing.
  steering_subscriber_ = node_.subscribe("steering_torque", 20, &CartSimNode::on_steering_torque, this);
  drive_subscriber_ = node_.subscribe("drive_torque", 20, &CartSimNode::on_drive_torque, this);
  reset_service_ = private_node_.advertiseService("reset", &CartSimNode::on_reset, this);
  pause_service_ = private_node_.advertiseService("pause", &CartSimNode::on_pause, this);

  diagnostic_updater_ = std::make_unique<diagnostic_updater::Updater>(node_, private_node_);
  diagnostic_updater_->setHardwareID("birkhoff_cart/" + simulation_->scene().name);
  diagnostic_updater_->add("simulation", this, &CartSimNode::produce_diagnostics);

  paused_ = parameters_.start_paused;
  restart_schedule();
  ROS_INFO("cart_sim: scene '%s' (%s), integrator %s, h = %g s, %s mode, publish %g Hz, end t = %s s%s%s",
           simulation_->scene().name.c_str(), parameters_.scene_path.c_str(), simulation_->integrator_name().c_str(),
           simulation_->step_size(), parameters_.fast ? "fast" : "real-time", parameters_.publish_rate,
           format_seconds(end_time_).c_str(), recorder_ ? ", recording to " : "",
           recorder_ ? parameters_.bag_path.c_str() : "");
}

CartSimNode::~CartSimNode() = default;

void CartSimNode::restart_schedule() {
  next_publish_index_ = 1;
  next_diagnostic_index_ = 1;
  clock_started_ = false;
  last_transform_stamp_ = ros::Time();
  pace_anchor_wall_ = ros::WallTime::now();
  pace_anchor_time_ = simulation_->state().time;
}

bool CartSimNode::end_reached() const {
  return simulation_->state().time + 0.5 * simulation_->step_size() > end_time_;
}

int CartSimNode::run() {
  run_start_wall_ = ros::WallTime::now();
  pace_anchor_wall_ = run_start_wall_;
  std::string outcome = "finished";
  while (true) {
    if (shutdown_signal_received() || !ros::ok()) {
      outcome = "interrupted (shutdown requested)";
      break;
    }
    if (record_failure_) break;  // a command could not be recorded (set in a callback, also while paused)
    if (paused_) {
      process_callbacks(0.02);
      pace_anchor_wall_ = ros::WallTime::now();
      pace_anchor_time_ = simulation_->state().time;
      continue;
    }
    if (end_reached()) break;
    apply_watchdogs();
    const double time_before = simulation_->state().time;
    const ros::WallTime step_start = ros::WallTime::now();
    try {
      simulation_->step();
    } catch (const StepError& error) {
      step_failure_ = error.what();
      break;
    }
    const double step_wall_time = (ros::WallTime::now() - step_start).toSec();
    stepping_wall_time_ += step_wall_time;
    period_stepping_wall_time_ += step_wall_time;
    ++period_steps_;
    ++total_steps_;
    simulated_time_ += simulation_->state().time - time_before;

    const double time = simulation_->state().time;
    const bool publish_due = pass_due_instants(simulation_->scene().initial_state.time, publish_period_, time,
                                               0.5 * simulation_->step_size(), next_publish_index_);
    if (!clock_started_ || publish_due) publish_clock(time);
    clock_started_ = true;
    if (publish_due) {
      publish_instant();
      if (record_failure_) break;
    }
    pace();
  }

  if (step_failure_) {
    ROS_ERROR("cart_sim: step failed at t = %.9g s: %s", simulation_->state().time, step_failure_->c_str());
    outcome = "step failure: " + *step_failure_;
    diagnostic_updater_->force_update();
  }
  if (record_failure_) {
    ROS_ERROR("cart_sim: bag write failed at t = %.9g s, stopping (the node does not run without its record): %s",
              simulation_->state().time, record_failure_->c_str());
  }
  if (recorder_) {
    try {
      recorder_->close();
    } catch (const std::exception& error) {
      // Keep the first cause (the failed write); the close failure follows it.
      record_failure_ = record_failure_ ? *record_failure_ + "; then " + error.what() : std::string(error.what());
    }
  }
  if (record_failure_) {
    ROS_FATAL("cart_sim: the record failed: %s", record_failure_->c_str());
    outcome = "record failure: " + *record_failure_;
  }
  write_summary(outcome);
  if (step_failure_) return kExitStepFailure;
  if (record_failure_) return kExitRecordFailure;
  return kExitFinished;
}

void CartSimNode::apply_watchdogs() {
  const double time = simulation_->state().time;
  if (steering_channel_ && steering_channel_->check_watchdog(time)) {
    simulation_->set_steering_command(steering_channel_->torque());
    ROS_WARN("cart_sim: no steering_torque command for %g s at t = %.6g s: steering torque set to 0",
             steering_channel_->timeout(), time);
  }
  if (drive_channel_ && drive_channel_->check_watchdog(time)) {
    simulation_->set_drive_command(drive_channel_->torque());
    ROS_WARN("cart_sim: no drive_torque command for %g s at t = %.6g s: drive torque set to 0",
             drive_channel_->timeout(), time);
  }
}

}  // namespace birkhoff_cart
