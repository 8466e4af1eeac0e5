// The ROS wrapper around a core Simulation (robot_localization style: the core knows nothing of
// ROS; this class only translates). Every private parameter is read once in load_parameters() and
// documented in docs/ros_interface.md, "ROS interface" (meaning, unit, default).
//
// Time: the node steps the simulation and publishes /clock itself (run with /use_sim_time true);
// message stamps are the scene's time t (scene time t is ROS time t). The first /clock is one step
// after the start (t0 + h), never 0. A run with an end is cut into steps by the rule that
// cart_simulate uses (step_schedule.h): whole steps on t0 + n h, then one landing step exactly on
// t0 + T, which is published as the run's last instant. Three ways to run (docs/ros_interface.md, "Running modes"):
//  - fast: as fast as possible (or at ~real_time_factor). Callbacks run at the first step after the
//    transport queued them (SignalingCallbackQueue's flag, one atomic load per step).
//  - real time: paced by absolute wall-clock deadlines (WallClockPacing); the node sleeps until the
//    next publish instant is due or a message arrives, then runs the steps due by then.
//  - lockstep: at every publish instant the node publishes the state and /clock, then waits until
//    every expected command topic has answered (or ~lockstep_timeout), and callbacks run only
//    there, so a closed loop through another node is the same on every run.
//
// Parts with a job of their own are classes: CommandInputs (the command topics, their watchdogs and
// the lockstep answers), StepRequests (~step on its own thread), RunRecord (the bag of each run and
// its failure), RunWorkMeter (what the run costs in wall time), InstantPublisher (the topics of a
// publish instant, /clock and tf, and what of them goes into the bag), CartSimReports (/diagnostics,
// the progress lines, the summary), PoseRequests (~set_state and initialpose), RunSettings (what
// dynamic_reconfigure may change while running).
// The member functions are defined by job: cart_sim_node.cpp (construction and the time loop),
// cart_sim_pacing.cpp (callbacks, real-time deadlines, the lockstep barrier, following /clock),
// cart_sim_publishing.cpp, cart_sim_services.cpp (~reset, ~pause), cart_sim_teleport.cpp
// (a restart of the run from a new state).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <ros/spinner.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/core/accuracy_guard.h"
#include "birkhoff_cart/SetCartState.h"
#include "birkhoff_cart/core/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/simulation.h"
#include "birkhoff_cart/ros/run_record.h"
#include "birkhoff_cart/core/node_logic/run_work_meter.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/cart_sim_reports.h"
#include "birkhoff_cart/ros/command_inputs.h"
#include "birkhoff_cart/ros/conversions.h"
#include "birkhoff_cart/ros/instant_publisher.h"
#include "birkhoff_cart/ros/pose_requests.h"
#include "birkhoff_cart/ros/run_settings.h"
#include "birkhoff_cart/ros/shutdown_signals.h"
#include "birkhoff_cart/ros/signaling_callback_queue.h"
#include "birkhoff_cart/ros/step_requests.h"
#include "birkhoff_cart/core/node_logic/wall_clock_pacing.h"

namespace birkhoff_cart {

/// Something that prevents the node from starting (bad parameter, scene, integrator or bag).
class NodeStartupError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CartSimNode {
 public:
  /// Exit codes of run().
  static constexpr int kExitFinished = 0;     ///< duration reached or shutdown requested
  static constexpr int kExitStepFailure = 1;  ///< a StepError stopped the simulation
  static constexpr int kExitStartupFailure = 2;  ///< the constructor threw NodeStartupError (main's exit)
  static constexpr int kExitRecordFailure = 3;   ///< the bag could not be written
  static constexpr int kExitInternalError = 4;   ///< an unexpected exception left the loop (bag closed)
  static constexpr int kExitForced = kForcedExitCode;        ///< a second SIGINT/SIGTERM: quick exit after a flush

  /// Loads parameters and scene, builds the simulation, opens the bag, advertises. Throws
  /// NodeStartupError with a message naming the problem.
  CartSimNode(ros::NodeHandle node, ros::NodeHandle private_node);
  ~CartSimNode();

  /// The time loop; returns one of the exit codes after closing the bag and printing the summary.
  int run();
  /// Asks run() to end as at a shutdown signal (thread-safe): the nodelet's unload.
  void request_stop() { stop_flag_ = true; }

  const Simulation& simulation() const { return *simulation_; }
  const CartSimParameters& parameters() const { return parameters_; }

 private:
  int run_loop(std::string& outcome);
  /// The record has failed (the node stops: it does not run without its record).
  bool record_failed() const;

  // cart_sim_services.cpp
  bool on_reset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool on_pause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);

