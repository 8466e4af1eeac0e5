// cart_sim's construction and time loop (see cart_sim_node.h). It never computes physics: the
// state, the diagnostics and the rates all come from the core.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <rosgraph_msgs/Clock.h>

#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/ros/accuracy_reporting.h"
#include "birkhoff_cart/core/node_logic/instant_schedule.h"
#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {
namespace {

constexpr double kLastInstantLinger = 0.1;  // [s of wall time] after a run that ended well

// What roscpp's own /clock subscription does, for a node that does not publish /clock.
void hear_clock(const rosgraph_msgs::Clock::ConstPtr& clock) { ros::Time::setNow(clock->clock); }

}  // namespace

CartSimNode::CartSimNode(ros::NodeHandle node, ros::NodeHandle private_node)
    : node_(node), private_node_(private_node) {
  try {
    parameters_ = load_parameters(private_node_);
  } catch (const std::exception& error) {
    throw NodeStartupError(std::string("bad parameter: ") + error.what());
  }
  for (const std::string& report : unknown_private_parameters(private_node_, cart_sim_parameter_names())) {
    ROS_WARN("cart_sim: %s", report.c_str());
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
  if (scene.odometry_sensor) odometry_sensor_.emplace(*scene.odometry_sensor, simulation_->model());
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
    run_duration_ = simulation_->scene().duration;
  } else if (parameters_.duration == 0.0 || std::isinf(parameters_.duration)) {
    run_duration_ = std::numeric_limits<double>::infinity();
  } else {
    run_duration_ = parameters_.duration;
  }
  loaded_start_time_ = start_time;
  end_time_ = std::numeric_limits<double>::infinity();
  if (std::isfinite(run_duration_)) {
    // The same plan as cart_simulate's (the scene's own duration was already checked by Simulation).
    try {
      end_time_ = plan_steps(start_time, run_duration_, simulation_->step_size()).end_time;
    } catch (const TimeLimitError& error) {
      const bool from_parameter = parameters_.duration > 0.0 && error.key() == "duration";
      const std::string key = from_parameter ? std::string("~duration") : "scene key '" + error.key() + "'";
      throw NodeStartupError("the run of scene " + parameters_.scene_path + " cannot be cut into steps: " + key +
                             ": " + error.problem());
    }
  }
  // ros::Time holds 32-bit seconds: a stamp at or past 2^32 s throws in roscpp. Refuse such a run
  // here by name; a run without end that gets there stops cleanly with exit 4 (run()).
  if (!(start_time < ros_conversions::kLatestRosTime) ||
      (std::isfinite(end_time_) && !(end_time_ < ros_conversions::kLatestRosTime))) {
    throw NodeStartupError("scene " + parameters_.scene_path + " runs from t = " + format_seconds(start_time) +
                           " s to t = " + format_seconds(end_time_) +
                           " s: cart_sim publishes scene time as ROS time, which ends before 2^32 s = " +
                           format_seconds(ros_conversions::kLatestRosTime) + " s");
  }
  // Stamps are scene time; a node on wall time would see them decades in the past. A follower of
  // another node's /clock needs that clock.
  bool use_sim_time = false;
  node_.param("/use_sim_time", use_sim_time, false);
  if (parameters_.follow_clock && !use_sim_time) {
    throw NodeStartupError("~follow_clock is true but /use_sim_time is false: there is no /clock to follow; "
                           "set /use_sim_time true");
  }
  if (!use_sim_time) {
    ROS_WARN("cart_sim: /use_sim_time is false, but every stamp cart_sim publishes is scene time (from t0 = %s s) "
             "and it drives /clock: nodes on wall time (tf listeners, rviz, robot_state_publisher) will drop "
             "its messages as too old. Set /use_sim_time true before starting them (every launch file of "
             "birkhoff_cart does, but lockstep.launch, whose loop reads only stamps).", format_seconds(start_time).c_str());
  }
  publish_period_ = 1.0 / parameters_.publish_rate;
  double real_time_factor = parameters_.real_time_factor;
  if (!parameters_.fast && real_time_factor == 0.0) real_time_factor = 1.0;
  if (parameters_.follow_clock) real_time_factor = 0.0;  // the leader's /clock is the pace
  pacing_ = WallClockPacing(real_time_factor);

  try {
    commands_.emplace(*simulation_, parameters_, start_time);
  } catch (const std::invalid_argument& error) {
    throw NodeStartupError(error.what());
  }

  // The record comes first: a node that cannot keep its record does not run at all.
  if (!parameters_.bag_path.empty()) {
    try {
      record_.emplace(parameters_.bag_path, parameters_.bag_compression, parameters_.min_free_disk_space);
    } catch (const std::exception& error) {
      throw NodeStartupError(std::string("cannot record (~bag_path): ") + error.what());
    }
  }

  // Every subscription and service of the node goes through callback_queue_.
  node_.setCallbackQueue(&callback_queue_);
  private_node_.setCallbackQueue(&callback_queue_);
  publisher_.emplace(node_, private_node_, parameters_, simulation_->scene().initial_state.time);
  // Without ~publish_clock the node hears /clock from the clock source as any node does (main()
  // moved roscpp's own subscription away: see InstantPublisher).
  if (!parameters_.publish_clock && ros::Time::isSimTime()) {
    ros::NodeHandle clock_node(node_, "", ros::M_string{{"/clock", "/clock"}});
    clock_subscriber_ = clock_node.subscribe("/clock", 1, &hear_clock);
  }
  commands_->subscribe(node_, [this](const std::string& topic, double time, const std_msgs::Float64& message) {
    record_command(topic, time, message);
  });
  reset_service_ = private_node_.advertiseService("reset", &CartSimNode::on_reset, this);
  pause_service_ = private_node_.advertiseService("pause", &CartSimNode::on_pause, this);
  pose_requests_.emplace(node_, private_node_, parameters_, *simulation_,
                         [this](const CartState& target, const std::string& source, std::string& message) {
                           return teleport(target, source, message);
                         });
  step_requests_ = std::make_unique<StepRequests>(
      private_node_,
      [this]() -> std::string {
        if (parameters_.lockstep) return "~lockstep is on: the controllers' answers pace the run";
        if (parameters_.follow_clock) return "~follow_clock is on: the leader's /clock paces the run";
        if (!paused_) return "the run is not paused (call ~pause with data: true first)";
        return "";
      },
      [this] { callback_queue_.wake(); });

  settings_.emplace(private_node_, parameters_, accuracy_guard_, *commands_, *simulation_);

  reports_.emplace(RunView{parameters_, *simulation_, accuracy_guard_, work_, *commands_, record_, odometry_sensor_,
                           paused_, step_failure_, lockstep_timeouts_, end_time_},
                   node_, private_node_);

  paused_ = parameters_.start_paused;
  restart_schedule();
  const std::string step_control = simulation_->scene().integrator.step_control == StepControl::kReversible
                                       ? " (reversible step control for " +
                                             format_seconds(simulation_->scene().integrator.position_tolerance) +
                                             " m; h is the output step)"
                                       : "";
  ROS_INFO("cart_sim: scene '%s' (%s), integrator %s, h = %g s%s, %s mode%s, publish %g Hz, end t = %s s, frames %s -> "
           "%s, %s%s%s",
           simulation_->scene().name.c_str(), parameters_.scene_path.c_str(), simulation_->integrator_name().c_str(),
           simulation_->step_size(), step_control.c_str(), parameters_.fast ? "fast" : "real-time", parameters_.lockstep ? ", lockstep" : "",
           parameters_.publish_rate, format_seconds(end_time_).c_str(), parameters_.frames.odom.c_str(),
           parameters_.frames.base_link.c_str(),
           parameters_.publish_clock ? "publishing /clock"
                                     : (parameters_.follow_clock ? "following /clock" : "not publishing /clock"),
           record_ ? ", recording to " : "", record_ ? record_->bag().path().c_str() : "");
}

