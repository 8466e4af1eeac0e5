// cart_sim's node (see cart_sim_node.h): it wires its parts together. Construction, the time loop
// (batches of steps of the core's GuardedRun between publish instants, callbacks between steps, the
// waits of RunPacing and LockstepBarrier), the one restart of the run (~reset, ~set_state and
// initialpose, a follower moved onto its leader's clock), ~pause and the publish instant. It never
// computes physics: the state, the diagnostics and the rates all come from the core.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/ros/accuracy_reporting.h"
#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {
namespace {

using Clock = WallClockPacing::Clock;

constexpr double kLastInstantLinger = 0.1;  // [s of wall time] after a run that ended well

/// One part of the node's start: an `Error` it throws stops the start, as NodeStartupError(`prefix` + its message).
template <class Error = std::exception, class Part>
void start_part(const std::string& prefix, Part&& part) {
  try {
    part();
  } catch (const Error& error) {
    throw NodeStartupError(prefix + error.what());
  }
}

}  // namespace

CartSimNode::CartSimNode(ros::NodeHandle node, ros::NodeHandle private_node)
    : node_(node), private_node_(private_node) {
  start_part("bad parameter: ", [&] { parameters_ = load_parameters(private_node_); });
  for (const std::string& report : unknown_private_parameters(private_node_, cart_sim_parameter_names())) {
    ROS_WARN("cart_sim: %s", report.c_str());
  }
  Scene scene;
  start_part("cannot load scene: ", [&] { scene = load_scene(parameters_.scene_path); });
  start_part("bad parameter: ", [&] { apply_integrator_overrides(parameters_, scene.integrator); });
  start_part("cannot build the simulation of " + parameters_.scene_path + ": ", [&] {
    run_ = std::make_unique<GuardedRun>(scene, OutputInstants::kCaller);  // checked at the publish instants
  });
  if (scene.odometry_sensor) odometry_sensor_.emplace(*scene.odometry_sensor, run_->simulation().model());
  start_part("bad parameter: ", [&] {
    run_->guard() = AccuracyGuard(ros_accuracy::load_requirements(private_node_, scene.accuracy));
  });

  const double start_time = run_->simulation().state().time;
  start_part<RunTimelineError>("", [&] {
    timeline_.emplace(parameters_.duration, run_->simulation().scene().duration, run_->simulation().step_size(),
                      parameters_.scene_path, start_time);
  });
  start_part<std::invalid_argument>("", [&] { RunPacing::check_sim_time(node_, parameters_, start_time); });
  instants_.emplace(1.0 / parameters_.publish_rate, parameters_.diagnostic_period);

  start_part<std::invalid_argument>("", [&] { commands_.emplace(run_->simulation(), parameters_, start_time); });

  // The record comes first: a node that cannot keep its record does not run at all.
  if (!parameters_.bag_path.empty()) {
    start_part("cannot record (~bag_path): ", [&] {
      record_.emplace(parameters_.bag_path, parameters_.bag_compression, parameters_.min_free_disk_space);
    });
  }

  // Every subscription and service of the node goes through callback_queue_.
  node_.setCallbackQueue(&callback_queue_);
  private_node_.setCallbackQueue(&callback_queue_);
  publisher_.emplace(node_, private_node_, parameters_, run_->simulation().scene().initial_state.time);
  start_part<std::invalid_argument>("bad parameter ~events: ", [&] {
    events_.emplace(private_node_, parameters_.events, run_->simulation(), parameters_.frames.odom);
  });
  pacing_.emplace(node_, parameters_, callback_queue_, work_, [this] { return stop_requested(); });
  commands_->subscribe(node_, [this](const std::string& topic, double time, const std_msgs::Float64& message) {
    record_command(topic, time, message);
  });
  reset_service_ = private_node_.advertiseService("reset", &CartSimNode::on_reset, this);
  pause_service_ = private_node_.advertiseService("pause", &CartSimNode::on_pause, this);
  pose_requests_.emplace(node_, private_node_, parameters_, run_->simulation(),
                         [this](const CartState& target, const std::string& source, std::string& message) {
                           return teleport(target, source, message);
                         });
  step_requests_ = std::make_unique<StepRequests>(private_node_, StepRequests::node_refusal(parameters_, paused_),
                                                  [this] { callback_queue_.wake(); }, start_time);

  settings_.emplace(private_node_, parameters_, run_->guard(), *commands_, run_->simulation());
  lockstep_.emplace(callback_queue_, *commands_, *publisher_, parameters_.lockstep_timeout,
                    [this] { return stop_requested(); }, paused_);

  reports_.emplace(RunView{parameters_, run_->simulation(), run_->guard(), work_, *commands_, record_, odometry_sensor_,
                           paused_, step_failure_, lockstep_->timeouts(), *timeline_},
                   node_, private_node_);

  paused_ = parameters_.start_paused;
  if (parameters_.follow_clock) pacing_->start_on_leader_clock_next(kLongestCatchUp);
  restart_schedule(RunStart::kWhole);
  reports_->log_start();
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
  run_->guard().reset();
  events_->restart();  // the events' occurrences count again from the new start
  ++restarts_;  // a batch in progress stops: its publish instants belonged to the old start
  const double time = run_->simulation().state().time;
  commands_->restart(time);
  if (start == RunStart::kWhole) timeline_->start_at(time);
  restart_schedule(start);
  step_requests_->cancel(source, time);
  return true;
}

