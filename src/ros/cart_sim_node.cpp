// cart_sim's node (see cart_sim_node.h): construction, the time loop, the one restart of the run
// (~reset, ~set_state and initialpose, a follower moved onto its leader's clock), ~pause, the
// pacing (callbacks between steps, real-time deadlines, pauses, the lockstep barrier, following a
// leader's /clock) and the publish instant. It never computes physics: the state, the diagnostics
// and the rates all come from the core.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <thread>

#include <rosgraph_msgs/Clock.h>

#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/ros/accuracy_reporting.h"
#include "birkhoff_cart/core/node_logic/instant_schedule.h"
#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {
namespace {

using Clock = WallClockPacing::Clock;

constexpr double kLastInstantLinger = 0.1;  // [s of wall time] after a run that ended well
// Longest single sleep [s]: a SIGINT/SIGTERM (whose handler cannot wake a condition) is seen
// within this time.
constexpr double kLongestSleep = 0.1;
/// How long a lockstep barrier polls for the controllers' answers before it sleeps [µs].
constexpr int kLockstepSpinMicroseconds = 200;
/// How long a follower waits for a /clock at a time before it looks at its callbacks again [s].
constexpr double kClockPoll = 0.01;

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

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
  if (!parameters_.step_control.empty()) scene.integrator.step_control = parse_step_control(parameters_.step_control);
  if (parameters_.position_tolerance > 0.0) {
    if (scene.integrator.step_control == StepControl::kFixed) {
      throw NodeStartupError("bad parameter: ~position_tolerance " + format_seconds(parameters_.position_tolerance) +
                             " m is the position error for a step control, and the run steps at fixed steps (scene " +
                             parameters_.scene_path +
                             "): give ~step_control adaptive or reversible with it, or leave it out");
    }
    scene.integrator.position_tolerance = parameters_.position_tolerance;
  }
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
  try {
    timeline_.emplace(parameters_.duration, simulation_->scene().duration, simulation_->step_size(),
                      parameters_.scene_path, start_time);
  } catch (const RunTimelineError& error) {
    throw NodeStartupError(error.what());
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
  pacing_ = WallClockPacing(pacing_factor(parameters_.fast, parameters_.real_time_factor, parameters_.follow_clock));

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
    clock_subscriber_ = clock_node.subscribe("/clock", 1, &CartSimNode::hear_clock, this);
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
      [this] { callback_queue_.wake(); }, start_time);

  settings_.emplace(private_node_, parameters_, accuracy_guard_, *commands_, *simulation_);

  reports_.emplace(RunView{parameters_, *simulation_, accuracy_guard_, work_, *commands_, record_, odometry_sensor_,
                           paused_, step_failure_, lockstep_timeouts_, *timeline_},
                   node_, private_node_);

  paused_ = parameters_.start_paused;
  if (parameters_.follow_clock) start_catch_up_ = kLongestCatchUp;
  restart_schedule(RunStart::kWhole);
  const StepControl control = simulation_->scene().integrator.step_control;
  const std::string step_control = control == StepControl::kFixed
                                       ? ""
                                       : std::string(" (") + to_string(control) + " step control for " +
                                             format_seconds(simulation_->scene().integrator.position_tolerance) +
                                             " m; h is the output step)";
  ROS_INFO("cart_sim: scene '%s' (%s), integrator %s, h = %g s%s, %s mode%s, publish %g Hz, end t = %s s, frames %s -> "
           "%s, %s%s%s",
           simulation_->scene().name.c_str(), parameters_.scene_path.c_str(), simulation_->integrator_name().c_str(),
           simulation_->step_size(), step_control.c_str(), parameters_.fast ? "fast" : "real-time", parameters_.lockstep ? ", lockstep" : "",
           parameters_.publish_rate, format_seconds(timeline_->end_time()).c_str(), parameters_.frames.odom.c_str(),
           parameters_.frames.base_link.c_str(),
           parameters_.publish_clock ? "publishing /clock"
                                     : (parameters_.follow_clock ? "following /clock" : "not publishing /clock"),
           record_ ? ", recording to " : "", record_ ? record_->bag().path().c_str() : "");
}

CartSimNode::~CartSimNode() = default;

// ---- The one restart of the run ----------------------------------------------------------------