CartSimNode::~CartSimNode() = default;

void CartSimNode::restart_schedule() {
  // From the current time to the run's end: the whole run after construction or ~reset, the rest of
  // it after a teleport (~set_state, /initialpose).
  const double start_time = simulation_->state().time;
  const bool whole_run = start_time == loaded_start_time_;
  simulation_->plan_run(whole_run || !std::isfinite(end_time_) ? run_duration_ : end_time_ - start_time);
  // The odometry starts again at the true pose; after ~reset its noise runs again from the seed.
  if (odometry_sensor_) odometry_sensor_->start(simulation_->state(), whole_run);
  next_publish_index_ = 1;
  next_diagnostic_index_ = 1;
  clock_started_ = false;
  publisher_->restart();
  pacing_.restart(WallClockPacing::Clock::now(), start_time);
}

bool CartSimNode::stop_requested() const { return stop_flag_ || shutdown_signal_received() || !ros::ok(); }

bool CartSimNode::take_step() {
  commands_->apply_watchdogs();
  const double time_before = simulation_->state().time;
  try {
    // Whole steps onto t0 + n h, then the schedule's final step onto the end time exactly.
    simulation_->step_on_schedule();
  } catch (const StepError& error) {
    step_failure_ = error.what();
    return false;
  }
  step_requests_->count_step(simulation_->state().time);
  work_.count_step(simulation_->state().time - time_before);
  if (!clock_started_) {  // the first /clock, t0 + h, unless that is a publish instant or the end (published there)
    clock_started_ = true;
    const double start = simulation_->scene().initial_state.time;
    const double time = simulation_->state().time;
    if (!simulation_->at_end() &&
        start + static_cast<double>(next_publish_index_) * publish_period_ > time + 0.5 * simulation_->step_size()) {
      publisher_->publish_clock(time);
    }
  }
  return true;
}