void CartSimNode::restart_schedule(RunStart start) {
  // From the current time: the whole run (construction, ~reset, a follower's start on its leader's
  // clock), or the rest of it up to the end in force (a teleport).
  const double start_time = run_->simulation().state().time;
  const bool whole_run = start == RunStart::kWhole;
  run_->simulation().plan_run(timeline_->length_from(start_time, whole_run));
  // The odometry starts again at the true pose; after a whole run's start its noise runs again from the seed.
  if (odometry_sensor_) odometry_sensor_->start(run_->simulation().state(), whole_run);
  instants_->restart();
  publisher_->restart();
  pacing_->deadlines().restart(Clock::now(), start_time);
}

void CartSimNode::reset_run(const std::string& source, double catch_up) {
  std::string refusal;
  if (!restart_run(source, RunStart::kWhole, [this] { run_->simulation().reset(); }, refusal)) return;
  // Each run gets its own bag: one bag across a reset would hold overlapping times of two runs,
  // which playback interleaves.
  if (record_) record_->next_run();
  // A follower's run starts on its leader's clock, not in its past (start_on_leader_clock_if_behind).
  if (parameters_.follow_clock) pacing_->start_on_leader_clock_next(catch_up);
  const double start_time = run_->simulation().state().time;
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
  const double time = run_->simulation().state().time;
  // Scene time stands still, or goes on, from now: the real-time deadlines start here (after a
  // ~step run while paused the last anchor lies far behind the scene time).
  pacing_->deadlines().restart(Clock::now(), time);
  step_requests_->cancel(request.data ? "~pause" : "~pause false (the run goes on)", time);
  response.success = true;
  response.message = std::string(paused_ ? "paused" : "running") + " at t = " + format_seconds(time) + " s";
  ROS_INFO("cart_sim: %s", response.message.c_str());
  return true;
}

bool CartSimNode::teleport(const CartState& target, const std::string& source, std::string& message) {
  if (run_->simulation().at_end()) {
    message = source + " refused: the run has ended at t = " + format_seconds(run_->simulation().state().time) + " s";
    ROS_ERROR("cart_sim: %s", message.c_str());
    return false;
  }
  if (!restart_run(source, RunStart::kRest, [&] { run_->simulation().restart_from(target); }, message)) return false;
  message = PoseRequests::teleported(source, run_->simulation(), target, record_.has_value());
  ROS_INFO("cart_sim: %s", message.c_str());
  return true;
}

// ---- The time loop -----------------------------------------------------------------------------

bool CartSimNode::stop_requested() const { return stop_flag_ || shutdown_signal_received() || !ros::ok(); }

bool CartSimNode::batch_interrupted(std::uint64_t restarts_before) const {
  return halted() || record_failed() || stop_requested() || restarts_ != restarts_before || pacing_->leader_went_back();
}