bool CartSimNode::restart_run(const std::string& source, RunStart start, const std::function<void()>& move,
                              std::string& message) {
  try {
    move();
  } catch (const std::invalid_argument& error) {
    message = source + " refused: " + error.what() + "; the simulation goes on unchanged";
    ROS_ERROR("cart_sim: %s", message.c_str());
    return false;
  }
  accuracy_guard_.reset();
  ++restarts_;  // a batch in progress stops: its publish instants belonged to the old start
  const double time = simulation_->state().time;
  commands_->restart(time);
  if (start == RunStart::kWhole) timeline_->start_at(time);
  restart_schedule(start);
  step_requests_->cancel(source, time);
  return true;
}

void CartSimNode::restart_schedule(RunStart start) {
  // From the current time: the whole run (construction, ~reset, a follower's start on its leader's
  // clock), or the rest of it up to the end in force (a teleport).
  const double start_time = simulation_->state().time;
  const bool whole_run = start == RunStart::kWhole;
  simulation_->plan_run(timeline_->length_from(start_time, whole_run));
  // The odometry starts again at the true pose; after a whole run's start its noise runs again from the seed.
  if (odometry_sensor_) odometry_sensor_->start(simulation_->state(), whole_run);
  next_publish_index_ = 1;
  next_diagnostic_index_ = 1;
  clock_started_ = false;
  publisher_->restart();
  pacing_.restart(Clock::now(), start_time);
}

void CartSimNode::reset_run(const std::string& source, double catch_up) {
  std::string refusal;
  if (!restart_run(source, RunStart::kWhole, [this] { simulation_->reset(); }, refusal)) return;
  // Each run gets its own bag: one bag across a reset would hold overlapping times of two runs,
  // which playback interleaves.
  if (record_) record_->next_run();
  // A follower's run starts on its leader's clock, not in its past (start_on_leader_clock_if_behind).
  if (parameters_.follow_clock) start_catch_up_ = catch_up;
  const double start_time = simulation_->state().time;
  ROS_INFO("cart_sim: reset to the scene's initial state at t = %.6g s%s%s%s", start_time,
           parameters_.follow_clock ? " (then onto the leader's clock)" : "",
           record_ && !record_->failure() ? ", recording to " : "",
           record_ && !record_->failure() ? record_->bag().path().c_str() : "");
}

bool CartSimNode::on_reset(std_srvs::Empty::Request& /*request*/, std_srvs::Empty::Response& /*response*/) {
  // A follower's new stamps go on from those it sent (no tf stamp twice): onto the leader's clock.
  reset_run("~reset", 0.0);
  return true;
}

bool CartSimNode::on_pause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
  paused_ = request.data;
  const double time = simulation_->state().time;
  // Scene time stands still, or goes on, from now: the real-time deadlines start here (after a
  // ~step run while paused the last anchor lies far behind the scene time).
  pacing_.restart(Clock::now(), time);
  step_requests_->cancel(request.data ? "~pause" : "~pause false (the run goes on)", time);
  response.success = true;
  response.message = std::string(paused_ ? "paused" : "running") + " at t = " + format_seconds(time) + " s";
  ROS_INFO("cart_sim: %s", response.message.c_str());
  return true;
}

bool CartSimNode::teleport(const CartState& target, const std::string& source, std::string& message) {
  if (simulation_->at_end()) {
    message = source + " refused: the run has ended at t = " + format_seconds(simulation_->state().time) + " s";
    ROS_ERROR("cart_sim: %s", message.c_str());
    return false;
  }
  if (!restart_run(source, RunStart::kRest, [&] { simulation_->restart_from(target); }, message)) return false;
  const Eigen::Vector2d base = simulation_->model().rear_axle_midpoint(target);
  std::ostringstream text;
  text << source << ": teleported at t = " << format_seconds(simulation_->state().time) << " s to base_link ("
       << base.x() << ", " << base.y() << ") m, heading " << target.heading << " rad, steering angle "
       << target.steering_angle << " rad, forward speed " << target.forward_speed << " m/s, steering rate "
       << target.steering_rate << " rad/s (a restart of the run from there" << (record_ ? "; the bag goes on)" : ")");
  message = text.str();
  ROS_INFO("cart_sim: %s", message.c_str());
  return true;
}

// ---- The time loop -----------------------------------------------------------------------------

bool CartSimNode::stop_requested() const { return stop_flag_ || shutdown_signal_received() || !ros::ok(); }

bool CartSimNode::batch_interrupted(std::uint64_t restarts_before) const {
  return halted() || record_failed() || stop_requested() || restarts_ != restarts_before || leader_clock_went_back_;
}

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