int CartSimNode::run_loop(std::string& outcome) {
  using Clock = WallClockPacing::Clock;
  while (true) {
    // The run's start: the scene's t0, or the time of the last teleport (~set_state, /initialpose).
    const double start = simulation_->scene().initial_state.time;
    if (stop_requested()) {
      outcome = "interrupted (shutdown requested)";
      break;
    }
    if (record_failed()) break;  // a command could not be recorded (set in a callback, also while paused)
    if (halted()) {
      wait_while_paused();
      continue;
    }
    if (simulation_->at_end()) break;
    // One batch: the steps up to the next publish instant (or the end). Between steps, callbacks
    // run when the transport has queued one (not in lockstep, where they run only at the barrier);
    // in real-time mode the node sleeps until a step is due.
    const double instant = start + static_cast<double>(next_publish_index_) * publish_period_;
    const double half_step = 0.5 * simulation_->step_size();
    if (parameters_.follow_clock) {  // the batch runs once the leader's /clock has reached its end
      const std::uint64_t resets_before = resets_;
      wait_for_clock(std::min(instant, end_time_));
      if (halted() || record_failed() || stop_requested() || resets_ != resets_before) continue;
    }
    Clock::time_point batch_start = Clock::now();
    bool failed = false;
    bool interrupted = false;
    double due_scene_time = -std::numeric_limits<double>::infinity();  // [s]
    // Steps asked for by ~step while paused run as fast as they can (not paced).
    const bool paced = pacing_.paced() && !paused_;
    while (!simulation_->at_end() && simulation_->state().time + half_step < instant) {
      if (halted()) {  // the ~step request is done (its last step was not on an instant)
        interrupted = true;
        break;
      }
      // Real time: a step is due once the wall clock has reached its scene time (half a step early
      // is fine). Steps due are run back to back; only a node that has caught up runs callbacks or
      // sleeps, so a command takes effect at the first step after its arrival in scene time too.
      const double next_time = simulation_->next_step_time();
      // The scene time due by now is read from the clock only when the last reading no longer
      // covers the next step (one clock read per catch-up, not per step).
      if (paced && due_scene_time < next_time - half_step) {
        due_scene_time = pacing_.scene_time_at(Clock::now());
      }
      const bool step_due = !paced || due_scene_time >= next_time - half_step;
      if ((!step_due || !paced) && !parameters_.lockstep && callback_queue_.pending()) {
        const std::uint64_t resets_before = resets_;
        process_callbacks();
        if (halted() || record_failed() || stop_requested() || resets_ != resets_before) {
          interrupted = true;  // paused, failed, stopping, reset or teleported: a new batch
          break;
        }
        if (!step_due) continue;
      }
      if (!step_due) {
        work_.add_stepping(std::chrono::duration<double>(Clock::now() - batch_start).count());
        wait_until_due(std::min(instant, end_time_));
        batch_start = Clock::now();
        if (halted() || record_failed() || stop_requested()) {
          interrupted = true;
          break;
        }
        continue;
      }
      if (!take_step()) {
        failed = true;
        break;
      }
    }
    work_.add_stepping(std::chrono::duration<double>(Clock::now() - batch_start).count());
    if (failed) break;
    if (interrupted) continue;
    const double time = simulation_->state().time;
    // The publish instants due by now, and the run's end t0 + T (an instant or not), published once.
    const bool instant_due = pass_due_instants(start, publish_period_, time, half_step, next_publish_index_);
    if (instant_due || simulation_->at_end()) {
      publisher_->publish_clock(time);
      publish_instant();
      if (record_failed()) break;
      if (parameters_.lockstep) wait_for_commands(time);
      if (parameters_.fast) reports_->report_progress();
    }
  }
  return 0;
}

