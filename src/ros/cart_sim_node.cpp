// The ROS wrapper around a core Simulation (see cart_sim_node.h). It never computes physics: the
// state, the diagnostics and the rates all come from the core.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include <ros/callback_queue.h>
#include <rosgraph_msgs/Clock.h>

#include "birkhoff_cart/core/scene.h"

namespace birkhoff_cart {
namespace {

std::atomic<bool> g_shutdown_signal{false};

extern "C" void on_shutdown_signal(int /*signal*/) { g_shutdown_signal.store(true); }

template <class T>
T read_parameter(const ros::NodeHandle& node, const std::string& name, const T& fallback) {
  T value;
  if (node.getParam(name, value)) return value;
  if (node.hasParam(name)) {
    throw std::invalid_argument("parameter " + node.resolveName(name) + " has the wrong type");
  }
  return fallback;
}

// Doubles may be written as integers on the parameter server (publish_rate: 100).
double read_double(const ros::NodeHandle& node, const std::string& name, double fallback) {
  XmlRpc::XmlRpcValue value;
  if (!node.getParam(name, value)) return fallback;
  if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(value);
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(value);
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
    // roslaunch <param value="..."/> without a type may arrive as a string ("1e-3", "-1").
    const std::string text = static_cast<std::string>(value);
    try {
      std::size_t used = 0;
      const double parsed = std::stod(text, &used);
      if (used == text.size()) return parsed;
    } catch (const std::exception&) {
    }
  }
  throw std::invalid_argument("parameter " + node.resolveName(name) + " must be a number");
}

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument(message);
}

std::string format_seconds(double value) {
  std::ostringstream text;
  text << std::setprecision(10) << value;
  return text.str();
}

// One schedule of instants start + k·period [s], k = index, index + 1, ...: advances `index` past
// every instant at or before `time` + `margin` [s] (half a step, so round-off in t does not move an
// instant to the next step). True when at least one instant was passed.
bool pass_due_instants(double start, double period, double time, double margin, std::uint64_t& index) {
  bool passed = false;
  while (start + static_cast<double>(index) * period <= time + margin) {
    passed = true;
    ++index;
  }
  return passed;
}

}  // namespace

void install_shutdown_signal_handlers() {
  std::signal(SIGINT, on_shutdown_signal);
  std::signal(SIGTERM, on_shutdown_signal);
}

bool shutdown_signal_received() { return g_shutdown_signal.load(); }

