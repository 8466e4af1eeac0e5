// cart_sim's pacing (see cart_sim_node.h): callbacks between steps, the absolute wall-clock
// deadlines of real-time mode, pauses and the lockstep barrier.
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <thread>

#include <algorithm>
#include <chrono>

namespace birkhoff_cart {
namespace {

using Clock = WallClockPacing::Clock;

// Longest single sleep [s]: a SIGINT/SIGTERM (whose handler cannot wake a condition) is seen
// within this time.
constexpr double kLongestSleep = 0.1;
/// How long a lockstep barrier polls for the controllers' answers before it sleeps [µs].
constexpr int kLockstepSpinMicroseconds = 200;

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace

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
  Clock::time_point next_note = after(parameters_.lockstep_timeout);
  while (!connected() && !stop_requested()) {
    callback_queue_.wait_until(after(0.01));
    process_callbacks();
    if (Clock::now() >= next_note) {
      ROS_WARN("cart_sim: lockstep: waiting for a controller (publishers on %s and a joint_states subscriber)",
               commands_->expected_topics().c_str());
      next_note = after(parameters_.lockstep_timeout);
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
      ROS_WARN("cart_sim: lockstep: no answer on %s within %g s of wall time after t = %.6g s; going on "
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
  // ros::Time::now() is the /clock of the node that drives it (roscpp hears /clock on its own
  // thread). 1 µs allows for the nanosecond rounding of ROS time.
  // A ~reset served while waiting ends the wait: `time` belongs to the run before it, and the
  // leader's /clock (reset too) would reach it only after as long again.
  constexpr double kStampRounding = 1e-6;  // [s]
  const std::uint64_t resets_before = resets_;
  while (ros::Time::now().toSec() < time - kStampRounding && !stop_requested() && !paused_ &&
         resets_ == resets_before) {
    callback_queue_.wait_until(after(0.01));
    process_callbacks();
  }
}

}  // namespace birkhoff_cart