bool CartSimNode::take_step() {
  commands_->apply_watchdogs();
  const double time_before = run_->simulation().state().time;
  try {
    // Whole steps onto t0 + n h, then the schedule's final step onto the end time exactly.
    run_->step();
  } catch (const StepError& error) {
    step_failure_ = error.what();
    return false;
  }
  step_requests_->count_step(run_->simulation().state().time);
  work_.count_step(run_->simulation().state().time - time_before);
  if (events_->after_step(record_ ? &*record_ : nullptr)) {  // a terminal event: the node pauses here
    paused_ = true;
    const double time = run_->simulation().state().time;
    pacing_->deadlines().restart(Clock::now(), time);
    step_requests_->cancel("a terminal event", time);
    ROS_INFO("cart_sim: paused at t = %s s by a terminal event (~pause false goes on)", format_seconds(time).c_str());
  }
  const Simulation& simulation = run_->simulation();
  if (instants_->first_clock_due(simulation.scene().initial_state.time, simulation.state().time,
                                 0.5 * simulation.step_size(), simulation.at_end())) {
    publisher_->publish_clock(simulation.state().time);
  }
  return true;
}

void CartSimNode::publish_instant() {
  const double wall_time_per_step = work_.end_period();  // [s]
  const OdometryEstimate* estimate = odometry_sensor_ ? &odometry_sensor_->read(run_->simulation().state()) : nullptr;
  // The accuracy guard is judged here, once per instant, before the messages are filled from it.
  const Diagnostics diagnostics = run_->simulation().diagnostics();
  run_->check(run_->simulation().state().time, diagnostics);
  publisher_->publish(run_->simulation(), diagnostics, run_->guard(), wall_time_per_step, estimate,
                      record_ ? &*record_ : nullptr);
  const Simulation& simulation = run_->simulation();
  if (instants_->pass_diagnostic_instants(simulation.scene().initial_state.time, simulation.state().time,
                                          0.5 * simulation.step_size())) {
    reports_->publish_diagnostics();
  }
}

