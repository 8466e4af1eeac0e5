// LockstepBarrier (lockstep_barrier.h): cart_sim's waits for its controllers.
#include "birkhoff_cart/ros/lockstep_barrier.h"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

#include <ros/console.h>

#include "birkhoff_cart/core/node_logic/wall_clock_pacing.h"

namespace birkhoff_cart {
namespace {

using Clock = WallClockPacing::Clock;

/// How long the barrier polls for the controllers' answers before it sleeps [µs].
constexpr int kLockstepSpinMicroseconds = 200;

}  // namespace

LockstepBarrier::LockstepBarrier(SignalingCallbackQueue& queue, CommandInputs& commands,
                                 const InstantPublisher& publisher, double timeout,
                                 std::function<bool()> stop_requested, const std::atomic<bool>& paused)
    : queue_(queue), commands_(commands), publisher_(publisher), timeout_(timeout),
      stop_requested_(std::move(stop_requested)), paused_(paused) {}

void LockstepBarrier::wait_for_controllers() {
  const auto connected = [this] { return commands_.controllers_connected() && publisher_.joint_state_subscribers() > 0; };
  // A note every ~lockstep_timeout, at most one a second (a tiny timeout would flood the log).
  const double note_interval = std::max(timeout_, 1.0);  // [s of wall time]
  Clock::time_point next_note = WallClockPacing::after(note_interval);
  while (!connected() && !stop_requested_()) {
    queue_.wait_until(WallClockPacing::after(0.01));
    queue_.call_pending();
    if (Clock::now() >= next_note) {
      ROS_WARN("cart_sim: lockstep: waiting for a controller (publishers on %s and a joint_states subscriber)",
               commands_.expected_topics().c_str());
      next_note = WallClockPacing::after(note_interval);
    }
  }
}

void LockstepBarrier::wait_for_commands(double time) {
  const Clock::time_point give_up = WallClockPacing::after(timeout_);
  // Callbacks run only here in lockstep: everything queued since the last barrier (the answers,
  // ~pause, ~reset) takes effect at this instant.
  queue_.call_pending();
  while (!commands_.answered() && !stop_requested_() && !paused_) {
    const Clock::time_point now = Clock::now();
    if (now >= give_up) {
      ++timeouts_;
      // Counted each time; said at most once a second (a tiny ~lockstep_timeout would flood the log).
      ROS_WARN_THROTTLE(1.0, "cart_sim: lockstep: no answer on %s within %g s of wall time after t = %.6g s; going on "
               "(%lu timeouts so far)",
               commands_.unanswered_topics().c_str(), timeout_, time, static_cast<unsigned long>(timeouts_));
      break;
    }
    // A controller in the same process (a nodelet) answers within microseconds: poll for it a
    // little before sleeping, since a sleep and its wake-up cost more than the answer takes.
    const Clock::time_point spin_until = now + std::chrono::microseconds(kLockstepSpinMicroseconds);
    while (!queue_.pending() && Clock::now() < spin_until) std::this_thread::yield();
    queue_.wait_until(std::min(give_up, now + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(WallClockPacing::kLongestSleep))));
    queue_.call_pending();
  }
  // The answers are recorded at the instant they answer, in the order of their topics' names.
  commands_.end_barrier(time);
}

}  // namespace birkhoff_cart
