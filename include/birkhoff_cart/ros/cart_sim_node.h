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
// Parts with a job of their own are classes: GuardedRun (the core's run: the simulation and its
// accuracy guard), PublishSchedule (the publish and /diagnostics instants), RunPacing (real-time
// deadlines, pauses, a leader's /clock), LockstepBarrier (the lockstep waits), CommandInputs (the
// command topics, their watchdogs and the lockstep answers), StepRequests (~step on its own
// threads), RunRecord (the bag of each run and its failure), RunWorkMeter (what the run costs in
// wall time), RunTimeline (where the run starts and ends, and the ROS-time rules), InstantPublisher
// (the topics of a publish instant, /clock and tf, and what of them goes into the bag),
// CartSimReports (/diagnostics, the progress lines, the start line, the summary), PoseRequests
// (~set_state and initialpose), RunSettings (what dynamic_reconfigure may change while running).
// Every restart of the run (~reset, ~set_state, initialpose, a follower moved onto its leader's
// clock) goes through restart_run().
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
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
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/core/run/guarded_run.h"
#include "birkhoff_cart/SetCartState.h"
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/run_record.h"
#include "birkhoff_cart/core/node_logic/run_work_meter.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/cart_sim_reports.h"
#include "birkhoff_cart/ros/command_inputs.h"
#include "birkhoff_cart/ros/conversions.h"
#include "birkhoff_cart/ros/event_reports.h"
#include "birkhoff_cart/ros/instant_publisher.h"
#include "birkhoff_cart/ros/lockstep_barrier.h"
#include "birkhoff_cart/ros/pose_requests.h"
#include "birkhoff_cart/ros/run_pacing.h"
#include "birkhoff_cart/ros/run_settings.h"
#include "birkhoff_cart/ros/shutdown_signals.h"
#include "birkhoff_cart/ros/signaling_callback_queue.h"
#include "birkhoff_cart/ros/step_requests.h"
#include "birkhoff_cart/core/node_logic/instant_schedule.h"
#include "birkhoff_cart/core/node_logic/run_timeline.h"
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

  const Simulation& simulation() const { return run_->simulation(); }
  const CartSimParameters& parameters() const { return parameters_; }

 private:
  int run_loop(std::string& outcome);
  /// The record has failed (the node stops: it does not run without its record).
  bool record_failed() const;

  /// Whether a restart starts a whole run (T long: construction, ~reset, a follower's start on its
  /// leader's clock) or the rest of one (up to the end in force: a teleport).
  enum class RunStart { kWhole, kRest };
  /// The one restart of the run: `move` moves the simulation to the new run's start
  /// (Simulation::reset or restart_from; std::invalid_argument refuses, with nothing changed);
  /// then the accuracy guard, the commands' hold, the plan, the publish instants and the pacing
  /// start again there and an open ~step is cancelled. False, with `message` naming the refusal
  /// ("<source> refused: ..."), when `move` refused.
  bool restart_run(const std::string& source, RunStart start, const std::function<void()>& move,
                   std::string& message);
  /// Plans the run in the simulation from the current state (Simulation::plan_run: a whole run or
  /// the rest of one) and restarts the publish instants and the pacing there. The simulation then
  /// owns the schedule: at_end(), next_step_time().
  void restart_schedule(RunStart start);

  bool on_reset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool on_pause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  /// ~reset's work (also a follower's when its leader's /clock goes back): the scene's initial
  /// state, the next run's bag; a follower then starts on its leader's clock, catching up at most
  /// `catch_up` [s] of the leader's lead by stepping.
  void reset_run(const std::string& source, double catch_up);
  /// Restarts the run from `target` at the current time (Simulation::restart_from); the bag goes
  /// on. False, with `message` naming the problem and nothing changed, when it is refused.
  bool teleport(const CartState& target, const std::string& source, std::string& message);
  /// Paused with no ~step request open: the loop waits.
  bool halted() const { return paused_ && !step_requests_->open(); }
  /// The batch in progress must stop: paused, the record failed, stopping, a restart since
  /// `restarts_before` (its publish instants belonged to the old start) or the leader's clock went back.
  bool batch_interrupted(std::uint64_t restarts_before) const;

  /// Into the bag (while it can be written): a command message at scene time `time` [s].
  void record_command(const std::string& topic, double time, const std_msgs::Float64& message);
  /// The next step of the run's schedule (watchdogs first); false when it failed (step_failure_ set).
  bool take_step();
  /// One publish instant: the guard checked, the state published and recorded, /diagnostics when due.
  void publish_instant();

  bool stop_requested() const;
  /// ~follow_clock, at the start of a whole run: once a /clock is heard, moves the run's start onto
  /// the leader's clock (start_on_leader_clock) instead of replaying the leader's past in a burst.
  /// True when the start moved (a new batch begins).
  bool start_on_leader_clock_if_behind();

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  SignalingCallbackQueue callback_queue_;  ///< every subscription and service of the node
  CartSimParameters parameters_;
  /// The simulation and its accuracy guard (scene `accuracy` + ~accuracy/...), checked at every publish instant.
  std::unique_ptr<GuardedRun> run_;
  std::optional<CommandInputs> commands_;  ///< steering_torque, drive_torque: channels, watchdogs, lockstep answers
  std::optional<RunRecord> record_;  ///< the bag of each run; none without ~bag_path
  std::optional<EventReports> events_;  ///< ~events: crossings published on ~events; a terminal one pauses

  std::optional<InstantPublisher> publisher_;  ///< the topics of a publish instant, /clock, tf
  /// The scene's odometry sensor (docs/odometry_sensor.md); none: odom is the exact state.
  std::optional<OdometrySensor> odometry_sensor_;
  ros::ServiceServer reset_service_;
  ros::ServiceServer pause_service_;
  std::optional<PoseRequests> pose_requests_;  ///< ~set_state and initialpose, teleporting through teleport()
  std::unique_ptr<StepRequests> step_requests_;  ///< ~step, on threads of its own
  std::optional<RunSettings> settings_;  ///< what dynamic_reconfigure may change while running
  std::optional<LockstepBarrier> lockstep_;  ///< the waits for the controllers (~lockstep)

  std::optional<RunTimeline> timeline_;   ///< where the run started and stops, the ROS-time rules
  std::optional<RunPacing> pacing_;  ///< real-time deadlines, pauses, a leader's /clock
  std::optional<PublishSchedule> instants_;  ///< the publish and /diagnostics instants, the first /clock
  std::atomic<bool> paused_{false};  ///< read by the ~step thread
  std::atomic<bool> stop_flag_{false};  ///< request_stop()
  std::uint64_t restarts_ = 0;            ///< restarts of the run (~reset, teleports, a follower's move)
  std::optional<std::string> step_failure_;

  RunWorkMeter work_;  ///< wall time of the run: integration_error, diagnostics, progress, summary
  /// /diagnostics, progress lines, the summary; last, since it reads the members above.
  std::optional<CartSimReports> reports_;
};

}  // namespace birkhoff_cart
