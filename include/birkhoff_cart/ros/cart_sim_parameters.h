// Every private parameter of cart_sim, read and validated in one place (robot_localization's
// loadParams habit). Each is documented in docs/ros_interface.md, "ROS interface" (meaning, unit, default).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/ros/conversions.h"

namespace birkhoff_cart {

/// Every private parameter of cart_sim, with its default (docs/ros_interface.md, "ROS interface").
struct CartSimParameters {
  std::string scene_path;                    ///< ~scene: scene YAML (required)
  std::string integrator;                    ///< ~integrator: registry name; "" = the scene's
  double step_size = 0.0;                    ///< ~step_size: h [s]; 0 = the scene's (under a step control: the output step)
  std::string step_control;                  ///< ~step_control: fixed, reversible or adaptive; "" = the scene's
  double position_tolerance = 0.0;           ///< ~position_tolerance: [m] at the end of the run, under a step control; 0 = the scene's
  double publish_rate = 100.0;               ///< ~publish_rate: [Hz of scene time]
  bool fast = false;                         ///< ~fast: lockstep as fast as possible (true) or real time
  double real_time_factor = 0.0;             ///< ~real_time_factor: [-]; 0 = unlimited (fast) / 1 (real time)
  double duration = -1.0;                    ///< ~duration: [s]; < 0 = the scene's; 0 = until shutdown
  double command_timeout = 0.5;              ///< ~command_timeout: watchdog silence [s of scene time]; 0 = off
  double max_steering_torque = 100.0;        ///< ~max_steering_torque: clamp [N·m]
  double max_drive_torque = 200.0;           ///< ~max_drive_torque: clamp [N·m]
  bool lockstep = false;                     ///< ~lockstep: wait for the controllers at every publish instant
  std::vector<std::string> lockstep_topics;  ///< ~lockstep_topics: topics to wait for; default: every command topic the scene takes
  bool lockstep_topics_given = false;        ///< ~lockstep_topics was set (even to [])
  double lockstep_timeout = 5.0;             ///< ~lockstep_timeout: wait at most [s of wall time], then go on with a warning
  std::string bag_path;                      ///< ~bag_path: record here; "" = no record
  bool record_wall_time = true;              ///< ~record_wall_time: false records integration_error.wall_time_per_step as 0 (bit-identical bags)
  std::string bag_compression = "lz4";       ///< ~bag_compression: lz4, bz2 or none
  std::uint64_t min_free_disk_space = 16u << 20;  ///< ~min_free_disk_space: refuse to record below [bytes]; 0 = no check
  std::string summary_path;                  ///< ~summary_path: also write the final summary here; "" = no file
  std::string frame_prefix;                  ///< ~frame_prefix: before every frame and joint name ("cart1/")
  ros_conversions::FrameNames frames;        ///< ~frame_prefix + ~odom_frame, ~base_frame, ~ground_truth_frame; ~world_frame
  ros_conversions::OdometryCovariance odometry_covariance;  ///< ~pose/twist_covariance_diagonal
  bool publish_tf = true;                    ///< ~publish_tf: odom → base_link on /tf
  bool publish_world_tf = true;              ///< ~publish_world_tf: the identity ~world_frame → odom on /tf_static
  bool publish_clock = true;                 ///< ~publish_clock: the node drives /clock
  bool follow_clock = false;                 ///< ~follow_clock: step only up to another node's /clock
  bool start_paused = false;                 ///< ~start_paused: wait for ~pause(false) before stepping
  double diagnostic_period = 1.0;            ///< ~diagnostic_period: /diagnostics every [s of scene time]
  std::vector<std::string> events;           ///< ~events: FIELD=VALUE[,rising|falling][,terminal] each (docs/events.md)
  // The accuracy guard's limits (~accuracy/<quantity> and the residual thresholds mapped onto it)
  // are read by ros_accuracy::load_requirements.
};

/// Every private parameter cart_sim reads, relative to its namespace ("accuracy/" covers the
/// accuracy guard's limits): a parameter on the master outside this list is reported as a typo.
const std::vector<std::string>& cart_sim_parameter_names();

/// Reads and validates every private parameter. Throws std::invalid_argument naming the first bad one.
CartSimParameters load_parameters(const ros::NodeHandle& private_node);

/// The integrator settings the parameters override (~integrator, ~step_size, ~step_control,
/// ~position_tolerance), each when given. Throws std::invalid_argument for a position tolerance
/// asked of a run at fixed steps (no control would hold it).
void apply_integrator_overrides(const CartSimParameters& parameters, IntegratorSettings& settings);

/// `value` [s] with 10 significant digits, for log lines and service answers.
std::string format_seconds(double value);

}  // namespace birkhoff_cart
