// Reading and validating cart_sim's private parameters (see cart_sim_parameters.h).
#include "birkhoff_cart/ros/cart_sim_parameters.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <XmlRpcValue.h>

#include <algorithm>

#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/run/state_events.h"
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

/// One private parameter of cart_sim: its name (relative to the node's namespace) and how it is read
/// into CartSimParameters, with the checks it needs on its own. A new parameter is its field in
/// CartSimParameters and one row here (and its row in docs/ros_interface.md).
struct ParameterRow {
  const char* name;
  void (*read)(const ros::NodeHandle& p, CartSimParameters& parameters);
};

using Node = const ros::NodeHandle&;
using Parameters = CartSimParameters&;

const std::vector<ParameterRow>& parameter_rows() {
  static const std::vector<ParameterRow> rows = {
      {"scene",
       [](Node p, Parameters parameters) {
         parameters.scene_path = read_parameter<std::string>(p, "scene", "");
         require(!parameters.scene_path.empty(), "parameter " + p.resolveName("scene") + " (scene YAML path) is required");
       }},
      {"integrator",
       [](Node p, Parameters parameters) {
         parameters.integrator = read_parameter<std::string>(p, "integrator", parameters.integrator);
       }},
      {"step_size",
       [](Node p, Parameters parameters) {
         parameters.step_size = read_double_parameter(p, "step_size", parameters.step_size);
         require(std::isfinite(parameters.step_size) && parameters.step_size >= 0.0,
                 "~step_size must be >= 0 s (0 = the scene's)");
       }},
      {"step_control",
       [](Node p, Parameters parameters) {
         parameters.step_control = read_parameter<std::string>(p, "step_control", parameters.step_control);
         if (parameters.step_control.empty()) return;
         try {
           parse_step_control(parameters.step_control);
         } catch (const std::invalid_argument& error) {
           throw std::invalid_argument("~step_control: " + std::string(error.what()));
         }
       }},
      {"position_tolerance",
       [](Node p, Parameters parameters) {
         parameters.position_tolerance = read_double_parameter(p, "position_tolerance", parameters.position_tolerance);
         require(std::isfinite(parameters.position_tolerance) && parameters.position_tolerance >= 0.0,
                 "~position_tolerance must be >= 0 m (0 = the scene's), got " +
                     format_seconds(parameters.position_tolerance));
       }},
      {"publish_rate",
       [](Node p, Parameters parameters) {
         parameters.publish_rate = read_double_parameter(p, "publish_rate", parameters.publish_rate);
         // An instant's index k (t0 + k/rate) stays exact in a double over ROS time's 2^32 s up to 2^21 Hz.
         require(std::isfinite(parameters.publish_rate) && parameters.publish_rate > 0.0 &&
                     parameters.publish_rate <= kHighestInstantRate,
                 "~publish_rate must be > 0 and <= 1e6 Hz, got " + format_seconds(parameters.publish_rate));
       }},
      {"fast", [](Node p, Parameters parameters) { parameters.fast = read_parameter<bool>(p, "fast", parameters.fast); }},
      {"real_time_factor",
       [](Node p, Parameters parameters) {
         parameters.real_time_factor = read_double_parameter(p, "real_time_factor", parameters.real_time_factor);
         require(std::isfinite(parameters.real_time_factor) && parameters.real_time_factor >= 0.0,
                 "~real_time_factor must be >= 0 (0 = unlimited in fast mode, 1 in real-time mode)");
       }},
      {"duration",
       [](Node p, Parameters parameters) {
         parameters.duration = read_double_parameter(p, "duration", parameters.duration);
         require(!std::isnan(parameters.duration), "~duration must be a number of seconds");
       }},
      {"command_timeout",
       [](Node p, Parameters parameters) {
         parameters.command_timeout = read_double_parameter(p, "command_timeout", parameters.command_timeout);
         require(std::isfinite(parameters.command_timeout) && parameters.command_timeout >= 0.0,
                 "~command_timeout must be >= 0 s (0 = no watchdog)");
       }},
      {"max_steering_torque",
       [](Node p, Parameters parameters) {
         parameters.max_steering_torque = read_double_parameter(p, "max_steering_torque", parameters.max_steering_torque);
         require(std::isfinite(parameters.max_steering_torque) && parameters.max_steering_torque > 0.0,
                 "~max_steering_torque must be > 0 N m");
       }},
      {"max_drive_torque",
       [](Node p, Parameters parameters) {
         parameters.max_drive_torque = read_double_parameter(p, "max_drive_torque", parameters.max_drive_torque);
         require(std::isfinite(parameters.max_drive_torque) && parameters.max_drive_torque > 0.0,
                 "~max_drive_torque must be > 0 N m");
       }},
      {"lockstep",
       [](Node p, Parameters parameters) { parameters.lockstep = read_parameter<bool>(p, "lockstep", parameters.lockstep); }},
      {"lockstep_topics",
       [](Node p, Parameters parameters) {
         parameters.lockstep_topics_given = p.hasParam("lockstep_topics");
         parameters.lockstep_topics =
             read_parameter<std::vector<std::string>>(p, "lockstep_topics", parameters.lockstep_topics);
         for (const std::string& topic : parameters.lockstep_topics) {
           require(topic == "steering_torque" || topic == "drive_torque",
                   "~lockstep_topics may hold only steering_torque and drive_torque, got '" + topic + "'");
         }
       }},
      {"lockstep_timeout",
       [](Node p, Parameters parameters) {
         parameters.lockstep_timeout = read_double_parameter(p, "lockstep_timeout", parameters.lockstep_timeout);
         require(std::isfinite(parameters.lockstep_timeout) && parameters.lockstep_timeout > 0.0,
                 "~lockstep_timeout must be > 0 s of wall time");
       }},
      {"bag_path",
       [](Node p, Parameters parameters) { parameters.bag_path = read_parameter<std::string>(p, "bag_path", parameters.bag_path); }},
      {"record_wall_time",
       [](Node p, Parameters parameters) {
         parameters.record_wall_time = read_parameter<bool>(p, "record_wall_time", parameters.record_wall_time);
       }},
      {"bag_compression",
       [](Node p, Parameters parameters) {
         parameters.bag_compression = read_parameter<std::string>(p, "bag_compression", parameters.bag_compression);
         BagRecorder::parse_compression(parameters.bag_compression);  // throws naming the bad value
       }},
      {"min_free_disk_space",
       [](Node p, Parameters parameters) {
         // [bytes]; read as a number so sizes beyond a 32-bit XmlRpc int (2 GiB) can be given as 1.6e10.
         const double bytes =
             read_double_parameter(p, "min_free_disk_space", static_cast<double>(parameters.min_free_disk_space));
         require(std::isfinite(bytes) && bytes >= 0.0 && bytes < 1.8e19,
                 "~min_free_disk_space must be >= 0 bytes (0 = no check)");
         parameters.min_free_disk_space = static_cast<std::uint64_t>(bytes);
       }},
      {"summary_path",
       [](Node p, Parameters parameters) {
         parameters.summary_path = read_parameter<std::string>(p, "summary_path", parameters.summary_path);
       }},
      // The frame names as given; check_together() puts ~frame_prefix before them.
      {"frame_prefix",
       [](Node p, Parameters parameters) {
         parameters.frame_prefix = read_parameter<std::string>(p, "frame_prefix", parameters.frame_prefix);
       }},
      {"odom_frame",
       [](Node p, Parameters parameters) {
         parameters.frames.odom = read_parameter<std::string>(p, "odom_frame", parameters.frames.odom);
       }},
      {"base_frame",
       [](Node p, Parameters parameters) {
         parameters.frames.base_link = read_parameter<std::string>(p, "base_frame", parameters.frames.base_link);
       }},
      {"ground_truth_frame",
       [](Node p, Parameters parameters) {
         parameters.frames.ground_truth =
             read_parameter<std::string>(p, "ground_truth_frame", parameters.frames.ground_truth);
       }},
      {"world_frame",
       [](Node p, Parameters parameters) {
         parameters.frames.world = read_parameter<std::string>(p, "world_frame", parameters.frames.world);
       }},
      {"publish_world_tf",
       [](Node p, Parameters parameters) {
         parameters.publish_world_tf = read_parameter<bool>(p, "publish_world_tf", parameters.publish_world_tf);
       }},
      {"pose_covariance_diagonal",
       [](Node p, Parameters parameters) {
         parameters.odometry_covariance.pose_diagonal =
             read_variances(p, "pose_covariance_diagonal", parameters.odometry_covariance.pose_diagonal);
       }},
      {"twist_covariance_diagonal",
       [](Node p, Parameters parameters) {
         parameters.odometry_covariance.twist_diagonal =
             read_variances(p, "twist_covariance_diagonal", parameters.odometry_covariance.twist_diagonal);
       }},
      {"publish_tf",
       [](Node p, Parameters parameters) { parameters.publish_tf = read_parameter<bool>(p, "publish_tf", parameters.publish_tf); }},
      {"publish_clock",
       [](Node p, Parameters parameters) {
         parameters.publish_clock = read_parameter<bool>(p, "publish_clock", parameters.publish_clock);
       }},
      {"follow_clock",
       [](Node p, Parameters parameters) {
         parameters.follow_clock = read_parameter<bool>(p, "follow_clock", parameters.follow_clock);
       }},
      {"start_paused",
       [](Node p, Parameters parameters) {
         parameters.start_paused = read_parameter<bool>(p, "start_paused", parameters.start_paused);
       }},
      {"events",
       [](Node p, Parameters parameters) {
         // A list of event texts, or one string of them separated by ';' (roslaunch's events:=...),
         // each trimmed of spaces; a blank string is none, an empty event between ';' is refused.
         XmlRpc::XmlRpcValue value;
         if (p.getParam("events", value) && value.getType() == XmlRpc::XmlRpcValue::TypeString) {
           const std::string given = static_cast<std::string>(value);
           parameters.events.clear();
           if (given.find_first_not_of(" \t") != std::string::npos) {
             std::string::size_type from = 0;
             while (from <= given.size()) {
               const std::string::size_type end = std::min(given.find(';', from), given.size());
               std::string text = given.substr(from, end - from);
               text.erase(0, text.find_first_not_of(" \t"));
               text.erase(text.find_last_not_of(" \t") + 1);
               require(!text.empty(), "parameter " + p.resolveName("events") + ": an empty event in '" + given +
                                          "' (events are separated by ';')");
               parameters.events.push_back(text);
               from = end + 1;
             }
           }
         } else {
           parameters.events = read_parameter<std::vector<std::string>>(p, "events", parameters.events);
         }
         try {
           state_field_events(parameters.events);
         } catch (const std::invalid_argument& error) {
           throw std::invalid_argument("parameter " + p.resolveName("events") + ": " + error.what());
         }
       }},
      {"diagnostic_period",
       [](Node p, Parameters parameters) {
         parameters.diagnostic_period = read_double_parameter(p, "diagnostic_period", parameters.diagnostic_period);
         require(std::isfinite(parameters.diagnostic_period) && parameters.diagnostic_period >= 1.0 / kHighestInstantRate,
                 "~diagnostic_period must be >= 1e-6 s, got " + format_seconds(parameters.diagnostic_period));
       }},
  };
  return rows;
}

