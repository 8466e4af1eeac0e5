// Reading and validating cart_sim's private parameters (see cart_sim_parameters.h).
#include "birkhoff_cart/ros/cart_sim_parameters.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/integrator_settings.h"
#include "birkhoff_cart/ros/bag_recorder.h"
#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {
namespace {

/// What a parameter of type T must be, for a refusal.
template <class T>
const char* expected_type();
template <>
const char* expected_type<bool>() { return "a bool (true or false)"; }
template <>
const char* expected_type<std::string>() { return "a string"; }
template <>
const char* expected_type<std::vector<std::string>>() { return "a list of strings"; }

template <class T>
T read_parameter(const ros::NodeHandle& node, const std::string& name, const T& fallback) {
  T value;
  if (node.getParam(name, value)) return value;
  if (node.hasParam(name)) {
    throw std::invalid_argument("parameter " + node.resolveName(name) + " must be " + expected_type<T>() + ", got " +
                                describe_parameter_value(node, name));
  }
  return fallback;
}

/// The most publish (or diagnostic) instants per second of scene time [Hz]: the instant index k
/// stays exact in a double (2^53) over the 2^32 s of ROS time.
constexpr double kHighestInstantRate = 1e6;

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument(message);
}

// Six variances [x, y, z, roll, pitch, yaw] (ros_controllers' *_covariance_diagonal), each finite
// and >= 0 [m², rad² or (m/s)², (rad/s)²].
std::array<double, 6> read_variances(const ros::NodeHandle& node, const std::string& name,
                                     const std::array<double, 6>& fallback) {
  XmlRpc::XmlRpcValue value;
  if (!node.getParam(name, value)) return fallback;
  const std::string rule = "parameter " + node.resolveName(name) +
                           " must be a list of 6 variances >= 0 (x, y, z, roll, pitch, yaw)";
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != 6) throw std::invalid_argument(rule);
  std::array<double, 6> variances{};
  for (int i = 0; i < 6; ++i) {
    if (value[i].getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      variances[i] = static_cast<double>(value[i]);
    } else if (value[i].getType() == XmlRpc::XmlRpcValue::TypeInt) {
      variances[i] = static_cast<int>(value[i]);
    } else {
      throw std::invalid_argument(rule);
    }
    if (!std::isfinite(variances[i]) || variances[i] < 0.0) throw std::invalid_argument(rule);
  }
  return variances;
}

}  // namespace

void apply_integrator_overrides(const CartSimParameters& parameters, IntegratorSettings& settings) {
  if (!parameters.integrator.empty()) settings.name = parameters.integrator;
  if (parameters.step_size > 0.0) settings.step_size = parameters.step_size;
  if (!parameters.step_control.empty()) settings.step_control = parse_step_control(parameters.step_control);
  if (parameters.position_tolerance > 0.0) {
    if (settings.step_control == StepControl::kFixed) {
      throw std::invalid_argument("~position_tolerance " + format_seconds(parameters.position_tolerance) +
                                  " m is the position error for a step control, and the run steps at fixed steps "
                                  "(scene " + parameters.scene_path +
                                  "): give ~step_control adaptive or reversible with it, or leave it out");
    }
    settings.position_tolerance = parameters.position_tolerance;
  }
}

std::string format_seconds(double value) {
  std::ostringstream text;
  text << std::setprecision(10) << value;
  return text.str();
}

const std::vector<std::string>& cart_sim_parameter_names() {
  static const std::vector<std::string> names = {
      "scene", "integrator", "step_size", "step_control", "position_tolerance", "publish_rate", "fast", "real_time_factor", "duration", "command_timeout",
      "max_steering_torque", "max_drive_torque", "lockstep", "lockstep_topics", "lockstep_timeout", "bag_path",
      "record_wall_time", "bag_compression", "min_free_disk_space", "summary_path", "frame_prefix", "odom_frame",
      "base_frame", "world_frame", "ground_truth_frame", "publish_world_tf", "pose_covariance_diagonal", "twist_covariance_diagonal", "publish_tf", "publish_clock",
      "follow_clock", "start_paused", "diagnostic_period", "energy_residual_warn", "energy_residual_error",
      "p2_residual_warn", "p2_residual_error", "constraint_residual_warn", "constraint_residual_error", "end_launch",
      "accuracy/",
      // dynamic_reconfigure's own copies (cfg/CartSim.cfg), left on the master by an earlier run
      "energy_balance_relative_warn", "energy_balance_relative_error", "p2_balance_warn", "p2_balance_error",
      "constraint_warn", "constraint_error", "estimated_error_warn", "estimated_error_error", "energy_balance_warn",
      "energy_balance_error"};
  return names;
}

