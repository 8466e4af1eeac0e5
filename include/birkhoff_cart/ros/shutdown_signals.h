// Signal handling without roscpp's: SIGINT and SIGTERM request a clean shutdown (cart_sim closes its
// bag and prints its summary before it exits, while roscpp and its log output still run).
//
// A first signal sets a flag that the process's own loop polls (cart_sim's time loop, the nodelet
// manager's wait; SignalsPolled marks that span). Outside such a span (start-up, the end) nothing
// polls it, and roscpp may be blocked in a call to the master (it retries for ever when
// ROS_MASTER_URI names a dead port): there the first signal also asks roscpp to shut down, as
// roscpp's own handler does, so the call returns and the process stops.
#pragma once

namespace birkhoff_cart {

/// Exit code after a second SIGINT/SIGTERM: the process leaves at once (128 + SIGINT).
constexpr int kForcedExitCode = 130;

/// Where roscpp's own /clock subscription of a clock source is remapped to (cart_sim's main), so
/// the process does not hear back the /clock it publishes. Nothing is published there.
constexpr const char* kUnheardClockTopic = "/birkhoff_cart/unheard_clock";

/// Installs the SIGINT/SIGTERM handlers: the first signal asks for a clean shutdown (and, while no
/// SignalsPolled lives, roscpp's shutdown), a second one exits at once with kForcedExitCode. Call
/// once after ros::init(..., NoSigintHandler).
void install_shutdown_signal_handlers();
/// True once SIGINT/SIGTERM arrived.
bool shutdown_signal_received();

/// While one lives, a loop of this process polls shutdown_signal_received() itself: a first signal
/// then only sets the flag (roscpp stays up for the loop's clean end). Nestable; thread-safe.
class SignalsPolled {
 public:
  SignalsPolled();
  ~SignalsPolled();
  SignalsPolled(const SignalsPolled&) = delete;
  SignalsPolled& operator=(const SignalsPolled&) = delete;
};

/// ~end_launch (docs/ros_interface.md): a roslaunch that started this process with required="true"
/// prints a red "REQUIRED process has died!" block whenever it ends, also after a clean finish. This
/// asks the parent roslaunch, if the parent is one, to shut down (SIGINT); with `wait` it then waits
/// (at most 5 s) for roslaunch's own SIGINT, so that the process exits while roslaunch is already
/// shutting down. The cart_sim node waits; the nodelet (whose manager roslaunch stops) does not.
void end_parent_launch(bool wait);

}  // namespace birkhoff_cart