int CartSimNode::run() {
  if (parameters_.lockstep) wait_for_controllers();
  const WallClockPacing::Clock::time_point run_start = WallClockPacing::Clock::now();
  work_.start(run_start, simulation_->state().time);
  pacing_.restart(run_start, simulation_->state().time);
  std::string outcome = "finished";
  std::optional<std::string> internal_error;
  try {
    run_loop(outcome);
  } catch (const std::exception& error) {
    // Anything else that escapes the loop (e.g. roscpp refusing a time): a clear line, the bag
    // closed, exit 4; never std::terminate with the record left unfinished.
    internal_error = error.what();
  }
  step_requests_->end(simulation_->state().time);

  if (!internal_error && !step_failure_ && !record_failed() && !stop_requested() &&
      (publisher_->listened() || reports_->diagnostics_listened())) {
    // publish() only queues a message for roscpp's transport threads: give them a moment to send
    // the last instant (subscribers lost the last /tf when the node left at once). Without a
    // subscriber roscpp queued nothing, and the wait would only lengthen the run (by a third of a
    // 300 s fast run of the default scene).
    ros::WallDuration(kLastInstantLinger).sleep();
  }
  if (step_failure_) {
    ROS_ERROR("cart_sim: step failed at t = %.9g s: %s", simulation_->state().time, step_failure_->c_str());
    outcome = "step failure: " + *step_failure_;
    reports_->publish_diagnostics();
  }
  if (internal_error) {
    ROS_FATAL("cart_sim: stopped at t = %.9g s by an unexpected error: %s", simulation_->state().time,
              internal_error->c_str());
    outcome = "internal error: " + *internal_error;
  }
  if (record_failed()) {
    ROS_ERROR("cart_sim: bag write failed at t = %.9g s, stopping (the node does not run without its record): %s",
              simulation_->state().time, record_->failure()->c_str());
  }
  if (record_) record_->finish();
  if (record_failed()) {
    ROS_FATAL("cart_sim: the record failed: %s", record_->failure()->c_str());
    outcome = "record failure: " + *record_->failure();
  }
  reports_->write_summary(outcome);
  if (internal_error) return kExitInternalError;
  if (step_failure_) return kExitStepFailure;
  if (record_failed()) return kExitRecordFailure;
  return kExitFinished;
}

void CartSimNode::record_command(const std::string& topic, double time, const std_msgs::Float64& message) {
  if (record_) record_->write(topic, ros_conversions::to_ros_time(time), message);
}

bool CartSimNode::record_failed() const { return record_ && record_->failure(); }

}  // namespace birkhoff_cart