int CartSimNode::run_loop(std::string& outcome) {
  while (true) {
    // The run's start: the scene's t0, or the time of the last restart (a teleport, a follower's start).
    const double start = run_->simulation().scene().initial_state.time;
    if (stop_requested()) {
      outcome = "interrupted (shutdown requested)";
      break;
    }
    if (record_failed()) break;  // a command could not be recorded (set in a callback, also while paused)
    if (pacing_->leader_went_back()) {  // the leader was reset: so is this cart, onto the leader's new clock
      pacing_->take_leader_reset();
      reset_run("the leader's /clock going back", kLongestCatchUp);
      continue;
    }
    if (halted()) {
      pacing_->wait_while_paused(run_->simulation().state().time);
      continue;
    }
    if (run_->simulation().at_end()) break;
    // One batch: the steps up to the next publish instant (or the end). Between steps, callbacks
    // run when the transport has queued one (not in lockstep, where they run only at the barrier);
    // in real-time mode the node sleeps until a step is due.
    const double instant = instants_->next_instant(start);
    const double half_step = 0.5 * run_->simulation().step_size();
    if (parameters_.follow_clock) {  // the batch runs once the leader's /clock has reached its end
      if (pacing_->starting_on_leader_clock() && start_on_leader_clock_if_behind()) continue;
      if (pacing_->starting_on_leader_clock()) continue;  // no /clock heard yet
      // A restart served while waiting ends the wait (the instant belongs to the run before it), and
      // so does the leader's clock going back (its reset).
      const std::uint64_t restarts_before = restarts_;
      pacing_->wait_for_clock(std::min(instant, timeline_->end_time()),
                              [this, restarts_before] { return batch_interrupted(restarts_before); });
      if (batch_interrupted(restarts_before)) continue;
    }
    Clock::time_point batch_start = Clock::now();
    bool failed = false;
    bool interrupted = false;
    double due_scene_time = -std::numeric_limits<double>::infinity();  // [s]
    // Steps asked for by ~step while paused run as fast as they can (not paced).
    const bool paced = pacing_->deadlines().paced() && !paused_;
    while (!run_->simulation().at_end() && run_->simulation().state().time + half_step < instant) {
      if (halted()) {  // the ~step request is done (its last step was not on an instant)
        interrupted = true;
        break;
      }
      // Real time: a step is due once the wall clock has reached its scene time (half a step early
      // is fine). Steps due are run back to back; only a node that has caught up runs callbacks or
      // sleeps, so a command takes effect at the first step after its arrival in scene time too.
      const double next_time = run_->simulation().next_step_time();
      // The scene time due by now is read from the clock only when the last reading no longer
      // covers the next step (one clock read per catch-up, not per step).
      if (paced && due_scene_time < next_time - half_step) {
        due_scene_time = pacing_->deadlines().scene_time_at(Clock::now());
      }
      const bool step_due = !paced || due_scene_time >= next_time - half_step;
      if ((!step_due || !paced) && !parameters_.lockstep && callback_queue_.pending()) {
        const std::uint64_t restarts_before = restarts_;
        callback_queue_.call_pending();
        if (batch_interrupted(restarts_before)) {
          interrupted = true;  // paused, failed, stopping, restarted or the leader reset: a new batch
          break;
        }
        if (!step_due) continue;
      }
      if (!step_due) {
        work_.add_stepping(std::chrono::duration<double>(Clock::now() - batch_start).count());
        pacing_->wait_until_due(std::min(instant, timeline_->end_time()));
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
    const double time = run_->simulation().state().time;
    // The publish instants due by now, and the run's end t0 + T (an instant or not), published once.
    const bool instant_due = instants_->pass_publish_instants(start, time, half_step);
    if (instant_due || run_->simulation().at_end()) {
      publisher_->publish_clock(time);
      publish_instant();
      if (record_failed()) break;
      if (parameters_.lockstep) {
        lockstep_->wait_for_commands(time);
        // The wait is the controllers' time, not the simulator's: real-time pacing starts again here.
        if (pacing_->deadlines().paced()) pacing_->deadlines().restart(Clock::now(), run_->simulation().state().time);
      }
      if (parameters_.fast) reports_->report_progress();
    }
  }
  return 0;
}

int CartSimNode::run() {
  if (parameters_.lockstep) lockstep_->wait_for_controllers();
  const WallClockPacing::Clock::time_point run_start = WallClockPacing::Clock::now();
  work_.start(run_start, run_->simulation().state().time);
  pacing_->deadlines().restart(run_start, run_->simulation().state().time);
  std::string outcome = "finished";
  std::optional<std::string> internal_error;
  try {
    run_loop(outcome);
  } catch (const std::exception& error) {
    // Anything else that escapes the loop (e.g. roscpp refusing a time): a clear line, the bag
    // closed, exit 4; never std::terminate with the record left unfinished.
    internal_error = error.what();
  }
  step_requests_->end(run_->simulation().state().time, stop_requested());

  if (!internal_error && !step_failure_ && !record_failed() && !stop_requested() &&
      (publisher_->listened() || reports_->diagnostics_listened())) {
    // publish() only queues a message for roscpp's transport threads: give them a moment to send
    // the last instant (subscribers lost the last /tf when the node left at once). Without a
    // subscriber roscpp queued nothing, and the wait would only lengthen the run (by a third of a
    // 300 s fast run of the default scene).
    ros::WallDuration(kLastInstantLinger).sleep();
  }
  outcome = reports_->report_stop(outcome, internal_error);
  if (record_failed()) {
    ROS_ERROR("cart_sim: bag write failed at t = %.9g s, stopping (the node does not run without its record): %s",
              run_->simulation().state().time, record_->failure()->c_str());
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


// ---- A follower's start on its leader's clock ----------------------------------------------------

bool CartSimNode::start_on_leader_clock_if_behind() {
  const std::optional<RunPacing::LeaderStart> leader =
      pacing_->leader_start(run_->simulation().state().time, instants_->publish_period());
  if (!leader) return false;  // no /clock heard yet
  const double start = leader->start;  // [s]
  if (!(start > run_->simulation().state().time)) return false;  // the leader has not passed this run's first instant
  // The whole run, moved: its end and the ROS-time rules checked before anything changes.
  std::string refusal = timeline_->refusal_to_start_at(start);
  CartState target = run_->simulation().state();
  target.time = start;
  if (refusal.empty() &&
      restart_run("the start on the leader's clock", RunStart::kWhole, [&] { run_->simulation().restart_from(target); },
                  refusal)) {
    ROS_INFO("cart_sim: the leader's /clock is at t = %s s: this cart's run starts on it, at t = %s s (not in "
             "the leader's past, which it would replay in a burst)",
             format_seconds(leader->leader_time).c_str(), format_seconds(start).c_str());
    return true;
  }
  ROS_WARN("cart_sim: cannot start on the leader's clock at t = %s s (%s); this cart steps from t = %s s up to it",
           format_seconds(start).c_str(), refusal.c_str(), format_seconds(run_->simulation().state().time).c_str());
  return false;
}

}  // namespace birkhoff_cart