/// What the rows cannot check alone: the prefixed frames apart, and the clock's two roles.
void check_together(CartSimParameters& parameters) {
  const std::string world = parameters.frames.world;  // not prefixed: carts share the world
  parameters.frames = ros_conversions::prefixed_frames(parameters.frame_prefix, parameters.frames.odom,
                                                       parameters.frames.base_link, parameters.frames.ground_truth);
  parameters.frames.world = world;
  require(parameters.frames.odom != parameters.frames.base_link, "~odom_frame and ~base_frame must differ");
  require(parameters.frames.ground_truth != parameters.frames.odom &&
              parameters.frames.ground_truth != parameters.frames.base_link,
          "~ground_truth_frame must differ from the odom and base frames (one frame pair, one source)");
  require(!parameters.frames.world.empty() && parameters.frames.world != parameters.frames.odom &&
              parameters.frames.world != parameters.frames.base_link &&
              parameters.frames.world != parameters.frames.ground_truth,
          "~world_frame must be a frame name other than the odom, base and ground truth frames");
  require(!(parameters.follow_clock && parameters.publish_clock),
          "~follow_clock needs ~publish_clock false: a node cannot follow the clock it drives itself");
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
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const ParameterRow& row : parameter_rows()) all.emplace_back(row.name);
    // Read elsewhere: ~end_launch (nodes/cart_sim.cpp); the accuracy guard's limits and the residual
    // thresholds mapped onto them (accuracy_reporting.cpp); dynamic_reconfigure's own copies
    // (cfg/CartSim.cfg), left on the master by an earlier run.
    all.insert(all.end(), {"end_launch", "accuracy/", "energy_residual_warn", "energy_residual_error",
                           "p2_residual_warn", "p2_residual_error", "constraint_residual_warn",
                           "constraint_residual_error", "energy_balance_relative_warn",
                           "energy_balance_relative_error", "p2_balance_warn", "p2_balance_error", "constraint_warn",
                           "constraint_error", "estimated_error_warn", "estimated_error_error", "energy_balance_warn",
                           "energy_balance_error"});
    return all;
  }();
  return names;
}

CartSimParameters load_parameters(const ros::NodeHandle& private_node) {
  CartSimParameters parameters;
  for (const ParameterRow& row : parameter_rows()) row.read(private_node, parameters);
  check_together(parameters);
  return parameters;
}
}  // namespace birkhoff_cart