CartSimParameters load_parameters(const ros::NodeHandle& private_node) {
  CartSimParameters parameters;
  const ros::NodeHandle& p = private_node;
  parameters.scene_path = read_parameter<std::string>(p, "scene", "");
  require(!parameters.scene_path.empty(), "parameter " + p.resolveName("scene") + " (scene YAML path) is required");
  parameters.integrator = read_parameter<std::string>(p, "integrator", parameters.integrator);
  parameters.step_size = read_double(p, "step_size", parameters.step_size);
  require(std::isfinite(parameters.step_size) && parameters.step_size >= 0.0,
          "~step_size must be >= 0 s (0 = the scene's)");
  parameters.publish_rate = read_double(p, "publish_rate", parameters.publish_rate);
  require(std::isfinite(parameters.publish_rate) && parameters.publish_rate > 0.0, "~publish_rate must be > 0 Hz");
  parameters.fast = read_parameter<bool>(p, "fast", parameters.fast);
  parameters.real_time_factor = read_double(p, "real_time_factor", parameters.real_time_factor);
  require(std::isfinite(parameters.real_time_factor) && parameters.real_time_factor >= 0.0,
          "~real_time_factor must be >= 0 (0 = unlimited in fast mode, 1 in real-time mode)");
  parameters.duration = read_double(p, "duration", parameters.duration);
  require(!std::isnan(parameters.duration), "~duration must be a number of seconds");
  parameters.command_timeout = read_double(p, "command_timeout", parameters.command_timeout);
  require(std::isfinite(parameters.command_timeout) && parameters.command_timeout >= 0.0,
          "~command_timeout must be >= 0 s (0 = no watchdog)");
  parameters.max_steering_torque = read_double(p, "max_steering_torque", parameters.max_steering_torque);
  require(std::isfinite(parameters.max_steering_torque) && parameters.max_steering_torque > 0.0,
          "~max_steering_torque must be > 0 N·m");
  parameters.max_drive_torque = read_double(p, "max_drive_torque", parameters.max_drive_torque);
  require(std::isfinite(parameters.max_drive_torque) && parameters.max_drive_torque > 0.0,
          "~max_drive_torque must be > 0 N·m");
  parameters.bag_path = read_parameter<std::string>(p, "bag_path", parameters.bag_path);
  parameters.bag_compression = read_parameter<std::string>(p, "bag_compression", parameters.bag_compression);
  BagRecorder::parse_compression(parameters.bag_compression);  // throws naming the bad value
  // [bytes]; read as a number so sizes beyond a 32-bit XmlRpc int (2 GiB) can be given as 1.6e10.
  const double min_free_disk_space =
      read_double(p, "min_free_disk_space", static_cast<double>(parameters.min_free_disk_space));
  require(std::isfinite(min_free_disk_space) && min_free_disk_space >= 0.0 && min_free_disk_space < 1.8e19,
          "~min_free_disk_space must be >= 0 bytes (0 = no check)");
  parameters.min_free_disk_space = static_cast<std::uint64_t>(min_free_disk_space);
  parameters.summary_path = read_parameter<std::string>(p, "summary_path", parameters.summary_path);
  parameters.frames.odom = read_parameter<std::string>(p, "odom_frame", parameters.frames.odom);
  parameters.frames.base_link = read_parameter<std::string>(p, "base_frame", parameters.frames.base_link);
  parameters.publish_tf = read_parameter<bool>(p, "publish_tf", parameters.publish_tf);
  parameters.publish_clock = read_parameter<bool>(p, "publish_clock", parameters.publish_clock);
  parameters.start_paused = read_parameter<bool>(p, "start_paused", parameters.start_paused);
  parameters.diagnostic_period = read_double(p, "diagnostic_period", parameters.diagnostic_period);
  require(std::isfinite(parameters.diagnostic_period) && parameters.diagnostic_period > 0.0,
          "~diagnostic_period must be > 0 s");
  parameters.energy_residual_warn = read_double(p, "energy_residual_warn", parameters.energy_residual_warn);
  parameters.energy_residual_error = read_double(p, "energy_residual_error", parameters.energy_residual_error);
  parameters.p2_residual_warn = read_double(p, "p2_residual_warn", parameters.p2_residual_warn);
  parameters.p2_residual_error = read_double(p, "p2_residual_error", parameters.p2_residual_error);
  parameters.constraint_residual_warn = read_double(p, "constraint_residual_warn", parameters.constraint_residual_warn);
  parameters.constraint_residual_error =
      read_double(p, "constraint_residual_error", parameters.constraint_residual_error);
  require(parameters.energy_residual_warn > 0.0 && parameters.energy_residual_warn <= parameters.energy_residual_error,
          "~energy_residual_warn must be > 0 and <= ~energy_residual_error [J]");
  require(parameters.p2_residual_warn > 0.0 && parameters.p2_residual_warn <= parameters.p2_residual_error,
          "~p2_residual_warn must be > 0 and <= ~p2_residual_error [N·m·s]");
  require(parameters.constraint_residual_warn > 0.0 &&
              parameters.constraint_residual_warn <= parameters.constraint_residual_error,
          "~constraint_residual_warn must be > 0 and <= ~constraint_residual_error [m/s]");
  return parameters;
}

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

void CartSimNode::publish_clock(double time) {
  if (!parameters_.publish_clock) return;
  rosgraph_msgs::Clock clock;
  clock.clock = ros_conversions::to_ros_time(time);
  clock_publisher_.publish(clock);
}