CartSimParameters load_parameters(const ros::NodeHandle& private_node) {
  CartSimParameters parameters;
  const ros::NodeHandle& p = private_node;
  parameters.scene_path = read_parameter<std::string>(p, "scene", "");
  require(!parameters.scene_path.empty(), "parameter " + p.resolveName("scene") + " (scene YAML path) is required");
  parameters.integrator = read_parameter<std::string>(p, "integrator", parameters.integrator);
  parameters.step_size = read_double_parameter(p, "step_size", parameters.step_size);
  require(std::isfinite(parameters.step_size) && parameters.step_size >= 0.0,
          "~step_size must be >= 0 s (0 = the scene's)");
  parameters.step_control = read_parameter<std::string>(p, "step_control", parameters.step_control);
  if (!parameters.step_control.empty()) {
    try {
      parse_step_control(parameters.step_control);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument("~step_control: " + std::string(error.what()));
    }
  }
  parameters.position_tolerance = read_double_parameter(p, "position_tolerance", parameters.position_tolerance);
  require(std::isfinite(parameters.position_tolerance) && parameters.position_tolerance >= 0.0,
          "~position_tolerance must be >= 0 m (0 = the scene's), got " + format_seconds(parameters.position_tolerance));
  parameters.publish_rate = read_double_parameter(p, "publish_rate", parameters.publish_rate);
  // An instant's index k (t0 + k/rate) stays exact in a double over ROS time's 2^32 s up to 2^21 Hz.
  require(std::isfinite(parameters.publish_rate) && parameters.publish_rate > 0.0 &&
              parameters.publish_rate <= kHighestInstantRate,
          "~publish_rate must be > 0 and <= 1e6 Hz, got " + format_seconds(parameters.publish_rate));
  parameters.fast = read_parameter<bool>(p, "fast", parameters.fast);
  parameters.real_time_factor = read_double_parameter(p, "real_time_factor", parameters.real_time_factor);
  require(std::isfinite(parameters.real_time_factor) && parameters.real_time_factor >= 0.0,
          "~real_time_factor must be >= 0 (0 = unlimited in fast mode, 1 in real-time mode)");
  parameters.duration = read_double_parameter(p, "duration", parameters.duration);
  require(!std::isnan(parameters.duration), "~duration must be a number of seconds");
  parameters.command_timeout = read_double_parameter(p, "command_timeout", parameters.command_timeout);
  require(std::isfinite(parameters.command_timeout) && parameters.command_timeout >= 0.0,
          "~command_timeout must be >= 0 s (0 = no watchdog)");
  parameters.max_steering_torque = read_double_parameter(p, "max_steering_torque", parameters.max_steering_torque);
  require(std::isfinite(parameters.max_steering_torque) && parameters.max_steering_torque > 0.0,
          "~max_steering_torque must be > 0 N m");
  parameters.max_drive_torque = read_double_parameter(p, "max_drive_torque", parameters.max_drive_torque);
  require(std::isfinite(parameters.max_drive_torque) && parameters.max_drive_torque > 0.0,
          "~max_drive_torque must be > 0 N m");
  parameters.lockstep = read_parameter<bool>(p, "lockstep", parameters.lockstep);
  parameters.lockstep_topics_given = p.hasParam("lockstep_topics");
  parameters.lockstep_topics = read_parameter<std::vector<std::string>>(p, "lockstep_topics", parameters.lockstep_topics);
  for (const std::string& topic : parameters.lockstep_topics) {
    require(topic == "steering_torque" || topic == "drive_torque",
            "~lockstep_topics may hold only steering_torque and drive_torque, got '" + topic + "'");
  }
  parameters.lockstep_timeout = read_double_parameter(p, "lockstep_timeout", parameters.lockstep_timeout);
  require(std::isfinite(parameters.lockstep_timeout) && parameters.lockstep_timeout > 0.0,
          "~lockstep_timeout must be > 0 s of wall time");
  parameters.bag_path = read_parameter<std::string>(p, "bag_path", parameters.bag_path);
  parameters.record_wall_time = read_parameter<bool>(p, "record_wall_time", parameters.record_wall_time);
  parameters.bag_compression = read_parameter<std::string>(p, "bag_compression", parameters.bag_compression);
  BagRecorder::parse_compression(parameters.bag_compression);  // throws naming the bad value
  // [bytes]; read as a number so sizes beyond a 32-bit XmlRpc int (2 GiB) can be given as 1.6e10.
  const double min_free_disk_space =
      read_double_parameter(p, "min_free_disk_space", static_cast<double>(parameters.min_free_disk_space));
  require(std::isfinite(min_free_disk_space) && min_free_disk_space >= 0.0 && min_free_disk_space < 1.8e19,
          "~min_free_disk_space must be >= 0 bytes (0 = no check)");
  parameters.min_free_disk_space = static_cast<std::uint64_t>(min_free_disk_space);
  parameters.summary_path = read_parameter<std::string>(p, "summary_path", parameters.summary_path);
  parameters.frame_prefix = read_parameter<std::string>(p, "frame_prefix", parameters.frame_prefix);
  parameters.frames = ros_conversions::prefixed_frames(
      parameters.frame_prefix, read_parameter<std::string>(p, "odom_frame", parameters.frames.odom),
      read_parameter<std::string>(p, "base_frame", parameters.frames.base_link),
      read_parameter<std::string>(p, "ground_truth_frame", parameters.frames.ground_truth));
  require(parameters.frames.odom != parameters.frames.base_link, "~odom_frame and ~base_frame must differ");
  require(parameters.frames.ground_truth != parameters.frames.odom &&
              parameters.frames.ground_truth != parameters.frames.base_link,
          "~ground_truth_frame must differ from the odom and base frames (one frame pair, one source)");
  parameters.frames.world = read_parameter<std::string>(p, "world_frame", parameters.frames.world);
  require(!parameters.frames.world.empty() && parameters.frames.world != parameters.frames.odom &&
              parameters.frames.world != parameters.frames.base_link &&
              parameters.frames.world != parameters.frames.ground_truth,
          "~world_frame must be a frame name other than the odom, base and ground truth frames");
  parameters.publish_world_tf = read_parameter<bool>(p, "publish_world_tf", parameters.publish_world_tf);
  parameters.odometry_covariance.pose_diagonal =
      read_variances(p, "pose_covariance_diagonal", parameters.odometry_covariance.pose_diagonal);
  parameters.odometry_covariance.twist_diagonal =
      read_variances(p, "twist_covariance_diagonal", parameters.odometry_covariance.twist_diagonal);
  parameters.publish_tf = read_parameter<bool>(p, "publish_tf", parameters.publish_tf);
  parameters.publish_clock = read_parameter<bool>(p, "publish_clock", parameters.publish_clock);
  parameters.follow_clock = read_parameter<bool>(p, "follow_clock", parameters.follow_clock);
  require(!(parameters.follow_clock && parameters.publish_clock),
          "~follow_clock needs ~publish_clock false: a node cannot follow the clock it drives itself");
  parameters.start_paused = read_parameter<bool>(p, "start_paused", parameters.start_paused);
  parameters.diagnostic_period = read_double_parameter(p, "diagnostic_period", parameters.diagnostic_period);
  require(std::isfinite(parameters.diagnostic_period) && parameters.diagnostic_period >= 1.0 / kHighestInstantRate,
          "~diagnostic_period must be >= 1e-6 s, got " + format_seconds(parameters.diagnostic_period));
  return parameters;
}
}  // namespace birkhoff_cart