void CartSimNode::publish_instant() {
  const double wall_time_per_step = work_.end_period();  // [s]
  const OdometryEstimate* estimate = odometry_sensor_ ? &odometry_sensor_->read(simulation_->state()) : nullptr;
  // The accuracy guard is judged here, once per instant, before the messages are filled from it.
  const Diagnostics diagnostics = simulation_->diagnostics();
  accuracy_guard_.check(simulation_->state().time, diagnostics, simulation_->statistics());
  publisher_->publish(*simulation_, diagnostics, accuracy_guard_, wall_time_per_step, estimate,
                      record_ ? &*record_ : nullptr);
  if (pass_due_instants(simulation_->scene().initial_state.time, parameters_.diagnostic_period, simulation_->state().time,
                        0.5 * simulation_->step_size(), next_diagnostic_index_)) {
    reports_->publish_diagnostics();
  }
}

int CartSimNode::run_loop(std::string& outcome) {
  while (true) {
    // The run's start: the scene's t0, or the time of the last restart (a teleport, a follower's start).
    const double start = simulation_->scene().initial_state.time;
    if (stop_requested()) {
      outcome = "interrupted (shutdown requested)";
      break;
    }
    if (record_failed()) break;  // a command could not be recorded (set in a callback, also while paused)
    if (leader_clock_went_back_) {  // the leader was reset: so is this cart, onto the leader's new clock
      leader_clock_went_back_ = false;
      ROS_INFO("cart_sim: the leader's /clock went back from t = %s s to t = %s s (the leader was reset); this cart "
               "starts its scene again on the new clock",
               format_seconds(leader_clock_before_).c_str(), format_seconds(ros::Time::now().toSec()).c_str());
      reset_run("the leader's /clock going back", kLongestCatchUp);
      continue;
    }
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
      if (start_catch_up_ && start_on_leader_clock_if_behind()) continue;
      if (start_catch_up_) continue;  // no /clock heard yet
      const std::uint64_t restarts_before = restarts_;
      wait_for_clock(std::min(instant, timeline_->end_time()));
      if (batch_interrupted(restarts_before)) continue;
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
        const std::uint64_t restarts_before = restarts_;
        process_callbacks();
        if (batch_interrupted(restarts_before)) {
          interrupted = true;  // paused, failed, stopping, restarted or the leader reset: a new batch
          break;
        }
        if (!step_due) continue;
      }
      if (!step_due) {
        work_.add_stepping(std::chrono::duration<double>(Clock::now() - batch_start).count());
        wait_until_due(std::min(instant, timeline_->end_time()));
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
  step_requests_->end(simulation_->state().time, stop_requested());

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


// ---- Pacing ------------------------------------------------------------------------------------

void CartSimNode::process_callbacks() { callback_queue_.call_pending(); }

bool CartSimNode::wait_until_due(double time) {
  // The deadline is computed from the anchor on every wake: a reset or pause in a callback moves
  // the anchor, and the next wait follows it.
  while (!stop_requested()) {
    const Clock::time_point deadline = std::min(pacing_.due(time), after(kLongestSleep));
    if (callback_queue_.wait_until(deadline)) {
      return false;  // a message: the caller runs the steps due by now, then the callbacks
    }
    if (Clock::now() >= pacing_.due(time)) return true;
  }
  return false;
}

void CartSimNode::wait_while_paused() {
  const Clock::time_point start = Clock::now();
  callback_queue_.wait_until(after(kLongestSleep));
  process_callbacks();
  work_.add_paused(std::chrono::duration<double>(Clock::now() - start).count());
  // Scene time stood still: the next deadline starts from now.
  pacing_.restart(Clock::now(), simulation_->state().time);
}

void CartSimNode::wait_for_controllers() {
  const auto connected = [this] {
    return commands_->controllers_connected() && publisher_->joint_state_subscribers() > 0;
  };
  // A note every ~lockstep_timeout, at most one a second (a tiny timeout would flood the log).
  const double note_interval = std::max(parameters_.lockstep_timeout, 1.0);  // [s of wall time]
  Clock::time_point next_note = after(note_interval);
  while (!connected() && !stop_requested()) {
    callback_queue_.wait_until(after(0.01));
    process_callbacks();
    if (Clock::now() >= next_note) {
      ROS_WARN("cart_sim: lockstep: waiting for a controller (publishers on %s and a joint_states subscriber)",
               commands_->expected_topics().c_str());
      next_note = after(note_interval);
    }
  }
}

void CartSimNode::wait_for_commands(double time) {
  const Clock::time_point give_up = after(parameters_.lockstep_timeout);
  const auto answered = [this] { return commands_->answered(); };
  // Callbacks run only here in lockstep: everything queued since the last barrier (the answers,
  // ~pause, ~reset) takes effect at this instant.
  process_callbacks();
  while (!answered() && !stop_requested() && !paused_) {
    const Clock::time_point now = Clock::now();
    if (now >= give_up) {
      ++lockstep_timeouts_;
      // Counted each time; said at most once a second (a tiny ~lockstep_timeout would flood the log).
      ROS_WARN_THROTTLE(1.0, "cart_sim: lockstep: no answer on %s within %g s of wall time after t = %.6g s; going on "
               "(%lu timeouts so far)",
               commands_->unanswered_topics().c_str(), parameters_.lockstep_timeout, time,
               static_cast<unsigned long>(lockstep_timeouts_));
      break;
    }
    // A controller in the same process (a nodelet) answers within microseconds: poll for it a
    // little before sleeping, since a sleep and its wake-up cost more than the answer takes.
    const Clock::time_point spin_until = now + std::chrono::microseconds(kLockstepSpinMicroseconds);
    while (!callback_queue_.pending() && Clock::now() < spin_until) std::this_thread::yield();
    callback_queue_.wait_until(std::min(give_up, now + std::chrono::duration_cast<Clock::duration>(
                                                           std::chrono::duration<double>(kLongestSleep))));
    process_callbacks();
  }
  // The answers are recorded at the instant they answer, in the order of their topics' names.
  commands_->end_barrier(time);
  // The wait is the controllers' time, not the simulator's: real-time pacing starts again here.
  if (pacing_.paced()) pacing_.restart(Clock::now(), simulation_->state().time);
}

void CartSimNode::wait_for_clock(double time) {
  // ros::Time::now() is the /clock of the node that drives it (hear_clock). 1 µs allows for the
  // nanosecond rounding of ROS time. A restart served while waiting ends the wait (`time` belongs
  // to the run before it), and so does the leader's clock going back (its reset).
  constexpr double kStampRounding = 1e-6;  // [s]
  const std::uint64_t restarts_before = restarts_;
  while (ros::Time::now().toSec() < time - kStampRounding && !batch_interrupted(restarts_before)) {
    callback_queue_.wait_until(after(kClockPoll));
    process_callbacks();
  }
}

bool CartSimNode::start_on_leader_clock_if_behind() {
  if (ros::Time::now().isZero()) {  // no /clock heard yet: wait for the leader's first
    callback_queue_.wait_until(after(kClockPoll));
    process_callbacks();
    return false;
  }
  const double catch_up = *start_catch_up_;
  start_catch_up_.reset();
  const double leader_time = ros::Time::now().toSec();
  const double start = start_on_leader_clock(simulation_->state().time, leader_time, publish_period_, catch_up);
  if (!(start > simulation_->state().time)) return false;  // the leader has not passed this run's first instant
  // The whole run, moved: its end and the ROS-time rules checked before anything changes.
  RunTimeline moved = *timeline_;
  std::string refusal;
  try {
    moved.start_at(start);
  } catch (const RunTimelineError& error) {
    refusal = error.what();
  }
  CartState target = simulation_->state();
  target.time = start;
  if (refusal.empty() &&
      restart_run("the start on the leader's clock", RunStart::kWhole, [&] { simulation_->restart_from(target); },
                  refusal)) {
    ROS_INFO("cart_sim: the leader's /clock is at t = %s s: this cart's run starts on it, at t = %s s (not in "
             "the leader's past, which it would replay in a burst)",
             format_seconds(leader_time).c_str(), format_seconds(start).c_str());
    return true;
  }
  ROS_WARN("cart_sim: cannot start on the leader's clock at t = %s s (%s); this cart steps from t = %s s up to it",
           format_seconds(start).c_str(), refusal.c_str(), format_seconds(simulation_->state().time).c_str());
  return false;
}

void CartSimNode::hear_clock(const rosgraph_msgs::Clock::ConstPtr& clock) {
  const ros::Time before = ros::Time::now();
  if (parameters_.follow_clock && clock->clock < before) {
    leader_clock_went_back_ = true;
    leader_clock_before_ = before.toSec();
  }
  ros::Time::setNow(clock->clock);  // what roscpp's own /clock subscription does
}

}  // namespace birkhoff_cart