void CartSimNode::publish_instant() {
  const CartState& state = simulation_->state();
  const CartModel& model = simulation_->model();
  const nav_msgs::Odometry odometry = ros_conversions::to_odometry(state, model, parameters_.frames);
  const sensor_msgs::JointState joints =
      ros_conversions::to_joint_state(state, model, ros_conversions::actuator_efforts(*simulation_));
  last_wall_time_per_step_ = period_steps_ > 0 ? period_stepping_wall_time_ / static_cast<double>(period_steps_) : 0.0;
  period_stepping_wall_time_ = 0.0;
  period_steps_ = 0;
  const IntegrationError error = ros_conversions::to_integration_error(
      state, simulation_->diagnostics(), simulation_->statistics(), simulation_->integrator_name(),
      simulation_->step_size(), last_wall_time_per_step_);

  odometry_publisher_.publish(odometry);
  joint_state_publisher_.publish(joints);
  integration_error_publisher_.publish(error);
  if (transform_broadcaster_ && odometry.header.stamp != last_transform_stamp_) {
    transform_broadcaster_->sendTransform(ros_conversions::to_transform(state, model, parameters_.frames));
    last_transform_stamp_ = odometry.header.stamp;
  }
  ++published_instants_;
  if (recorder_ && !record_failure_) {
    try {
      recorder_->write(integration_error_publisher_.getTopic(), error.header.stamp, error);
      recorder_->write(odometry_publisher_.getTopic(), odometry.header.stamp, odometry);
      recorder_->write(joint_state_publisher_.getTopic(), joints.header.stamp, joints);
    } catch (const std::exception& failure) {
      record_failure_ = failure.what();
    }
  }
  if (pass_due_instants(simulation_->scene().initial_state.time, parameters_.diagnostic_period, state.time,
                        0.5 * simulation_->step_size(), next_diagnostic_index_)) {
    diagnostic_updater_->force_update();
  }
}

void CartSimNode::produce_diagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const Diagnostics diagnostics = simulation_->diagnostics();
  const double wall_elapsed = (ros::WallTime::now() - run_start_wall_).toSec();
  const double real_time_factor = wall_elapsed > 0.0 ? simulated_time_ / wall_elapsed : 0.0;

  struct Check {
    const char* name;
    double value;
    double warn;
    double error;
  };
  const Check checks[] = {
      {"energy-balance residual", std::abs(diagnostics.energy_balance_residual), parameters_.energy_residual_warn,
       parameters_.energy_residual_error},
      {"p2-balance residual", std::abs(diagnostics.p2_balance_residual), parameters_.p2_residual_warn,
       parameters_.p2_residual_error},
      {"constraint residual", diagnostics.max_constraint_residual, parameters_.constraint_residual_warn,
       parameters_.constraint_residual_error},
  };
  unsigned char level = diagnostic_msgs::DiagnosticStatus::OK;
  std::string message;
  for (const Check& check : checks) {
    unsigned char check_level = diagnostic_msgs::DiagnosticStatus::OK;
    if (!(check.value < check.error)) {  // NaN counts as an error
      check_level = diagnostic_msgs::DiagnosticStatus::ERROR;
    } else if (check.value >= check.warn) {
      check_level = diagnostic_msgs::DiagnosticStatus::WARN;
    }
    if (check_level != diagnostic_msgs::DiagnosticStatus::OK) {
      message += std::string(message.empty() ? "" : "; ") + check.name +
                 (check_level == diagnostic_msgs::DiagnosticStatus::ERROR ? " above error threshold"
                                                                           : " above warning threshold");
    }
    level = std::max(level, check_level);
  }
  const std::uint64_t rejections = (steering_channel_ ? steering_channel_->rejected() : 0) +
                                   (drive_channel_ ? drive_channel_->rejected() : 0);
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
  status.add("scene", simulation_->scene().name);
  status.add("integrator", simulation_->integrator_name());
  status.add("step size [s]", simulation_->step_size());
  status.add("scene time [s]", simulation_->state().time);
  status.add("steps taken", simulation_->statistics().steps);
  status.add("paused", paused_);
  status.add("real-time factor [-]", real_time_factor);
  status.add("step cost [s]", last_wall_time_per_step_);
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
  add_channel("steering_torque", steering_channel_);
  add_channel("drive_torque", drive_channel_);
}

void CartSimNode::receive_command(CommandChannel& channel, const std::string& topic,
                                  const std_msgs::Float64& message) {
  const double time = simulation_->state().time;
  const CommandChannel::Outcome outcome = channel.receive(message.data, time);
  if (outcome == CommandChannel::Outcome::kRejected) {
    ROS_ERROR_THROTTLE(1.0, "cart_sim: rejected non-finite %s command (%g) at t = %.6g s (%lu rejected so far)",
                       topic.c_str(), message.data, time, static_cast<unsigned long>(channel.rejected()));
  } else if (outcome == CommandChannel::Outcome::kClamped) {
    ROS_WARN_THROTTLE(1.0, "cart_sim: %s command %g clamped to %g N·m", topic.c_str(), message.data,
                      channel.torque());
  }
  if (recorder_ && !record_failure_) {
    try {
      recorder_->write(topic, ros_conversions::to_ros_time(std::max(time, 0.0)), message);
    } catch (const std::exception& failure) {
      record_failure_ = failure.what();
    }
  }
}