  // cart_sim_teleport.cpp
  /// Restarts the run from `target` at the current time (Simulation::restart_from) and restarts the
  /// commands' hold, the accuracy guard, the schedule and the publish instants there; the bag goes
  /// on. False, with `message` naming the problem and nothing changed, when it is refused.
  bool teleport(const CartState& target, const std::string& source, std::string& message);
  /// Paused with no ~step request open: the loop waits.
  bool halted() const { return paused_ && !step_requests_->open(); }

  // cart_sim_node.cpp
  /// Plans the run in the simulation from the current state (Simulation::plan_run; construction,
  /// ~reset, a teleport: the simulation's step count is 0) and restarts the publish instants and
  /// the pacing there. The simulation then owns the schedule: at_end(), next_step_time().
  void restart_schedule();
  /// Into the bag (while it can be written): a command message at scene time `time` [s].
  void record_command(const std::string& topic, double time, const std_msgs::Float64& message);
  /// The next step of the run's schedule (watchdogs first); false when it failed (step_failure_ set).
  bool take_step();

  // cart_sim_publishing.cpp
  /// One publish instant: the guard checked, the state published and recorded, /diagnostics when due.
  void publish_instant();

  // cart_sim_pacing.cpp
  /// Runs the queued callbacks (commands, services) now.
  void process_callbacks();
  /// Real-time mode: sleeps until scene time `time` [s] is due or a message arrives; runs the
  /// callbacks of an arrival. True when `time` is due.
  bool wait_until_due(double time);
  /// Paused: waits for a message (~pause, ~reset) or 0.1 s; counts the paused wall time.
  void wait_while_paused();
  /// Lockstep: after publishing instant `time` [s], waits for every expected command topic.
  void wait_for_commands(double time);
  /// Lockstep, before the first step: waits until every expected command topic has a publisher
  /// and joint_states a subscriber (a state published before would be lost and its barrier time out).
  void wait_for_controllers();
  bool stop_requested() const;
  /// ~follow_clock: waits until the /clock another node drives reaches scene time `time` [s] (the
  /// end of the next batch of steps), so this cart's stamps are instants of that clock, never ahead.
  void wait_for_clock(double time);

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  SignalingCallbackQueue callback_queue_;  ///< every subscription and service of the node
  CartSimParameters parameters_;
  std::unique_ptr<Simulation> simulation_;
  AccuracyGuard accuracy_guard_;  ///< scene `accuracy` + ~accuracy/...; checked at every publish instant
  std::optional<CommandInputs> commands_;  ///< steering_torque, drive_torque: channels, watchdogs, lockstep answers
  std::optional<RunRecord> record_;  ///< the bag of each run; none without ~bag_path

  std::optional<InstantPublisher> publisher_;  ///< the topics of a publish instant, /clock, tf
  /// The scene's odometry sensor (docs/odometry_sensor.md); none: odom is the exact state.
  std::optional<OdometrySensor> odometry_sensor_;
  ros::Subscriber clock_subscriber_;  ///< /clock from elsewhere when ~publish_clock is false
  ros::ServiceServer reset_service_;
  ros::ServiceServer pause_service_;
  std::optional<PoseRequests> pose_requests_;  ///< ~set_state and initialpose, teleporting through teleport()
  std::unique_ptr<StepRequests> step_requests_;  ///< ~step, on a thread of its own
  std::optional<RunSettings> settings_;  ///< what dynamic_reconfigure may change while running

  double run_duration_ = 0.0;             ///< T: the run's length from its start [s]; +inf = without end
  double end_time_ = 0.0;                 ///< t0 + T, where the run stops exactly [s]; +inf = never
  double loaded_start_time_ = 0.0;        ///< the scene's t0 [s] (a teleport starts the run's rest elsewhere)
  double publish_period_ = 0.01;          ///< [s]
  WallClockPacing pacing_;
  std::uint64_t next_publish_index_ = 1;  ///< k of the next publish instant t0 + k/publish_rate
  std::uint64_t next_diagnostic_index_ = 1;
  bool clock_started_ = false;            ///< the first /clock (t0 + h) went out
  std::atomic<bool> paused_{false};  ///< read by the ~step thread
  std::atomic<bool> stop_flag_{false};  ///< request_stop()
  std::uint64_t resets_ = 0;              ///< ~reset calls served
  std::optional<std::string> step_failure_;

  std::uint64_t lockstep_timeouts_ = 0;  ///< lockstep instants that went on without every answer

  RunWorkMeter work_;  ///< wall time of the run: integration_error, diagnostics, progress, summary
  /// /diagnostics, progress lines, the summary; last, since it reads the members above.
  std::optional<CartSimReports> reports_;
};

}  // namespace birkhoff_cart