void CartSimNode::on_steering_torque(const std_msgs::Float64::ConstPtr& message) {
  if (!steering_channel_) {
    ROS_WARN_THROTTLE(5.0, "cart_sim: scene '%s' has no steering_torque effect with source 'command': "
                      "ignoring %s", simulation_->scene().name.c_str(), steering_subscriber_.getTopic().c_str());
    return;
  }
  receive_command(*steering_channel_, steering_subscriber_.getTopic(), *message);
  simulation_->set_steering_command(steering_channel_->torque());
}

void CartSimNode::on_drive_torque(const std_msgs::Float64::ConstPtr& message) {
  if (!drive_channel_) {
    ROS_WARN_THROTTLE(5.0, "cart_sim: scene '%s' has no drive_torque effect with source 'command': ignoring %s",
                      simulation_->scene().name.c_str(), drive_subscriber_.getTopic().c_str());
    return;
  }
  receive_command(*drive_channel_, drive_subscriber_.getTopic(), *message);
  simulation_->set_drive_command(drive_channel_->torque());
}

bool CartSimNode::on_reset(std_srvs::Empty::Request& /*request*/, std_srvs::Empty::Response& /*response*/) {
  simulation_->reset();
  const double start_time = simulation_->state().time;
  if (steering_channel_) {
    steering_channel_->restart(start_time);
    simulation_->set_steering_command(steering_channel_->torque());
  }
  if (drive_channel_) {
    drive_channel_->restart(start_time);
    simulation_->set_drive_command(drive_channel_->torque());
  }
  restart_schedule();
  ROS_INFO("cart_sim: reset to the scene's initial state at t = %.6g s", start_time);
  return true;
}

bool CartSimNode::on_pause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
  paused_ = request.data;
  response.success = true;
  response.message = std::string(paused_ ? "paused" : "running") + " at t = " +
                     format_seconds(simulation_->state().time) + " s";
  ROS_INFO("cart_sim: %s", response.message.c_str());
  return true;
}

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

void CartSimNode::write_summary(const std::string& outcome) {
  const CartState& state = simulation_->state();
  const Diagnostics diagnostics = simulation_->diagnostics();
  const Eigen::Vector2d rear_axle_midpoint = simulation_->model().rear_axle_midpoint(state);
  const double wall_time = (ros::WallTime::now() - run_start_wall_).toSec();
  std::ostringstream text;
  text << std::setprecision(9);
  text << "cart_sim summary: " << outcome << ". Scene '" << simulation_->scene().name << "', integrator "
       << simulation_->integrator_name() << ", h = " << simulation_->step_size() << " s, final t = " << state.time
       << " s. Final pose of base_link (rear-axle midpoint A): x = " << rear_axle_midpoint.x()
       << " m, y = " << rear_axle_midpoint.y() << " m, theta = " << state.heading
       << " rad. Energy T* = " << diagnostics.energy << " J, energy-balance residual = "
       << diagnostics.energy_balance_residual << " J, p2-balance residual = " << diagnostics.p2_balance_residual
       << " N m s, max constraint residual = " << diagnostics.max_constraint_residual << " m/s";
  if (diagnostics.has_reference) {
    text << ", reference position error = " << diagnostics.reference_position_error << " m";
  }
  text << ". Steps: " << total_steps_ << " (" << simulation_->statistics().newton_iterations_total
       << " Newton iterations since the last start), wall time " << wall_time << " s (stepping "
       << stepping_wall_time_ << " s), real-time factor " << (wall_time > 0.0 ? simulated_time_ / wall_time : 0.0)
       << ". Published instants: " << published_instants_ << ".";
  if (recorder_) {
    text << " Bag: " << recorder_->current_path() << (record_failure_ ? " (unfinished; " : " (");
    bool first = true;
    for (const auto& [topic, count] : recorder_->message_counts()) {
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
